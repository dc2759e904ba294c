"""Manufactured solutions of the heat and thermoelastic solvers (numbers only): the L2 error of a
steady heat problem with source, reaction and Robin boundary (:func:`heat_mms_error`) and of
thermoelasticity with body force, prescribed temperature and a traction face
(:func:`elastic_mms_error`) on refined meshes (:func:`spatial_study`). The other studies are
:mod:`gatetherm.validation.verification`."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.sparse.linalg import spsolve
from skfem import CellBasis, ElementVector, FacetBasis, Mesh, MeshTet, MeshTri, asm

from gatetherm.solvers.elasticity import moduli, stiffness, thermal_load
from gatetherm.solvers.fem import element
from gatetherm.solvers.heat import capacity, conduction, film, film_load
from gatetherm.validation.verification_common import _EDGE, _l2, _sigma, _solve_fixed, observed_order, vector_load


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


SPATIAL_HEAT = {"2-D P1": (2, 1, (3, 4, 5, 6, 7)), "2-D P2": (2, 2, (2, 3, 4, 5, 6)),
                "3-D P1": (3, 1, (6, 8, 12, 16, 24)), "3-D P2": (3, 2, (3, 4, 6, 8, 12))}
"""Heat MMS: label -> (dimension, element order, refinement levels of :func:`unit_mesh`)."""
SPATIAL_ELASTIC = {"2-D P1": (2, 1, (3, 4, 5, 6, 7)), "2-D P2": (2, 2, (2, 3, 4, 5, 6)),
                   "3-D P1": (3, 1, (6, 8, 12, 16, 20)), "3-D P2": (3, 2, (2, 3, 4, 6, 8))}
"""Thermoelastic MMS (plane stress in 2-D): label -> (dimension, order, levels)."""
