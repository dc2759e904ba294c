"""Whether a compensation helps, judged on data it was not fitted on: never silently worse.

The held-out span is the last ``fraction`` (default 30 %) of the compensated record. On it the
largest |δ| left by the compensation (``held_out_um``) is compared with the largest |δ| without
it (``uncompensated_um``), both from the axis' reference at the record's start. What a method fits
is fitted for this check on the record before the span only: the paper method's K_i, K_C by
``fit`` on the first 70 % of the record, the ``mlr`` regression on the first 70 % of the model's
own run; what fits nothing on the record (K from beam theory or FE, the ``rom`` reduced model and
its causal Kalman filter, an error model fitted on another record) is checked as applied. An error
model fitted on this same record up to inside the span is not checked (``unchecked``): its
held-out benefit cannot be known from this record.

Verdict, with the displacement sensor's resolution r (:data:`RESOLUTION_UM`, 0.1 um): ``worse`` when
``held_out_um > uncompensated_um + r``, ``no-gain`` within r of it (a difference no sensor can see),
else ``better``. The correction as applied is checked on the same span too (:func:`as_applied`):
where it is worse there, the verdict is ``worse`` whatever a refitted check says. A worse correction
is refused (:func:`guard`, one line naming the figures and a better choice) unless forced; forced, it
runs with a warning in the log and in the summary. A correction of no measurable gain, or one that
could not be checked, runs with a warning.
"""
from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass

import numpy as np

from gatetherm import InputError
from gatetherm.studies.run.timeseries import TimeSeries

log = logging.getLogger(__name__)

HELD_OUT = 0.3
"""Default held-out fraction: the last 30 % of the record."""
VERDICTS = ("better", "no-gain", "worse", "unchecked")
RESOLUTION_UM = 0.1
"""Resolution of a displacement reading, um (the paper's differential transformer): smaller
differences between the compensated and uncompensated δ are no gain and no loss."""


@dataclass(frozen=True)
class Benefit:
    """A compensation's benefit on the held-out span."""

    held_out_um: float | None
    """Largest |δ| the compensation leaves on the held-out span, um (None: unchecked)."""
    uncompensated_um: float
    """Largest |δ| without compensation on the same span, um."""
    fraction: float
    """Held-out fraction of the record's duration, dimensionless."""
    start_s: float
    """Start of the held-out span, s."""
    verdict: str
    """One of :data:`VERDICTS`."""
    basis: str
    """What the check compensated with (e.g. "K_i, K_C fitted on the first 70 %")."""
    forced: bool = False
    """True where a worse correction was applied because the user insisted."""

    def as_dict(self) -> dict:
        """The summary entry ``benefit``."""
        return dataclasses.asdict(self)

    def sentence(self, method: str) -> str:
        """E.g. "mlr would leave δ 6.85 um > 6.10 um uncompensated on the held-out last 30 %"."""
        last = f"the held-out last {self.fraction * 100:.0f} %"
        if self.held_out_um is None:
            return f"{method}: benefit unchecked on {last} ({self.basis})"
        rel = {"worse": ">", "no-gain": "≈"}.get(self.verdict, "<")
        return (f"{method} would leave δ {self.held_out_um:.2f} um {rel} {self.uncompensated_um:.2f} um "
                f"uncompensated on {last}")


def span_start(t_s: np.ndarray, fraction: float) -> float:
    """Start of the held-out span: the last ``fraction`` of the time from the first to the last sample, s."""
    if not 0 < fraction < 1:
        raise InputError("--held-out", f"{fraction:g} is not a fraction in (0, 1)", "e.g. --held-out 0.3")
    return float(t_s[0] + (1.0 - fraction) * (t_s[-1] - t_s[0]))


def before(ts: TimeSeries, fraction: float) -> TimeSeries:
    """The record before its held-out span (what a method may be fitted on for the check)."""
    keep = ts.time_s < span_start(ts.time_s, fraction)
    return TimeSeries({n: ts[n][keep] for n in ts.names}, dict(ts.metadata))


def benefit(loop, fraction: float, basis: str) -> Benefit:
    """The :class:`Benefit` of a closed loop (``t_s``, ``delta_um``, ``delta_comp_um``) on its
    held-out last ``fraction``."""
    start = span_start(loop.t_s, fraction)
    late = loop.t_s >= start
    unc = float(np.max(np.abs(loop.delta_um[late])))
    comp = np.abs(loop.delta_comp_um[late])
    if late.sum() < 2 or not np.isfinite(comp).all():
        return Benefit(None, unc, fraction, start, "unchecked", f"{basis}; too few held-out samples")
    held = float(np.max(comp))
    verdict = "worse" if held > unc + RESOLUTION_UM else "no-gain" if held >= unc - RESOLUTION_UM else "better"
    return Benefit(held, unc, fraction, start, verdict, basis)


def as_applied(b: Benefit, loop) -> Benefit:
    """``b``, or ``worse`` where the correction as applied (``loop``) leaves a larger |δ| than no
    compensation on the same held-out span: what a check with a refit says does not stand for the
    correction the user gets (a paper method whose on-line factors run away on the whole record's K)."""
    if b.verdict == "worse" or b.basis.startswith("as applied"):
        return b
    applied = benefit(loop, b.fraction, "as applied")
    if applied.verdict != "worse":
        return b
    return dataclasses.replace(applied, basis=f"as applied (the check with {b.basis} said {b.verdict}, "
                               f"{'unknown' if b.held_out_um is None else f'{b.held_out_um:.2f} um'})")


def over_record(loop, settle_s: float, method: str, model: str = "") -> str:
    """A warning where the correction as applied leaves a larger |δ| over the record after its first
    ``settle_s`` than no compensation there ('' where it does not), and why: a prediction that misses δ
    by more than δ itself (``model``, what of a case it comes from, describes another machine or
    another record), or a method that adapts on line, worse while it adapts and better on the held-out span."""
    late = loop.t_s >= loop.t_s[0] + settle_s
    comp = np.abs(loop.delta_comp_um[late])
    if not late.any() or not np.isfinite(comp).any():
        return ""
    left, unc = float(np.nanmax(comp)), float(np.max(np.abs(loop.delta_um[late])))
    if left <= unc + RESOLUTION_UM:
        return ""
    missed = float(np.nanmax(np.abs(loop.delta_um[late] - loop.delta_pred_um[late])))
    fix = f"the prediction ({model}) does not describe this record: one of another machine? give that machine's " \
        "case" if model else "the method does not describe this machine: leave the axis uncompensated"
    why = "worse while it adapts" if missed <= unc + RESOLUTION_UM else \
        f"its prediction misses δ by up to {missed:.2f} um, more than δ itself; {fix}"
    return (f"{method} as applied leaves |δ| up to {left:.2f} um over the record after {settle_s / 60:g} min, "
            f"more than the {unc:.2f} um uncompensated: {why}")


def unchecked(loop, fraction: float, why: str) -> Benefit:
    """A :class:`Benefit` that could not be measured, and why."""
    start = span_start(loop.t_s, fraction)
    return Benefit(None, float(np.max(np.abs(loop.delta_um[loop.t_s >= start]))), fraction, start, "unchecked", why)


def guard(b: Benefit, method: str, force: bool, better: str) -> tuple[Benefit, str | None]:
    """Refuse a worse correction (InputError, one line: the figures, ``better`` (the better choice)
    and ``--force``), or, with ``force``, pass it marked forced with a warning sentence; an unchecked
    one and one of no measurable gain pass with a warning. Returns the benefit and the warning (None if none)."""
    if b.verdict in ("unchecked", "no-gain"):
        warning = f"{b.sentence(method)}: " + ("its correction may make δ worse" if b.verdict == "unchecked" else
                                               f"no gain beyond the {RESOLUTION_UM:g} um resolution")
        log.warning("%s", warning)
        return b, warning
    if b.verdict != "worse":
        return b, None
    if not force:
        raise InputError(f"--method {method}" if method != "error model" else "--model",
                         b.sentence(method), f"{better}, or --force (force=True) to apply it anyway")
    warning = f"{b.sentence(method)}: applied because forced"
    log.warning("%s", warning)
    return dataclasses.replace(b, forced=True), warning
