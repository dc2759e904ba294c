"""``gatetherm compensate`` as one call: the record (a file, a paper condition or a case's own run)
compensated, and the result that writes and summarises it (:mod:`gatetherm.api`)."""
from __future__ import annotations

import dataclasses
import logging
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from gatetherm import InputError, write_text_atomic
from gatetherm.api.run import PATH, Case
from gatetherm.checks import argument, json_text
from gatetherm.outdir import output_dir

PUBLIC = ("CompensationRun", "compensate_run")  # offered as gt.NAME (gatetherm.api finds them here)

log = logging.getLogger(__name__)

WRITTEN = ("u_piezo_um", "delta_pred_um", "delta_comp_um")
"""Columns compensate adds to its input. Those of an earlier compensation (a file with its
``compensation`` metadata) and ``u_piezo_um`` are replaced with a warning; in any other
file a column of these names is refused, since it would be lost."""
#: What a compensation writes into its output directory; a rerun replaces all of it.
OUTPUTS = ("compensated.csv", "compensation.png", "piezo_loops.png", "summary.json")


def _name(given) -> str | None:
    """A record's or case's name as given (a Case: its source)."""
    return None if given is None else given if isinstance(given, str) else given.source if isinstance(given, Case) \
        else str(given)


def _um(value) -> str:
    return "n/a" if value is None else f"{value:.2f} um"


@dataclass(frozen=True)
class CompensationRun:
    """A compensated record (:func:`compensate_run`): what ``gatetherm compensate`` writes and prints."""

    series: object
    """The input record with the columns :data:`WRITTEN` added (a TimeSeries)."""
    compensation: object
    """The :class:`~gatetherm.studies.control.methods.Compensation` (``.loop``, ``.summary``, ``.label``)."""
    record: dict
    """summary.json's content: the compensation's summary and where the record and model came from."""
    what: str
    """The record's name: its file, ``condition N`` or the case file."""
    method: str
    """paper, mlr, rom or errormodel."""
    actuator: object
    """The actuator in the loop (ActuatorParams), None: ideal."""
    settle_s: float
    """The settling time after which the residual band is measured, s."""
    delta_label: str
    """The displacement's label on the plot."""
    keep: tuple
    """The run's input files, never overwritten or removed by :meth:`write`."""

    def write(self, out: str | os.PathLike) -> str:
        """Write ``out/compensated.csv``, ``compensation.png``, ``piezo_loops.png`` (with an actuator) and
        ``summary.json`` (last), as one transaction (:func:`gatetherm.outdir.output_dir`: a failure
        leaves the previous results). Returns the line naming what was written (:meth:`wrote`)."""
        with output_dir(out, OUTPUTS, keep=self.keep) as stage:
            self.write_into(stage)
        return self.wrote(out)

    def wrote(self, out: str | os.PathLike) -> str:
        """The line naming the files written into ``out``."""
        return f"wrote {out}/compensated.csv, compensation.png, {'piezo_loops.png, ' if self.actuator else ''}" \
               "summary.json"

    def write_into(self, stage: Path) -> None:
        """Write the files into ``stage``, an :func:`~gatetherm.outdir.output_dir` stage."""
        from gatetherm.studies.run.timeseries import write_timeseries
        from gatetherm.validation.plots import save
        from gatetherm.validation.plots.compensation import plot_compensation, plot_piezo_loops

        text = json_text(self.record, "summary.json", indent=2)
        write_timeseries(stage / "compensated.csv", self.series)
        save(plot_compensation(self.compensation.loop, title=f"{self.what}: {self.method}, "
                               f"{self.compensation.label}", delta=self.delta_label), stage / "compensation.png")
        if self.actuator:
            save(plot_piezo_loops(self.actuator), stage / "piezo_loops.png")
        write_text_atomic(stage / "summary.json", text)

    def summary(self) -> str:
        """The figures ``gatetherm compensate`` prints: bands, updates, the held-out benefit, warnings."""
        s, comp = self.record, self.compensation
        lines = [f"{self.what}: {comp.head}; swing {s['swing_um']:.2f} um, "
                 f"prediction error band {_um(s['prediction_error_band_um'])}, "
                 f"residual band {_um(s['residual_band_um'])} over the whole run after {self.settle_s / 60:g} min, "
                 f"as applied ({_um(s['residual_at_updates_um'])} at the update instants), {s['updates']} updates"]
        b = s["benefit"]
        checked = "the correction as applied" if b["basis"].startswith("as applied") else \
            "a separate check, not the correction applied above"
        lines.append(f"held-out last {b['fraction'] * 100:.0f} % ({checked}): {_um(b['held_out_um'])} compensated, "
                     f"{_um(b['uncompensated_um'])} uncompensated ({b['verdict']}; {b['basis']})")
        lines += [f"warning: {line}" for line in s.get("warnings", [])]
        if "warning" in s:
            lines.append(f"warning: {s['warning']}")
        return "\n".join(lines)


def compensate_run(data: str | os.PathLike | None = None, case: str | os.PathLike | Case | None = None, *,
                   condition: int | None = None, dim: int = 2, config: str | os.PathLike | None = None,
                   method: str = "paper",
                   interval_min: float = 5.0, updates: str = "event", max_updates: int = 60,
                   ideal: bool = False, rom: str | os.PathLike | None = None, model: str | os.PathLike | None = None,
                   out: str | os.PathLike | None = None,
                   on_progress: Callable[[int, int], None] | None = None, **settings) -> CompensationRun:
    """Compensate a record as ``gatetherm compensate`` does: a time-series file, one of the paper's
    conditions simulated on the frame, or a case's own run; never silently worse (:func:`compensate`).

    Parameters
    ----------
    data : path, optional
        The record (docs/data-format.md): θ_A, θ_B, θ_C and δ (or what ``model`` reads).
    case : path or Case, optional
        The model; without ``data`` its own run is compensated (it needs ``[time]`` and ``[signals]``).
        Default: the paper's frame of ``dim`` and ``config``.
    condition : int, optional
        The paper's condition 1, 2 or 3, simulated on the frame (not with ``case``).
    dim, config
        The paper frame's dimension and model file, where no ``case`` is given.
    method : str
        ``"paper"``, ``"mlr"`` or ``"rom"``.
    interval_min : float
        The actuator's update interval, min.
    updates, max_updates
        rom: ``"event"`` (within the budget ``max_updates``) or ``"fixed"`` (every ``interval_min``).
    ideal : bool
        An ideal actuator (the stroke equals the command) instead of the case's.
    rom : path, optional
        A reduced model from ``gatetherm reduce`` (rom; default: built, and cached in ``out``).
    out : path, optional
        Write the result there too (:meth:`CompensationRun.write`), the directory made ready and
        locked before the run (:func:`gatetherm.outdir.output_dir`: a refusal or failure leaves the
        previous results); a reduced model built for rom is cached there (rom.npz, rom.key).
    model : path, optional
        A model.json of ``gatetherm errormodel fit`` to replay instead of ``method`` (with ``target``,
        ``correction``).
    on_progress : callable, optional
        ``on_progress(i, n)``: the run's samples, then the compensation, i increasing up to n.
    **settings
        Fields of :class:`gatetherm.studies.control.methods.Settings`: ``Ki``, ``Kc`` (um/K), ``k_source``,
        ``states``, ``sensors``, ``target``, ``correction``, ``force``, ``held_out`` (fraction).

    Returns
    -------
    CompensationRun
        ``.record`` (summary.json's figures), ``.compensation``, ``.write(out)``, ``.summary()``.
    """
    from gatetherm.api.case import gate_frame, load_case
    from gatetherm.studies.control.compensator import CompensatorParams
    from gatetherm.studies.control.methods import Settings, compensate as run_methods
    from gatetherm.studies.control.predictive import PredictiveParams
    from gatetherm.studies.run.reduce import load_rom
    from gatetherm.studies.run.timeseries import read_timeseries
    from gatetherm.validation.plots.labels import signal_labels

    argument("data", data, (*PATH, type(None)), "a time-series file's path or None")
    argument("case", case, (*PATH, Case, type(None)), "a case file's path, a Case or None")
    if data is not None and condition is not None:
        raise InputError("data", "and condition are both given", "give one: a measured record, or one of the "
                         "paper's conditions to simulate")
    if not interval_min > 0:
        raise InputError("interval_min", f"got {interval_min!r}, must be > 0 min", "e.g. interval_min=5.0")
    params = CompensatorParams(update_interval_s=interval_min * 60.0)
    control = PredictiveParams(mode=updates, max_updates=max_updates, interval_s=params.update_interval_s)
    fitted = None
    if model is not None:  # a bad model file or target fails before anything is run
        from gatetherm.studies.errormodel.model import load_model
        from gatetherm.studies.errormodel.replay import loop_target

        fitted = load_model(model)
        loop_target(fitted, settings.get("target"))
    s = Settings("errormodel" if fitted else method, params, control=control, model=fitted, **settings)
    _refuse_unused(s, rom=rom, updates=updates, max_updates=max_updates)
    if condition is not None:
        from gatetherm.frame.conditions import condition as check_condition

        check_condition(condition)  # a bad number fails before the model is built
    if isinstance(case, Case):
        model_case = case
    else:
        model_case = load_case(case) if case is not None and condition is None else gate_frame(dim, config)
    keep = (config, None if data is None else str(data), *model_case.files)
    ts, what = None, None
    if data is not None:
        ts, what = read_timeseries(data, required=("time_s",)), str(data)
        clash = [name for name in WRITTEN[1:] if name in ts]
        if clash and "compensation" not in ts.metadata:
            raise InputError(f"{data}, column {clash[0]}", "compensate writes a column of this name "
                             "and the file is not from an earlier compensate", "rename the column so that it is kept")

    def compensated() -> CompensationRun:
        nonlocal ts, what
        steps = 1
        if ts is None:
            ts, steps = _own_run(model_case, condition, on_progress)
            what = f"condition {condition}" if condition is not None else _name(case)
        actuator = None if ideal else model_case.actuator
        replaced = [name for name in WRITTEN if name in ts]
        if replaced:
            log.warning("%s: the existing columns %s are replaced", what, ", ".join(replaced))
        borrowed = "the paper frame's piezo (no --case); give the machine's case for its actuator, or --ideal" \
            if case is None and condition is None else ""  # a record of the user's machine on the frame's actuator
        comp = run_methods(ts, model_case, s, actuator, rom=load_rom(rom) if rom else None,
                           rom_dir=None if out is None else Path(out), source=what, rom_source=rom, borrowed=borrowed)
        if on_progress is not None:
            on_progress(steps, steps)
        record = {**comp.summary, "data": _name(data), "case": _name(case), "condition": condition,
                  "config": model_case.source, "dim": model_case.dim, **({"model": model} if model else {})}
        json_text(record, "summary.json", indent=2)  # a non-finite figure is refused before anything is written
        loop = comp.loop
        series = ts.with_columns(u_piezo_um=loop.stroke_um, delta_pred_um=loop.delta_pred_um,
                                 delta_comp_um=loop.delta_comp_um)
        series = dataclasses.replace(series, metadata={
            **series.metadata, "compensation": f"{'' if s.method == 'paper' else s.method + ': '}{comp.label}, "
            f"{'actuator model' if actuator else 'ideal actuator'}"})
        return CompensationRun(series, comp, record, what, s.method, actuator, params.settle_s,
                               signal_labels(model_case.problem).get("delta_um", "δ"), keep)

    if out is None:
        return compensated()
    with output_dir(out, OUTPUTS, keep=keep) as stage:
        result = compensated()
        result.write_into(stage)
    return result


def _own_run(case: Case, condition: int | None, on_progress) -> tuple:
    """The time series of ``case``'s own run (or of the paper's ``condition`` on the frame), and the
    progress steps (the run's samples and the compensation)."""
    from gatetherm.api.case import condition as paper_condition
    from gatetherm.api.run import run
    from gatetherm.studies.control.methods import compensated_case
    from gatetherm.studies.run.timeseries import FORMAT

    compensated_case(case)
    schedule = paper_condition(condition, case) if condition is not None else case.schedule
    res = run(case, schedule, keep=(), on_step=on_progress and (lambda i, n: on_progress(i, n + 1)))
    meta = {"format": FORMAT, "source": "gatetherm compensate", "schedule": schedule.label,
            "dim": str(case.dim), "config": case.source}
    return res.scenario.series({**meta, **({"condition": str(condition)} if condition else {})}), \
        len(schedule.times) + 1


#: The settings that only one method reads (the option, its methods): given with another method
#: they would be ignored without a word.
ONLY_FOR = {"target": ("--target", ("errormodel",)), "correction": ("--correction", ("errormodel",)),
            "Ki": ("--Ki", ("paper",)), "Kc": ("--Kc", ("paper",)), "k_source": ("--k-source", ("paper",)),
            "states": ("--states", ("rom",)), "sensors": ("--sensors", ("rom",)), "rom": ("--rom", ("rom",)),
            "updates": ("--updates", ("rom",)), "max_updates": ("--max-updates", ("rom",))}


def _refuse_unused(s, **given) -> None:
    """InputError naming a setting given (not its default) that the method of ``s`` does not read."""
    import dataclasses
    import inspect

    defaults = {f.name: f.default for f in dataclasses.fields(s)}
    defaults.update({k: p.default for k, p in inspect.signature(compensate_run).parameters.items() if k in given})
    values = {**{k: getattr(s, k) for k in ONLY_FOR if hasattr(s, k)}, **given}
    for key, (option, methods) in ONLY_FOR.items():
        if key in values and s.method not in methods and values[key] != defaults[key]:
            what = "--model" if s.method == "errormodel" else f"--method {s.method}"
            use = "--model MODEL.json" if methods == ("errormodel",) else f"--method {methods[0]}"
            raise InputError(option, f"is read by {use} only: {what} would ignore it", f"drop {option}, or use {use}")
