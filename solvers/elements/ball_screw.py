"""A ball screw's nut (``kind = "ball_screw_nut"``): the preload drag and the friction of the axial load."""
from __future__ import annotations

import math

import numpy as np

from gatetherm.checks import Range
from gatetherm.solvers.elements import POSITIVE_M, ElementKind, paren

__all__ = ["ball_screw_nut_loss", "ball_screw_nut_text", "screw_preload_torque"]


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


def ball_screw_nut_text(n: str, lead: float, diameter: float, preload: float, load: str, efficiency: float) -> str:
    """:func:`ball_screw_nut_loss` as an expression of the texts ``n`` and ``load``."""
    n, load, tp = paren(n), paren(load), screw_preload_torque(lead, diameter, preload)
    return f"({tp!r} + {lead / (2.0 * math.pi) * (1.0 / efficiency - 1.0)!r}*abs({load}))" \
           f"*{2.0 * math.pi / 60.0!r}*abs({n})"


def read(t, text) -> str:
    """The loss of a nut's ``[sources.REGION]`` table (:class:`~gatetherm.solvers.elements.ElementKind`)."""
    return ball_screw_nut_text(
        text("speed", "1/min"), t.number("lead", POSITIVE_M), t.number("diameter", POSITIVE_M),
        t.number("preload", Range(0.0, unit="N"), 0.0), text("load", "N", 0.0),
        t.number("efficiency", Range(0.0, 1.0, lo_open=True, unit="1"), 0.9))


KINDS = (ElementKind("ball_screw_nut", ("speed", "lead", "diameter", "preload", "load", "efficiency"), read, 30,
                     ("diameter", "lead")),)
