"""Linear thermoelasticity: plane stress or plane strain (2-D section) or 3-D solid.

σ = C : (ε(u) − α (T − T_ref) I). Supports hold chosen displacement components of a
boundary at zero or put it on an elastic foundation (stiffness per unit area). The
temperature enters the load linearly, ``K u = B (T − T_ref)``, so any linear output
``g·u`` is a fixed weight vector on the temperature, ``w = Bᵀ K⁻¹ g`` (one adjoint
solve per output): sensors need no elastic solve per time step.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from skfem import BilinearForm, CellBasis, ElementVector, FacetBasis, LinearForm, asm
from skfem.helpers import ddot, div, sym_grad

from gatetherm import InputError
from gatetherm.solvers import p1
from gatetherm.solvers.fem import Field, dof_basis, element
from gatetherm.solvers.linsolve import SPDSolver, expand_order, nd_order, restrict_order, rigid_body_modes
from gatetherm.solvers.material import lame, lame_plane_stress, thermal_stress_modulus

log = logging.getLogger(__name__)

MODE_NAMES = {2: ("translation x", "translation y", "rotation about z"),
              3: ("translation x", "translation y", "translation z", "rotation about z",
                  "rotation about x", "rotation about y")}
"""Rigid-body modes in the order of :func:`~gatetherm.solvers.linsolve.rigid_body_modes`."""


@BilinearForm
def stiffness(u, v, w):
    return w.t * (w.lam * div(u) * div(v) + 2.0 * w.mu * ddot(sym_grad(u), sym_grad(v)))


@BilinearForm
def thermal_load(T, v, w):
    """Trial: temperature rise; test: displacement. ``w.b`` is the thermal stress modulus."""
    return w.t * w.b * T * div(v)


@LinearForm
def thermal_load_at(v, w):
    """The load of a temperature rise ``w.T`` given at the quadrature points."""
    return w.t * w.b * w.T * div(v)


@BilinearForm
def foundation(u, v, w):
    return w.k * w.t * sum(u[c] * v[c] for c in w.comps)


def moduli(E: np.ndarray, nu: np.ndarray, alpha: np.ndarray, dim: int, plane: str = "stress"):
    """Element-wise (λ, μ, thermal stress modulus): plane stress, plane strain or 3-D."""
    if dim == 2 and plane == "stress":
        lam, mu = lame_plane_stress(E, nu)
        return lam, mu, thermal_stress_modulus(E, nu, alpha, 2)
    lam, mu = lame(E, nu)
    return lam, mu, thermal_stress_modulus(E, nu, alpha, 3)


@dataclass(frozen=True)
class ElasticSystem:
    """Assembled elastic operators on the free DOFs, solver set up once."""

    basis: CellBasis
    K: sp.csr_matrix
    """Stiffness on the free DOFs."""
    B: sp.csr_matrix
    """Thermal load per unit temperature rise (all DOFs × heat DOFs)."""
    free: np.ndarray
    solve: SPDSolver
    """Solves with the stiffness on the free DOFs (one or more right-hand sides)."""
    plane: str = "stress"
    """2-D: "stress" or "strain"."""

    def displacement(self, dT: np.ndarray) -> np.ndarray:
        """Displacement field (m) for the temperature rise ``dT`` (K) on the heat basis
        (``dT`` (n, k): k fields in one solve)."""
        return self.from_load(self.B @ dT)

    def from_load(self, load: np.ndarray) -> np.ndarray:
        """Displacement field (m) for a load vector (N) on the displacement basis."""
        u = np.zeros((self.basis.N,) + np.shape(load)[1:])
        u[self.free] = self.solve(load[self.free])
        return u

    def point_functional(self, xyz: np.ndarray, component: int) -> np.ndarray:
        """Vector g with g·u = u_component at point ``xyz``."""
        P = self.basis.probes(np.asarray(xyz, dtype=float).reshape(-1, 1))
        return P.tocsr()[component].toarray().ravel()

    def weights(self, g: np.ndarray) -> np.ndarray:
        """Temperature weights w with w·dT = g·u(dT) (adjoint solve); ``g`` may be
        (N,) or (outputs, N), giving (n_T,) or (outputs, n_T)."""
        G = np.atleast_2d(g)
        Z = np.zeros((self.basis.N, G.shape[0]))
        Z[self.free] = self.solve(np.ascontiguousarray(G[:, self.free].T))  # all outputs in one solve
        W = (self.B.T @ Z).T
        return W[0] if np.ndim(g) == 1 else W


def fixed_dofs(vb: CellBasis, mesh, supports) -> np.ndarray:
    """Displacement DOFs held at zero by the supports without a foundation stiffness. With
    DOFs at the nodes only (P1), the facets' nodes give them directly, interleaved as
    scikit-fem numbers them (its general path builds the mesh's edges: 0.6 s on the 3-D frame)."""
    dim = mesh.dim()
    if vb.N == dim * mesh.nvertices:
        out = [(dim * np.unique(mesh.facets[:, mesh.boundaries[s.boundary]])[:, None] + list(s.components)).ravel()
               for s in supports if s.stiffness is None]
        return np.unique(np.concatenate(out)) if out else np.zeros(0, dtype=np.int64)
    names = [f"u^{c + 1}" for c in range(dim)]
    out = [vb.get_dofs(mesh.boundaries[s.boundary]).all([names[c] for c in s.components])
           for s in supports if s.stiffness is None]
    return np.unique(np.concatenate(out)) if out else np.zeros(0, dtype=np.int64)


def free_modes(vb: CellBasis, fixed: np.ndarray, K_found: sp.spmatrix | None) -> list[str]:
    """Rigid-body modes the supports leave free (names of :data:`MODE_NAMES`)."""
    dim = vb.mesh.dim()
    R = rigid_body_modes(vb.doflocs, vb.split_indices())
    R = R / np.linalg.norm(R, axis=0)
    G = R[fixed].T @ R[fixed]
    if K_found is not None:
        F = R.T @ (K_found @ R)
        scale = np.abs(F).max()
        G = G + (F / scale if scale > 0 else F)
    w, V = np.linalg.eigh(G)
    loose = V[:, w < 1e-10 * max(w.max(), 1.0)]
    return [MODE_NAMES[dim][int(np.argmax(np.abs(v)))] for v in loose.T]


def assemble_elastic(mesh, order: int, T_basis: CellBasis, E: Field, nu: Field, alpha: Field,
                     thickness: Field, supports, plane: str = "stress",
                     simplices: p1.Simplices | None = None) -> ElasticSystem:
    """Assemble on a scikit-fem mesh with named boundaries; the temperature lives on
    ``T_basis`` (same mesh). ``supports`` are :class:`~gatetherm.solvers.problem.Support`.
    A rigid-body mode the supports leave free is an :class:`~gatetherm.InputError`.
    Linear elements use ``simplices`` (:func:`~gatetherm.solvers.p1.simplices` of the
    mesh, found if not given)."""
    dim = mesh.dim()
    q = 2 * order - 1  # exact for the stiffness and the thermal load on affine simplices
    lam, mu, b = moduli(E.values, nu.values, alpha.values, dim, plane)
    node_order = None
    if order == 1 and T_basis.elem.maxdeg == 1:  # the same matrices, vectorised (solvers/p1.py)
        s, th = simplices or p1.simplices(mesh), thickness.values
        vb, node_order = dof_basis(mesh, ElementVector(element(dim, order))), s.order
        K = p1.stiffness(s.pattern, s.G, s.vol, lam * th, mu * th)
        B = p1.thermal_load(s.pattern, s.G, s.vol, b * th)
    else:
        vb = CellBasis(mesh, ElementVector(element(dim, order)), intorder=q)
        T_basis, t = CellBasis(mesh, T_basis.elem, intorder=q), thickness.at(vb)
        K = asm(stiffness, vb, lam=Field(lam).at(vb), mu=Field(mu).at(vb), t=t)
        B = asm(thermal_load, T_basis, vb, b=Field(b).at(vb), t=t)
    K_found = None
    for s in supports:
        if s.stiffness is not None:
            fb = FacetBasis(mesh, vb.elem, facets=mesh.boundaries[s.boundary])
            Kf = asm(foundation, fb, k=s.stiffness, t=thickness.at(fb), comps=s.components)
            K_found = Kf if K_found is None else K_found + Kf
    fixed = fixed_dofs(vb, mesh, supports)
    loose = free_modes(vb, fixed, K_found)
    if loose:
        raise InputError("supports", f"the supports leave rigid-body motion free ({', '.join(loose)})",
                         "hold more displacement components (clamped, normal, fixed) or add a foundation")
    if K_found is not None:
        K = K + K_found
    free = np.setdiff1d(np.arange(vb.N), fixed)
    K = K.tocsr()
    dof_order = nd_order(K, dim) if node_order is None else expand_order(node_order, dim)
    perm = restrict_order(dof_order, free, vb.N)
    K = K[free]  # in two steps: the full matrix goes before the columns are taken
    K = K[:, free]
    rbm = rigid_body_modes(vb.doflocs, vb.split_indices())[free]
    log.info("elastic system: %d free DOFs (P%d, %d-D%s)", len(free), order, dim,
             f" plane {plane}" if dim == 2 else "")
    nodal = len(free) % dim == 0 and bool(np.all(free.reshape(-1, dim) == (free[::dim] // dim * dim)[:, None]
                                                   + np.arange(dim)))
    solve = SPDSolver(K, dim, rbm, perm, nodal)
    return ElasticSystem(vb, K, B.tocsr(), free, solve, plane)
