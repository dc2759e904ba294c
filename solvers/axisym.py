"""Axisymmetric bodies: a 2-D section in the half-plane (r, z) = (x, y), r ≥ 0, revolved
about the y axis.

Every integral is over the full revolution: an element of area or length weighs 2π r
(:class:`Revolution` is the section's "thickness"), so powers, forces, volumes, heat
capacities and flows are those of the whole ring. The strain has the hoop component
ε_θθ = u_r / r, its stress σ_θθ is the component ``"tt"``; the moduli are the 3-D ones.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from skfem import BilinearForm, LinearForm
from skfem.helpers import ddot, div, sym_grad

from gatetherm.solvers.fem import Field


@dataclass(frozen=True)
class Revolution(Field):
    """The weight 2π r of the revolved section at quadrature points (``values``: at the
    element centroids)."""

    @classmethod
    def of(cls, mesh) -> "Revolution":
        return cls(2.0 * np.pi * mesh.p[0, mesh.t].mean(axis=0))

    def at(self, basis) -> np.ndarray:
        return 2.0 * np.pi * np.asarray(basis.global_coordinates())[0]


def _trace(u, r):
    return div(u) + u[0] / r


@BilinearForm
def stiffness(u, v, w):
    r = w.x[0]
    return w.t * (w.lam * _trace(u, r) * _trace(v, r)
                  + 2.0 * w.mu * (ddot(sym_grad(u), sym_grad(v)) + u[0] * v[0] / r ** 2))


@BilinearForm
def thermal_load(T, v, w):
    """Trial: temperature rise; test: displacement (``w.b``: thermal stress modulus)."""
    return w.t * w.b * T * _trace(v, w.x[0])


@LinearForm
def thermal_load_at(v, w):
    """The load of a temperature rise ``w.T`` given at the quadrature points."""
    return w.t * w.b * w.T * _trace(v, w.x[0])


@BilinearForm
def stress_of_u(u, v, w):
    """Trial: displacement; test: scalar. Component ``(w.i, w.j)`` of ``λ tr ε I + 2 μ ε``,
    (2, 2) the hoop stress."""
    r, i, j = w.x[0], w.i, w.j
    if i == j == 2:
        return (2.0 * w.mu * u[0] / r + w.lam * _trace(u, r)) * v
    s = 2.0 * w.mu * sym_grad(u)[i][j]
    return (s + w.lam * _trace(u, r)) * v if i == j else s * v
