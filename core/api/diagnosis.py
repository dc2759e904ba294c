"""``gatetherm diagnose`` as one call: the model of a case file or the paper's frame replayed
through a measured run, and the result that writes and summarises its diagnosis (:mod:`gatetherm.api`)."""
from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Mapping, Sequence

from gatetherm import InputError, write_text_atomic
from gatetherm.api.run import PATH, Case
from gatetherm.checks import argument

PUBLIC = ("DiagnosisRun", "diagnose_run", "diagnosis_hypotheses", "diagnosis_model")

#: What a diagnosis writes into its output directory; a rerun replaces all of it.
OUTPUTS = ("residuals.png", "scores.png", "before_after.png", "model.toml", "report.md", "diagnosis.json")


def diagnosis_model(case: str | os.PathLike | None = None, *, dim: int = 2, config: str | os.PathLike | None = None,
                    mesh_size: float | None = None, mesh_factor: float | None = None) -> Case:
    """The model a diagnosis replays: a case file, or the paper's frame.

    Parameters
    ----------
    case : path, optional
        A case file (it needs ``[time]``); default: the paper's frame.
    dim, config
        The frame's dimension (2 or 3) and model file (default: the shipped paper model).
    mesh_size : float, optional
        The frame's element size, m (default: the model file's); not with ``case``.
    mesh_factor : float, optional
        The case file's element sizes times this factor; only with ``case``.

    Returns
    -------
    Case
        Raises InputError for a combination that does not go (naming the command's options).
    """
    from gatetherm.api.case import gate_frame, load_case

    argument("case", case, (*PATH, type(None)), "a case file's path or None")
    if case is None:
        if mesh_factor is not None:
            raise InputError("--mesh-factor", "goes with --case only", "give --mesh-size for the paper model")
        model = gate_frame(dim, config)
        if mesh_size is not None:
            model = model.with_overrides({"mesh.size" if dim == 2 else "mesh.size_3d": mesh_size})
        return model
    if mesh_size is not None:
        raise InputError("--case/--mesh-size", "a case file gives its own mesh", "set [mesh] in the case file instead")
    model = load_case(case, 1.0 if mesh_factor is None else mesh_factor)
    if model.time is None:
        raise InputError(f"{case}: time", "a diagnosed case needs [time] (a transient run)",
                         "add [time] with end and step; the run's times come from --data")
    return model


def diagnosis_hypotheses(model: Case, uncertain: Sequence[str] = (), as_json: bool = False) -> str:
    """The hypotheses a diagnosis of ``model`` tries: catalogue effects, existing parameters,
    dimensions and sensor faults (``gatetherm diagnose --list-effects``).

    Parameters
    ----------
    model : Case
        The model (:func:`diagnosis_model`).
    uncertain : sequence of str
        Dimensions to try besides those the model marks (``geometry.NAME``, ``mesh.parameters.NAME``).
    as_json : bool
        A JSON list of the hypotheses instead of a table.

    Returns
    -------
    str
        The table (kind, name, parameter, plausible range, unit, and what each means) or the JSON text.
    """
    from gatetherm.studies.diagnosis.hypotheses import catalogue
    from gatetherm.studies.diagnosis.progress import FIRST_RUNS
    from gatetherm.studies.run.simulate import signal_columns

    argument("model", model, Case, "a Case", "make one with gt.load_case(path) or gt.gate_frame()")
    pieces = catalogue(model, signal_columns(model.problem), tuple(uncertain))
    if as_json:
        return json.dumps([p.describe() for p in pieces], indent=2)
    rows = [f"{'kind':<10} {'name':<34} {'parameter':<12} {'plausible range':<23} {'unit':<9}"]
    for p in pieces:
        rows.append(f"{p.kind:<10} {p.label:<34} {p.param:<12} {f'{p.lo:.4g} … {p.hi:.4g}':<23} {p.unit:<9}")
        if p.kind != "sensor":
            rows.append(f"{'':<11}{p.doc}")
    rows.append("Sensor faults are tried on every compared channel of the file (further T_<name>_degC too).")
    rerun = sum(p.rerun for p in pieces if p.kind != "sensor")
    rows.append(f"A diagnosis tries every hypothesis above (--effects, --parameters, --no-sensors restrict them); "
                f"{rerun} need model runs (about {FIRST_RUNS} each in the first round, a few tens more per piece "
                "chosen), the others act on a kept run.")
    return "\n".join(rows)


def _with_unit(number: str, unit: str) -> str:
    """``number`` and its unit, none for a factor (unit 1)."""
    return number if unit in ("", "1") else f"{number} {unit}"


def order_warning(diag, metadata: dict) -> str:
    """The warning of a model whose discretisation error exceeds the resolution; where it was replayed
    with P2 and the data are gatetherm's own run (metadata ``source: gatetherm``), the hint to --keep-order."""
    made = metadata.get("source", "").startswith("gatetherm")
    return (f"warning: the model's discretisation error (P2 - P1) exceeds the resolution on "
            f"{', '.join(diag.too_coarse)}; " + ("the diagnosis replayed it with P2 elements" if diag.order == 2 else
                                                "refine the mesh (--mesh-factor) or set order = 2")
            + ("; the data are a run gatetherm simulated (source: gatetherm): if on this mesh with P1, they carry the "
               "same discretisation error, and --keep-order replays with P1" if made and diag.order == 2 else "")
            + " (report.md, 1. Replay)")


@dataclass(frozen=True)
class DiagnosisRun:
    """A diagnosis of a measured file (:func:`diagnose_run`): what ``gatetherm diagnose`` writes and prints."""

    diagnosis: object
    """The :class:`~gatetherm.studies.diagnosis.discrepancy.Diagnosis` (verdict, pieces, groups …)."""
    model: Case
    """The model replayed."""
    data: str
    """The measured file, as given."""
    metadata: dict
    """The measured file's metadata (its ``source``)."""
    record: dict
    """What diagnosis.json records besides the diagnosis: ``case``, ``mesh_size``, ``mesh_factor``."""
    keep: tuple
    """The run's input files, never overwritten or removed by :meth:`write`."""

    def write(self, out: str | os.PathLike) -> str:
        """Write ``out/residuals.png``, ``scores.png``, ``before_after.png`` and ``model.toml`` (pieces
        found, the paper frame), ``report.md`` and last ``diagnosis.json``, as one transaction
        (:func:`gatetherm.outdir.output_dir`). Returns the line naming what was written (:meth:`wrote`)."""
        from gatetherm.outdir import output_dir

        with output_dir(out, OUTPUTS, keep=self.keep) as stage:
            self.write_into(stage, out)
        return self.wrote(out)

    def wrote(self, out: str | os.PathLike) -> str:
        """The line naming the files written into ``out``, the model runs and the time taken."""
        return f"wrote {out}/report.md, diagnosis.json ({self.diagnosis.runs} model runs, " \
               f"{self.diagnosis.seconds:.0f} s)"

    def write_into(self, stage: Path, out: str | os.PathLike) -> None:
        """Write the files into ``stage``, an :func:`~gatetherm.outdir.output_dir` stage of ``out``."""
        from gatetherm.studies.diagnosis.discrepancy import adopted_case
        from gatetherm.studies.diagnosis.report import report_markdown
        from gatetherm.studies.run.output import write_json
        from gatetherm.validation.plots import save
        from gatetherm.validation.plots.discrepancy import DPI, plot_before_after, plot_residuals, plot_scores

        diag, case = self.diagnosis, self.model
        adopted = adopted_case(case, diag)
        files = {"residuals": "residuals.png"}
        save(plot_residuals(diag), stage / files["residuals"], DPI)
        if diag.rounds:
            files["scores"] = "scores.png"
            save(plot_scores(diag), stage / files["scores"], DPI)
        if adopted is not None:
            files["before_after"] = "before_after.png"
            save(plot_before_after(diag), stage / files["before_after"], DPI)
        text = None if adopted is None else adopted.origin.model_file(adopted, (
            f"gatetherm diagnose of {self.data}: verdict {diag.verdict}, pieces "
            + ", ".join(r.piece.label for r in diag.pieces) + f"\nbase model: {case.source}"))
        if text is not None:
            files["model"] = str(Path(out) / "model.toml")
            write_text_atomic(stage / "model.toml", text)
        write_text_atomic(stage / "report.md", report_markdown(diag, self.data, case.source, files))
        write_json(stage / "diagnosis.json", {**diag.summary(), "data": self.data, "config": case.source,
                                              "case": self.record.get("case"), "model_file": files.get("model"),
                                              "mesh_size": self.record.get("mesh_size"),
                                              "mesh_factor": self.record.get("mesh_factor")})

    def summary(self) -> str:
        """The verdict, the pieces found and the held-out RMS before and after, as ``gatetherm diagnose`` prints."""
        diag = self.diagnosis
        s = diag.summary()
        lines = [f"verdict: {diag.verdict}"]
        for r in diag.pieces:
            lines.append(f"  {r.piece.kind} {r.piece.label}: {r.piece.param} = "
                         f"{_with_unit(f'{r.value:.4g} ± {r.sigma:.2g}', r.piece.unit)}, "
                         f"{100 * r.share:.0f} % of the held-out residual"
                         + (f" (or: {', '.join(q.label for q in r.alternatives)})" if r.alternatives else ""))
        lines += [f"  cannot be told apart: {g.sentence()}" for g in diag.groups]
        lines += [f"  stand-in, not a cause: {p.label} {p.param} = {_with_unit(f'{v:.4g}', p.unit)} ({why})"
                  for p, v, why in diag.stand_ins]
        lines += [f"  dropped, the model refuses it: {p.label} ({why})" for p, why in diag.dropped]
        if diag.cause:
            lines.append(f"  what kind of cause would fit: {diag.cause}")
        if s["best_rejected"]:
            lines.append(f"best rejected: {s['best_rejected']} (gain {s['margin']:.1f} < margin {diag.margin_min:g})")
        if s["rms_after_um"] is not None:
            lines.append(f"held-out RMS of delta: {s['rms_before_um']:.3g} um -> {s['rms_after_um']:.3g} um")
        if diag.too_coarse:
            lines.append(order_warning(diag, self.metadata))
        return "\n".join(lines)


def diagnose_run(model: Case, data: str | os.PathLike, *, out: str | os.PathLike | None = None,
                 record: Mapping[str, object] | None = None, config: str | os.PathLike | None = None,
                 on_progress: Callable[[int, int], None] | None = None, **settings) -> DiagnosisRun:
    """Diagnose the measured file ``data`` against ``model`` as ``gatetherm diagnose`` does
    (:func:`diagnose`; docs/diagnosis.md).

    Parameters
    ----------
    model : Case
        The model (:func:`diagnosis_model`: a case file's, or the paper frame's).
    data : path
        The measured run: every input the model reads, and the channels to compare.
    out : path, optional
        Write the result there too (:meth:`DiagnosisRun.write`), the directory made ready and locked
        before the diagnosis starts (:func:`gatetherm.outdir.output_dir`: a refusal or failure leaves
        the previous results).
    record : dict, optional
        What diagnosis.json records of how the model was made: ``case``, ``mesh_size`` (m), ``mesh_factor``.
    config : path, optional
        The model file the frame was read from (never overwritten by :meth:`DiagnosisRun.write`).
    on_progress : callable, optional
        ``on_progress(i, n)`` after every model run and where the plan changes: ``i`` model runs done
        (never falling, one more at a time) of about ``n`` planned (estimated, and updated as the search
        goes: ``n`` may change, never below ``i + 1`` before the end); the last call has ``i == n ==``
        the result's ``diagnosis.runs``.
    **settings
        Fields of :class:`gatetherm.studies.diagnosis.discrepancy.Settings` (``train_fraction``,
        ``effects``, ``parameters``, ``sensors``, ``uncertain``, ``refine`` …).

    Returns
    -------
    DiagnosisRun
        ``.diagnosis``, ``.write(out)``, ``.summary()``.
    """
    from gatetherm.studies.diagnosis.discrepancy import Settings, diagnose as run_diagnosis
    from gatetherm.studies.run.scenario import measured_schedule, span_note
    from gatetherm.studies.run.timeseries import read_timeseries

    argument("model", model, Case, "a Case", "make one with gt.diagnosis_model() or gt.load_case(path)")
    argument("data", data, PATH, "a time-series file's path")
    if model.time is None:
        raise InputError("model", f"{model.name!r} is steady (no [time]): a diagnosis compares a transient run",
                         "give the case [time] with end and step; the run's times come from the data")
    choices = Settings(**settings)
    keep = (config, str(data), *model.files)
    ts = read_timeseries(data, required=("time_s",))
    measured_schedule(model, ts, str(data))  # every input the case reads is in the file
    span_note(model, ts, str(data), warn=True)

    def diagnosed() -> DiagnosisRun:
        diag = run_diagnosis(model, ts, choices, on_progress)
        return DiagnosisRun(diag, model, str(data), dict(ts.metadata), dict(record or {}), keep)

    if out is None:
        return diagnosed()
    from gatetherm.outdir import output_dir

    with output_dir(out, OUTPUTS, keep=keep) as stage:
        result = diagnosed()
        result.write_into(stage, out)
    return result
