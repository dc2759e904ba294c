"""The discrepancy workflow: replay, locate, select the missing pieces, name them.

1. *Replay* the measured inputs through the model (:mod:`replay`). A linear-element model is
   run once with quadratic elements too; where the difference exceeds a sensor's resolution
   and the baseline residual is significant, the diagnosis replays with quadratic elements: a
   residual the model's own mesh makes is not a missing piece (:attr:`Settings.refine`).
2. *Locate* significant residuals per channel and phase (:mod:`locate`).
3. *Select*: forward selection over every hypothesis (catalogue effects, existing
   parameters off, dimensions marked as uncertain, sensor faults; :mod:`hypotheses`), fitted
   on the training window (the first ``train_fraction`` of the run) and scored on the
   held-out rest, each channel group weighing the same (:mod:`calibrate`, :mod:`select`).
4. *Check*: the model-form checks (:mod:`checks`): the chosen set must hold on each input
   phase when fitted on the others, with the same values, plausible ones, and a sensor fault
   needs evidence of a sensor; a piece that fails is a stand-in, not a cause, and is not named:
   the selection runs again without the stand-ins, so the next candidates get their turn
   (:func:`~select.select_confirmed`). A hypothesis whose model run the model refuses (a part
   left free to move, a singular system) is dropped with its reason and listed, and the
   diagnosis goes on.
5. *Group*: hypotheses the data cannot tell from a named piece are one group with it, with
   the measurement that would separate them (:mod:`identify`); a physical piece is named
   before an equivalent sensor fault.
6. *Name*. The verdict is

   * ``no-discrepancy``: the baseline residual is nowhere significant;
   * ``explained``: the named pieces leave no significant residual anywhere in the run, and
     hold on every input phase they were not fitted to;
   * ``partly-explained``: pieces were named, but a significant residual remains or they do
     not hold on a phase (the report says which channels and phases, and what kind of cause
     would fit: :mod:`pattern`);
   * ``unexplained``: no hypothesis lowers the held-out score by the margin, or those that do
     are stand-ins.
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass

import numpy as np

from gatetherm import InputError
from gatetherm.studies.diagnosis.calibrate import Objective, Scored, uncertainty
from gatetherm.studies.diagnosis.checks import Checks, confirm
from gatetherm.studies.diagnosis.hypotheses import (Piece, configure, effect_keys, effect_pieces, parameter_pieces,
                                                    sensor_pieces)
from gatetherm.studies.diagnosis.identify import Group, groups, physical_first
from gatetherm.studies.diagnosis.locate import Finding, Phase, case_phases, locate, noise_sd
from gatetherm.studies.diagnosis.pattern import kind_of_cause, unexplained
from gatetherm.studies.diagnosis.progress import Budget
from gatetherm.studies.diagnosis.replay import DELTA, Replayer, compared_channels, resolution, residuals
from gatetherm.studies.diagnosis.select import Round, Selection, physical_in_place, select, select_confirmed
from gatetherm.studies.run.case import Case
from gatetherm.studies.run.timeseries import TimeSeries

log = logging.getLogger(__name__)

VERDICTS = ("no-discrepancy", "explained", "partly-explained", "unexplained")


@dataclass(frozen=True)
class Settings:
    """How a diagnosis is run."""

    train_fraction: float = 0.6
    """Fraction of the run (from its start) used for fitting; the rest is held out, 1."""
    margin_min: float = 10.0
    """Score units (log-likelihood) by which an addition must lower the held-out score, penalty included."""
    effects: tuple[str, ...] | None = None
    """Candidate catalogue effects (None: every one that can act on the model)."""
    parameters: tuple[str, ...] | None = None
    """Candidate existing parameters and dimensions, by name (None: all of the model file's or the case's)."""
    uncertain: tuple[str, ...] = ()
    """Dimensions to try besides those the case marks (``geometry.NAME`` of the frame,
    ``mesh.parameters.NAME`` of a case file); each new value meshes the case again."""
    sensors: bool = True
    """Try sensor faults of every compared channel."""
    max_pieces: int = 4
    screen_top: int = 3
    """Hypotheses that need model runs fitted for real in each round after the first (the rest screened)."""
    p2_check: bool = True
    """A linear-element case is run once more with quadratic elements: its own discretisation error
    against the sensors' resolution (:attr:`Diagnosis.discretisation`)."""
    refine: bool = True
    """Where that error exceeds the resolution and the baseline residual is significant, replay with
    quadratic elements (a residual the model's own mesh makes is not a missing piece)."""


@dataclass(frozen=True)
class PieceResult:
    """A chosen piece with its fitted value."""

    piece: Piece
    value: float
    sigma: float
    share: float
    """Its share of the held-out residual: the rise of the held-out score when it alone is taken out of
    the final set, over the sum of those rises."""
    alternatives: tuple[Piece, ...] = ()

    def entry(self) -> dict:
        """The ``diagnosis.json`` entry."""
        p = self.piece
        params = ({"channel": p.channel} if p.channel else {}) | {p.param: float(self.value)}
        out = {"kind": p.kind, "name": p.name, "params": params, "uncertainty": {p.param: float(self.sigma)},
               "unit": p.unit, "share_of_residual": float(self.share)}
        if self.alternatives:
            out["alternatives"] = [q.label for q in self.alternatives]
        return out


@dataclass(frozen=True)
class Diagnosis:
    """Everything the report shows."""

    verdict: str
    reason: str
    pieces: tuple[PieceResult, ...]
    best_rejected: tuple[Piece, Scored] | None
    baseline: Scored
    final: Scored
    rounds: tuple[Round, ...]
    removed: tuple[Piece, ...]
    channels: tuple[str, ...]
    scale: dict[str, float]
    time_s: np.ndarray
    train_end_s: float
    phases: tuple[Phase, ...]
    findings: tuple[Finding, ...]
    """Baseline residual per channel and phase over the whole run."""
    remaining: tuple[Finding, ...]
    """Residual with the chosen pieces, per channel and phase (empty without pieces)."""
    residual_before: dict[str, np.ndarray]
    residual_after: dict[str, np.ndarray] | None
    runs: int
    seconds: float
    has_ambient: bool = False
    """The file recorded the room temperature (the model was driven by it)."""
    margin_min: float = Settings.margin_min
    dim: int = 2
    """Dimension of the replayed model."""
    inputs: tuple[str, ...] | None = None
    """The columns of the file that drove the case."""
    discretisation: dict[str, float] | None = None
    """A P1 case: the largest |P2 − P1| of the baseline per channel, in units of its resolution
    (above 1, the model's own discretisation error shows in the data)."""
    checks: Checks | None = None
    """The model-form checks of the named pieces (:mod:`checks`)."""
    stand_ins: tuple[tuple[Piece, float, str], ...] = ()
    """Pieces that made the model fit but failed a check: (piece, value, why)."""
    groups: tuple[Group, ...] = ()
    """Named pieces with the hypotheses the data cannot tell from them."""
    cause: str = ""
    """What kind of cause would fit the residual that stays unexplained (:mod:`pattern`)."""
    order: int = 1
    """Element order of the replayed model (2 for a P1 case whose discretisation error showed in the data:
    :attr:`Settings.refine`)."""
    dropped: tuple[tuple[Piece, str], ...] = ()
    """Hypotheses whose model run the model refused (a part left free to move, a singular system):
    (piece, the model's one-line reason); out of the search, the diagnosis went on without them."""

    @property
    def too_coarse(self) -> list[str]:
        """Channels on which the discretisation check exceeds the resolution."""
        return [c for c, v in (self.discretisation or {}).items() if v > 1.0]

    @property
    def named_effects(self) -> list[str]:
        return [r.piece.name for r in self.pieces if r.piece.kind == "effect"]

    @property
    def margin(self) -> float | None:
        """Score gain the best rejected addition would have brought (below ``margin_min``)."""
        return None if self.best_rejected is None else float(self.rounds[-1].before - self.best_rejected[1].score)

    def summary(self) -> dict:
        """The ``diagnosis.json`` content."""
        after = self.final.rms if self.pieces else None
        rej = self.best_rejected
        return {
            "verdict": self.verdict, "reason": self.reason, "pieces": [r.entry() for r in self.pieces],
            "named_effects": self.named_effects, "best_rejected": rej[0].label if rej else None,
            "margin": self.margin,
            "rms_before_um": self.baseline.rms.get(DELTA), "rms_after_um": after.get(DELTA) if after else None,
            "rms_before": self.baseline.rms, "rms_after": after,
            "fitted": {f"{r.piece.label}.{r.piece.param}": r.value for r in self.pieces},
            "uncertainty": {f"{r.piece.label}.{r.piece.param}": r.sigma for r in self.pieces},
            "removed": [p.label for p in self.removed],
            "rounds": [{"added": [p.label for p in r.added], "score_before": r.before,
                        "trials": [{"name": p.label, "kind": p.kind, "score": s.score, "explains": s.explains,
                                    "screened_only": s.approx, "value": s.values[p], "rms_heldout": s.rms}
                                   for p, s in r.trials],
                        "pairs": [{"names": [p.label for p in pq], "score": s.score, "explains": s.explains,
                                   "screened_only": s.approx, "values": [s.values[p] for p in pq]}
                                  for pq, s in r.pairs[:5]]} for r in self.rounds],
            "baseline_score": self.baseline.score, "final_score": self.final.score,
            "channels": list(self.channels), "noise_scale": self.scale, "train_end_s": self.train_end_s,
            "significant": [f.sentence() for f in self.findings if f.significant],
            "remaining": [f.sentence() for f in self.remaining if f.significant],
            "model_runs": self.runs, "wall_time_s": round(self.seconds, 1), "dim": self.dim, "order": self.order,
            "discretisation_p2_minus_p1_in_resolutions": self.discretisation,
            "checks": self.checks.summary() if self.checks else None,
            "stand_ins": [{"name": p.label, "kind": p.kind, "value": float(v), "why": why}
                          for p, v, why in self.stand_ins],
            "groups": [g.entry() for g in self.groups],
            "dropped": [{"name": p.label, "kind": p.kind, "why": why} for p, why in self.dropped],
            "unexplained": unexplained(self.remaining if self.pieces else self.findings),
            "kind_of_cause": self.cause,
        }


def candidates(case: Case, channels, has_ambient: bool, settings: Settings) -> list[Piece]:
    """The hypotheses a diagnosis tries (those that can act on the file)."""
    known = effect_keys(case)
    asked = known if settings.effects is None else list(settings.effects)
    bad = [n for n in asked if n not in known]
    if bad:
        raise InputError("--effects", f"'{bad[0]}' is not an effect this case can have",
                         f"choose from {', '.join(known)}")
    effects = effect_pieces(case, asked, has_ambient)
    params = parameter_pieces(case, uncertain=settings.uncertain)
    names = [p.name for p in params]
    bad = [n for n in settings.parameters or () if n not in names]
    if bad:
        raise InputError("--parameters", f"unknown parameter {', '.join(bad)}", f"choose from {', '.join(names)}")
    if settings.parameters is not None:
        params = [p for p in params if p.name in settings.parameters or p.name in settings.uncertain]
    return effects + params + (sensor_pieces(channels, case) if settings.sensors else [])


def _shares(obj: Objective, final: Scored) -> list[float]:
    """Per named piece: how much the held-out score rises when it alone is taken out of the
    final set (the others keep their values), as a fraction of the sum over the pieces."""
    values = final.values
    rise = [max(obj.scored({q: v for q, v in values.items() if q != p}).fit - final.fit, 0.0) for p in values]
    total = sum(rise)
    return [r / total if total > 0 else float("nan") for r in rise]


def _verdict(discrepant: bool, sel, final: Scored | None = None, stand=(), checks: Checks | None = None
             ) -> tuple[str, str]:
    """The verdict and its reason from the selection ``sel``, the named set ``final`` (default: the
    selection's), the stand-ins (labels) and the model-form ``checks`` of the named set."""
    final = sel.final if final is None else final
    if not discrepant:
        return "no-discrepancy", "the baseline residual is within the sensor resolution"
    if not final.values:
        if stand:
            return "unexplained", (f"{' + '.join(stand)} make the model fit, but fail the model-form checks: "
                                   "stand-ins, not causes")
        rej = sel.best_rejected
        return "unexplained", ("no hypothesis lowers the held-out score by the margin"
                               + (f" (best: {rej[0].label})" if rej else ""))
    names = " + ".join(p.label for p in final.values)
    failed = [f"{f.phase.label} {f.phase.span()}" for f in (checks.folds if checks else ()) if not f.holds]
    if final.explains and not failed:
        return "explained", f"{names} leave no significant residual" + (
            " and hold on every phase they were not fitted to" if checks and checks.folds else "")
    why = ([] if final.explains else ["a significant residual remains"]) + \
        ([f"fitted on the other phases they do not hold on {', '.join(failed)}"] if failed else [])
    return "partly-explained", f"{names} lower the held-out score, but " + " and ".join(why)


def diagnose(case: Case, ts: TimeSeries, settings: Settings = Settings(), on_progress=None) -> Diagnosis:
    """Run the whole workflow on a measured series ``ts``, replayed through ``case``.

    Parameters
    ----------
    case : Case
        The model (a case file's, or the paper frame's: :func:`~gatetherm.frame.case.gate_frame`).
    ts : TimeSeries
        The measurement: every input the case reads, and the channels to compare.
    settings : Settings
        Training window, margin, candidate effects and parameters.
    on_progress : callable, optional
        ``on_progress(i, n)``: ``i`` model runs done of about ``n`` planned (:mod:`progress`).

    Returns
    -------
    Diagnosis
    """
    if not 0.2 <= settings.train_fraction <= 0.9:
        raise InputError("--train-fraction", f"must be between 0.2 and 0.9, got {settings.train_fraction}",
                         "e.g. 0.6: fit on the first 3 h of a 5-h run, score on the last 2 h")
    t0 = time.perf_counter()
    budget = Budget(on_progress, settings.max_pieces, 2 if case.problem.order == 1 and settings.p2_check else 1)
    rep = Replayer(case, ts, budget=budget)
    t = rep.times
    base_cols = rep.run()
    inputs = tuple(rep.drive.columns)
    channels = compared_channels(ts, base_cols, inputs)
    pool = candidates(case, channels, rep.has_ambient, settings)
    train = t <= settings.train_fraction * t[-1]
    if (~train).sum() < 5 or train.sum() < 5:
        raise InputError("--data", f"{len(t)} samples are too few to train and hold out", "give a longer run")
    run_phases = case_phases(case, t, rep.drive.columns)
    res0, findings, discrepant = _located(ts, base_cols, channels, t, run_phases)
    check, runs, refined, p1_run = None, 0, "", None
    if case.problem.order == 1 and settings.p2_check:
        fine = Replayer(case.with_order(2), ts, budget=budget)
        fine_cols = fine.run()
        check = {c: float(np.max(np.abs(fine_cols[c] - base_cols[c]))) / resolution(c) for c in channels}
        coarse = [c for c, v in check.items() if v > 1.0]
        if discrepant and coarse and settings.refine:
            log.info("diagnosis: the P1 model's discretisation error exceeds the resolution on %s (%.2g "
                     "resolutions): replaying with P2 elements", ", ".join(coarse), max(check.values()))
            runs, rep, base_cols, p1_run = rep.runs, fine, fine_cols, rep.seconds
            res0, findings, discrepant = _located(ts, base_cols, channels, t, run_phases)
            refined = "" if discrepant else ("with P2 elements the baseline residual is within the sensor "
                                             "resolution: the P1 model's was its own discretisation error")
        else:
            runs = fine.runs
    scale = {c: max(resolution(c), noise_sd(res0[c])) for c in channels}
    obj = Objective(rep, ts, channels, scale, train)
    chk, stand, grp = None, {}, []
    if discrepant:
        budget.announce(pool, rep.seconds, rep.config.problem.order, p1_run)
        sel, named, chk = select_confirmed(
            lambda cands, dropped: select(obj, cands, settings.margin_min, settings.max_pieces, settings.screen_top,
                                          dropped=dropped),
            lambda s: confirm(obj, physical_in_place(s), run_phases, settings.margin_min, s.base.score), pool)
        stand = sel.stand_ins
        solo = {p: s.values[p] for p, s in sel.rounds[0].trials} if sel.rounds else {}
        usable = [p for p in pool if p not in sel.dropped]
        named, grp = physical_first(named, groups(obj, named, usable, sel.alternatives, solo, settings.margin_min))
        final = sel.final if named == sel.final.values else obj.scored(named)
    else:
        base = obj.scored({})
        sel = Selection(base, base, [])
        final = base
    verdict, reason = _verdict(discrepant, sel, final, [p.label for p in stand], chk)
    reason = refined or reason
    sigma = uncertainty(obj, final.values)
    by_piece = {g.piece: g for g in grp}
    pieces = tuple(PieceResult(p, v, sigma[p], share, by_piece[p].members if p in by_piece else ())
                   for (p, v), share in zip(final.values.items(), _shares(obj, final)))
    after = obj.residuals(final.values, solve=False)[0] if pieces else None
    remaining = tuple(locate(t, after, run_phases)) if after else ()
    cause = kind_of_cause(t, after or res0, base_cols, list(remaining or findings)) if verdict != "explained" else ""
    runs += rep.runs
    budget.finish()
    log.info("diagnosis: %s (%s), %d model runs", verdict, reason, runs)
    return Diagnosis(verdict, reason, pieces, sel.best_rejected, sel.base, final, tuple(sel.rounds),
                     tuple(sel.removed), channels, scale, t, float(t[train][-1]), tuple(run_phases), tuple(findings),
                     remaining, res0, after, runs, time.perf_counter() - t0, rep.has_ambient, settings.margin_min,
                     rep.dim, inputs, check, chk, tuple((p, v, why) for p, (v, why) in stand.items()), tuple(grp),
                     cause, rep.config.problem.order, tuple(sel.dropped.items()))


def _located(ts: TimeSeries, cols: dict, channels, t: np.ndarray, run_phases) -> tuple[dict, list[Finding], bool]:
    """The residual of the model's run ``cols`` (at the times ``t``) per channel, its findings per
    phase, and whether any is significant."""
    res = residuals(ts, cols, channels)
    found = locate(t, res, run_phases)
    return res, found, any(f.significant for f in found)


def adopted_case(case: Case, diag: Diagnosis) -> Case | None:
    """The case with every chosen piece in it (parameters changed, effects on, sensor faults set)."""
    if not diag.pieces:
        return None
    return configure(case, {r.piece: r.value for r in diag.pieces})

