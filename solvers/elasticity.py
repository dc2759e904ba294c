"""Linear thermoelasticity: plane stress (2-D section) or 3-D solid.

σ = C : (ε(u) − α (T − T_ref) I), mounting face clamped (or on an elastic
foundation of stiffness ``k_base`` per unit area). The temperature enters the
load linearly, ``K u = B (T − T_ref)``, so any linear displacement output
``g·u`` is a fixed weight vector on the temperature, ``w = Bᵀ K⁻¹ g``
(one adjoint solve per output): sensors need no elastic solve per time step.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Callable

import numpy as np
import scipy.sparse as sp
from skfem import BilinearForm, CellBasis, ElementVector, FacetBasis, asm
from skfem.helpers import ddot, div, dot, sym_grad

from gatetherm.solvers.fem import Field, element
from gatetherm.solvers.linsolve import rigid_body_modes, spd_solver
from gatetherm.solvers.material import lame, lame_plane_stress, thermal_stress_modulus

log = logging.getLogger(__name__)


@BilinearForm
def stiffness(u, v, w):
    return w.t * (w.lam * div(u) * div(v) + 2.0 * w.mu * ddot(sym_grad(u), sym_grad(v)))


@BilinearForm
def thermal_load(T, v, w):
    """Trial: temperature rise; test: displacement. ``w.b`` is the thermal stress modulus."""
    return w.t * w.b * T * div(v)


@BilinearForm
def foundation(u, v, w):
    return w.k * w.t * dot(u, v)


def moduli(E: np.ndarray, nu: np.ndarray, alpha: np.ndarray, dim: int):
    """Element-wise (λ, μ, thermal stress modulus) for plane stress (2-D) or 3-D."""
    lam, mu = (lame_plane_stress if dim == 2 else lame)(E, nu)
    return lam, mu, thermal_stress_modulus(E, nu, alpha, dim)


@dataclass(frozen=True)
class ElasticSystem:
    """Assembled elastic operators on the free DOFs, solver set up once."""

    basis: CellBasis
    K: sp.csr_matrix
    B: sp.csr_matrix
    free: np.ndarray
    solve: Callable[[np.ndarray], np.ndarray]

    def displacement(self, dT: np.ndarray) -> np.ndarray:
        """Displacement field (m) for the temperature rise ``dT`` (K) on the heat basis."""
        u = np.zeros(self.basis.N)
        u[self.free] = self.solve((self.B @ dT)[self.free])
        return u

    def point_functional(self, xyz: np.ndarray, component: int) -> np.ndarray:
        """Vector g with g·u = u_component at point ``xyz``."""
        P = self.basis.probes(np.asarray(xyz, dtype=float).reshape(-1, 1))
        return P.tocsr()[component].toarray().ravel()

    def weights(self, g: np.ndarray) -> np.ndarray:
        """Temperature weights w with w·dT = g·u(dT) (adjoint solve)."""
        z = np.zeros(self.basis.N)
        z[self.free] = self.solve(g[self.free])
        return self.B.T @ z


def assemble_elastic(mesh, order: int, T_basis: CellBasis, E: Field, nu: Field, alpha: Field,
                     thickness: Field, k_base: float | None = None) -> ElasticSystem:
    """Assemble on a mesh with a ``mounting_face`` boundary; the temperature
    lives on ``T_basis`` (same mesh). ``k_base`` (N/m³) replaces the clamp by
    an elastic foundation."""
    dim = mesh.dim()
    q = 2 * order - 1  # exact for the stiffness and the thermal load on affine simplices
    vb = CellBasis(mesh, ElementVector(element(dim, order)), intorder=q)
    T_basis = CellBasis(mesh, T_basis.elem, intorder=q)
    lam, mu, b = moduli(E.values, nu.values, alpha.values, dim)
    t = thickness.at(vb)
    K = asm(stiffness, vb, lam=Field(lam).at(vb), mu=Field(mu).at(vb), t=t)
    B = asm(thermal_load, T_basis, vb, b=Field(b).at(vb), t=t)
    if k_base is None:
        fixed = vb.get_dofs("mounting_face").all()
    else:
        fb = FacetBasis(mesh, vb.elem, facets=mesh.boundaries["mounting_face"])
        K = K + asm(foundation, fb, k=k_base, t=thickness.at(fb))
        fixed = np.zeros(0, dtype=np.int64)
    free = np.setdiff1d(np.arange(vb.N), fixed)
    Kff = K[free][:, free]
    rbm = rigid_body_modes(vb.doflocs, vb.split_indices())[free]
    log.info("elastic system: %d free DOFs (P%d, %d-D)", len(free), order, dim)
    return ElasticSystem(vb, K.tocsr(), B.tocsr(), free, spd_solver(Kff, dim, rbm))
