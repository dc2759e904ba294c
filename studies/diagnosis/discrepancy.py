"""The discrepancy workflow: replay, locate, recalibrate, test candidate effects, name.

1. *Replay* the measured inputs through the model (:mod:`studies.replay`).
2. *Locate* significant residuals per channel and phase (:mod:`studies.locate`).
3. *Recalibrate* the existing uncertain parameters, 4. fit every *candidate*
   catalogue effect, one parameter each (:mod:`studies.calibrate`), all on the
   training window (the first ``train_fraction`` of the run).
5. *Name*: every hypothesis is scored on the held-out rest of the run by
   ``χ² + k ln n`` (χ² of all channels weighted by their noise scale, at least
   the sensor resolution; k fitted parameters; n held-out samples). A hypothesis
   *explains* the data when no channel keeps a significant held-out residual.
   The verdict is

   * ``no-discrepancy``: the baseline residual is nowhere significant;
   * ``missing-effect``: the best-scoring hypothesis is an effect that explains
     the data and beats every other hypothesis (recalibration included) by at
     least ``margin_min``;
   * ``parameter-mismatch``: otherwise, if the recalibrated model explains it
     (existing parameters come before new physics);
   * ``unexplained``: nothing explains it, or several effects do equally well.
"""
from __future__ import annotations

import dataclasses
import logging
import time
from dataclasses import dataclass

import numpy as np

from gatetherm import InputError
from gatetherm.solvers.effects import CATALOGUE
from gatetherm.solvers.frame import PUMP, SUPPLY
from gatetherm.studies.diagnosis.calibrate import (RECAL, Fit, Objective, baseline, effect_uncertainty,
                               fit_effect, fit_recalibration)
from gatetherm.studies.run.config import Config
from gatetherm.studies.diagnosis.locate import Finding, Phase, locate, noise_sd, phases, significant
from gatetherm.studies.diagnosis.replay import DELTA, Replayer, compared_channels, resolution, residuals
from gatetherm.studies.run.timeseries import TimeSeries

log = logging.getLogger(__name__)

VERDICTS = ("no-discrepancy", "parameter-mismatch", "missing-effect", "unexplained")


@dataclass(frozen=True)
class Settings:
    """How a diagnosis is run."""

    train_fraction: float = 0.6
    """Fraction of the run (from its start) used for fitting; the rest is held out, 1."""
    margin_min: float = 10.0
    """Score difference (χ² units) by which a named effect must beat every other hypothesis."""
    effects: tuple[str, ...] = tuple(CATALOGUE)
    """Candidate effects."""
    recalibrate: bool = True


@dataclass(frozen=True)
class Candidate:
    """A fitted hypothesis scored on the held-out window."""

    fit: Fit
    score: float
    """χ² on the held-out window + k ln n."""
    rms: dict[str, float]
    """Held-out RMS residual per channel (channel unit)."""
    explains: bool
    """No channel keeps a significant held-out residual."""

    @property
    def name(self) -> str:
        return self.fit.name


@dataclass(frozen=True)
class Diagnosis:
    """Everything the report shows."""

    verdict: str
    named_effect: str | None
    runner_up: str | None
    margin: float | None
    reason: str
    adopted: Candidate | None
    """The hypothesis kept (named effect or recalibration), else None."""
    baseline: Candidate
    candidates: tuple[Candidate, ...]
    """Recalibration and effects, best score first."""
    channels: tuple[str, ...]
    scale: dict[str, float]
    time_s: np.ndarray
    train_end_s: float
    phases: tuple[Phase, ...]
    findings: tuple[Finding, ...]
    """Baseline residual per channel and phase over the whole run."""
    residual_before: dict[str, np.ndarray]
    residual_after: dict[str, np.ndarray] | None
    runs: int
    seconds: float
    has_ambient: bool = False
    """The file recorded the room temperature (the model was driven by it)."""
    margin_min: float = Settings.margin_min

    def summary(self) -> dict:
        """The ``diagnosis.json`` content."""
        after = self.adopted.rms if self.adopted else None
        return {
            "verdict": self.verdict, "named_effect": self.named_effect, "runner_up": self.runner_up,
            "margin": self.margin, "reason": self.reason,
            "rms_before_um": self.baseline.rms.get(DELTA), "rms_after_um": after.get(DELTA) if after else None,
            "rms_before": self.baseline.rms, "rms_after": after,
            "fitted": self.adopted.fit.values if self.adopted else {},
            "uncertainty": self.adopted.fit.sigma if self.adopted else {},
            "candidates": [{"name": c.name, "score": c.score, "k": c.fit.k, "explains": c.explains,
                            "fitted": c.fit.values, "rms_heldout": c.rms} for c in self.candidates],
            "baseline_score": self.baseline.score, "channels": list(self.channels),
            "noise_scale": self.scale, "train_end_s": self.train_end_s,
            "significant": [f.sentence() for f in self.findings if f.significant],
            "model_runs": self.runs, "wall_time_s": round(self.seconds, 1),
        }


def _score(obj: Objective, fit: Fit, held: np.ndarray, t: np.ndarray) -> Candidate:
    cols = obj.columns(fit.hypothesis)
    res = residuals(obj.measured, cols, obj.channels)
    n = len(obj.vector(fit.hypothesis, held))
    rms = {c: float(np.sqrt(np.nanmean(res[c][held] ** 2))) for c in obj.channels}
    sig = any(np.any(significant(t, res[c], resolution(c)) & held) for c in obj.channels)
    return Candidate(fit, obj.chi2(fit.hypothesis, held) + fit.k * np.log(max(n, 1)), rms, not sig)


def decide(base: Candidate, ranked: list[Candidate], discrepant: bool, margin_min: float):
    """(verdict, named effect, runner-up, margin, reason) from scored hypotheses, best first."""
    if not discrepant:
        return "no-discrepancy", None, None, None, "the baseline residual is within the sensor resolution"
    pool = sorted(ranked + [base], key=lambda c: c.score)
    if len(pool) < 2:
        return "unexplained", None, None, None, "no candidate was tried"
    best, second = pool[0], pool[1]
    margin = float(second.score - best.score)
    recal = next((c for c in ranked if c.name == "recalibration"), None)
    is_effect = best.name not in ("recalibration", "baseline")
    if is_effect and best.explains and margin >= margin_min:
        return ("missing-effect", best.name, second.name, margin,
                f"{best.name} explains the held-out data and beats {second.name} by {margin:.1f}")
    why_not = (f"{best.name} does not explain the held-out data" if not best.explains else
               f"{best.name} beats {second.name} by only {margin:.1f} (< {margin_min:g})")
    if recal is not None and recal.explains:
        runner = next(c for c in pool if c is not recal)
        return ("parameter-mismatch", None, runner.name, float(runner.score - recal.score),
                "recalibrating the existing parameters closes the gap"
                + (f"; no effect is established: {why_not}" if is_effect and best is not recal else ""))
    if not any(c.explains for c in ranked):
        return ("unexplained", None, best.name, margin,
                f"no candidate explains the held-out residual (best: {best.name})")
    return "unexplained", None, second.name, margin, f"no single effect is established: {why_not}"


def diagnose(config: Config, ts: TimeSeries, dim: int = 2, mesh=None,
             settings: Settings = Settings()) -> Diagnosis:
    """Run the whole workflow on a measured series ``ts``."""
    if not 0.2 <= settings.train_fraction <= 0.9:
        raise InputError("--train-fraction", f"must be between 0.2 and 0.9, got {settings.train_fraction}",
                         "e.g. 0.6: fit on the first 3 h of a 5-h run, score on the last 2 h")
    unknown = [e for e in settings.effects if e not in CATALOGUE]
    if unknown:
        raise InputError("--effects", f"unknown effect(s) {', '.join(unknown)}",
                         f"choose from {', '.join(CATALOGUE)}")
    t0 = time.perf_counter()
    rep = Replayer(config, ts, dim, mesh)
    t = rep.times
    base_cols = rep.run()
    channels = compared_channels(ts, base_cols)
    res0 = residuals(ts, base_cols, channels)
    scale = {c: max(resolution(c), noise_sd(res0[c])) for c in channels}
    train = t <= settings.train_fraction * t[-1]
    held = ~train
    if held.sum() < 5 or train.sum() < 5:
        raise InputError("--data", f"{len(t)} samples are too few to train and hold out", "give a longer run")
    run_phases = phases(t, rep.drive.columns[SUPPLY], rep.drive.columns[PUMP])
    findings = locate(t, res0, run_phases)
    obj = Objective(rep, ts, channels, scale, train)
    base = _score(obj, baseline(obj), held, t)
    discrepant = any(f.significant for f in findings)
    fits: list[Fit] = []
    if discrepant:
        if settings.recalibrate:
            fits.append(fit_recalibration(obj, RECAL))
        fits += [fit_effect(obj, name) for name in settings.effects]
    ranked = sorted((_score(obj, f, held, t) for f in fits), key=lambda c: c.score)
    verdict, named, runner, margin, reason = decide(base, ranked, discrepant, settings.margin_min)
    adopted = next((c for c in ranked if c.name == (named or "recalibration")), None) \
        if verdict in ("missing-effect", "parameter-mismatch") else None
    if adopted is not None and adopted.name != "recalibration":
        fit = effect_uncertainty(obj, adopted.fit)
        adopted = dataclasses.replace(adopted, fit=fit)
        ranked = [adopted if c.name == fit.name else c for c in ranked]
    after = residuals(ts, obj.columns(adopted.fit.hypothesis), channels) if adopted else None
    log.info("diagnosis: %s (%s), %d model runs", verdict, reason, rep.runs)
    return Diagnosis(verdict, named, runner, margin, reason, adopted, base, tuple(ranked), channels, scale,
                     t, float(t[train][-1]), tuple(run_phases), tuple(findings), res0, after, rep.runs,
                     time.perf_counter() - t0, rep.has_ambient, settings.margin_min)


def adopted_config(config: Config, diag: Diagnosis) -> Config | None:
    """The model with the diagnosis applied (effect on, or parameters recalibrated)."""
    if diag.adopted is None:
        return None
    hyp = diag.adopted.fit.hypothesis
    thermal = dataclasses.replace(config.model.thermal, **dict(hyp.thermal))
    return dataclasses.replace(config, model=dataclasses.replace(config.model, thermal=thermal),
                               effects={**config.effects, **dict(hyp.effects)})
