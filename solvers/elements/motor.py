"""A motor (``kind = "motor"``): the loss at its efficiency (a number or a loss map) and an idle loss."""
from __future__ import annotations

import math

import numpy as np

from gatetherm.checks import Range
from gatetherm.solvers.elements import ElementKind, paren

__all__ = ["motor_loss", "motor_text"]

EFFICIENCY = Range(0.0, 1.0, lo_open=True, unit="1")


def motor_loss(n, torque, efficiency, idle):
    """Loss of a motor, W: ``|T ω| (1/η − 1) + P_idle``, ``n`` in 1/min, ``T`` in N·m,
    ``η`` its efficiency at the operating point (a number, or an expression of the speed and
    torque columns: a loss map), ``P_idle`` a loss that does not depend on the load."""
    return np.abs(torque * 2.0 * math.pi * n / 60.0) * (1.0 / efficiency - 1.0) + idle


def motor_text(n: str, torque: str, efficiency: str, idle: float) -> str:
    """:func:`motor_loss` as an expression of the texts ``n``, ``torque`` and ``efficiency``."""
    return f"abs({paren(torque)}*{paren(n)}*{2.0 * math.pi / 60.0!r})*(1/{paren(efficiency)} - 1) + {idle!r}"


def read(t, text) -> str:
    """The loss of a motor's ``[sources.REGION]`` table (:class:`~gatetherm.solvers.elements.ElementKind`);
    a constant efficiency is checked here, an expression over the run (``parts``)."""
    if t.data.get("efficiency") is not None and not isinstance(t.data["efficiency"], str):
        EFFICIENCY.check(t.key("efficiency"), t.data["efficiency"])
    return motor_text(text("speed", "1/min"), text("torque", "N m"), text("efficiency", "1"),
                      t.number("idle", Range(0.0, unit="W"), 0.0))


KINDS = (ElementKind("motor", ("speed", "torque", "efficiency", "idle"), read, 50,
                     parts=(("efficiency", "1", EFFICIENCY),)),)
