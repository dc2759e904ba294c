"""A fitted thermal-error model: :class:`ErrorModel`, one :class:`TargetModel` per target.

Per target (a displacement column, um)::

    delta(t) = c0 + sum_j b_j x_j(t)

with ``x_j`` the :class:`~gatetherm.studies.errormodel.terms.Term` values (temperature rises
from the model's reference temperatures, K; operating inputs through first-order lags) and
``b_j`` in um/K or um. Its file is :mod:`gatetherm.studies.errormodel.model`, its evaluation
:mod:`gatetherm.studies.errormodel.prediction`.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gatetherm import InputError
from gatetherm.studies.errormodel.terms import Term

FORMS = ("static", "dynamic", "paper")
"""static: sensors (and differences) only; dynamic: also lags (inputs, temperatures);
paper: ``K_i (theta_a - theta_b) - K_C theta_c`` without intercept (eq 21)."""


@dataclass(frozen=True)
class TargetModel:
    """The model of one target column."""

    target: str
    """The predicted column, um."""
    form: str
    """One of :data:`FORMS`."""
    terms: tuple[Term, ...]
    """The regressors."""
    coefficients: tuple[float, ...]
    """One per term, um/K (sensor, difference) or um (input)."""
    intercept_um: float = 0.0
    """Constant c0, um (0 in the paper's form)."""
    residual: dict = field(default_factory=dict)
    """On the fitting span: ``mae_um``, ``rms_um``, ``max_abs_um``, ``samples``."""
    held_out_mae_um: float | None = None
    """Held-out mean absolute error inside the fitting span, um: of the cross-validation (``cv``; leave
    one run out with three or more runs), or with ``choose_latest`` the forward-chaining error on the
    span's latest blocks that chose the model."""
    selection: tuple[dict, ...] = ()
    """The forward-selection path: per step ``terms`` (labels), ``sensors`` (count), ``cv_mae_um``."""
    noise_um: float | None = None
    """Standard deviation the temperature sensors' noise adds to the prediction, um:
    ``sqrt(sum_k (c_k sigma_k)^2)`` at the fit's sensor resolution (None: not recorded)."""
    interval: dict = field(default_factory=dict)
    """The 90 % interval from held-out residuals (:func:`~gatetherm.studies.errormodel.trust.calibrate`):
    ``half_width_um`` (um), ``coverage`` (fraction of held-out samples inside, out of sample),
    ``samples``, ``level``; within one or two runs also ``blocks`` (the held-out blocks it is a
    conformal quantile over), ``growth`` ("horizon"), ``fit_end_s`` and ``fit_length_s`` (s): the
    half-width grows as ``1 + h / fit_length_s``
    (:func:`~gatetherm.studies.errormodel.trust.calibrate_forward`); empty: not calibrated."""
    ranges: tuple = ()
    """Per term its (smallest, largest) value on the fitting rows (the drift detector's reference)."""

    @property
    def sensors(self) -> tuple[str, ...]:
        """The temperature columns the model reads, in term order."""
        cols = [c for t in self.terms if t.kind not in ("input", "drift") for c in t.columns]
        return tuple(dict.fromkeys(cols))

    @property
    def columns(self) -> tuple[str, ...]:
        """Every column the model reads."""
        return tuple(dict.fromkeys(c for t in self.terms for c in t.columns))


@dataclass(frozen=True)
class ErrorModel:
    """Thermal-error models of one or more targets fitted on one series."""

    targets: tuple[TargetModel, ...]
    """One model per target."""
    reference_degC: dict[str, float]
    """Temperature of each used sensor that the rises are taken from, degC (default: its first
    valid sample in the fitting span)."""
    fit_span: dict
    """``start_s``, ``end_s`` (s) and ``samples`` of the fitting span; ``source``: the data file."""
    max_gap_s: float = 300.0
    """Longest gap (s) in a used column that predictions bridge (linear fill); longer gaps are NaN."""
    settings: dict = field(default_factory=dict)
    """The fit settings (:class:`~gatetherm.studies.errormodel.fit.FitParams`) as a dict."""
    run_reference: bool = False
    """True (fitted on several runs): every predicted file is its own run, its rises taken from its
    first sample and the prediction zero there (:mod:`~gatetherm.studies.errormodel.runs`)."""

    @property
    def columns(self) -> tuple[str, ...]:
        """Every column any target model reads."""
        return tuple(dict.fromkeys(c for m in self.targets for c in m.columns))

    def target(self, name: str) -> TargetModel:
        """The model of target ``name``."""
        for m in self.targets:
            if m.target == name:
                return m
        raise InputError(f"target {name}", "not in the model", f"use one of {', '.join(self.names)}")

    @property
    def names(self) -> tuple[str, ...]:
        """The target columns."""
        return tuple(m.target for m in self.targets)


def residual_stats(r: np.ndarray) -> dict:
    """MAE, RMS and largest absolute value (um) and count of residuals ``r`` (um)."""
    return {"mae_um": float(np.mean(np.abs(r))), "rms_um": float(np.sqrt(np.mean(r**2))),
            "max_abs_um": float(np.max(np.abs(r))), "samples": int(r.size)}
