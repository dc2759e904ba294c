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

The functions live by task in this package's modules: :mod:`gatetherm.api.case` (cases,
schedules), :mod:`gatetherm.api.run` (runs), :mod:`gatetherm.api.jobs` (runs written: ``gatetherm
run``, ``simulate``), :mod:`gatetherm.api.frame` (``mesh``, ``beam``), :mod:`gatetherm.api.reduction`,
:mod:`gatetherm.api.control` (compensation, diagnosis), :mod:`gatetherm.api.compensation` and
:mod:`gatetherm.api.diagnosis` (the commands ``compensate`` and ``diagnose``), :mod:`gatetherm.api.errormodel`,
:mod:`gatetherm.api.sensors`, :mod:`gatetherm.api.study` (sweeps), :mod:`gatetherm.api.reports`,
:mod:`gatetherm.api.validate_study`, :mod:`gatetherm.api.export`, :mod:`gatetherm.api.live` and
:mod:`gatetherm.api.zoo`; every public name is offered here.

### Errors

Every public function checks its arguments where it is called, before any numerics, and says
in one line (``str(err)``) which argument is wrong and how to fix it. Types come from the
function's annotations (:mod:`gatetherm.api.boundary`: a string where a list belongs, a number
for a path, a callback that is not a function, a NaN, a fraction for a count are refused
before any work); ranges and names from each function:

- :class:`TypeError` for an argument of the wrong type: ``gt.run("case.toml")`` gives
  ``case: got str 'case.toml', expected a Case; make one with gt.load_case(path) or
  gt.gate_frame()``; the same for ``schedule``, ``effects``, ``keep``, ``on_step``, ``ax``, a
  bool where a number belongs (``gt.condition(True)``) …
- :class:`gatetherm.InputError` (a ``ValueError``) for a value out of its range or one that
  would mislead: ``gt.gate_frame(dim=4)`` gives ``dim: got 4, must be 2 or 3; …``;
  ``gt.condition(1, step_s=7)`` (7 s does not divide the 5 h: the run would end at 17 997 s),
  ``gt.reduce(case, states=0)`` or a steady case, ``gt.load_case(path, mesh_factor=nan)``,
  ``keep=[nan]``, ``fields_every=0``, ``run.field("T", t=nan)``, ``gt.plot.deformed`` of a
  heat-only run, ``gt.plot.save(ax, path, dpi=1e6)``, ``run.write(folder)`` that would overwrite
  a file the case reads. The same class reports bad input files (case files, schedules, model
  files), naming the file, the key or line and the fix; a number that would be written to a
  file as NaN or infinity is :class:`gatetherm.checks.NonFiniteError`, a kind of InputError
  naming the quantity.
- :class:`gatetherm.UnknownName` (an InputError and a ``KeyError``) for a name not among those
  offered: ``run["nosuch_um"]``, ``run.field("Tx")``, naming the ones there are.
- ``OSError`` for a file that cannot be written (a full disk), naming the file.

Anything else is a defect of gatetherm: please report it.
"""
from gatetherm import InputError  # noqa: F401 - with the ranges below, for the command line's checks
from gatetherm.api.compensation import OUTPUTS as COMPENSATE_OUTPUTS  # noqa: F401 - for the command line
from gatetherm.api.compensation import WRITTEN  # noqa: F401 - for the command line
from gatetherm.api.diagnosis import OUTPUTS as DIAGNOSE_OUTPUTS  # noqa: F401 - for the command line
from gatetherm.checks import POSITIVE, Range  # noqa: F401
from gatetherm.solvers.errors import SolverError  # noqa: F401 - with these below, for the command line's dispatcher
from gatetherm.studies.run.formats import FORMATS  # noqa: F401 - the command line's export formats
from gatetherm.studies.sweeps.runner import PointsFailed  # noqa: F401

from gatetherm.studies.control.methods import K_SOURCES  # noqa: F401 - the command line's choices
from gatetherm.studies.control.predictive import THERMOCOUPLES  # noqa: F401 - the command line's default

WORKERS = Range(1, whole=True)  # worker processes: the command line's --workers (not in the reference)
SEED = Range(0, 2**32 - 1, whole=True)  # a random seed: the command line's --seed (not in the reference)


def _discover(namespace: dict) -> list[str]:
    """Import every module of this package and offer the names of its ``PUBLIC`` in ``namespace``
    (this module's): a new task is one module (``core/api/TASK.py`` with ``PUBLIC = ("task",
    "TaskResult")``), found without a list to edit. ``gatetherm.API`` reads the same ``PUBLIC``
    from the sources."""
    import importlib
    import pkgutil

    names = []
    for info in pkgutil.iter_modules(__path__):
        module = importlib.import_module(f"{__name__}.{info.name}")
        for name in getattr(module, "PUBLIC", ()):
            if name in names:
                raise ImportError(f"{module.__name__}: {name} is offered by another module of gatetherm.api too")
            namespace[name] = getattr(module, name)
            names.append(name)
    return sorted(names)


__all__ = _discover(globals())


def _check_arguments() -> None:
    """Every public function checks its arguments' types where it is called
    (:func:`gatetherm.api.boundary.checked`)."""
    import inspect

    from gatetherm.api.boundary import checked

    for name in __all__:
        if inspect.isfunction(globals()[name]) and not hasattr(globals()[name], "__checked__"):
            globals()[name] = checked(globals()[name])


_check_arguments()


def __getattr__(name: str):
    """``gatetherm.api.plot``: the plots (:mod:`gatetherm.validation.plots.api`, as ``gt.plot``),
    imported on first use; the compensation methods (:mod:`gatetherm.studies.control.method`), read
    when asked: ``METHODS`` every one, ``COMPENSATION_METHODS`` those ``gatetherm compensate
    --method`` offers (errormodel is its --model), ``METHOD_SUMMARIES`` their summaries by name,
    ``STEPWISE_METHODS`` those of ``gatetherm live``."""
    from gatetherm.studies.control import method

    if name in ("METHODS", "COMPENSATION_METHODS", "STEPWISE_METHODS", "METHOD_SUMMARIES"):
        return {"METHODS": method.names, "COMPENSATION_METHODS": method.offered,
                "STEPWISE_METHODS": lambda: method.offered(stepwise=True),
                "METHOD_SUMMARIES": lambda: {m.name: m.summary for m in method.methods() if m.offered}}[name]()
    if name == "plot":
        import importlib

        return importlib.import_module("gatetherm.validation.plots.api")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
