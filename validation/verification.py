"""Code verification of the heat and thermoelastic solvers: numbers only.

Manufactured solutions (steady heat with source, reaction and Robin boundary;
thermoelasticity with body force, prescribed temperature and a traction face)
give spatial errors on refined meshes; patch cases are exact; an exact modal
solution of the semi-discrete heat system gives the time-stepping error; a
Fourier series checks a 1-D slab with a sudden surface film; the frame model's
step energy balance is accounted over a run. Nothing here plots or writes files.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
import scipy.linalg
from scipy.optimize import brentq
from scipy.sparse.linalg import spsolve
from skfem import (CellBasis, ElementVector, FacetBasis, Functional, LinearForm, Mesh, MeshTet,
                   MeshTri, asm, condense)
from skfem.helpers import dot

from solvers.elasticity import assemble_elastic, moduli, stiffness, thermal_load
from solvers.fem import Field, element
from solvers.heat import (HeatSystem, Inputs, ThermalParams, TimeScheme, assemble_heat, capacity, conduction,
                          energy_step, film, film_load, march)

_EDGE = 1e-9
"""Relative coordinate tolerance for picking mesh sides, 1."""


# --- shared helpers ---------------------------------------------------------------------------

def observed_order(h, err) -> float:
    """Least-squares slope of log(err) against log(h) (or log(dt))."""
    return float(np.polyfit(np.log(np.asarray(h, float)), np.log(np.asarray(err, float)), 1)[0])


def _const(mesh: Mesh, *values: float) -> list[Field]:
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


def clamped_bar_tip(L: float = 0.4, h: float = 0.02, dT: float = 10.0, order: int = 2,
                    nx: int = 4, ny: int = 80, E=1.2e11, nu=0.26, alpha=1.05e-5):
    """(FE, beam theory, FE by adjoint weights) x-displacement (m) of the tip centre of
    an ``h × L`` (m) bar clamped on its mounting face y = 0, for a rise growing linearly
    by ``dT`` (K) across the width, through :func:`solvers.elasticity.assemble_elastic`.
    Beam theory: uniform curvature α dT/h, tip ``−α dT L² / (2h)``."""
    m = rectangle(np.linspace(0.0, h, nx + 1), np.linspace(0.0, L, ny + 1), {"bottom": "mounting_face"})
    tb = CellBasis(m, element(2, order), intorder=2 * order)
    el = assemble_elastic(m, order, tb, *_const(m, E, nu, alpha, 0.1))
    T = dT * (tb.doflocs[0] / h - 0.5)
    g = el.point_functional([0.5 * h, L], 0)
    return float(g @ el.displacement(T)), -alpha * dT * L ** 2 / (2 * h), float(el.weights(g) @ T)


# --- time stepping ----------------------------------------------------------------------------

@dataclass(frozen=True)
class HarmonicDrive:
    """Inputs ``T_amb = amb0 + amb1 cos(ω t)``, ``T_supply = sup0 + sup1 cos(ω t)``
    (°C, ω in rad/s), the pump on while ``floor(t / period)`` is even (t, period in s)."""

    amb0: float = 20.0
    amb1: float = 0.0
    sup0: float = 40.0
    sup1: float = 0.0
    omega: float = 1.0
    period: float = np.inf

    def pump(self, t: float) -> bool:
        return bool(np.floor(t / self.period) % 2 == 0)

    def __call__(self, t: float) -> Inputs:
        c = np.cos(self.omega * t)
        return Inputs(self.sup0 + self.sup1 * c, self.pump(t), self.amb0 + self.amb1 * c)


def unit_heat_system(n: int = 4, order: int = 1) -> HeatSystem:
    """A small real heat system in unit-free numbers: the unit square (n × n cells),
    k = ρc = 1, tank wall x = 0, mounting face y = 0, free surface elsewhere,
    out-of-plane loss on, and a supply hose (capacity 0.25, loss 0.5); with the pump on
    (n = 4, P1) its modes decay at 4 to 510 per s."""
    s = np.linspace(0.0, 1.0, n + 1)
    m = rectangle(s, s, {"left": "tank_wall", "bottom": "mounting_face",
                         "right": "free_surface", "top": "free_surface"})
    p = ThermalParams(T0=20.0, h_air=1.0, h_base=0.5, h_oil_on=5.0, h_oil_off=1.0,
                      oil_rho_c=1.0, flow_rate=2.0, hose_capacity=0.25, hose_loss=0.5)
    return assemble_heat(m, order, *_const(m, 1.0, 1.0, 1.0), p, oil_volume=0.5)


def steady_state(sys: HeatSystem, drive, t: float = 0.0) -> np.ndarray:
    """The state in equilibrium with the inputs frozen at time ``t``."""
    pump = bool(drive(t).pump)
    return spsolve(sys.K(pump).tocsc(), sys.f(t, drive, pump))


def exact_response(sys: HeatSystem, drive: HarmonicDrive, times: np.ndarray,
                   U0: np.ndarray | None = None) -> np.ndarray:
    """Exact solution of the semi-discrete system ``M U' + K(pump) U = f(t)`` at
    ``times`` (rows), by modes of ``K φ = λ M φ``. Pump switches must fall on ``times``.

    Each mode obeys ``y' + λ y = a + c cos ωt``; its solution is
    ``y_p(t) + e^{−λ(t − t0)} (y(t0) − y_p(t0))`` with
    ``y_p = a/λ + (ω sin ωt + λ cos ωt) c/(λ² + ω²)``. With a hose ``K`` is not
    symmetric (the flow runs one way): the modes are the general eigenvectors and
    ``y(t0) = φ⁻¹ U(t0)``.
    """
    M, w = sys.M.toarray(), drive.omega
    inlet = np.zeros(sys.n)
    inlet[sys.inlet] = 1.0
    modes = {}
    U = sys.initial() if U0 is None else np.array(U0, float)
    out = [U]
    for t0, t1 in zip(times[:-1], times[1:]):
        pump = drive.pump(0.5 * (t0 + t1))
        if pump not in modes:
            lam, phi = scipy.linalg.eig(sys.K(pump).toarray(), M)
            lam, phi = lam.real, phi.real  # real: the hose feeds the symmetric solid-oil block one way
            G = sys.coefficients(pump)[1]
            a = sys.f_amb * drive.amb0 + sys.f_src + G * drive.sup0 * inlet
            c = sys.f_amb * drive.amb1 + G * drive.sup1 * inlet
            inv = np.linalg.inv(phi)
            Minv = inv @ np.linalg.inv(M)
            modes[pump] = lam, phi, inv, Minv @ a, Minv @ c / (lam ** 2 + w ** 2)
        lam, phi, inv, a, c = modes[pump]
        yp = lambda t: a / lam + (w * np.sin(w * t) + lam * np.cos(w * t)) * c  # noqa: E731
        U = phi @ (yp(t1) + np.exp(-lam * (t1 - t0)) * (inv @ U - yp(t0)))
        out.append(U)
    return np.array(out)


def time_errors(sys: HeatSystem, drive: HarmonicDrive, t_end: float, steps, scheme: TimeScheme,
                U0: np.ndarray | None = None, final_only: bool = False):
    """(dt in s, error in K) per step count in ``steps``: the max over nodes of
    |U − exact|, maximised over all step times or taken at ``t_end`` only (``final_only``)."""
    dts, errs = [], []
    for n in steps:
        times = np.linspace(0.0, t_end, n + 1)
        U = np.array([u for _, u in march(sys, drive, times, scheme, U0)])
        e = np.abs(U - exact_response(sys, drive, times, U0)).max(axis=1)
        dts.append(t_end / n)
        errs.append(float(e[-1] if final_only else e.max()))
    return np.array(dts), np.array(errs)


def slab_film_series(xi, fo: float, biot: float, terms: int = 200) -> np.ndarray:
    """Dimensionless temperature ``(T − T_amb)/(T_i − T_amb)`` of a slab initially at
    ``T_i``, insulated at ``xi = 0`` and cooled by a film (Biot ``h L / k``) at ``xi = 1``,
    at Fourier number ``fo = a t / L²``: ``Σ C_n e^{−λ_n² fo} cos(λ_n xi)`` with
    ``λ_n tan λ_n = Bi`` and ``C_n = 4 sin λ_n / (2 λ_n + sin 2λ_n)``."""
    lam = np.array([brentq(lambda s: s * np.sin(s) - biot * np.cos(s), n * np.pi,
                           (n + 0.5) * np.pi) for n in range(terms)])
    C = 4 * np.sin(lam) / (2 * lam + np.sin(2 * lam))
    return np.cos(np.multiply.outer(np.asarray(xi, float), lam)) @ (C * np.exp(-lam ** 2 * fo))


def slab_film_error(order: int = 2, nx: int = 20, dt: float = 2.0, scheme: TimeScheme = TimeScheme(),
                    t_end: float = 1200.0, L: float = 0.1, h: float = 500.0,
                    k: float = 48.0, rho_c: float = 3.6975e6, every: float = 60.0) -> float:
    """Max |θ_FE − θ_series| (θ = (T − T_amb)/(T_i − T_amb)) over the nodes and the
    times ``every``, ``2 every``, … ≤ ``t_end`` (s) of a strip ``L × L/20`` (m) at
    ``T_i``, cooled by a film ``h`` (W/(m² K)) on its mounting face x = 0 and
    insulated elsewhere, built by :func:`solvers.heat.assemble_heat` and marched by
    :func:`solvers.heat.march` (whose start-up damps the shock of the film switched
    on at t = 0)."""
    T_i, T_amb = 20.0, 60.0
    m = rectangle(np.linspace(0.0, L, nx + 1), [0.0, L / 20], {
        "left": "mounting_face", "right": "tank_wall", "top": "free_surface", "bottom": "free_surface"})
    params = ThermalParams(T0=T_i, h_air=0.0, h_base=h, h_oil_on=0.0, h_oil_off=0.0, flow_rate=0.0)
    sys = assemble_heat(m, order, *_const(m, k, rho_c, 1.0), params, oil_volume=1e-6)
    drive = lambda t: Inputs(T_i, False, T_amb)  # noqa: E731
    times = np.arange(0.0, t_end + 0.5 * dt, dt)
    xi = (L - sys.basis.doflocs[0]) / L
    err = 0.0
    for t, U in march(sys, drive, times, scheme):
        if t >= every and abs(t / every - round(t / every)) < 1e-9:
            exact = slab_film_series(xi, k / rho_c * t / L ** 2, h * L / k)
            err = max(err, float(np.abs((U[:sys.n_solid] - T_amb) / (T_i - T_amb) - exact).max()))
    return err


def energy_balance(sys: HeatSystem, drive, times: np.ndarray, theta: float) -> dict[str, np.ndarray]:
    """Per-step heat (J) over a θ-method march without start-up grading: the terms of
    :func:`solvers.heat.energy_step` (solid: ``wall + source = stored + lost``), the
    oil's own account (``supply`` brought by the flow, ``supply = oil_stored + wall``)
    and, with a hose, the hose's (``hose_in = hose_stored + hose_lost``; enthalpy flows
    G (T_supply − T_hose) into the hose, G (T_hose − T_oil) into the tank)."""
    states = list(march(sys, drive, times, TimeScheme(theta, restart=1)))
    o, i = sys.oil, sys.inlet
    out: dict[str, list[float]] = {}
    for (t0, U0), (t1, U1) in zip(states[:-1], states[1:]):
        dt, G = t1 - t0, sys.coefficients(bool(drive(0.5 * (t0 + t1)).pump))[1]
        Um = theta * U1 + (1 - theta) * U0
        u = {k: theta * getattr(drive(t1), k) + (1 - theta) * getattr(drive(t0), k) for k in ("T_supply", "T_amb")}
        terms = {**energy_step(sys, U0, U1, t0, t1, drive, theta),
                 "oil_stored": sys.M[o, o] * (U1[o] - U0[o])}
        if i == o:
            terms["supply"] = dt * G * (u["T_supply"] - Um[o])
        else:
            terms["supply"] = dt * G * (Um[i] - Um[o])
            terms["hose_in"] = dt * G * (u["T_supply"] - Um[i])
            terms["hose_lost"] = dt * sys.params.hose_loss * (Um[i] - u["T_amb"])
            terms["hose_stored"] = sys.M[i, i] * (U1[i] - U0[i])
        for key, v in terms.items():
            out.setdefault(key, []).append(float(v))
    return {key: np.array(v) for key, v in out.items()}
