"""What the error-model functions of :mod:`gatetherm.api.errormodel` return: each result holds
its numbers, writes the files of its command (``.write(out)``, a transaction:
:func:`gatetherm.outdir.output_dir`) and says what it found (``.summary()``, the command's lines)."""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path

from gatetherm import write_text_atomic
from gatetherm.checks import json_text
from gatetherm.outdir import output_dir
from gatetherm.studies.errormodel.model import ErrorModel, save_model

FIT_OUTPUTS = ("model.json",)
"""What a fit or a refit writes into its output directory."""
PREDICT_OUTPUTS = ("prediction.csv", "summary.json", "prediction.png")
"""What a prediction writes into its output directory."""


@dataclass(frozen=True)
class ErrorModelFit:
    """What :func:`~gatetherm.api.errormodel.errormodel_fit` returns: the fitted model and how it was held out."""

    model: ErrorModel
    """The models of the targets (``.targets``), the reference temperatures, degC, and the span, s."""
    runs: int
    """Runs fitted on."""
    held_out: str
    """How the held-out error was taken: ``"leave one run out"`` (three or more runs) or the
    cross-validation within a run (``"blocked"``, ``"chain"``)."""
    files: tuple[str, ...] = ()
    """The data files read (kept by :meth:`write`: never overwritten)."""

    def write(self, out) -> Path:
        """Write ``out/model.json`` (replacing a previous one only on success); returns its path."""
        with output_dir(out, FIT_OUTPUTS, keep=self.files) as stage:
            save_model(stage / "model.json", self.model)
        return Path(out) / "model.json"

    def summary(self, out=None) -> str:
        """Per target the form, sensors, time constants, held-out error and 90 % interval (what
        ``gatetherm errormodel fit`` prints); ``out``: the folder written, for the first line."""
        m0 = self.model
        lines = [f"wrote {Path(out) / 'model.json'} (fitted on {self.runs} run(s), {m0.fit_span['samples']} samples; "
                 f"held-out error: {self.held_out}; readings smoothed over {m0.settings.get('smooth_s', 0.0):g} s)"] \
            if out is not None else []
        for m in m0.targets:
            taus = ", ".join(f"{t.tau_s:.0f} s" for t in m.terms if t.tau_s is not None) or "none"
            drift = next((f"; drift {b:.3g} um/h" for t, b in zip(m.terms, m.coefficients) if t.kind == "drift"), "")
            iv = m.interval
            band = (f"; 90 % interval +-{iv['half_width_um']:.3g} um (held-out samples inside: "
                    f"{iv['coverage']:.0%})" if iv.get("coverage") is not None else "")
            lines.append(f"{m.target}: {m.form}; sensors {', '.join(m.sensors)}; time constants {taus}{drift}; "
                         f"held-out MAE {m.held_out_mae_um:.3g} um, fit RMS {m.residual['rms_um']:.3g} um, "
                         f"sensor noise {m.noise_um:.2g} um{band}")
            if m.form == "paper":
                best = "; ".join(f"{' and '.join(s['terms'])}: {s['cv_mae_um']:.3g} um" for s in m.selection[:3])
                lines.append(f"  best triples, held-out MAE: {best}")
                continue
            by_sensors = {}
            for s in m.selection:
                if s["form"] == m.form:
                    by_sensors[s["sensors"]] = min(s["cv_mae_um"], by_sensors.get(s["sensors"], float("inf")))
            curve = ", ".join(f"{k}: {v:.3g} um" for k, v in sorted(by_sensors.items()))
            lines.append(f"  forward path, held-out MAE by sensors: {curve}")
        return "\n".join(lines)


@dataclass(frozen=True)
class Prediction:
    """What :func:`~gatetherm.api.errormodel.errormodel_predict` returns: predictions with their 90 %
    intervals, scores and drift warnings."""

    predicted: dict
    """Target -> predicted displacement per sample, um."""
    lower: dict
    """Target -> lower end of the 90 % interval per sample, um."""
    upper: dict
    """Target -> upper end of the 90 % interval per sample, um."""
    scores: dict
    """Per target :func:`~gatetherm.studies.errormodel.model.score` (MAE, RMS where measured, um)
    with ``share_outside`` (samples beyond the fitted ranges) and ``share_missed`` (measured
    samples outside the interval)."""
    gaps: dict = field(default_factory=dict)
    """Per column with gaps its :class:`~gatetherm.studies.errormodel.terms.GapReport`."""
    warnings: tuple[str, ...] = ()
    """One line per target whose record is unlike the fitting data."""
    model: ErrorModel | None = None
    """The model applied."""
    data: object = None
    """The time series it was applied to (:class:`~gatetherm.studies.run.timeseries.TimeSeries`)."""
    sources: tuple[str, str] = ("", "")
    """Where the model and the data came from (their files, or ``""``)."""

    def write(self, out) -> Path:
        """Write ``out/prediction.csv`` (``time_s``, ``<target>_pred``, ``_lo``, ``_hi``, and the
        measured ``<target>`` where the data have it; um), ``out/prediction.png`` and
        ``out/summary.json`` (scores, warnings, filled gaps), replacing the previous ones only on
        success; returns the path of ``prediction.csv``."""
        from gatetherm.studies.run.timeseries import TimeSeries, write_timeseries
        from gatetherm.validation.plots import save
        from gatetherm.validation.plots.errormodel import plot_model_prediction

        ts = self.data
        cols = {"time_s": ts.time_s}
        for name, p in self.predicted.items():
            cols[f"{name}_pred"] = p
            cols[f"{name}_lo"], cols[f"{name}_hi"] = self.lower[name], self.upper[name]
            if name in ts:
                cols[name] = ts[name]
        model_file, data_file = self.sources
        summary = {"model": model_file, "data": data_file, "targets": self.scores, "warnings": list(self.warnings)}
        summary["gaps"] = {k: dataclasses.asdict(g) for k, g in self.gaps.items()}
        with output_dir(out, PREDICT_OUTPUTS, keep=tuple(f for f in (data_file, model_file) if f)) as stage:
            source = {"source": f"gatetherm errormodel predict {model_file}"}
            write_timeseries(stage / "prediction.csv", TimeSeries(cols, source))
            save(plot_model_prediction(self.model, ts), stage / "prediction.png")
            write_text_atomic(stage / "summary.json", json_text(summary, "summary.json", indent=2))
        return Path(out) / "prediction.csv"

    def summary(self, out=None) -> str:
        """The filled gaps, MAE and RMS per measured target and the drift warnings (what
        ``gatetherm errormodel predict`` prints); ``out``: the folder written, for the first line."""
        lines = [f"wrote {Path(out) / 'prediction.csv'}, prediction.png, summary.json"] if out is not None else []
        for name, g in self.gaps.items():
            lines.append(f"{name}: {g.filled} missing samples filled (longest gap {g.longest_s:.0f} s), "
                         f"{g.unpredicted} in gaps over {self.model.max_gap_s:.0f} s not predicted")
        for name, e in self.scores.items():
            if "mae_um" in e:
                inside = "" if e["share_missed"] is None else f", {1 - e['share_missed']:.0%} inside the 90 % interval"
                lines.append(f"{name}: MAE {e['mae_um']:.3g} um, RMS {e['rms_um']:.3g} um over {e['samples']} "
                             f"samples{inside}")
        lines += [f"warning: {w}" for w in self.warnings]
        return "\n".join(lines)


@dataclass(frozen=True)
class Refit:
    """What :func:`~gatetherm.api.errormodel.errormodel_refit` returns; unpacks as ``(model, report)``."""

    model: ErrorModel
    """The refitted model (or the current coefficients, per target, where refitting was worse)."""
    report: dict
    """Per target ``kept`` (bool), ``current_mae_um``, ``refit_mae_um`` (um, on the window's last
    quarter) and ``samples``."""
    window_s: float
    """The refit window at the end of the data, s (the file's span where shorter)."""
    files: tuple[str, ...] = ()
    """The input files (kept by :meth:`write`: never overwritten)."""

    def __iter__(self):
        return iter((self.model, self.report))

    def write(self, out) -> Path:
        """Write ``out/model.json`` (replacing a previous one only on success); returns its path."""
        with output_dir(out, FIT_OUTPUTS, keep=self.files) as stage:
            save_model(stage / "model.json", self.model)
        return Path(out) / "model.json"

    def summary(self, out=None) -> str:
        """Per target whether it was refitted and the errors that decided (what ``gatetherm
        errormodel refit`` prints); ``out``: the folder written, for the first line."""
        lines = [f"wrote {Path(out) / 'model.json'} (refitted on the last {self.window_s / 3600.0:g} h)"] \
            if out is not None else []
        for name, r in self.report.items():
            verdict = "kept the current coefficients" if r["kept"] else "refitted"
            lines.append(f"{name}: {verdict}: on the window's last quarter {r['refit_mae_um']:.3g} um refitted "
                         f"against {r['current_mae_um']:.3g} um current ({r['samples']} samples)")
        return "\n".join(lines)
