"""Code verification of the heat and thermoelastic solvers: numbers only.

Manufactured solutions (steady heat with source, reaction and Robin boundary;
thermoelasticity with body force, prescribed temperature and a traction face)
give spatial errors on refined meshes; patch cases are exact; an exact modal
solution of the semi-discrete heat system, a 1-D slab's Fourier series and the
frame's energy accounts check the time stepping (:mod:`validation.verification_time`).
Nothing here plots or writes files. The manufactured solutions are
:mod:`gatetherm.validation.verification_mms`, the shared pieces
:mod:`gatetherm.validation.verification_common` (their names importable from here too); the
exact elastic cases are here.
"""
from __future__ import annotations

from typing import Callable

import numpy as np
from skfem import CellBasis, ElementVector, FacetBasis, Mesh, MeshTet, MeshTri, asm

from gatetherm.solvers.elasticity import assemble_elastic, moduli, stiffness, thermal_load
from gatetherm.solvers.problem import Support
from gatetherm.solvers.fem import element
from gatetherm.validation.verification_common import (  # noqa: F401 (re-exported)
    _l2, _sigma, _solve_fixed, dofs_where, observed_order, rectangle, uniform_fields, vector_load)
from gatetherm.validation.verification_mms import (  # noqa: F401 (re-exported)
    ELASTIC_T, ELASTIC_U, HEAT_U, SPATIAL_ELASTIC, SPATIAL_HEAT, CosProduct, elastic_mms_error, heat_mms_error,
    spatial_study, unit_mesh)


# --- exact elastic cases ----------------------------------------------------------------------

def thermoelastic_solve(mesh: Mesh, order: int, T_order: int, T_fun: Callable,
                        fixed: Callable[[CellBasis], np.ndarray], traction=None,
                        E=1.2e11, nu=0.26, alpha=1.05e-5):
    """Solve with the module forms ``stiffness`` and ``thermal_load`` for the
    temperature rise ``T_fun(x)`` (K, interpolated on P``T_order``), the DOFs
    ``fixed(basis)`` held at zero and an optional ``traction`` = (facets, vector in Pa).
    Returns (displacement basis, displacement DOFs, stress in Pa at its quadrature points)."""
    dim = mesh.dim()
    lam, mu, b = moduli(E, nu, alpha, dim)
    q = 2 * max(order, T_order)
    vb = CellBasis(mesh, ElementVector(element(dim, order)), intorder=q)
    tb = CellBasis(mesh, element(dim, T_order), quadrature=vb.quadrature)
    T = T_fun(tb.doflocs)
    rhs = asm(thermal_load, tb, vb, b=b, t=1.0) @ T
    if traction is not None:
        fb = FacetBasis(mesh, vb.elem, facets=traction[0], intorder=q)
        rhs = rhs + asm(vector_load, fb, f=np.asarray(traction[1], float)[:, None, None]
                        * np.ones(fb.X.shape[-1]))
    U = _solve_fixed(asm(stiffness, vb, lam=lam, mu=mu, t=1.0), rhs, fixed(vb))
    return vb, U, _sigma(vb.interpolate(U).grad, np.asarray(tb.interpolate(T)), lam, mu, b)


# --- exact cases on a block -------------------------------------------------------------------

BLOCK = (0.3, 0.1, 0.05)
"""Length, height and depth of the test block of the exact cases, m."""


def block(dim: int, n: int = 6) -> Mesh:
    """The :data:`BLOCK` in n × 2 (× 2) cells."""
    L, H, D = BLOCK
    x, y, z = np.linspace(0, L, n + 1), np.linspace(0, H, 3), np.linspace(0, D, 3)
    return MeshTri.init_tensor(x, y) if dim == 2 else MeshTet.init_tensor(x, y, z)


def at_point(point) -> Callable:
    """``where(x)`` for the DOFs at exactly ``point``."""
    return lambda x: np.all(np.abs(x - np.reshape(point, (-1, 1))) < 1e-12, axis=0)


def statically_determinate(dim: int) -> Callable[[CellBasis], np.ndarray]:
    """Supports of the block that remove only the rigid motions: origin fixed, (L, 0[, 0])
    held in y[, z], and in 3-D (0, H, 0) held in z."""
    L, H, _ = BLOCK
    o = np.zeros(dim)

    def fixed(vb):
        d = [dofs_where(vb, at_point(o), range(dim)), dofs_where(vb, at_point(np.r_[L, o[1:]]), range(1, dim))]
        if dim == 3:
            d.append(dofs_where(vb, at_point([0.0, H, 0.0]), [2]))
        return np.concatenate(d)
    return fixed


def component_values(vb: CellBasis, U: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Displacement components (dim, nodes) and the node coordinates (dim, nodes)."""
    idx = vb.split_indices()
    x = vb.doflocs[:, idx[0]]
    if not all(np.array_equal(vb.doflocs[:, i], x) for i in idx):
        raise ValueError("the components' DOFs are not at the same points")
    return np.array([U[i] for i in idx]), x


def free_expansion(dim: int, order: int, dT: float = 30.0, alpha: float = 1.05e-5) -> dict[str, float]:
    """Uniform ΔT (K) on the block held only against rigid motion (u = α ΔT x exactly):
    largest |u − α ΔT x| and the tip's relative error, in units of α ΔT L, and the largest
    |σ| in units of the thermal stress b ΔT."""
    L = BLOCK[0]
    vb, U, sig = thermoelastic_solve(block(dim), order, 1, lambda x: np.full(x.shape[1], dT),
                                     statically_determinate(dim), alpha=alpha)
    u, x = component_values(vb, U)
    tip = dofs_where(vb, at_point(np.r_[L, np.zeros(dim - 1)]), [0])
    b = moduli(1.2e11, 0.26, alpha, dim)[2]
    return {"u": float(np.abs(u - alpha * dT * x).max() / (alpha * dT * L)),
            "tip": float(abs(U[tip][0] / (alpha * dT * L) - 1.0)), "stress": float(np.abs(sig).max() / (b * dT))}


LINEAR_T = (10.0, 100.0, -60.0, 40.0)
"""T = a + g·x of the stress-free case: a in K, g in K/m."""


def linear_temperature(dim: int, T_order: int) -> dict[str, float]:
    """A linear rise :data:`LINEAR_T` gives the compatible strain α T I (quadratic
    displacement: P2 reproduces it): largest |σ| in units of b T_max, and the largest
    displacement in m (not zero: the block does expand)."""
    g = np.array(LINEAR_T[1:])[:dim]
    vb, U, sig = thermoelastic_solve(block(dim), 2, T_order, lambda x: LINEAR_T[0] + g @ x,
                                     statically_determinate(dim))
    T_max = LINEAR_T[0] + np.abs(g) @ np.array(BLOCK)[:dim]
    return {"stress": float(np.abs(sig).max() / (moduli(1.2e11, 0.26, 1.05e-5, dim)[2] * T_max)),
            "u_max": float(np.abs(U).max())}


def clamped_bar_tip(L: float = 0.4, h: float = 0.02, dT: float = 10.0, order: int = 2,
                    nx: int = 4, ny: int = 80, E=1.2e11, nu=0.26, alpha=1.05e-5):
    """(FE, beam theory, FE by adjoint weights) x-displacement (m) of the tip centre of
    an ``h × L`` (m) bar clamped on its mounting face y = 0, for a rise growing linearly
    by ``dT`` (K) across the width, through :func:`solvers.elasticity.assemble_elastic`.
    Beam theory: uniform curvature α dT/h, tip ``−α dT L² / (2h)``."""
    m = rectangle(np.linspace(0.0, h, nx + 1), np.linspace(0.0, L, ny + 1), {"bottom": "mounting_face"})
    tb = CellBasis(m, element(2, order), intorder=2 * order)
    el = assemble_elastic(m, order, tb, *uniform_fields(m, E, nu, alpha, 0.1), (Support("mounting_face", (0, 1)),))
    T = dT * (tb.doflocs[0] / h - 0.5)
    g = el.point_functional([0.5 * h, L], 0)
    return float(g @ el.displacement(T)), -alpha * dT * L ** 2 / (2 * h), float(el.weights(g) @ T)
