"""Heat from machine elements: the losses of bearings, ball screws, linear guides and motors.

Each loss is a small pure function of its operating point (numbers or numpy arrays), and the
same formula as the text of an expression (:class:`~gatetherm.solvers.expr.Value`) of the
run's inputs, which a case's source reads (``[sources.REGION] kind``): the heat problem, the
reduced model and the checks of a schedule then see an ordinary power in W. The formulas and
their sources are in ``docs/model.md`` (Machine elements); ``tests/test_elements.py`` checks
every expression against its function.

Units as the handbooks give them: speeds in 1/min, viscosity in mm²/s, lengths in m (the
bearing formula converts to mm), forces in N, torques in N·m, losses in W.
"""
from __future__ import annotations

import math

import numpy as np

BEARING_TYPES = {
    "angular_contact_oil": (3.3, 4.7e-4),
    "angular_contact_grease": (2.0, 4.7e-4),
    "deep_groove_oil": (2.0, 1.4e-4),
    "deep_groove_grease": (1.35, 1.4e-4),
    "cylindrical_roller_oil": (3.1, 3.0e-4),
    "cylindrical_roller_grease": (0.8, 3.0e-4),
}
"""Palmgren's factors (f0, f1) of common bearing types and lubrications: f0 the middle of the
handbook's range for oil bath or grease; f1 of a roller bearing the middle of 0.0002–0.0004, of
a ball bearing ``z (P0/C0)^y`` at P0/C0 = 0.1 (angular contact: z = 0.001, y = 0.33; deep
groove: z = 0.0005, y = 0.55). Typical values: a maker's f0 and f1 replace them."""
NU_N_LIMIT = 2000.0
"""ν n (mm²/s · 1/min) below which Palmgren's speed term is constant."""


def palmgren_torque(n, nu, dm, f0, f1, load):
    """Palmgren's friction torque of a rolling bearing, N·m: ``M = M0 + M1`` with
    ``M0 = 1e-7 f0 (ν n)^(2/3) dm³`` for ``ν n ≥ 2000``, else ``160e-7 f0 dm³``, and
    ``M1 = f1 P1 dm`` (N·mm, dm in mm).

    Parameters
    ----------
    n : float or array
        Speed, 1/min (its sign is ignored).
    nu : float or array
        Kinematic viscosity of the lubricant at operating temperature, mm²/s.
    dm : float
        Mean diameter, m.
    f0, f1 : float
        Palmgren's factors of the bearing type and lubrication (:data:`BEARING_TYPES`).
    load : float or array
        Load P1 that determines the friction torque, N (its sign is ignored).
    """
    d = dm * 1e3
    x = np.abs(nu * n)
    m0 = np.where(x >= NU_N_LIMIT, 1e-7 * f0 * x ** (2.0 / 3.0) * d ** 3, 160e-7 * f0 * d ** 3)
    return 1e-3 * (m0 + f1 * np.abs(load) * d)


def bearing_loss(n, nu, dm, f0, f1, load):
    """Loss of a rolling bearing, W: :func:`palmgren_torque` times ``2π |n|/60``."""
    return palmgren_torque(n, nu, dm, f0, f1, load) * 2.0 * math.pi * np.abs(n) / 60.0


def screw_preload_torque(lead, diameter, preload):
    """Drag torque of a preloaded ball-screw nut, N·m: ``0.05 (tan β)^(-1/2) Fp l/(2π)``
    with ``tan β = l/(π d0)`` (the makers' formula, THK and NSK catalogues)."""
    tan_beta = lead / (math.pi * diameter)
    return 0.05 * tan_beta ** -0.5 * preload * lead / (2.0 * math.pi)


def ball_screw_nut_loss(n, lead, diameter, preload, load, efficiency):
    """Loss of a ball-screw nut, W: ``(Tp + |Fa| l/(2π) (1/η − 1)) · 2π |n|/60``, the preload
    drag (:func:`screw_preload_torque`) and the friction of the axial load ``Fa`` (N) at the
    screw's efficiency ``η``; ``n`` the screw's speed, 1/min; lead and diameter in m."""
    torque = screw_preload_torque(lead, diameter, preload) + \
        np.abs(load) * lead / (2.0 * math.pi) * (1.0 / efficiency - 1.0)
    return torque * 2.0 * math.pi * np.abs(n) / 60.0


def guide_loss(v, load, friction, seal):
    """Loss of a linear guide's carriage, W: ``(μ |F| + F_seal) |v|``, ``v`` in m/s, the
    load ``F`` and the seals' drag ``F_seal`` in N, ``μ`` the rolling friction coefficient."""
    return (friction * np.abs(load) + seal) * np.abs(v)


def motor_loss(n, torque, efficiency, idle):
    """Loss of a motor, W: ``|T ω| (1/η − 1) + P_idle``, ``n`` in 1/min, ``T`` in N·m,
    ``η`` its efficiency at the operating point (a number, or an expression of the speed and
    torque columns: a loss map), ``P_idle`` a loss that does not depend on the load."""
    return np.abs(torque * 2.0 * math.pi * n / 60.0) * (1.0 / efficiency - 1.0) + idle


# --- the same formulas as expressions of the run's inputs (texts of Values) -------------------

def _p(text: str) -> str:
    return f"({text})"


def bearing_text(n: str, nu: str, dm: float, f0: float, f1: float, load: str) -> str:
    """:func:`bearing_loss` as an expression of the texts ``n``, ``nu`` and ``load``."""
    n, nu, load, d = _p(n), _p(nu), _p(load), dm * 1e3
    x = f"abs({n}*{nu})"
    m0 = f"({x} >= {NU_N_LIMIT!r})*{1e-7 * f0 * d ** 3!r}*{x}**(2/3) + ({x} < {NU_N_LIMIT!r})*{160e-7 * f0 * d ** 3!r}"
    return f"1e-3*({m0} + {f1 * d!r}*abs({load}))*{2.0 * math.pi / 60.0!r}*abs({n})"


def ball_screw_nut_text(n: str, lead: float, diameter: float, preload: float, load: str, efficiency: float) -> str:
    """:func:`ball_screw_nut_loss` as an expression of the texts ``n`` and ``load``."""
    n, load, tp = _p(n), _p(load), screw_preload_torque(lead, diameter, preload)
    return f"({tp!r} + {lead / (2.0 * math.pi) * (1.0 / efficiency - 1.0)!r}*abs({load}))" \
           f"*{2.0 * math.pi / 60.0!r}*abs({n})"


def guide_text(v: str, load: str, friction: float, seal: float) -> str:
    """:func:`guide_loss` as an expression of the texts ``v`` and ``load``."""
    v, load = _p(v), _p(load)
    return f"({friction!r}*abs({load}) + {seal!r})*abs({v})"


def motor_text(n: str, torque: str, efficiency: str, idle: float) -> str:
    """:func:`motor_loss` as an expression of the texts ``n``, ``torque`` and ``efficiency``."""
    return f"abs({_p(torque)}*{_p(n)}*{2.0 * math.pi / 60.0!r})*(1/{_p(efficiency)} - 1) + {idle!r}"
