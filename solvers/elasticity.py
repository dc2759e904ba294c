"""Linear thermoelasticity: plane stress or plane strain (2-D section) or 3-D solid.

σ = C : (ε(u) − α (T − T_ref) I). Supports hold chosen displacement components of a
boundary at zero or put it on an elastic foundation (stiffness per unit area). The
temperature enters the load linearly, ``K u = B (T − T_ref)``, so any linear output
``g·u`` is a fixed weight vector on the temperature, ``w = Bᵀ K⁻¹ g`` (one adjoint
solve per output): sensors need no elastic solve per time step. What the supports hold, and a
part they leave free, is :mod:`gatetherm.solvers.supports` (its names importable from here too).
"""
from __future__ import annotations

import logging
import re
from dataclasses import dataclass
from functools import partial

import numpy as np
import scipy.sparse as sp
from skfem import BilinearForm, CellBasis, ElementVector, FacetBasis, LinearForm, asm
from skfem.helpers import ddot, div, sym_grad

from gatetherm import InputError
from gatetherm.solvers import p1
from gatetherm.solvers.fem import Field, complement, dof_basis, element
from gatetherm.solvers.helper import Pending
from gatetherm.solvers.linsolve import SPDSolver, expand_order, nd_order, restrict_order, rigid_body_modes
from gatetherm.solvers.material import lame, lame_plane_stress, thermal_stress_modulus
from gatetherm.solvers.supports import (  # noqa: F401 (re-exported)
    MODE_NAMES, _held_by, _refuse_loose, fixed_dofs, free_modes, parts, support_dofs)

log = logging.getLogger(__name__)


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
    stiffness: Pending
    """:attr:`K`, assembled where it is first needed: in the solver's helper process where
    :meth:`~gatetherm.solvers.linsolve.SPDSolver.start` sets one up (then never here)."""
    thermal: Pending
    """:attr:`B`, assembled where it is first needed (linear elements: after the solver's helper
    process is started, which does not need it)."""
    free: np.ndarray
    solve: SPDSolver
    """Solves with the stiffness on the free DOFs (one or more right-hand sides)."""
    plane: str = "stress"
    """2-D: "stress", "strain" or "axisymmetric"."""
    K_fixed: sp.csr_matrix | None = None
    """Stiffness columns of the held DOFs (all rows), where a support prescribes a displacement."""

    @property
    def K(self) -> sp.csr_matrix:
        """Stiffness on the free DOFs."""
        return self.stiffness.result()

    @property
    def B(self) -> sp.csr_matrix:
        """Thermal load per unit temperature rise (all DOFs × heat DOFs)."""
        return self.thermal.result()

    def displacement(self, dT: np.ndarray) -> np.ndarray:
        """Displacement field (m) for the temperature rise ``dT`` (K) on the heat basis
        (``dT`` (n, k): k fields in one solve)."""
        return self.from_load(self.B @ dT)

    def from_load(self, load: np.ndarray) -> np.ndarray:
        """Displacement field (m) for a load vector (N) on the displacement basis."""
        return self.later(load).result()

    def later(self, load: np.ndarray):
        """:meth:`from_load` as a :class:`~gatetherm.solvers.helper.Pending`: solved beside the
        caller where the solver runs in a helper process
        (:meth:`~gatetherm.solvers.linsolve.SPDSolver.start`)."""
        shape = (self.basis.N,) + np.shape(load)[1:]

        def full(x):
            u = np.zeros(shape)
            u[self.free] = x
            return u
        return self.solve.submit(load[self.free]).then(full)

    def point_functional(self, xyz: np.ndarray, component: int) -> np.ndarray:
        """Vector g with g·u = u_component at point ``xyz``."""
        P = p1.probes(self.basis, np.asarray(xyz, dtype=float).reshape(-1, 1))
        return P[component].toarray().ravel()

    def weights(self, g: np.ndarray) -> np.ndarray:
        """Temperature weights w with w·dT = g·u(dT) (adjoint solve); ``g`` may be
        (N,) or (outputs, N), giving (n_T,) or (outputs, n_T)."""
        return self.weights_later(g).result()

    def weights_later(self, g: np.ndarray):
        """:meth:`weights` as a :class:`~gatetherm.solvers.helper.Pending` (see :meth:`later`)."""
        G = np.atleast_2d(g)
        Z = self.later(np.ascontiguousarray(G.T))  # all outputs in one solve
        return Z.then(lambda z: (self.B.T @ z).T[0] if np.ndim(g) == 1 else (self.B.T @ z).T)


class _Solver(SPDSolver):
    """:class:`~gatetherm.solvers.linsolve.SPDSolver`, a singular matrix (zero pivot) refused as bad input."""

    def _make(self, rhs: int):
        try:
            return super()._make(rhs)
        except (RuntimeError, ArithmeticError) as err:
            if not re.search("pivot|singular|definite", str(err), re.I):
                raise
            raise InputError("supports", f"the elastic system is singular ({err})",
                             "a part is not held: hold every part, or join it to a held one") from None


def _free_order(s: p1.Simplices, dim: int, free: np.ndarray, n: int) -> np.ndarray | None:
    """The order of the free DOFs from the mesh nodes' (``dim`` DOFs per node, ``n`` in all)."""
    return restrict_order(expand_order(s.order, dim), free, n)


def assemble_elastic(mesh, order: int, T_basis: CellBasis, E: Field, nu: Field, alpha: Field,
                     thickness: Field, supports, plane: str = "stress",
                     simplices: p1.Simplices | None = None, lines=None, contacts=()) -> ElasticSystem:
    """Assemble on a scikit-fem mesh with named boundaries; the temperature lives on
    ``T_basis`` (same mesh). ``supports`` are :class:`~gatetherm.solvers.problem.Support`
    (on a boundary, or on a line of ``lines``, 3-D: name to node pairs); ``contacts`` the
    :class:`~gatetherm.solvers.problem.Contact` joints of a mesh cut open along them. A part
    the supports and joints leave free to move is an :class:`~gatetherm.InputError` naming it.
    Linear elements use ``simplices`` (:func:`~gatetherm.solvers.p1.simplices` of the
    mesh, found if not given)."""
    from gatetherm.solvers import axisym
    from gatetherm.solvers.contact import joints

    dim, axi = mesh.dim(), plane == "axisymmetric"
    q = 2 * order + 1 if axi else 2 * order - 1  # exact for stiffness and thermal load on affine simplices
    lam, mu, b = moduli(E.values, nu.values, alpha.values, dim, plane)
    linear = order == 1 and T_basis.elem.maxdeg == 1 and not axi
    if linear:  # the same matrices, vectorised (solvers/p1.py)
        simplices, th = simplices or p1.simplices(mesh), thickness.values
        vb = dof_basis(mesh, ElementVector(element(dim, order)))
        K = partial(p1.stiffness, simplices.pattern, simplices.G, simplices.vol, lam * th, mu * th)
        B = Pending(lambda: p1.thermal_load(simplices.pattern, simplices.G, simplices.vol, b * th).tocsr())
    else:
        vb = CellBasis(mesh, ElementVector(element(dim, order)), intorder=q)
        T_basis, t = CellBasis(mesh, T_basis.elem, intorder=q), thickness.at(vb)
        forms = (axisym.stiffness, axisym.thermal_load) if axi else (stiffness, thermal_load)
        K = partial(asm, forms[0], vb, lam=Field(lam).at(vb), mu=Field(mu).at(vb), t=t)
        B = Pending.of(asm(forms[1], T_basis, vb, b=Field(b).at(vb), t=t).tocsr())
    springs = []
    for s in supports:
        if s.stiffness is not None:
            fb = FacetBasis(mesh, vb.elem, facets=mesh.boundaries[s.boundary])
            springs.append(asm(foundation, fb, k=s.stiffness, t=thickness.at(fb), comps=s.components))
    springs += joints(vb, mesh, contacts, thickness, float(np.nanmax(E.values)))
    fixed = fixed_dofs(vb, mesh, supports, lines)
    pieces = parts(vb) if contacts else None
    loose = free_modes(vb, fixed, springs, pieces, axi)
    if loose:
        _refuse_loose(vb, mesh, loose, pieces)
    free = complement(vb.N, fixed)

    def whole():  # with the supports' springs
        A = K()
        return (A + sum(springs[1:], springs[0]) if springs else A).tocsr()

    def on_free(A):  # in two steps: the full matrix goes before the columns are taken
        A = A[free]
        return A[:, free]
    K_fixed, size = None, None  # the size: the made matrix's
    if linear and not any(s.values for s in supports):  # the nodes' order, found when a factor needs it
        Kf, size = Pending(lambda: on_free(whole())), (len(free), _free_nonzeros(simplices.pattern, free, dim))
        perm = partial(_free_order, simplices, dim, free, vb.N)
    else:
        A = whole()
        K_fixed = A[:, fixed] if any(s.values for s in supports) else None
        perm = partial(_free_order, simplices, dim, free, vb.N) if linear else \
            restrict_order(nd_order(A, dim), free, vb.N)
        Kf = Pending.of(on_free(A))
    rbm = rigid_body_modes(vb.doflocs, vb.split_indices())[free]
    log.info("elastic system: %d free DOFs (P%d, %d-D%s)", len(free), order, dim,
             f" plane {plane}" if dim == 2 else "")
    nodal = len(free) % dim == 0 and bool(np.all(free.reshape(-1, dim) == (free[::dim] // dim * dim)[:, None]
                                                   + np.arange(dim)))
    return ElasticSystem(vb, Kf, B, free, _Solver(Kf, dim, rbm, perm, nodal, size=size), plane, K_fixed)


def _free_nonzeros(pattern: p1.Pattern, free: np.ndarray, dim: int) -> int:
    """Nonzeros of the stiffness on the ``free`` DOFs (``dim`` per node, interleaved) without
    assembling it: each node pair's block has (free DOFs of one) × (free DOFs of the other)."""
    c = np.bincount(free // dim, minlength=pattern.n).astype(float)
    return int(c @ (pattern.graph() @ c))
