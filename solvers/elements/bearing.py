"""Rolling bearings (``kind = "bearing"``, and ``"ball_screw_bearing"``, a ball screw's support
bearing): Palmgren's friction torque times the speed."""
from __future__ import annotations

import math

import numpy as np

from gatetherm.checks import Range
from gatetherm.solvers.elements import FACTOR, POSITIVE_M, ElementKind, paren

__all__ = ["BEARING_TYPES", "NU_N_LIMIT", "bearing_loss", "bearing_text", "palmgren_torque"]

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
VISCOSITY = Range(0.0, lo_open=True, unit="mm²/s")
"""A lubricant's kinematic viscosity (Palmgren's law reads only |ν n|: a negative one would pass unseen)."""


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


def bearing_text(n: str, nu: str, dm: float, f0: float, f1: float, load: str) -> str:
    """:func:`bearing_loss` as an expression of the texts ``n``, ``nu`` and ``load``."""
    n, nu, load, d = paren(n), paren(nu), paren(load), dm * 1e3
    x = f"abs({n}*{nu})"
    m0 = f"({x} >= {NU_N_LIMIT!r})*{1e-7 * f0 * d ** 3!r}*{x}**(2/3) + ({x} < {NU_N_LIMIT!r})*{160e-7 * f0 * d ** 3!r}"
    return f"1e-3*({m0} + {f1 * d!r}*abs({load}))*{2.0 * math.pi / 60.0!r}*abs({n})"


def read(t, text) -> str:
    """The loss of a bearing's ``[sources.REGION]`` table (:class:`~gatetherm.solvers.elements.ElementKind`)."""
    f0, f1 = BEARING_TYPES[t.string("type", "angular_contact_oil", tuple(BEARING_TYPES))]
    return bearing_text(text("speed", "1/min"), text("viscosity", "mm²/s", rng=VISCOSITY),
                        t.number("dm", POSITIVE_M), t.number("f0", FACTOR, f0), t.number("f1", FACTOR, f1),
                        text("load", "N", 0.0))


KEYS = ("type", "speed", "dm", "f0", "f1", "viscosity", "load")
KINDS = (ElementKind("bearing", KEYS, read, 10, ("dm",), (("viscosity", "mm²/s", VISCOSITY),)),
         ElementKind("ball_screw_bearing", KEYS, read, 20, ("dm",), (("viscosity", "mm²/s", VISCOSITY),)))
