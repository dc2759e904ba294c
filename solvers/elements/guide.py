"""A linear guide's carriage (``kind = "guide"``): rolling friction of the load and the seals' drag."""
from __future__ import annotations

import numpy as np

from gatetherm.checks import Range
from gatetherm.solvers.elements import ElementKind, paren

__all__ = ["guide_loss", "guide_text"]

FRICTION = Range(0.0, 1.0, unit="1")
"""A guide's rolling friction coefficient (typically 0.002 to 0.005; above 1 is no rolling guide)."""


def guide_loss(v, load, friction, seal):
    """Loss of a linear guide's carriage, W: ``(μ |F| + F_seal) |v|``, ``v`` in m/s, the
    load ``F`` and the seals' drag ``F_seal`` in N, ``μ`` the rolling friction coefficient."""
    return (friction * np.abs(load) + seal) * np.abs(v)


def guide_text(v: str, load: str, friction: float, seal: float) -> str:
    """:func:`guide_loss` as an expression of the texts ``v`` and ``load``."""
    v, load = paren(v), paren(load)
    return f"({friction!r}*abs({load}) + {seal!r})*abs({v})"


def read(t, text) -> str:
    """The loss of a guide's ``[sources.REGION]`` table (:class:`~gatetherm.solvers.elements.ElementKind`)."""
    return guide_text(text("speed", "m/s"), text("load", "N", 0.0), t.number("friction", FRICTION, 0.003),
                      t.number("seal", Range(0.0, unit="N"), 0.0))


KINDS = (ElementKind("guide", ("speed", "load", "friction", "seal"), read, 40),)
