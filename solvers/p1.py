"""Linear (P1) simplex matrices assembled vectorised in numpy: capacity, conduction,
elastic stiffness and the thermal-load matrix, the same as scikit-fem's forms of
:mod:`gatetherm.solvers.heat` and :mod:`gatetherm.solvers.elasticity` (to round-off,
``tests/test_p1.py``) at a fraction of the time and memory on a large mesh (the 3-D
frame's elastic stiffness: 10.7 s and a 1.9 GB peak of triplets through ``asm``).

Every element matrix follows from the barycentric gradients; the mesh's node-pair
pattern is found once (:class:`Pattern`), and each matrix component is summed onto it
:data:`CHUNK` elements at a time. Vector DOFs are interleaved, ``dim * node + component``, as
scikit-fem's ``ElementVector`` numbers them.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass
from functools import cached_property, partial
from math import factorial

import numpy as np
import scipy.sparse as sp

from gatetherm.solvers.iterative import SolverError
from gatetherm.solvers.linsolve import nd_order

log = logging.getLogger(__name__)


CHUNK = 1 << 14
"""Elements whose matrices are made and summed (``np.add.at``) at a time: temporaries of a few
MB on any mesh. On the 3-D frame at 20 × the nodes, whole arrays of element entries had made
GBs of temporaries, each new to its process (``docs/performance.md``, "2026-12-06 night")."""


def gradients(points: np.ndarray, cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Barycentric gradients (E, d+1, d) and measures (E,) of the simplices ``cells``
    (E, d+1) of ``points`` (N, d): the rows of the inverse Jacobian by cofactors (cross
    products in 3-D), a third of the time of a batched ``np.linalg.inv``; :data:`CHUNK`
    elements at a time."""
    G, vol = np.empty(cells.shape + (points.shape[1],)), np.empty(len(cells))
    for s in range(0, len(cells), CHUNK):
        G[s:s + CHUNK], vol[s:s + CHUNK] = _gradients(points[cells[s:s + CHUNK]])
    return G, vol


def _gradients(X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    J = X[:, 1:] - X[:, :1]  # (E, d, d): rows x_i − x_0
    if X.shape[2] == 3:
        a, b, c = J[:, 0], J[:, 1], J[:, 2]
        cof = np.stack([np.cross(b, c), np.cross(c, a), np.cross(a, b)], axis=1)
        det = np.einsum("ij,ij->i", a, cof[:, 0])
    else:
        det = J[:, 0, 0] * J[:, 1, 1] - J[:, 0, 1] * J[:, 1, 0]
        cof = np.stack([np.stack([J[:, 1, 1], -J[:, 1, 0]], -1), np.stack([-J[:, 0, 1], J[:, 0, 0]], -1)], axis=1)
    G = np.empty(X.shape)
    G[:, 1:] = cof / det[:, None, None]  # row i: the gradient of λ_i
    G[:, 0] = -G[:, 1:].sum(axis=1)
    return G, np.abs(det) / factorial(X.shape[2])


class Pattern:
    """The node-pair sparsity pattern of a P1 mesh and the map of element entries onto it."""

    def __init__(self, cells: np.ndarray, n_nodes: int):
        k = cells.shape[1]
        cells = cells.astype(np.int32 if n_nodes < 2 ** 31 else np.int64, copy=False)
        i = np.repeat(cells, k, axis=1).ravel()
        j = np.tile(cells, (1, k)).ravel()
        A = sp.csr_matrix((np.ones(len(i), dtype=np.int8), (i, j)), shape=(n_nodes, n_nodes))  # sorted, summed
        self.indices, self.indptr = A.indices.astype(np.int32), A.indptr.astype(np.int32)
        # each entry's position looked up in its row (about 0.6 × the time of one searchsorted over all,
        # benchmarks/assembly_parts.py), a chunk of elements at a time
        A = sp.csr_array((np.arange(A.nnz, dtype=float), A.indices, A.indptr), shape=A.shape)
        self.inv = np.empty(len(i), dtype=np.int32 if A.nnz < 2 ** 31 else np.int64)
        """Position of every element entry (element-major, row-major within) in the pattern."""
        step = CHUNK * k * k
        for s in range(0, len(i), step):
            self.inv[s:s + step] = A[i[s:s + step], j[s:s + step]]
        self.n, self.nnz, self.k = n_nodes, A.nnz, k

    def graph(self) -> sp.csr_matrix:
        """The node adjacency (the pattern as a matrix of ones)."""
        return sp.csr_matrix((np.ones(self.nnz), self.indices, self.indptr), shape=(self.n, self.n))

    def _sum(self, form, per_element, out: np.ndarray) -> np.ndarray:
        """The element matrices ``form(*rows)`` (e, k, k) of the arrays ``per_element``, made
        :data:`CHUNK` elements at a time, summed onto the pattern into ``out`` (nnz,)."""
        kk = self.k * self.k
        out[:] = 0.0
        for s in range(0, len(self.inv) // kk, CHUNK):
            np.add.at(out, self.inv[s * kk:(s + CHUNK) * kk], np.ravel(form(*(x[s:s + CHUNK] for x in per_element))))
        return out

    def scalar(self, form, *per_element: np.ndarray) -> sp.csr_matrix:
        """The matrix of the element matrices ``form(*per_element)`` (E, k, k), made from the
        rows (elements) of the arrays ``per_element`` a chunk at a time."""
        data = self._sum(form, per_element, np.empty(self.nnz))
        return sp.csr_matrix((data, self.indices, self.indptr), shape=(self.n, self.n))

    def blocks(self, form, rows: int, cols: int, *per_element: np.ndarray) -> sp.csr_matrix:
        """A matrix of ``rows`` × ``cols`` blocks per node pair, ``form(a, b, *per_element)``
        (E, k, k) giving the element entries of block component (a, b) (made as :meth:`scalar`'s);
        DOFs interleaved."""
        data, one = np.empty((self.nnz, rows, cols)), np.empty(self.nnz)
        for a in range(rows):
            for b in range(cols):
                data[:, a, b] = self._sum(partial(form, a, b), per_element, one)
        return sp.bsr_matrix((data, self.indices, self.indptr), shape=(rows * self.n, cols * self.n)).tocsr()


def mass(G: np.ndarray, vol: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Element matrices of ``∫ c u v`` (c per element): ``c vol (1 + δ_ij) / ((d+1)(d+2))``."""
    k = G.shape[1]
    return (c * vol)[:, None, None] * ((np.ones((k, k)) + np.eye(k)) / (k * (k + 1)))


def conduction(G: np.ndarray, vol: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Element matrices of ``∫ c ∇u·∇v``."""
    return (c * vol)[:, None, None] * np.matmul(G, G.transpose(0, 2, 1))


def elastic(a: int, b: int, G: np.ndarray, vol: np.ndarray, lam: np.ndarray, mu: np.ndarray) -> np.ndarray:
    """Component (a, b) of the element matrices of ``∫ λ div u div v + 2 μ ε(u):ε(v)``:
    ``vol (λ G_ia G_jb + μ G_ib G_ja + μ δ_ab G_i·G_j)``, v test (i), u trial (j)."""
    out = ((lam * vol)[:, None] * G[:, :, a])[:, :, None] * G[:, None, :, b]
    out += ((mu * vol)[:, None] * G[:, :, b])[:, :, None] * G[:, None, :, a]
    if a == b:
        out += conduction(G, vol, mu)
    return out


def heat_strain(a: int, _: int, G: np.ndarray, vol: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Component (a, 0) of the element matrices of ``∫ b T div v``, T trial (j), v test (i):
    ``b vol G_ia / (d+1)``."""
    k = G.shape[1]
    return np.broadcast_to(((b * vol / k)[:, None] * G[:, :, a])[:, :, None], G.shape[:2] + (k,))


def stiffness(pattern: Pattern, G: np.ndarray, vol: np.ndarray, lam: np.ndarray, mu: np.ndarray) -> sp.csr_matrix:
    """``∫ λ div u div v + 2 μ ε(u):ε(v)`` (λ, μ per element, thickness included): :func:`elastic`."""
    return pattern.blocks(elastic, G.shape[2], G.shape[2], G, vol, lam, mu)


def thermal_load(pattern: Pattern, G: np.ndarray, vol: np.ndarray, b: np.ndarray) -> sp.csr_matrix:
    """``∫ b T div v`` (T trial, P1 scalar; v test, P1 vector): :func:`heat_strain`."""
    return pattern.blocks(heat_strain, G.shape[2], 1, G, vol, b)


def facet_terms(points: np.ndarray, facets: np.ndarray, w: np.ndarray, n: int) -> tuple[sp.csr_matrix, np.ndarray]:
    """``(∫_F w u v, ∫_F w v)`` over the boundary facets ``facets`` (F, d) of P1 simplices
    in ``points`` (N, d), ``w`` per facet: the facet's mass matrix ``w |F| (1 + δ_ij) / (d (d+1))``
    and load ``w |F| / d``, on ``n`` unknowns (as scikit-fem's ``FacetBasis`` forms give them)."""
    X = points[facets]
    if points.shape[1] == 3:
        area = 0.5 * np.linalg.norm(np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0]), axis=1)
    else:
        area = np.linalg.norm(X[:, 1] - X[:, 0], axis=1)
    k = facets.shape[1]
    Ke = mass(np.empty((len(facets), k, 0)), area, w)
    i = np.repeat(facets, k, axis=1).ravel()
    A = sp.csr_matrix((Ke.ravel(), (i, np.tile(facets, (1, k)).ravel())), shape=(n, n))
    return A, np.bincount(facets.ravel(), weights=np.repeat(w * area / k, k), minlength=n)


@dataclass(frozen=True)
class Simplices:
    """What every P1 matrix and factor on one mesh shares, found once per model: the
    barycentric gradients, the element measures, the node-pair pattern and a fill-reducing
    (METIS) order of the nodes, which the heat, elastic (node blocks) and stress-recovery
    factors all use (None without pymetis)."""

    G: np.ndarray
    vol: np.ndarray
    pattern: Pattern

    @cached_property
    def order(self) -> np.ndarray | None:
        """Found when first asked for (0.3 s on the 3-D frame; an elastic system solved by
        AMG-CG in a helper process is set up before it), or by the process
        :meth:`find_order_beside` started."""
        pending = self.__dict__.pop("_order_beside", None)
        if pending is not None:
            try:
                return pending.result()
            except SolverError as err:
                log.debug("%s: found here", err)
        return nd_order(self.pattern.graph())

    def find_order_beside(self) -> None:
        """Start finding :attr:`order` in a forked process (:func:`~gatetherm.solvers.helper.forked`),
        so that the caller's first factor finds it made; where the process may fork."""
        from gatetherm.process import can_fork
        from gatetherm.solvers.helper import forked

        if "order" not in self.__dict__ and "_order_beside" not in self.__dict__ and can_fork():
            graph = self.pattern.graph()
            self.__dict__["_order_beside"] = forked(lambda: nd_order(graph), "METIS order")


def simplices(mesh) -> Simplices:
    """:class:`Simplices` of a scikit-fem simplex mesh."""
    G, vol = gradients(mesh.p.T, mesh.t.T)
    return Simplices(G, vol, Pattern(mesh.t.T, mesh.nvertices))


def probes(basis, points: np.ndarray) -> sp.csr_matrix:
    """``basis.probes(points)`` (points ``(d, n)``): the matrix giving a field's values there.
    For linear elements (scalar or vector) on simplices from the barycentric coordinates of
    each point in an element around its nearest node; otherwise, or for a point in none of
    those, scikit-fem's, whose element finder imports scipy.spatial and builds a k-d tree of
    the elements on every call."""
    from skfem import ElementTetP1, ElementTriP1, ElementVector

    inner = basis.elem.elem if isinstance(basis.elem, ElementVector) else basis.elem
    if type(inner) not in (ElementTriP1, ElementTetP1):
        return basis.probes(points).tocsr()
    p, t = basis.mesh.p, basis.mesh.t
    X = np.asarray(points, dtype=float).reshape(p.shape[0], -1)
    nodes, weights = [], []
    for x in X.T:
        star = np.flatnonzero((t == np.argmin(((p - x[:, None]) ** 2).sum(axis=0))).any(axis=0))
        V = p[:, t[:, star]].transpose(2, 1, 0)  # (k, d+1, d): the vertices of the elements around it
        lam = np.linalg.solve((V[:, 1:] - V[:, :1]).transpose(0, 2, 1), (x - V[:, 0])[..., None])[..., 0]
        bary = np.c_[1.0 - lam.sum(axis=1), lam]
        inside = np.flatnonzero(bary.min(axis=1) >= -1e-10)
        if not len(inside):
            return basis.probes(points).tocsr()
        nodes.append(t[:, star[inside[0]]])
        weights.append(bary[inside[0]])
    comps, n = basis.nodal_dofs.shape[0], X.shape[1]
    cols = basis.nodal_dofs[:, np.array(nodes)]  # (comps, n, d+1): component c of point j in row c n + j
    rows = np.broadcast_to((np.arange(comps)[:, None] * n + np.arange(n))[:, :, None], cols.shape)
    data = np.broadcast_to(np.array(weights), cols.shape)
    return sp.csr_matrix((data.ravel(), (rows.ravel(), cols.ravel())), shape=(comps * n, basis.N))
