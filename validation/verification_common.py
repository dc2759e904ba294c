"""The pieces the code-verification studies share (:mod:`gatetherm.validation.verification`,
:mod:`gatetherm.validation.verification_time`): the observed order of a convergence study, meshes
and fields, the L2 error of a solution, a solve with held DOFs, and the stress of a displacement."""
from __future__ import annotations

from typing import Callable

import numpy as np
from scipy.sparse.linalg import spsolve
from skfem import CellBasis, Functional, LinearForm, Mesh, MeshTri, condense
from skfem.helpers import dot

from gatetherm.solvers.fem import Field

_EDGE = 1e-9
"""Relative coordinate tolerance for picking mesh sides, 1."""


def observed_order(h, err) -> float:
    """Least-squares slope of log(err) against log(h) (or log(dt))."""
    return float(np.polyfit(np.log(np.asarray(h, float)), np.log(np.asarray(err, float)), 1)[0])


def uniform_fields(mesh: Mesh, *values: float) -> list[Field]:
    """Uniform element-wise coefficient fields."""
    return [Field(np.full(mesh.nelements, float(v))) for v in values]


def rectangle(xs, ys, sides: dict[str, str]) -> MeshTri:
    """Tensor triangle mesh on ``xs × ys`` (m) whose sides ``left``/``right``/
    ``bottom``/``top`` become the boundaries named in ``sides`` (side → name)."""
    m = MeshTri.init_tensor(np.asarray(xs, float), np.asarray(ys, float))
    (x0, x1), (y0, y1) = (xs[0], xs[-1]), (ys[0], ys[-1])
    tol = _EDGE * max(x1 - x0, y1 - y0)
    test = {"left": lambda p: abs(p[0] - x0) < tol, "right": lambda p: abs(p[0] - x1) < tol,
            "bottom": lambda p: abs(p[1] - y0) < tol, "top": lambda p: abs(p[1] - y1) < tol}
    out: dict[str, np.ndarray] = {}
    for side, name in sides.items():
        f = m.facets_satisfying(test[side], boundaries_only=True)
        out[name] = np.union1d(out.get(name, np.zeros(0, dtype=np.int64)), f)
    return m.with_boundaries(out)


def _l2(basis: CellBasis, U: np.ndarray, exact: Callable) -> float:
    """L2 norm of (the FE field of U) − exact, scalar or vector."""
    def sq(w):
        d = (w.uh - exact(w.x)) ** 2
        return d if d.ndim == 2 else d.sum(axis=0)
    return float(np.sqrt(Functional(sq).assemble(basis, uh=basis.interpolate(U))))


def _solve_fixed(K, rhs, D: np.ndarray, U: np.ndarray | None = None) -> np.ndarray:
    """Solve ``K U = rhs`` with the DOFs ``D`` held at ``U[D]`` (zero without ``U``).
    Sparse LU with SciPy's default COLAMD ordering: on these regular meshes SuperLU's
    MMD_AT_PLUS_A ordering is ~40 times slower."""
    A, b, U, free = condense(K, rhs, x=np.zeros(len(rhs)) if U is None else U, D=D)
    U[free] = spsolve(A.tocsc(), b)
    return U


def dofs_where(basis: CellBasis, where: Callable, components) -> np.ndarray:
    """Vector-basis DOFs of the ``components`` whose locations satisfy ``where(x)``."""
    idx = basis.split_indices()
    return np.concatenate([idx[c][where(basis.doflocs[:, idx[c]])] for c in components])



@LinearForm
def vector_load(v, w):
    """Body force or traction ``w.f`` (a vector at the quadrature points)."""
    return dot(w.f, v)


def _sigma(G: np.ndarray, T: np.ndarray, lam, mu, b) -> np.ndarray:
    """σ = λ tr(ε) I + 2μ ε − b T I from the displacement gradient ``G`` (dim, dim, ...)."""
    I = np.eye(len(G)).reshape(len(G), len(G), *([1] * (G.ndim - 2)))
    return (lam * np.trace(G) - b * T) * I + mu * (G + np.swapaxes(G, 0, 1))
