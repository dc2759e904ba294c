"""Stress recovery: the thermoelastic stress projected (L2) onto the continuous Lagrange
space of the displacement's degree, over all elements or over one region (a stress
that jumps between regions, as at a heated spot, is read from one side).

A projected component at a point is linear in the displacement and the temperature
rise, ``σ_c(p) = g_u·u + g_T·ΔT``; :class:`Recovery` gives those vectors, so a stress
probe costs what a displacement probe costs. Von Mises is computed from the components.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from skfem import BilinearForm, CellBasis, ElementVector, LinearForm, asm
from skfem.helpers import div, sym_grad

from gatetherm.solvers.elasticity import moduli
from gatetherm.solvers.fem import Field, dof_basis, element

COMPONENTS = {(2, "stress"): ("xx", "yy", "xy"), (2, "strain"): ("xx", "yy", "zz", "xy"),
              (2, "axisymmetric"): ("xx", "yy", "tt", "xy"),
              (3, "stress"): ("xx", "yy", "zz", "xy", "yz", "xz"), (3, "strain"): ("xx", "yy", "zz", "xy", "yz", "xz")}
"""Stress components reported, by (dimension, 2-D plane kind); axisymmetric: x radial, y
axial, "tt" the hoop stress."""
_INDEX = {"xx": (0, 0), "yy": (1, 1), "zz": (2, 2), "xy": (0, 1), "yz": (1, 2), "xz": (0, 2), "tt": (2, 2)}


@BilinearForm
def mass(u, v, w):
    return u * v


@BilinearForm
def stress_of_u(u, v, w):
    """Trial: displacement; test: scalar. Component ``(w.i, w.j)`` of ``λ tr ε I + 2 μ ε``."""
    i, j = w.i, w.j
    s = 2.0 * w.mu * sym_grad(u)[i][j] if i < w.dim and j < w.dim else 0.0 * div(u)
    return (s + w.lam * div(u)) * v if i == j else s * v


@BilinearForm
def stress_of_T(T, v, w):
    """Trial: temperature rise; test: scalar. The thermal part ``−b ΔT`` of a normal component."""
    return -w.b * T * v


@LinearForm
def stress_of_T_at(v, w):
    """The thermal part of a normal component for a rise ``w.T`` given at the quadrature points."""
    return -w.b * w.T * v


def von_mises(s: dict[str, np.ndarray]) -> np.ndarray:
    """Von Mises stress from components (missing ones are zero; the hoop stress "tt" is the
    third normal one)."""
    g = {k: np.asarray(s.get(k, 0.0)) for k in _INDEX}
    g["zz"] = g["zz"] + g["tt"]
    return np.sqrt(0.5 * ((g["xx"] - g["yy"]) ** 2 + (g["yy"] - g["zz"]) ** 2 + (g["zz"] - g["xx"]) ** 2)
                   + 3.0 * (g["xy"] ** 2 + g["yz"] ** 2 + g["xz"] ** 2))


@dataclass(frozen=True)
class Assembled:
    """The projection's right-hand sides per unit displacement as matrices, one per component."""

    S: dict[str, sp.csr_matrix]

    def __call__(self, u: np.ndarray) -> dict[str, np.ndarray]:
        return {c: S @ u for c, S in self.S.items()}

    def transposed(self, z: np.ndarray) -> dict[str, np.ndarray]:
        return {c: S.T @ z for c, S in self.S.items()}


@dataclass(frozen=True)
class ElementStress:
    """The same for linear simplices, element by element and never assembled (six matrices of
    three blocks per node pair: 0.15 GB on the 3-D frame): the stress is constant on each
    element, so ``∫ σ_c(u) ψ_i = Σ_{e ∋ i} vol_e σ_c,e(u) / (d+1)``."""

    cells: np.ndarray
    """(E, d+1) node indices of the elements projected over."""
    G: np.ndarray
    """(E, d+1, d) their barycentric gradients."""
    vol: np.ndarray
    lam: np.ndarray
    mu: np.ndarray
    """Per element: measure (m^d) and Lamé moduli (Pa, thickness included)."""
    components: tuple[str, ...]
    n: int
    """Number of nodes."""

    def __call__(self, u: np.ndarray) -> dict[str, np.ndarray]:
        d, k = self.G.shape[2], self.G.shape[1]
        grad = np.matmul(u.reshape(self.n, d)[self.cells].transpose(0, 2, 1), self.G)  # ∂_b u_a per element
        div = np.trace(grad, axis1=1, axis2=2)
        w, nodes = self.vol / k, self.cells.ravel()
        out = {}
        for c in self.components:
            i, j = _INDEX[c]
            s = self.mu * (grad[:, i, j] + grad[:, j, i]) if i < d and j < d else 0.0
            s = s + (self.lam * div if i == j else 0.0)
            out[c] = np.bincount(nodes, weights=np.repeat(w * s, k), minlength=self.n)
        return out

    def transposed(self, z: np.ndarray) -> dict[str, np.ndarray]:
        d, k = self.G.shape[2], self.G.shape[1]
        zbar = self.vol / k * z[self.cells].sum(axis=1)
        dofs = (d * self.cells[:, :, None] + np.arange(d)).ravel()
        out = {}
        for c in self.components:
            i, j = _INDEX[c]
            W = np.zeros(self.G.shape)  # ∂σ_c,e / ∂u[node j, component b]
            if i < d and j < d:
                W[:, :, j] += self.mu[:, None] * self.G[:, :, i]
                W[:, :, i] += self.mu[:, None] * self.G[:, :, j]
            if i == j:
                W += self.lam[:, None, None] * self.G
            out[c] = np.bincount(dofs, weights=(W * zbar[:, None, None]).ravel(), minlength=d * self.n)
        return out


@dataclass
class Recovery:
    """L2 projection of the stress onto the scalar space ``scalar`` restricted to the
    elements ``elements`` (all when None). Set up once per region; holds a factor."""

    scalar: CellBasis
    """Scalar Lagrange basis of the displacement's degree on the region."""
    full: CellBasis
    """The same on the whole mesh (same DOF numbers), to evaluate at points."""
    active: np.ndarray
    """Its DOFs touched by the region."""
    lu: object
    """Factor of the region's mass matrix on the active DOFs."""
    S: Assembled | ElementStress
    """The projection's right-hand sides per unit displacement: ``S(u)`` per component, and
    ``S.transposed(z)`` the products ``Sᵀ z`` per component."""
    Q: dict[str, sp.csr_matrix]
    """Per normal component: the right-hand side per unit nodal temperature rise."""
    components: tuple[str, ...]

    def at(self, xyz) -> np.ndarray:
        """Row φ with φ·s = the value at ``xyz`` of a field ``s`` on :attr:`scalar`."""
        from gatetherm.solvers import p1

        return p1.probes(self.full, np.asarray(xyz, float).reshape(-1, 1)).toarray().ravel()

    def _z(self, xyz) -> np.ndarray:
        phi = self.at(xyz)
        z = np.zeros(self.scalar.N)
        z[self.active] = self.lu.solve(phi[self.active])
        return z

    def point(self, xyz) -> dict[str, tuple[np.ndarray, np.ndarray | None]]:
        """Per component at ``xyz``: ``(g_u, g_T)`` with ``σ = g_u·u + g_T·ΔT`` (g_T None
        for shear components)."""
        z = self._z(xyz)
        gu = self.S.transposed(z)
        return {c: (gu[c], self.Q[c].T @ z if c in self.Q else None) for c in self.components}

    def field(self, u: np.ndarray, rhs_T: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """Projected components (on ``scalar``) for displacement ``u`` and the thermal
        right-hand sides ``rhs_T`` (per normal component, see :meth:`thermal_rhs`)."""
        rhs = self.S(u)
        b = np.column_stack([(rhs[c] + rhs_T.get(c, 0.0))[self.active] for c in self.components])
        s = np.zeros((self.scalar.N, len(self.components)))
        s[self.active] = self.lu.solve(b).reshape(b.shape)  # every component in one solve
        return dict(zip(self.components, s.T))

    def thermal_rhs(self, dT: np.ndarray) -> dict[str, np.ndarray]:
        """The thermal right-hand sides for a nodal temperature rise."""
        return {c: Q @ dT for c, Q in self.Q.items()}


def recovery(mesh, order: int, fields: dict[str, Field], dim: int, plane: str, T_elem,
             elements: np.ndarray | None = None, T_at=None, simplices=None) -> Recovery:
    """Set up the projection on ``elements`` (all if None). ``T_elem`` is the element of
    the nodal temperature rise; when the rise is prescribed instead, ``T_elem`` is None and
    ``T_at(basis)`` gives it at a basis's quadrature points: ``Q`` then holds one column,
    the thermal right-hand side itself (``thermal_rhs(np.ones(1))``). ``simplices``: the
    mesh's :class:`~gatetherm.solvers.p1.Simplices`, if found already (linear elements)."""
    q = 2 * order
    comps = COMPONENTS[(dim, plane)]
    normal = [c for c in comps if c[0] == c[1] and not (dim == 2 and plane == "stress" and c == "zz")]
    lam_e, mu_e, b_e = moduli(fields["E"].values, fields["nu"].values, fields["alpha"].values, dim, plane)
    if order == 1 and plane != "axisymmetric":
        return _p1_recovery(mesh, dim, comps, normal, lam_e, mu_e, b_e, elements, T_at, simplices)
    kw = {"intorder": q} if elements is None else {"intorder": q, "elements": elements}
    sb = CellBasis(mesh, element(dim, order), **kw)
    ub = CellBasis(mesh, ElementVector(element(dim, order)), **kw)
    lam, mu, b = (Field(v).at(sb) for v in (lam_e, mu_e, b_e))
    M = asm(mass, sb).tocsr()
    active = np.unique(sb.element_dofs)
    from gatetherm.solvers import axisym

    form = axisym.stress_of_u if plane == "axisymmetric" else stress_of_u
    S = Assembled({c: asm(form, ub, sb, lam=lam, mu=mu, i=_INDEX[c][0], j=_INDEX[c][1], dim=dim).tocsr()
                   for c in comps})
    if T_elem is not None:
        tb = CellBasis(mesh, T_elem, **kw)
        Q = {c: asm(stress_of_T, tb, sb, b=b).tocsr() for c in normal}
    else:
        Q = {c: sp.csr_matrix(asm(stress_of_T_at, sb, b=b, T=T_at(sb))[:, None]) for c in normal}
    full = sb if elements is None else CellBasis(mesh, element(dim, order), intorder=q)
    return Recovery(sb, full, active, _factor(M[active][:, active], dim=dim), S, Q, comps)


def _p1_recovery(mesh, dim: int, comps, normal, lam, mu, b, elements, T_at, simplices) -> Recovery:
    """:func:`recovery` for linear elements, vectorised (solvers/p1.py): the element stress
    is constant (:class:`ElementStress`) and the thermal part is the mass matrix times ``−b``."""
    from gatetherm.solvers import p1

    b_all = b
    if elements is None:
        s = simplices or p1.simplices(mesh)
        cells, G, vol, pattern = mesh.t.T, s.G, s.vol, s.pattern
        active = np.arange(mesh.nvertices)
        order = lambda: s.order  # noqa: E731  (all nodes active; found only if the projection is factorised)
    else:
        cells = mesh.t.T[elements]
        G, vol = p1.gradients(mesh.p.T, cells)
        lam, mu, b = lam[elements], mu[elements], b[elements]
        pattern, active, order = p1.Pattern(cells, mesh.nvertices), np.unique(cells), None
    M = pattern.scalar(p1.mass, G, vol, np.ones(len(vol)))[active][:, active]

    S = ElementStress(cells, G, vol, lam, mu, tuple(comps), mesh.nvertices)
    if T_at is None:
        Qn = pattern.scalar(p1.mass, G, vol, -b)  # the same for every normal component
        Q = {c: Qn for c in normal}
    else:
        sb = CellBasis(mesh, element(dim, 1), intorder=2, **({} if elements is None else {"elements": elements}))
        Q = {c: sp.csr_matrix(asm(stress_of_T_at, sb, b=Field(b_all).at(sb), T=T_at(sb))[:, None]) for c in normal}
    full = dof_basis(mesh, element(dim, 1))
    return Recovery(full, full, active, _factor(M, order, dim), S, Q, comps)


def _factor(M: sp.spmatrix, order=None, dim: int = 3):
    """A solver of the mass matrix as an object with ``solve``: a sparse Cholesky factor in a
    METIS order (``order``, or a function giving it; None: found from ``M``), or AMG-CG where that
    would not fit (:func:`~gatetherm.solvers.linsolve.planned_solver`, planned for the six components
    of a few fields)."""
    from types import SimpleNamespace

    from gatetherm.solvers.linsolve import nd_order, planned_solver

    order = (lambda: nd_order(M)) if order is None else order  # an array or a function: planned_solver takes both
    solve = planned_solver(M, dim, 6 * 8, "stress projection", order=order, rtol=1e-12)[0]
    return SimpleNamespace(solve=solve)
