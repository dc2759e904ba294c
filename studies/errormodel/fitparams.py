"""The settings of :func:`~gatetherm.studies.errormodel.fit.fit_error_model` (:class:`FitParams`), its
forms and cross-validation kinds, and the noise rule's span threshold (:data:`SPAN_RESOLUTIONS`); the
fit's method is :mod:`gatetherm.studies.errormodel.fit`'s docstring."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gatetherm import InputError

FIT_FORMS = ("auto", "static", "dynamic", "paper")
CV_KINDS = ("blocked", "chain")
LATEST_SCORES = ("chain", "mean")
#: A temperature term spanning fewer resolutions than this in the fitting span is not offered.
SPAN_RESOLUTIONS = 10


@dataclass(frozen=True)
class FitParams:
    """Settings of :func:`fit_error_model`."""

    max_sensors: int = 4
    """Most temperature columns one target's model may read."""
    max_inputs: int = 2
    """Most operating-input terms in one target's model."""
    exponents: tuple[float, ...] = (1.0, 2.0)
    """Exponents p of the input terms (|u|/u_max)^p tried, dimensionless."""
    input_taus_s: tuple[float, ...] = (60.0, 120.0, 240.0, 480.0, 960.0, 1920.0, 3840.0)
    """Time constants of the input lags tried, s (the fast part; slow heating is what the temperatures see)."""
    sensor_taus_s: tuple[float, ...] = ()
    """Time constants of lagged temperature rises tried, s; empty = none."""
    differences: bool = False
    """Also offer every difference theta_a - theta_b as one regressor (two sensors, one coefficient)."""
    folds: tuple[int, ...] = (4, 5, 6, 7, 8)
    """Block counts of the blocked cross-validation; its error is averaged over them."""
    min_gain: float = 0.03
    """Relative drop of the held-out error a further term must bring, dimensionless."""
    form: str = "auto"
    """``auto``, ``static``, ``dynamic`` or ``paper`` (module docstring)."""
    refine: bool = True
    """Refine the selected time constants continuously and drop terms that do not earn ``min_gain``."""
    resolution_K: float = 0.05
    """Resolution of the temperature sensors, K, also taken as the standard deviation of their noise
    (a thermocouple's 0.05 K): a term spanning less than :data:`SPAN_RESOLUTIONS` times this in the
    fitting span is not offered, and the coefficients are fitted for readings with this noise
    (module docstring); 0 = exact, noise-free readings."""
    max_gap_s: float = 300.0
    """Longest gap in a used column that is bridged by linear interpolation, s; rows in longer gaps
    are left out of the fit and not predicted."""
    cv: str = "blocked"
    """Held-out error within a run: ``blocked`` (every block predicted by the fit on the others) or
    ``chain`` (forward chaining: the latest blocks, each predicted by the fit on the rows before it).
    Three or more runs are always held out one run at a time."""
    noisy_cv: bool = False
    """Score every candidate by its expected held-out error on readings carrying the sensors' noise
    (``resolution_K``): a term whose noise costs more than it explains is not chosen."""
    smooth_s: float = 0.0
    """Time constant of a first-order lag every temperature reading passes before it enters a term,
    in the fit as in ``predict``, s: white noise of the readings reduced to ``sqrt((1 - a) / (1 + a))``
    of it (``a = exp(-h / smooth_s)``, h the sample step), which the coefficients' noise rule then
    counts; 0 = the readings as they are."""
    smooth_grid_s: tuple[float, ...] = ()
    """Further values of ``smooth_s`` to try, s: the model is fitted with each (and ``smooth_s``) and
    the one of the lowest held-out error, summed over the targets, is kept (``settings``:
    ``smooth_held_out_um``, the sum for each value); empty = ``smooth_s`` only. Tried within one or
    two runs; three or more runs are fitted with ``smooth_s`` alone (docs/errormodel.md, "Several runs":
    chosen by leave one run out, the smoothing lost on four of five held-out simulated runs)."""
    anchor_s: float = 0.0
    """Each run's (and each predicted file's) first reading of a temperature column is replaced by the
    value there of the straight line through its readings of the first ``anchor_s`` seconds, s: with
    several runs every term is taken from that reading, and one noisy sample would offset the whole
    run; the noise rule then counts the reference's noise too. 0 = the first reading as it is."""
    choose_latest: bool = False
    """Within one or two runs, choose the model by its forward-chaining error on the fitting span's
    latest blocks (as a control uses it): the candidates are every model on each form's forward-selection
    path (ordered by ``cv``) and the refined pick, and the one of the lowest forward-chaining error is
    kept; ``held_out_mae_um`` is then that error, and so is what ``smooth_grid_s`` compares."""
    latest_score: str = "chain"
    """With ``choose_latest``, the score of a candidate: ``chain``, its forward-chaining error on the latest
    blocks; ``mean``, the mean of that and its blocked cross-validation error over the whole span (fixed
    weights, one half each; docs/errormodel.md, "Issue 56: ch5 on 0-40 %"). ``held_out_mae_um`` and the
    smoothing's comparison are then that score."""
    drift: bool = False
    """With several runs, also offer a slow drift, the hours since each run's start (kept only where
    it earns ``min_gain`` on the held-out runs); within one run a trend in time is confounded with
    the heating it should explain, and is not offered."""

    def __post_init__(self):
        if self.form not in FIT_FORMS:
            raise InputError("form", f"{self.form!r} is not one of {', '.join(FIT_FORMS)}", "e.g. form auto")
        if self.max_sensors < 1:
            raise InputError("max_sensors", f"{self.max_sensors} is not >= 1", "e.g. 4")
        if self.max_inputs < 0:
            raise InputError("max_inputs", f"{self.max_inputs} is not >= 0", "e.g. 2")
        if not self.folds or min(self.folds) < 2:
            raise InputError("folds", "need block counts >= 2", "e.g. (4, 5, 6, 7, 8)")
        bad = [(k, v) for k in ("exponents", "input_taus_s", "sensor_taus_s", "max_gap_s")
               for v in np.atleast_1d(getattr(self, k)) if not (np.isfinite(v) and v > 0)]
        if bad:
            raise InputError(bad[0][0], f"{bad[0][1]:g} is not > 0", "use positive values")
        if not (np.isfinite(self.resolution_K) and self.resolution_K >= 0):
            raise InputError("resolution_K", f"{self.resolution_K} is not >= 0", "e.g. 0.05 (K, a thermocouple)")
        if self.cv not in CV_KINDS:
            raise InputError("cv", f"{self.cv!r} is not one of {', '.join(CV_KINDS)}", "e.g. cv chain")
        if not all(np.isfinite(v) and v >= 0 for v in (self.smooth_s, self.anchor_s, *self.smooth_grid_s)):
            raise InputError("smooth_s, anchor_s", "must be >= 0", "e.g. 300 (s), 0 = off")
        if self.latest_score not in LATEST_SCORES:
            raise InputError("latest_score", f"{self.latest_score!r} is not one of {', '.join(LATEST_SCORES)}",
                             "e.g. latest_score chain")
        if not 0 <= self.min_gain < 1:
            raise InputError("min_gain", f"{self.min_gain} is outside [0, 1)", "e.g. 0.03")
