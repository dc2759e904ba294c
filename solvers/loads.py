"""Mechanical loads superposed on the thermal strain: gravity, a pressure, traction or total
force on a boundary, forces on points, prescribed displacements.

Every load is a sum of terms ``vector · value(env)`` (the values are
:class:`~gatetherm.solvers.expr.Value` expressions of time and the schedule): per term a
load vector ``f_j`` and, for a prescribed displacement, the pattern ``d_j`` of the DOFs it
moves. The displacement of each term for a unit value, ``U_j = d_j + K⁻¹ (f_j − K d_j)``
on the free DOFs, is solved once (:func:`unit_responses`), so a linear output ``g·u`` of a
run is ``w·ΔT + Σ_j (g·U_j) value_j(env)``: no elastic solve per time step.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from skfem import CellBasis, FacetBasis, LinearForm, asm
from skfem.helpers import dot

from gatetherm.solvers.expr import Value
from gatetherm.solvers.fem import Field, complement


@LinearForm
def body_load(v, w):
    """Component ``w.c`` of a unit acceleration acting on the density ``w.rho``."""
    return w.t * w.rho * v[w.c]


@LinearForm
def surface_load(v, w):
    """Component ``w.c`` of a unit traction; ``w.c = -1``: a unit pressure (into the body)."""
    return w.t * (-dot(w.n, v) if w.c < 0 else v[w.c])


@dataclass(frozen=True)
class Terms:
    """The mechanical loads of a problem on its elastic basis."""

    F: np.ndarray
    """Load vectors per unit value, N (DOFs × terms)."""
    D: np.ndarray
    """Prescribed displacements per unit value, m (DOFs × terms; zero but for a support's DOFs)."""
    values: tuple[Value, ...]
    """The value of every term."""

    def __len__(self) -> int:
        return len(self.values)

    def at(self, env) -> np.ndarray:
        """The terms' values for the variables ``env``."""
        return np.array([float(v(env)) for v in self.values])


def _zero(v: Value) -> bool:
    return v.is_constant and v.constant == 0.0


def mechanical_terms(problem, mesh, vb: CellBasis, fields: dict[str, Field], sensors: dict[str, int],
                     support_dofs) -> Terms | None:
    """The load terms of ``problem`` on the vector basis ``vb`` (None without any).
    ``fields`` holds ``rho`` and ``thickness``; ``sensors`` the mesh's point nodes;
    ``support_dofs(support, component)`` the DOFs a support holds."""
    q = 2 * vb.elem.maxdeg
    th = fields["thickness"]
    F, D, values = [], [], []

    def add(f, d, v):
        F.append(np.zeros(vb.N) if f is None else f)
        D.append(np.zeros(vb.N) if d is None else d)
        values.append(v)

    if any(not _zero(g) for g in problem.gravity):
        cb = CellBasis(mesh, vb.elem, intorder=q)
        rho, t = fields["rho"].at(cb), th.at(cb)
        for c, g in enumerate(problem.gravity):
            if not _zero(g):
                add(asm(body_load, cb, rho=rho, t=t, c=c), None, g)
    for load in problem.loads:
        fb = FacetBasis(mesh, vb.elem, facets=mesh.boundaries[load.boundary], intorder=q)
        t = th.at(fb)
        if load.kind == "pressure":
            add(asm(surface_load, fb, t=t, c=-1), None, load.values[0])
            continue
        scale = 1.0 / float(np.sum(t * fb.dx)) if load.kind == "force" else 1.0  # N over the area
        for c, v in enumerate(load.values):
            if not _zero(v):
                add(scale * asm(surface_load, fb, t=t, c=c), None, v)
    for pl in problem.point_loads:
        for c, v in enumerate(pl.force):
            if not _zero(v):
                f = np.zeros(vb.N)
                f[vb.nodal_dofs[c, sensors[pl.point]]] = 1.0
                add(f, None, v)
    owner = np.full(vb.N, -1)  # the term that moves each DOF: a later support wins at shared DOFs
    for s in problem.supports:
        if s.stiffness is not None:
            continue
        for k, c in enumerate(s.components):
            v = s.values[k] if s.values else Value(0.0)
            owner[support_dofs(s, c)] = -1 if _zero(v) else len(values)
            if not _zero(v):
                add(None, None, v)
    for j in np.unique(owner[owner >= 0]):
        D[j] = (owner == j).astype(float)
    if not values:
        return None
    return Terms(np.column_stack(F), np.column_stack(D), tuple(values))


def unit_responses(elastic, terms: Terms) -> np.ndarray:
    """The displacement (m, DOFs × terms) of every term for a unit value, in one solve with
    the elastic system's factor."""
    load = terms.F
    if elastic.K_fixed is not None:
        load = load - elastic.K_fixed @ terms.D[complement(len(terms.D), elastic.free)]
    return terms.D + elastic.from_load(load)
