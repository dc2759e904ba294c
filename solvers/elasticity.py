"""Linear thermoelasticity: plane stress or plane strain (2-D section) or 3-D solid.

σ = C : (ε(u) − α (T − T_ref) I). Supports hold chosen displacement components of a
boundary at zero or put it on an elastic foundation (stiffness per unit area). The
temperature enters the load linearly, ``K u = B (T − T_ref)``, so any linear output
``g·u`` is a fixed weight vector on the temperature, ``w = Bᵀ K⁻¹ g`` (one adjoint
solve per output): sensors need no elastic solve per time step.
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


def support_dofs(vb: CellBasis, mesh, boundary: str, components, lines=None) -> np.ndarray:
    """The displacement DOFs of ``components`` on a boundary, or (3-D) on a line of
    ``lines`` (name: node pairs). With DOFs at the nodes only (P1), the facets' nodes give
    them directly, interleaved as scikit-fem numbers them (its general path builds the
    mesh's edges: 0.6 s on the 3-D frame)."""
    dim = mesh.dim()
    if lines and boundary in lines:
        pairs = np.sort(lines[boundary], axis=1)
        out = [vb.nodal_dofs[c, np.unique(pairs)] for c in components]
        if vb.edge_dofs.size:
            index = {tuple(e): i for i, e in enumerate(np.sort(mesh.edges, axis=0).T.tolist())}
            edges = [index[tuple(e)] for e in pairs.tolist()]
            out += [vb.edge_dofs[c, edges] for c in components]
        return np.concatenate(out)
    if vb.N == dim * mesh.nvertices:
        return (dim * np.unique(mesh.facets[:, mesh.boundaries[boundary]])[:, None] + list(components)).ravel()
    names = [f"u^{c + 1}" for c in range(dim)]
    return vb.get_dofs(mesh.boundaries[boundary]).all([names[c] for c in components])


def fixed_dofs(vb: CellBasis, mesh, supports, lines=None) -> np.ndarray:
    """Displacement DOFs held (at zero or a prescribed value) by the supports without a
    foundation stiffness."""
    out = [support_dofs(vb, mesh, s.boundary, s.components, lines) for s in supports if s.stiffness is None]
    return np.unique(np.concatenate(out)) if out else np.zeros(0, dtype=np.int64)


def parts(vb: CellBasis) -> list[np.ndarray]:
    """The DOFs of every connected piece of the mesh (elements sharing a DOF)."""
    from scipy.sparse.csgraph import connected_components

    ed = vb.element_dofs
    e = ed.shape[1]
    graph = sp.coo_matrix((np.ones(ed.size), (np.tile(np.arange(e), ed.shape[0]), e + ed.ravel())),
                          shape=(e + vb.N, e + vb.N))
    label = connected_components(graph, directed=False)[1][e:]
    return [np.flatnonzero(label == k) for k in np.unique(label)]


def free_modes(vb: CellBasis, fixed: np.ndarray, springs=(), pieces=None,
               axisymmetric: bool = False) -> list[tuple[int, str]]:
    """Rigid-body modes the supports and the spring matrices (foundations, joints) leave
    free, as (piece, name of :data:`MODE_NAMES`): ``pieces`` are the DOF sets of the
    mesh's connected pieces (None: one). An axisymmetric body has one: translation y."""
    dim = vb.mesh.dim()
    R0 = rigid_body_modes(vb.doflocs, vb.split_indices())
    names = MODE_NAMES[dim]
    if axisymmetric:
        R0, names = R0[:, [1]], names[1:2]
    blocks = []
    for p in pieces or [np.arange(vb.N)]:
        R = np.zeros_like(R0)
        R[p] = R0[p]
        blocks.append(R)
    R = np.hstack(blocks)
    R = R / np.linalg.norm(R, axis=0)
    G = R[fixed].T @ R[fixed]
    for K in springs:
        G = G + _held_by(K, R)
    w, V = np.linalg.eigh(G)
    loose = V[:, w < 1e-10 * max(w.max(), 1.0)]
    m = len(names)
    return [(int(i) // m, names[int(i) % m]) for i in np.argmax(np.abs(loose), axis=0)]


def _held_by(K, R: np.ndarray) -> np.ndarray:
    """The energy ``Rᵀ K R`` of the rigid modes ``R`` in the spring matrix ``K`` (a foundation or
    a joint), in units of the energy its diagonal alone would give them (``Rᵀ diag(K) R``): O(1)
    for a mode the spring holds, round-off for one it carries along (a rigid motion of both sides
    of a joint). Scaled by its own largest entry instead, a joint's round-off became O(1) with
    either sign, and a held assembly was refused at P2 (issue 51)."""
    F = R.T @ (K @ R)
    diag = np.asarray(abs(K.diagonal()) if hasattr(K, "diagonal") else np.abs(np.diag(K)), dtype=float)
    scale = float(((R * R).T @ diag).max())
    if scale <= 0.0:
        return np.zeros_like(F)
    F = (F + F.T) / (2.0 * scale)
    w, V = np.linalg.eigh(F)  # a spring only holds: no round-off of either sign
    return (V * np.clip(w, 0.0, None)) @ V.T


def _refuse_loose(vb: CellBasis, mesh, loose, pieces) -> None:
    """The first free part as an :class:`~gatetherm.InputError` naming its regions."""
    piece = loose[0][0]
    modes = ", ".join(dict.fromkeys(n for p, n in loose if p == piece))
    if pieces is None:
        regions = list(mesh.subdomains)
    else:
        regions = [r for r, els in mesh.subdomains.items() if np.isin(vb.element_dofs[0, els[0]], pieces[piece])]
    raise InputError("supports", f"the part made of region{'s' * (len(regions) > 1)} {', '.join(regions)} is free to "
                     f"move ({modes})", "hold more displacement components (clamped, normal, fixed) or add a "
                     "foundation, or join the part to a held one (a contact stiffness in both directions)")


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
