"""Closed-form beam theory of the gate frame (paper section 3.1, eqs 1-29).

Two columns clamped at the mounting face (Euler-Bernoulli cantilevers of equal
stiffness ``EI``), joined at height ``l4`` by a tie bar (a bar spring ``k_C``).
The heat-source column carries the thermal curvature ``alpha (theta_A - theta_B) / h``
over the height ``l1``; the displacement of interest is the horizontal one at
height ``l`` (points E). Sign: ``delta > 0`` means tool and workpiece approach;
the tie-bar force ``P > 0`` is compression.

Everything broadcasts over numpy arrays. Coefficients are in m/K; callers convert
to µm. "No tie bar" is ``A_C = 0``: then ``k_C = 0``, ``1/D = 0`` exactly, so
``K_C = 0`` and ``K_i = alpha l1 (2l - l1) / (2h)`` with no division by zero.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from gatetherm import InputError

if TYPE_CHECKING:
    from gatetherm.frame.geometry import FrameParams
    from gatetherm.frame.problem import ModelConfig


@dataclass(frozen=True)
class BeamModel:
    """Geometry and materials of the beam model; any field may be an array (sweeps)."""

    l: ArrayLike
    """Height of the cutting area (points E) above the column mounting face, m."""
    l1: ArrayLike
    """Heated height of the heat-source column, from the mounting face, m (0 < l1 <= l)."""
    l4: ArrayLike
    """Height of the tie bar above the mounting face, m."""
    h: ArrayLike
    """Column width, distance from A to B, m."""
    EI: ArrayLike
    """Column bending stiffness (both columns), N m^2."""
    alpha: ArrayLike
    """Column linear expansion coefficient, 1/K."""
    l_C: ArrayLike
    """Tie-bar length, m."""
    A_C: ArrayLike
    """Tie-bar cross-section, m^2 (0 = no tie bar)."""
    E_C: ArrayLike
    """Tie-bar Young's modulus, Pa."""
    alpha_C: ArrayLike
    """Tie-bar linear expansion coefficient, 1/K."""

    def __post_init__(self):
        for name in ("l", "l1", "l4", "h", "EI", "l_C", "E_C"):
            if not np.all(np.asarray(getattr(self, name)) > 0):
                raise InputError(name, "must be > 0 everywhere", "give a positive value in SI units")
        if not np.all(np.asarray(self.A_C) >= 0):
            raise InputError("A_C", "must be >= 0 everywhere", "use A_C = 0 for no tie bar")
        if not np.all(np.asarray(self.l1) <= np.asarray(self.l)):
            raise InputError("l1", "heated height exceeds l", "the beam theory assumes l1 <= l")
        for name in ("alpha", "alpha_C"):
            if not np.all(np.isfinite(np.asarray(getattr(self, name)))):
                raise InputError(name, "must be finite", "give the expansion coefficient in 1/K")


def thermal_moment(EI: ArrayLike, alpha: ArrayLike, dtheta: ArrayLike, h: ArrayLike) -> np.ndarray:
    """Eq (1): bending moment ``M_h = E I alpha (theta_A - theta_B) / h`` in N m."""
    return np.asarray(EI) * alpha * np.asarray(dtheta) / h


def k_C(l_C: ArrayLike, A_C: ArrayLike, E_C: ArrayLike) -> np.ndarray:
    """Eq (8): axial stiffness of the tie bar ``A_C E_C / l_C`` in N/m (0 without tie bar)."""
    return np.asarray(A_C) * E_C / l_C


def k_m(EI: ArrayLike, l4: ArrayLike) -> np.ndarray:
    """Eq (8): column tip-load stiffness at the tie-bar height ``3 E I / l4^3`` in N/m."""
    return 3.0 * np.asarray(EI) / np.asarray(l4) ** 3


def _inv_D(m: BeamModel) -> np.ndarray:
    """``1/D = 1/(k_m/k_C + 2) = k_C / (k_m + 2 k_C)``, exactly 0 when ``A_C == 0``."""
    kc = k_C(m.l_C, m.A_C, m.E_C)
    return kc / (k_m(m.EI, m.l4) + 2.0 * kc)


def tie_force(m: BeamModel, dtheta_AB: ArrayLike, theta_C: ArrayLike) -> np.ndarray:
    """Eqs (7) / (11): compressive tie-bar force ``P`` in N.

    ``P = [s alpha (theta_A-theta_B)/(2h) + alpha_C theta_C l_C] / (1/k_C + 2/k_m)`` with
    ``s = l4^2`` for ``l4 <= l1`` (7) and ``s = l1 (2 l4 - l1)`` for ``l4 >= l1`` (11);
    ``1/(1/k_C + 2/k_m) = k_m / D`` is used so that ``A_C = 0`` gives ``P = 0``.
    """
    l1, l4 = np.asarray(m.l1), np.asarray(m.l4)
    s = np.where(l4 <= l1, l4**2, l1 * (2.0 * l4 - l1))
    free_gap = s * m.alpha * np.asarray(dtheta_AB) / (2.0 * m.h) + np.asarray(m.alpha_C) * theta_C * m.l_C
    return k_m(m.EI, l4) * _inv_D(m) * free_gap


def _branch_terms(l: ArrayLike, l1: ArrayLike, l4: ArrayLike):
    """The ``D``-free factors of eqs (22)-(24): ``K_i = alpha/(2h) [l1(2l-l1) - X/D]``,
    ``K_C = R l_C alpha_C / D``. Returns ``(X22, X23, X24), (R22_23, R24)``."""
    l, l1, l4 = (np.asarray(v, dtype=float) for v in (l, l1, l4))
    x22 = l4 * (3.0 * l - l4)
    x23 = l1 * (3.0 * l - l4) * (2.0 * l4 - l1) / l4
    x24 = l**2 * l1 * (3.0 * l4 - l) * (2.0 * l4 - l1) / l4**3
    r22 = (3.0 * l - l4) / l4
    r24 = l**2 * (3.0 * l4 - l) / l4**3
    return (x22, x23, x24), (r22, r24)


def coefficients(m: BeamModel) -> tuple[np.ndarray, np.ndarray]:
    """Eqs (22)-(24): ``(K_i, K_C)`` in m/K, branch by ``l4 <= l1``, ``l1 <= l4 <= l``, ``l4 >= l``."""
    l, l1, l4 = (np.asarray(v, dtype=float) for v in (m.l, m.l1, m.l4))
    (x22, x23, x24), (r22, r24) = _branch_terms(l, l1, l4)
    x = np.where(l4 <= l1, x22, np.where(l4 <= l, x23, x24))
    r = np.where(l4 <= l, r22, r24)
    inv_d = _inv_D(m)
    k_i = np.asarray(m.alpha) / (2.0 * np.asarray(m.h)) * (l1 * (2.0 * l - l1) - x * inv_d)
    k_c = r * m.l_C * np.asarray(m.alpha_C) * inv_d
    return k_i, k_c


def delta(m: BeamModel, dtheta_AB: ArrayLike, theta_C: ArrayLike) -> np.ndarray:
    """Eq (21): relative displacement ``K_i (theta_A - theta_B) - K_C theta_C`` in m (> 0: approach).

    Linear in the temperatures, so eq (25) for the rates is this function applied to
    the temperature rates.
    """
    k_i, k_c = coefficients(m)
    return k_i * np.asarray(dtheta_AB) - k_c * np.asarray(theta_C)


def beta(I: ArrayLike, l_C: ArrayLike, A_C: ArrayLike, l: ArrayLike) -> np.ndarray:
    """Eq (26): ``beta = 3 I l_C / (A_C l^3)`` (same material), so ``k_m/k_C = beta (l/l4)^3``.

    ``A_C = 0`` (no tie bar) gives ``inf``; :func:`normalised` accepts it (``K_C = 0``).
    For different materials the same role is played by ``3 E I l_C / (E_C A_C l^3)``.
    """
    with np.errstate(divide="ignore"):
        return 3.0 * np.asarray(I) * l_C / (np.asarray(A_C, dtype=float) * np.asarray(l) ** 3)


def _normalised_branches(a: ArrayLike, beta: ArrayLike):
    """Eqs (27), (28), (29) as ``((Ki, Kc) for a >= 2, for 1 <= a <= 2, for a <= 1)``."""
    a, b = np.asarray(a, dtype=float), np.asarray(beta, dtype=float)
    d = b * a**3 + 2.0
    kc_top = (3.0 * a - 1.0) / d
    return (
        (1.0 - 4.0 * (3.0 * a - 1.0) / (3.0 * a**2 * d), kc_top),
        (1.0 - (3.0 * a - 1.0) * (4.0 - a) / (3.0 * a * d), kc_top),
        (1.0 - a * (3.0 - a) * (4.0 - a) / (3.0 * d), a**2 * (3.0 - a) / d),
    )


def normalised(a: ArrayLike, beta: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Eqs (27)-(29), ``l1 = l/2``, same material: ``(K_i/(3 alpha l^2/(8h)), K_C/(alpha l_C))``.

    ``a = l/l4 > 0``; ``beta >= 0`` (``inf`` = no tie bar gives ``(1, 0)``).
    """
    a = np.asarray(a, dtype=float)
    (ki2, kc2), (ki12, kc12), (ki1, kc1) = _normalised_branches(a, beta)
    ki = np.where(a >= 2.0, ki2, np.where(a >= 1.0, ki12, ki1))
    kc = np.where(a >= 1.0, kc12, kc1)
    return ki, kc


def ki_scale(alpha: ArrayLike, l: ArrayLike, h: ArrayLike) -> np.ndarray:
    """Normalising factor of ``K_i`` in Fig. 7: ``3 alpha l^2 / (8 h)`` in m/K."""
    return 3.0 * np.asarray(alpha) * np.asarray(l) ** 2 / (8.0 * np.asarray(h))


def kc_scale(alpha_C: ArrayLike, l_C: ArrayLike) -> np.ndarray:
    """Normalising factor of ``K_C`` in Fig. 8: ``alpha_C l_C`` in m/K (``alpha l_C`` in the paper)."""
    return np.asarray(alpha_C) * np.asarray(l_C)


def denormalise(ki_norm: ArrayLike, kc_norm: ArrayLike, alpha: ArrayLike, l: ArrayLike,
                h: ArrayLike, l_C: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Inverse of :func:`normalised` (same material): ``(K_i, K_C)`` in m/K."""
    return np.asarray(ki_norm) * ki_scale(alpha, l, h), np.asarray(kc_norm) * kc_scale(alpha, l_C)


# --- the bridge from a frame model to the beam theory ------------------------------------------

def column_I(frame: FrameParams) -> float:
    """Second moment of area of a full column section, ``depth h^3 / 12`` in m^4 (the tank
    cavity is ignored, as in the paper)."""
    return frame.depth * frame.h ** 3 / 12.0


def beam_model(cfg: ModelConfig) -> BeamModel:
    """The beam model of a frame model: its l, l1, l4, h, l_C, A_C, column material E, alpha
    with :func:`column_I`, tie-bar material E_C, alpha_C."""
    f, m = cfg.frame, cfg.material
    tie = cfg.tie_material or m
    return BeamModel(l=f.l, l1=f.l1, l4=f.l4, h=f.h, EI=m.E * column_I(f), alpha=m.alpha, l_C=f.l_C,
                     A_C=f.A_C, E_C=tie.E, alpha_C=tie.alpha)


def theory_coefficients(cfg: ModelConfig) -> tuple[float, float]:
    """Beam-theory (K_i, K_C) of a frame model, um/K (eqs 22-24 via :func:`beam_model`)."""
    ki, kc = coefficients(beam_model(cfg))
    return float(ki) * 1e6, float(kc) * 1e6


def frame_beta(cfg: ModelConfig) -> float:
    """Eq (26) for a frame model, with the column-to-tie-bar modulus ratio (1 for one material)."""
    f, tie = cfg.frame, cfg.tie_material or cfg.material
    return float(beta(column_I(f) * cfg.material.E / tie.E, f.l_C, f.A_C, f.l))


def beta_area(cfg: ModelConfig, value: float) -> float:
    """The tie-bar section ``A_C`` (m^2) that gives eq (26)'s ``beta = value`` on a frame model."""
    f, tie = cfg.frame, cfg.tie_material or cfg.material
    return 3.0 * cfg.material.E * column_I(f) * f.l_C / (value * tie.E * f.l ** 3)
