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
:mod:`gatetherm.api.zoo`; every public name is offered here, its module imported when the name is
first used (a script or a service pays for the tasks it uses).

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
import sys
import types

from gatetherm import InputError, _api_modules  # noqa: F401 - InputError with the ranges below, for the command line
from gatetherm.checks import POSITIVE, Range  # noqa: F401
from gatetherm.process import start_libraries  # noqa: F401 - the command line's first step

WORKERS = Range(1, whole=True)  # worker processes: the command line's --workers (not in the reference)
SEED = Range(0, 2**32 - 1, whole=True)  # a random seed: the command line's --seed (not in the reference)

_CONSTANTS = {
    "COMPENSATE_OUTPUTS": ("gatetherm.api.compensation", "OUTPUTS"),  # what `compensate` writes into --out
    "WRITTEN": ("gatetherm.api.compensation", "WRITTEN"),
    "DIAGNOSE_OUTPUTS": ("gatetherm.api.diagnosis", "OUTPUTS"),
    "SolverError": ("gatetherm.solvers.errors", "SolverError"),  # with PointsFailed: the command line's dispatcher
    "PointsFailed": ("gatetherm.studies.sweeps.runner", "PointsFailed"),
    "FORMATS": ("gatetherm.studies.run.formats", "FORMATS"),  # the command line's export formats
    "K_SOURCES": ("gatetherm.studies.control.methods", "K_SOURCES"),  # the command line's choices
    "THERMOCOUPLES": ("gatetherm.studies.control.predictive", "THERMOCOUPLES"),  # the command line's default
}
"""The command line's constants (not in the reference): name -> (module, its name there), imported on first use."""

_WHERE = _api_modules(__path__)
"""Each offered name -> the module of this package whose ``PUBLIC`` offers it, read from the sources
(:func:`gatetherm._api_modules`, as ``gatetherm.API``): a new task is one module (``core/api/TASK.py``
with ``PUBLIC = ("task", "TaskResult")``), found without a list to edit, imported when one of its
names is first used (:func:`__getattr__`)."""

__all__ = sorted(_WHERE)


def _offer(module: types.ModuleType) -> None:
    """Put the names of ``module``'s ``PUBLIC`` into this module's globals, each function wrapped to
    check its arguments' types where it is called (:func:`gatetherm.api.boundary.checked`). A name
    already set here (a test's monkeypatch) is left as it is."""
    import inspect

    from gatetherm.api.boundary import checked

    here = globals()
    for name in getattr(module, "PUBLIC", ()):
        value = getattr(module, name)
        if inspect.isfunction(value) and not hasattr(value, "__checked__"):
            value = checked(value)
        current = here.get(name)
        if current is None or current is module:  # not yet offered, or the submodule of the same name
            here[name] = value


class _Api(types.ModuleType):
    """This module: a task module imported by anyone (``from gatetherm.api.live import …``) whose
    name is also an offered name (``live``, ``run``) leaves the function offered here, not the
    submodule, as the attribute (the import system sets the submodule on its package)."""

    def __setattr__(self, name, value):
        if isinstance(value, types.ModuleType) and value.__name__ == f"{__name__}.{name}" and name in _WHERE:
            _offer(value)
            if globals().get(name) is not value:
                return
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Api


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__, *_CONSTANTS, "plot", "METHODS", "COMPENSATION_METHODS",
                   "STEPWISE_METHODS", "METHOD_SUMMARIES"})


def __getattr__(name: str):
    """Each offered name (``__all__``): the module of this package offering it imported on first use,
    its names cached here. ``gatetherm.api.plot``: the plots (:mod:`gatetherm.validation.plots.api`,
    as ``gt.plot``); the compensation methods (:mod:`gatetherm.studies.control.method`), read when
    asked: ``METHODS`` every one, ``COMPENSATION_METHODS`` those ``gatetherm compensate --method``
    offers (errormodel is its --model), ``METHOD_SUMMARIES`` their summaries by name,
    ``STEPWISE_METHODS`` those of ``gatetherm live``; the command line's constants (``_CONSTANTS``)."""
    import importlib

    if name in _WHERE:
        _offer(importlib.import_module(f"{__name__}.{_WHERE[name]}"))
        return globals()[name]
    if name in _CONSTANTS:
        module, attribute = _CONSTANTS[name]
        globals()[name] = value = getattr(importlib.import_module(module), attribute)
        return value
    if name in ("METHODS", "COMPENSATION_METHODS", "STEPWISE_METHODS", "METHOD_SUMMARIES"):
        from gatetherm.studies.control import method

        return {"METHODS": method.names, "COMPENSATION_METHODS": method.offered,
                "STEPWISE_METHODS": lambda: method.offered(stepwise=True),
                "METHOD_SUMMARIES": lambda: {m.name: m.summary for m in method.methods() if m.offered}}[name]()
    if name == "plot":
        return importlib.import_module("gatetherm.validation.plots.api")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
