"""Sources that move: a power spread over the part of a region (or boundary) inside a band
centred at a position that follows the run's inputs (``[sources.REGION] position``), and the same
load for the reduced model as fixed vectors at anchor positions times hat inputs of the position.
``docs/model.md`` (Sources that move)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gatetherm import InputError
from gatetherm.solvers.expr import Value


@dataclass(frozen=True)
class MovingLoad:
    """A power spread over the part of a region (or boundary) inside a band of ``length`` centred at a moving
    ``position`` along a direction: each unknown's share of the region's load ``∫ t v`` is the
    integral over the band of a hat of half-width ``spacing`` around its point (a band shorter than
    the elements moves smoothly from node to node), normalised to the power."""

    weights: np.ndarray
    """``∫ t v`` over the region (solid unknowns)."""
    along: np.ndarray
    """Coordinate of every solid unknown's point along the direction, m."""
    spacing: float
    """Extent of an unknown along the direction, m (the median element's over the order)."""
    length: float
    position: Value
    value: Value
    """The power, W."""
    span: tuple[float, float] = (-np.inf, np.inf)
    """The region's extent along the direction, m."""

    def vector(self, env) -> np.ndarray:
        """The load of a unit power at the position of ``env`` (solid unknowns, sums to 1)."""
        p, half, d = float(self.position(env)), 0.5 * self.length, self.spacing
        w = self.weights * (_hat_integral((p + half - self.along) / d) - _hat_integral((p - half - self.along) / d))
        total = w.sum()
        if not total > 0:
            raise InputError(self.position.key or "position", f"the band at {p:g} m ({self.length:g} m long) "
                             f"misses its region (from {self.span[0]:g} to {self.span[1]:g} m)",
                             "keep the position on the region along the direction")
        return w / total

    def anchors(self) -> tuple[np.ndarray, float]:
        """Positions at which the reduced model takes this load's vector, m, and their spacing: from
        one end of the region to the other, :data:`ANCHOR_SPACING` bands or elements apart (at most
        :data:`MAX_ANCHORS`)."""
        lo, hi = self.span
        step = ANCHOR_SPACING * max(self.length, self.spacing)
        count = int(min(MAX_ANCHORS, max(2, np.ceil((hi - lo) / step - 1e-6) + 1)))
        return np.linspace(lo, hi, count), (hi - lo) / (count - 1)

    def interpolated(self) -> list[tuple[str, np.ndarray]]:
        """The load as fixed vectors times inputs: ``(input expression, vector)`` per anchor ``p_j``,
        the power times the hat ``max(0, 1 − |position − p_j|/Δ)``: the input matrix interpolated
        linearly over the positions (exact at the anchors)."""
        at, gap = self.anchors()
        power = self.value.text or repr(self.value.constant)
        pos, key = self.position.text or repr(self.position.constant), self.position.key
        return [(f"({power})*max(0, 1 - abs(({pos}) - {float(p)!r})/{float(gap)!r})", self._at(float(p), key))
                for p in at]

    def _at(self, p: float, key: str) -> np.ndarray:
        return MovingLoad(self.weights, self.along, self.spacing, self.length, Value(p, "", key),
                          self.value, self.span).vector({})


ANCHOR_SPACING = 1.0
"""Anchors of a moving load in the reduced model are this many band lengths (or elements, if longer) apart."""
MAX_ANCHORS = 41
"""Most anchors of one moving load (inputs of the reduced model)."""


def _hat_integral(u: np.ndarray) -> np.ndarray:
    """``∫_{-∞}^{u} max(0, 1 − |x|) dx``."""
    u = np.clip(u, -1.0, 1.0)
    return np.where(u < 0, 0.5 * (u + 1) ** 2, 1 - 0.5 * (1 - u) ** 2)


def moving_load(mesh, basis, src, weights: np.ndarray, order: int) -> MovingLoad:
    """The :class:`MovingLoad` of a source with a position (its region's or boundary's load ``weights``)."""
    d = np.asarray(src.direction, float)
    along = d @ mesh.p
    nodes = mesh.facets[:, mesh.boundaries[src.region]] if src.on_boundary else mesh.t[:, mesh.subdomains[src.region]]
    extent = np.ptp(along[nodes], axis=0)
    locs = basis.doflocs if getattr(basis, "doflocs", None) is not None else mesh.p
    inside = along[np.unique(nodes)]
    return MovingLoad(weights, d @ locs[:, :len(weights)], float(np.median(extent)) / order, src.length,
                      src.position, src.density, (float(inside.min()), float(inside.max())))
