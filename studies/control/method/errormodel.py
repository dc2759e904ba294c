"""The ``errormodel`` method: a thermal-error model fitted on measured data (``gatetherm errormodel
fit``, :mod:`gatetherm.studies.errormodel`), replayed on one of its targets; chosen by giving the
model (``--model``), not by ``--method``; step-wise
:func:`~gatetherm.studies.control.stepwise.error_model_stepper`."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from gatetherm import InputError
from gatetherm.studies.control.method import Batch, Job, Method, Setup

#: Fraction of a sample interval within which a fit's end and the held-out start count as the same instant.
SAME_INSTANT = 0.01


def batch(job: Job) -> Batch:
    """The model's forecast (or with ``correction``, the paper's on-line R) over the record; its benefit
    as applied, unless the model was fitted on this record into the held-out span."""
    from gatetherm.studies.errormodel.replay import loop_target, replay

    s = job.settings
    if s.model is None:
        raise InputError("--model", "the errormodel method needs a fitted model", "give --model MODEL.json")
    target = loop_target(s.model, s.target)
    loop = replay(s.model, job.ts, target, s.params, job.actuator, s.correction)
    label = f"error model, {target} ({s.model.target(target).form} form" \
        f"{', on-line R' if s.correction else ''}), update every {s.params.update_interval_s / 60:g} min"
    return Batch(loop, {"target": target, "correction": s.correction}, label, label,
                 benefit=_model_check(s.model, loop, s.held_out, job.source))


def _model_check(model, loop, fraction: float, source: str):
    """An error model's benefit: as applied, unless it was fitted on this record into the held-out span."""
    from gatetherm.studies.control import benefit as held

    fitted_on = str(model.fit_span.get("source", ""))
    start = held.span_start(loop.t_s, fraction)
    same = bool(fitted_on) and _same_file(fitted_on, source)
    if same and overlaps(float(model.fit_span.get("end_s", -np.inf)), start, loop.t_s):
        return held.unchecked(loop, fraction, f"the error model was fitted on this record ({fitted_on}) into its "
                              f"last {fraction * 100:.0f} %; refit it with --fit-span 0:{1 - fraction:g}")
    if same:
        return held.benefit(loop, fraction, f"as applied (the error model was fitted on this record before its last "
                            f"{fraction * 100:.0f} %)")
    return held.benefit(loop, fraction, f"as applied (the error model was fitted on {fitted_on or 'other data'})")


def overlaps(end_s: float, start_s: float, t_s) -> bool:
    """True if a fit ending at ``end_s`` reaches into a held-out span starting at ``start_s`` (s) by more
    than :data:`SAME_INSTANT` of the record's median sample interval: a fit to ``--fit-span 0:0.7``
    ends where the last 30 % starts, up to round-off (15120 s against 15119.999999999998 s)."""
    t = np.asarray(t_s, float)
    step = float(np.median(np.diff(t))) if t.size > 1 else 0.0
    return end_s > start_s + SAME_INSTANT * step


def _same_file(a: str, b: str) -> bool:
    try:
        return Path(a).resolve() == Path(b).resolve()
    except (OSError, ValueError):
        return a == b


def stepper(setup: Setup):
    """The model's stepper on its target (with ``setup.model`` a loaded model)."""
    from gatetherm.studies.control.stepwise import error_model_stepper
    from gatetherm.studies.errormodel.replay import loop_target

    return error_model_stepper(setup.model, loop_target(setup.model, setup.target), setup.params), "errormodel"


METHOD = Method("errormodel", batch, stepper, order=40, offered=False, title="error model", doc=__doc__)
