"""The public Python API: what a notebook or a script calls (``import gatetherm as gt``).

It composes the layers below for the common tasks and is itself composed by nothing but the
command line (``gatetherm.cli``), whose every command parses its arguments and calls a
function here::

    import gatetherm as gt
    case = gt.load_case("validation/examples/c_frame/case.toml")
    run = gt.run(case)                         # the case's own schedule, or schedule=...
    run.time, run["delta_um"]                  # numpy arrays
    run.field("T", t=run.time[-1])             # nodal fields on demand
    gt.plot.series(run, "delta_um", ax=ax)     # plots take ax= and return it
    run.write("out/")                          # what `gatetherm run` writes

The paper's frame is a case like any other: ``gt.gate_frame(dim=2)``.

The functions live by task in this package's modules: :mod:`gatetherm.api.run` (cases,
schedules, runs), :mod:`gatetherm.api.reduction`, :mod:`gatetherm.api.control` (compensation,
diagnosis), :mod:`gatetherm.api.errormodel` and :mod:`gatetherm.api.sensors`; every public name is offered here.
"""
from gatetherm.api.control import compensate, diagnose
from gatetherm.api.errormodel import Prediction, errormodel_fit, errormodel_predict, errormodel_refit
from gatetherm.api.reduction import check_rom, check_schedules, reduce, write_reduction
from gatetherm.api.run import Case, Run, Schedule, beam_coefficients, condition, configure, gate_frame, load_case, run, \
    schedule_file
from gatetherm.api.sensors import check_placement, place_sensors, write_placement

__all__ = ["Case", "Prediction", "Run", "Schedule", "beam_coefficients", "check_placement", "check_rom",
           "check_schedules", "compensate", "condition", "configure", "diagnose", "errormodel_fit",
           "errormodel_predict", "errormodel_refit", "gate_frame", "load_case", "place_sensors", "reduce",
           "run", "schedule_file", "write_placement", "write_reduction"]
