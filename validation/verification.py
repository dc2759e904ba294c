"""Code verification of the heat and thermoelastic solvers: numbers only.

Manufactured solutions (steady heat with source, reaction and Robin boundary;
thermoelasticity with body force, prescribed temperature and a traction face)
give spatial errors on refined meshes; patch cases are exact; an exact modal
solution of the semi-discrete heat system, a 1-D slab's Fourier series and the
frame's energy accounts check the time stepping (:mod:`validation.verification_time`).
Nothing here plots or writes files.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.sparse.linalg import spsolve
from skfem import (CellBasis, ElementVector, FacetBasis, Functional, LinearForm, Mesh, MeshTet,
                   MeshTri, asm, condense)
from skfem.helpers import dot

from gatetherm.solvers.elasticity import assemble_elastic, moduli, stiffness, thermal_load
from gatetherm.solvers.problem import Support
from gatetherm.solvers.fem import Field, element
from gatetherm.solvers.heat import capacity, conduction, film, film_load

_EDGE = 1e-9
"""Relative coordinate tolerance for picking mesh sides, 1."""


# --- shared helpers ---------------------------------------------------------------------------

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


# --- manufactured solutions -------------------------------------------------------------------

@dataclass(frozen=True)
class CosProduct:
    """Manufactured field ``amp · Π_j cos(k_j x_j + p_j)``; ``x`` is (dim, ...)."""

    amp: float
    k: tuple[float, ...]
    p: tuple[float, ...]

    def _d(self, x, diff: tuple[int, ...]):
        """The derivative ∂^diff of the field (``diff`` lists the axes)."""
        out = self.amp
        for j, (kj, pj) in enumerate(zip(self.k, self.p)):
            a = kj * x[j] + pj
            out = out * (np.cos(a), -kj * np.sin(a), -kj ** 2 * np.cos(a))[diff.count(j)]
        return out

    def value(self, x):
        return self._d(x, ())

    def grad(self, x):
        return np.array([self._d(x, (m,)) for m in range(len(self.k))])

    def laplacian(self, x):
        return sum(self._d(x, (m, m)) for m in range(len(self.k)))

    def hessian(self, x):
        n = len(self.k)
        return np.array([[self._d(x, (a, b)) for b in range(n)] for a in range(n)])


# One field per dimension: no symmetry, in no FE space; displacements in m, temperatures in K.
HEAT_U = {2: CosProduct(1.0, (1.3 * np.pi, 0.9 * np.pi), (0.2, -0.4)),
          3: CosProduct(1.0, (1.1 * np.pi, 0.8 * np.pi, 0.7 * np.pi), (0.2, -0.4, 0.3))}
ELASTIC_U = {2: (CosProduct(1e-4, (1.2 * np.pi, 0.7 * np.pi), (0.3, 0.1)),
                 CosProduct(-6e-5, (0.8 * np.pi, 1.1 * np.pi), (-0.2, 0.5))),
             3: (CosProduct(1e-4, (1.2 * np.pi, 0.7 * np.pi, 0.6 * np.pi), (0.3, 0.1, -0.2)),
                 CosProduct(-6e-5, (0.8 * np.pi, 1.1 * np.pi, 0.5 * np.pi), (-0.2, 0.5, 0.1)),
                 CosProduct(8e-5, (0.6 * np.pi, 0.9 * np.pi, 1.2 * np.pi), (0.4, -0.3, 0.2)))}
ELASTIC_T = {2: CosProduct(12.0, (0.9 * np.pi, 1.3 * np.pi), (0.1, 0.6)),
             3: CosProduct(12.0, (0.9 * np.pi, 1.3 * np.pi, 0.8 * np.pi), (0.1, 0.6, -0.3))}


def heat_mms_error(mesh: Mesh, order: int, rc: float = 2.0, h: float = 3.0) -> float:
    """L2 error of the steady problem ``rc u − ∇·(k ∇u) = q`` on ``mesh`` (all
    boundaries ``k ∂u/∂n + h (u − g) = 0``), ``k = 1 + x/2``, exact ``HEAT_U``,
    assembled from the module forms of :mod:`solvers.heat`.

    The reaction term ``rc u`` is what a backward-Euler step adds; ``q`` and
    ``g`` follow from the exact field by hand:
    ``q = rc u − k Δu − (∂k/∂x) ∂u/∂x`` and ``g = u + k ∇u·n / h``.
    """
    u = HEAT_U[mesh.dim()]
    e, q = element(mesh.dim(), order), 2 * order + 2
    cb, fb = CellBasis(mesh, e, intorder=q), FacetBasis(mesh, e, intorder=q)
    x, xf, n = (np.asarray(v) for v in (cb.global_coordinates(), fb.global_coordinates(), fb.normals))
    k, kf = 1.0 + 0.5 * x[0], 1.0 + 0.5 * xf[0]
    src = rc * u.value(x) - k * u.laplacian(x) - 0.5 * u.grad(x)[0]
    g = u.value(xf) + kf * np.sum(u.grad(xf) * n, axis=0) / h
    A = asm(conduction, cb, k=k, t=1.0) + asm(capacity, cb, rc=rc, t=1.0) + asm(film, fb, h=h, t=1.0)
    b = asm(film_load, cb, h=src, t=1.0) + asm(film_load, fb, h=h * g, t=1.0)
    return _l2(cb, spsolve(A.tocsc(), b), u.value)


@LinearForm
def vector_load(v, w):
    """Body force or traction ``w.f`` (a vector at the quadrature points)."""
    return dot(w.f, v)


def _sigma(G: np.ndarray, T: np.ndarray, lam, mu, b) -> np.ndarray:
    """σ = λ tr(ε) I + 2μ ε − b T I from the displacement gradient ``G`` (dim, dim, ...)."""
    I = np.eye(len(G)).reshape(len(G), len(G), *([1] * (G.ndim - 2)))
    return (lam * np.trace(G) - b * T) * I + mu * (G + np.swapaxes(G, 0, 1))


def elastic_mms_error(mesh: Mesh, order: int, E=1.2e11, nu=0.26, alpha=1.05e-5) -> float:
    """L2 displacement error (m) of thermoelasticity on the unit square/cube with the
    exact ``ELASTIC_U`` and temperature rise ``ELASTIC_T`` (on the P``order``
    temperature space), held at the exact values except on the traction face x = 1;
    module forms ``stiffness`` and ``thermal_load``, plane stress in 2-D.

    By hand, with ``b`` the thermal stress modulus,
    ``f = −(λ + μ) ∇(∇·u) − μ Δu + b ∇T`` and on x = 1 the traction ``σ n`` with
    ``σ = λ (∇·u) I + 2μ ε(u) − b T I``.
    """
    dim = mesh.dim()
    lam, mu, b = moduli(E, nu, alpha, dim)
    us, T = ELASTIC_U[dim], ELASTIC_T[dim]
    q = 2 * order + 2
    vb = CellBasis(mesh, ElementVector(element(dim, order)), intorder=q)
    tb = CellBasis(mesh, element(dim, order), quadrature=vb.quadrature)
    x = np.asarray(vb.global_coordinates())
    H = np.array([c.hessian(x) for c in us])                       # H[i, l, m] = ∂l ∂m u_i
    f = -(lam + mu) * np.einsum("mim...->i...", H) - mu * np.einsum("imm...->i...", H) \
        + b * T.grad(x)
    face = mesh.facets_satisfying(lambda p: p[0] > 1 - _EDGE, boundaries_only=True)
    fb = FacetBasis(mesh, vb.elem, facets=face, intorder=q)
    xf = np.asarray(fb.global_coordinates())
    sig = _sigma(np.array([c.grad(xf) for c in us]), T.value(xf), lam, mu, b)
    traction = np.einsum("ij...,j...->i...", sig, np.asarray(fb.normals))
    rhs = asm(vector_load, vb, f=f) + asm(vector_load, fb, f=traction) \
        + asm(thermal_load, tb, vb, b=b, t=1.0) @ T.value(tb.doflocs)
    U = np.zeros(vb.N)
    for c, idx in enumerate(vb.split_indices()):      # nodal interpolant: boundary values
        U[idx] = us[c].value(vb.doflocs[:, idx])
    clamp = vb.get_dofs(np.setdiff1d(mesh.boundary_facets(), face)).all()
    U = _solve_fixed(asm(stiffness, vb, lam=lam, mu=mu, t=1.0), rhs, clamp, U)
    return _l2(vb, U, lambda p: np.array([c.value(p) for c in us]))


def unit_mesh(dim: int, n: int) -> Mesh:
    """Unit square ``MeshTri().refined(n)`` (h = 2⁻ⁿ) or unit cube of n³ cubes of six
    tetrahedra (h = 1/n)."""
    if dim == 2:
        return MeshTri().refined(n)
    s = np.linspace(0.0, 1.0, n + 1)
    return MeshTet.init_tensor(s, s, s)


def spatial_study(error: Callable[[Mesh, int], float], dim: int, order: int, levels):
    """(h, L2 errors, observed order) of ``error(mesh, order)`` over ``unit_mesh(dim, n)``
    for n in ``levels``; ``error`` is :func:`heat_mms_error` or :func:`elastic_mms_error`."""
    h = np.array([2.0 ** -n if dim == 2 else 1.0 / n for n in levels])
    err = np.array([error(unit_mesh(dim, n), order) for n in levels])
    return h, err, observed_order(h, err)


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
SPATIAL_HEAT = {"2-D P1": (2, 1, (3, 4, 5, 6, 7)), "2-D P2": (2, 2, (2, 3, 4, 5, 6)),
                "3-D P1": (3, 1, (6, 8, 12, 16, 24)), "3-D P2": (3, 2, (3, 4, 6, 8, 12))}
"""Heat MMS: label -> (dimension, element order, refinement levels of :func:`unit_mesh`)."""
SPATIAL_ELASTIC = {"2-D P1": (2, 1, (3, 4, 5, 6, 7)), "2-D P2": (2, 2, (2, 3, 4, 5, 6)),
                   "3-D P1": (3, 1, (6, 8, 12, 16, 20)), "3-D P2": (3, 2, (2, 3, 4, 6, 8))}
"""Thermoelastic MMS (plane stress in 2-D): label -> (dimension, order, levels)."""


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
