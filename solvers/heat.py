"""Heat conduction in a solid, with lumped fluid volumes on its boundaries.

Unknowns are the nodal temperatures of the solid (°C) followed by one temperature per
lumped fluid volume and per supply hose (:class:`~gatetherm.solvers.problem.Fluid`).
Per unit of the 2-D out-of-plane thickness ``t`` (``t = 1`` in 3-D) the weak form is

    ∫ t ρc Ṫ v + ∫ t k ∇T·∇v + Σ_films ∫ t h (T − T_amb) v + ∫ h_f (T − T_amb) v
        + Σ_fluids ∫_wall t h_p (T − T_oil) v = ∫ t q v + Σ_flux ∫ t q_n v
    C_oil Ṫ_oil + ∫_wall t h_p (T_oil − T) + G_p (T_oil − T_in) = 0
    C_hose Ṫ_hose + G_p (T_hose − T_supply) + UA (T_hose − T_amb) = 0

with ``h_f`` the loss of the front and back faces of a 2-D section (2 h per unit of
section area), the wall film ``h_p`` and the supply's enthalpy flow ``G_p = ρc Q``
following the fluid's pump state ``p``, and ``T_in`` the fluid entering the volume: the
hose, or the supply without one. Fixed temperatures are Dirichlet conditions. The
matrix of the system depends only on the pump states (the *mode*); the right-hand side
is a sum of fixed vectors times input values.
"""
from __future__ import annotations

import functools
import logging
import time
from collections import Counter
from dataclasses import dataclass
from typing import Callable, Iterator, Mapping

import numpy as np
import scipy.sparse as sp
from skfem import BilinearForm, CellBasis, FacetBasis, LinearForm, asm
from skfem.helpers import dot, grad

from gatetherm import InputError
from gatetherm.solvers import p1
from gatetherm.solvers.expr import Value
from gatetherm.solvers.convection import VaryingFilm
from gatetherm.solvers.fem import Field, complement, dof_basis, element
from gatetherm.solvers.linsolve import Bordered, nd_order, planned_solver, restrict_order
from gatetherm.solvers.moving import MovingLoad, moving_load
from gatetherm.solvers.pardiso import Analyses
from gatetherm.solvers.scheme import TimeScheme

log = logging.getLogger(__name__)

Drive = Callable[[float], Mapping[str, float]]
"""The inputs of a run (schedule columns by name) at a time in s."""
Mode = tuple[bool, ...]
"""Pump state of every fluid."""


@BilinearForm
def capacity(u, v, w):
    return w.rc * w.t * u * v


@BilinearForm
def conduction(u, v, w):
    return w.k * w.t * dot(grad(u), grad(v))


@BilinearForm
def film(u, v, w):
    return w.h * w.t * u * v


@LinearForm
def film_load(v, w):
    return w.h * w.t * v


def environment(drive: Drive, t: float) -> dict[str, float]:
    """The variables an input expression sees at time ``t``: ``t`` and the drive's inputs."""
    return {"t": t, **drive(t)}


@dataclass(frozen=True)
class Load:
    """A term ``vector · value(env)`` of the right-hand side."""

    vector: np.ndarray
    value: Value
    kind: str
    """"film", "flux", "faces", "source" or "hose" (the hose's loss): for energy accounts."""


@dataclass(frozen=True)
class Pumped:
    """The part of the conductance and the load that follows one fluid's pump."""

    wall: sp.csr_matrix
    """Coupling of the wetted boundary and the fluid unknown for a unit film coefficient."""
    film_on: float
    film_off: float
    flow: sp.csr_matrix
    """Coupling of fluid and inlet unknowns by the supply for a unit conductance."""
    conductance: float
    """Enthalpy flow while pumping, W/K."""
    inlet: int
    """Index of the unknown the supply enters (the hose, or the fluid)."""
    pump: Value
    supply: Value

    def on(self, env) -> bool:
        return bool(self.pump(env) > 0.5)

    def coefficients(self, on: bool) -> tuple[float, float]:
        """(wall film coefficient, conductance) for a pump state."""
        return (self.film_on, self.conductance) if on else (self.film_off, 0.0)


PICARD_TOL = 1e-10
"""Change of every varying film's boundary-mean temperature, K, at which the Picard iterations stop."""
PICARD_MAX = 200
"""Most Picard iterations of one step (or of a steady state)."""


@dataclass(frozen=True)
class HeatSystem:
    """Assembled operators: ``M U' + K(mode) U = f(env, mode)`` with ``U[fixed]`` given.
    Immutable: the factorisations of its step matrices live in a :class:`HeatSolver`."""

    basis: CellBasis
    M: sp.csr_matrix
    K0: sp.csr_matrix
    """Conductance that does not depend on the pumps."""
    pumped: tuple[Pumped, ...]
    loads: tuple[Load, ...]
    """``f = Σ vector · value(env)`` (+ the supplies of the pumped fluids)."""
    fixed: tuple[tuple[np.ndarray, Value], ...]
    """Dirichlet conditions: solid dofs and their temperature."""
    n_solid: int
    lumped: dict[str, int]
    """Index of every fluid and hose unknown, by name."""
    T0: float
    """Initial temperature, °C."""
    simplices: p1.Simplices | None = None
    """The linear mesh's :class:`~gatetherm.solvers.p1.Simplices`: their METIS node order, found
    when a step matrix is first factorised, is the one every factor on the mesh shares (None: an
    order found from that step matrix)."""
    varying: tuple[VaryingFilm, ...] = ()
    """Films whose coefficient follows the temperature (Picard iterations: :func:`picard`)."""
    moving: tuple[MovingLoad, ...] = ()
    """Sources that follow a position."""

    @property
    def n(self) -> int:
        return self.M.shape[0]

    @functools.cached_property
    def fixed_dofs(self) -> np.ndarray:
        return np.unique(np.concatenate([d for d, _ in self.fixed])) if self.fixed else np.zeros(0, int)

    def mode(self, env) -> Mode:
        return tuple(p.on(env) for p in self.pumped)

    def K(self, mode: Mode) -> sp.csr_matrix:
        """Conductance matrix for a mode."""
        K = self.K0
        for p, on in zip(self.pumped, mode):
            h, G = p.coefficients(on)
            K = K + h * p.wall + G * p.flow
        return K.tocsr()

    def f(self, env, mode: Mode) -> np.ndarray:
        out = np.zeros(self.n)
        for load in self.loads:
            out += load.vector * load.value(env)
        for m in self.moving:
            out[:len(m.weights)] += m.vector(env) * m.value(env)
        for p, on in zip(self.pumped, mode):
            out[p.inlet] += p.coefficients(on)[1] * p.supply(env)
        return out

    def boundary_values(self, env) -> np.ndarray:
        """Temperatures of :attr:`fixed_dofs` (a later condition wins at shared nodes)."""
        out = np.zeros(self.n)
        for dofs, value in self.fixed:
            out[dofs] = value(env)
        return out[self.fixed_dofs]

    def correction(self, U: np.ndarray, env) -> np.ndarray:
        """The varying films' parts beyond the matrix (on the left-hand side), on all unknowns."""
        out = np.zeros(self.n)
        for v in self.varying:
            out[:len(v.a)] += v.correction(U, env)
        return out

    def surfaces(self, U: np.ndarray) -> np.ndarray:
        return np.array([v.surface(U) for v in self.varying])

    def initial(self, T0: float | None = None) -> np.ndarray:
        return np.full(self.n, self.T0 if T0 is None else T0)


HEAT_RTOL = 1e-7
"""Relative residual of a heat step solved iteratively: on the 3-D frame δ's first peak and
swing within 1e-5 µm of the factor's (``python benchmarks/scaling.py --dims 3 --factors 1
--paths direct iterative``); the march three quarters of its time at 1e-8
(``docs/performance.md``)."""


class HeatSolver:
    """Step solves of one :class:`HeatSystem`: the conductance matrix of each mode and a
    solver of each distinct (θ dt, mode) step matrix on the free unknowns, made on first
    use and kept (four per paper condition: 60-s and 15-s steps, pump on and off). Each
    is a sparse Cholesky factor or AMG-CG warm-started from the previous steps, as
    :func:`~gatetherm.solvers.linsolve.planned_solver` picks for the steps :meth:`expect` said
    it would take beside the memory held already."""

    def __init__(self, system: HeatSystem):
        self.system = system
        self.free = complement(system.n, system.fixed_dofs)
        """Unknowns not held by a fixed temperature (the solid's first, then the lumped ones)."""
        self.n_inner = int(np.sum(self.free < system.n_solid))
        """Free unknowns of the solid: the SPD block of every step matrix."""
        self._K: dict[Mode, sp.csr_matrix] = {}
        self._lu: dict[tuple[float, Mode], tuple[Bordered, sp.csr_matrix | None]] = {}
        self._order: list = []
        self._analyses = Analyses()  # the step matrices' factors share one PARDISO analysis
        self._amg: dict = {}  # AMG hierarchies by θ dt, shared by the modes
        self._expected: dict[tuple[float, Mode], int] = {}
        self.factor_seconds = 0.0
        """Seconds spent setting the step solvers up so far."""

    def K(self, mode: Mode) -> sp.csr_matrix:
        if mode not in self._K:
            self._K[mode] = self.system.K(mode)
        return self._K[mode]

    @property
    def factorisations(self) -> int:
        """How many step matrices were set up so far."""
        return len(self._lu)

    def expect(self, steps: Mapping[tuple[float, Mode], int]) -> None:
        """The number of steps of each ``(θ dt, mode)`` of the coming march (see :func:`step_keys`)."""
        self._expected = dict(steps)

    def _inner(self, S: sp.csr_matrix, rhs: int, what: str, theta_dt: float | None):
        """A solver of the solid block ``S`` (of the step ``θ dt``) for ``rhs`` solves: one METIS
        order and one PARDISO analysis for all the factors (the step matrices share a pattern:
        :mod:`~gatetherm.solvers.pardiso`); one AMG hierarchy for the
        modes of a ``θ dt`` (the pumps change only a wall's film; on the 3-D frame at 8 × the nodes
        2 % more iterations than with a hierarchy of its own: ``benchmarks/heat_amg.py``)."""
        sys = self.system

        def order():  # asked for only by a factor
            if not self._order:
                self._order.append(nd_order(S) if sys.simplices is None else
                                   restrict_order(sys.simplices.order, self.free[:self.n_inner], sys.n_solid))
            return self._order[0]
        solve, path = planned_solver(S, sys.basis.mesh.dim(), rhs, what, order=order, rtol=HEAT_RTOL, warm=rhs > 1,
                                     amg=self._amg.get(theta_dt), shared=self._analyses)
        if path == "iterative":
            self._amg.setdefault(theta_dt, solve.amg)
        return solve

    def _system(self, A: sp.csr_matrix, rhs: int, what: str, theta_dt: float | None = None):
        """``(Bordered solver, coupling to the fixed unknowns)`` of a matrix on all unknowns."""
        fixed = self.system.fixed_dofs
        coupling = None
        if fixed.size:
            coupling, A = A[self.free][:, fixed], A[self.free][:, self.free]
        return Bordered(A, self.n_inner, self._inner(A[:self.n_inner, :self.n_inner], rhs, what, theta_dt)), coupling

    def solve(self, dt: float, theta: float, mode: Mode, rhs: np.ndarray, held: np.ndarray) -> np.ndarray:
        """Solve ``(M/dt + θ K) U = rhs`` with ``U[fixed] = held``, by the solver of
        ``M/(θ dt) + K`` on the free unknowns, which backward Euler over dt/2 and
        Crank–Nicolson over dt share: of its SPD solid block, bordered by the lumped unknowns."""
        key = (round(theta * dt, 9), mode)
        fixed = self.system.fixed_dofs
        if key not in self._lu:
            t0 = time.perf_counter()
            A = (self.system.M / (theta * dt) + self.K(mode)).tocsr()
            self._lu[key] = self._system(A, self._expected.get(key, 1), f"heat step θdt={theta * dt:g} s, mode {mode}",
                                         key[0])
            seconds = time.perf_counter() - t0
            self.factor_seconds += seconds
            log.debug("set up the heat step solver for θdt=%g s, mode=%s in %.2f s", theta * dt, mode, seconds)
        solve, coupling = self._lu[key]
        if coupling is None:
            return solve(rhs / theta)
        U = np.empty(self.system.n)
        U[fixed] = held
        U[self.free] = solve(rhs[self.free] / theta - coupling @ held)
        return U

    def steady(self, env) -> np.ndarray:
        """The state in equilibrium with the inputs ``env``."""
        sys = self.system
        mode = sys.mode(env)
        K, f, held = self.K(mode), sys.f(env, mode), sys.boundary_values(env)
        solve, coupling = self._system(K, 1, f"steady heat, mode {mode}")

        def once(rhs):
            U = np.empty(sys.n)
            U[sys.fixed_dofs] = held
            U[self.free] = solve(rhs[self.free] - (coupling @ held if coupling is not None else 0.0))
            return U
        U = once(f)
        return picard(sys, lambda U: once(f - sys.correction(U, env)), U) if sys.varying else U


def picard(sys: HeatSystem, solve: Callable[[np.ndarray], np.ndarray], U: np.ndarray) -> np.ndarray:
    """Iterate ``U ← solve(U)`` (a solve with the varying films' coefficients of ``U``) until no
    film's boundary-mean temperature changes by more than :data:`PICARD_TOL`."""
    Ts = sys.surfaces(U)
    for _ in range(PICARD_MAX):
        U = solve(U)
        new = sys.surfaces(U)
        if np.max(np.abs(new - Ts)) <= PICARD_TOL:
            return U
        Ts = new
    worst = sys.varying[int(np.argmax(np.abs(new - Ts)))].boundary
    raise InputError(f"film of '{worst}'", f"the coefficient's Picard iterations did not settle in {PICARD_MAX}",
                     "give a reference film near the largest coefficient the run reaches, or shorter steps")


def theta_step(solver: HeatSolver, drive: Drive, U: np.ndarray, t0: float, t1: float, theta: float,
               mode: Mode) -> np.ndarray:
    """One θ-method step from ``U`` at ``t0`` to ``t1`` in ``mode``, through the weighted state
    ``W = θ U₁ + (1 − θ) U``: ``(M/(θ dt) + K) W = M U/(θ dt) + θ f₁ + (1 − θ) f₀``, then
    ``U₁ = (W − (1 − θ) U)/θ`` (the same step as ``(M/dt + θK) U₁ = (M/dt − (1 − θ)K) U + …``
    with one matrix product, not two)."""
    sys, dt = solver.system, t1 - t0
    env1 = environment(drive, t1)
    f = sys.f(env1, mode)
    if theta < 1:
        f = theta * f + (1 - theta) * sys.f(environment(drive, t0), mode)
    held, fixed = sys.boundary_values(env1) if sys.fixed else np.zeros(0), sys.fixed_dofs

    def step(f):
        W = solver.solve(dt, theta, mode, sys.M @ U / dt + theta * f, theta * held + (1 - theta) * U[fixed])
        if theta == 1:
            return W
        U1 = (W - (1 - theta) * U) / theta
        U1[fixed] = held
        return U1
    if not sys.varying:
        return step(f)
    # the films' rest at the step's weights: θ at the new state (iterated), 1 − θ at the old one
    f0 = f - (1 - theta) * sys.correction(U, environment(drive, t0)) if theta < 1 else f
    return picard(sys, lambda U1: step(f0 - theta * sys.correction(U1, env1)), U)


def substeps(t0: float, t1: float, scheme: TimeScheme, since: int) -> list[tuple[float, float, float]]:
    """The (start, end, θ) steps of the interval ``t0``..``t1``, the ``since``-th after a
    switch (0: the first): one θ step, or ``scheme.restart`` steps, the very first of them
    two backward-Euler half steps if θ < 1."""
    if since >= scheme.restart_intervals or scheme.restart <= 1:
        return [(t0, t1, scheme.theta)]
    s = np.linspace(t0, t1, scheme.restart + 1)
    steps = [(a, b, scheme.theta) for a, b in zip(s[:-1], s[1:])]
    if scheme.theta < 1 and since == 0:
        mid = 0.5 * (s[0] + s[1])
        steps[:1] = [(s[0], mid, 1.0), (mid, s[1], 1.0)]
    return [(float(a), float(b), th) for a, b, th in steps]


def steps(system: HeatSystem, drive: Drive, times: np.ndarray,
          scheme: TimeScheme = TimeScheme()) -> list[tuple[float, float, float, Mode, bool]]:
    """The steps ``(start, end, θ, mode, last of its interval)`` of a march over ``times``:
    the mode of an interval is read at its midpoint, and the first interval after a switch
    (and the first of all) is refined as :class:`TimeScheme` says."""
    out, last, since = [], None, 0
    for t0, t1 in zip(times[:-1], times[1:]):
        mode = system.mode(environment(drive, 0.5 * (t0 + t1)))
        since = 0 if mode != last else since + 1
        sub = substeps(float(t0), float(t1), scheme, since)
        out += [(a, b, theta, mode, i == len(sub) - 1) for i, (a, b, theta) in enumerate(sub)]
        last = mode
    return out


def step_keys(plan: list[tuple[float, float, float, Mode, bool]]) -> dict[tuple[float, Mode], int]:
    """How many of the :func:`steps` each step matrix ``(θ dt, mode)`` takes."""
    return dict(Counter((round(theta * (b - a), 9), mode) for a, b, theta, mode, _ in plan))


def march(system: HeatSystem | HeatSolver, drive: Drive, times: np.ndarray, scheme: TimeScheme = TimeScheme(),
          U0: np.ndarray | None = None) -> Iterator[tuple[float, np.ndarray]]:
    """Yield ``(t, U)`` at every entry of ``times``, starting with the initial state
    (fixed temperatures applied), stepping as :func:`steps` says.

    Pass a :class:`HeatSolver` to reuse its step solvers across runs; a bare
    :class:`HeatSystem` gets a solver of its own for this run.
    """
    solver = system if isinstance(system, HeatSolver) else HeatSolver(system)
    sys = solver.system
    U = sys.initial() if U0 is None else np.array(U0, dtype=float)
    if sys.fixed:
        U[sys.fixed_dofs] = sys.boundary_values(environment(drive, float(times[0])))
    yield float(times[0]), U
    todo = steps(sys, drive, np.asarray(times, dtype=float), scheme)
    solver.expect(step_keys(todo))
    for a, b, theta, mode, last in todo:
        U = theta_step(solver, drive, U, a, b, theta, mode)
        if last:
            yield b, U


def boundary_terms(mesh, name: str, e, q: int, thickness: Field) -> tuple[sp.csr_matrix, np.ndarray]:
    """``(∫ t u v, ∫ t v)`` over the named boundary (``t`` the 2-D thickness of the element
    beside each facet): a film of unit coefficient and its load. Linear elements in numpy
    (:func:`~gatetherm.solvers.p1.facet_terms`), others by scikit-fem's facet basis."""
    facets = mesh.boundaries[name]
    if e.maxdeg == 1:
        t = thickness.values[mesh.f2t[0, facets]] if np.ptp(thickness.values) else np.full(len(facets),
                                                                                           thickness.values[0])
        return p1.facet_terms(mesh.p.T, mesh.facets[:, facets].T, t, mesh.nvertices)
    fb = FacetBasis(mesh, e, facets=facets, intorder=q)
    tf = thickness.at(fb)
    return asm(film, fb, h=1.0, t=tf), asm(film_load, fb, h=1.0, t=tf)


def bordered(A: sp.spmatrix, d) -> sp.csr_matrix:
    """``[[A, 0], [0, diag(d)]]`` (CSR, no entry where ``d`` is 0): ``A``'s arrays extended, not
    made anew through triplets as ``sp.block_diag`` makes them."""
    A, d = A.tocsr(), np.asarray(d, dtype=float)
    n, on = A.shape[0], np.flatnonzero(d)
    indptr = np.r_[A.indptr, A.indptr[-1] + np.cumsum(d != 0)].astype(A.indptr.dtype)
    if not on.size:  # the same entries: A's arrays shared
        return sp.csr_matrix((A.data, A.indices, indptr), shape=(n + len(d),) * 2)
    return sp.csr_matrix((np.r_[A.data, d[on]], np.r_[A.indices, n + on].astype(A.indices.dtype), indptr),
                         shape=(n + len(d),) * 2)


def assemble_heat(mesh, problem, fields: dict[str, Field], intorder: int | None = None,
                  simplices: p1.Simplices | None = None) -> HeatSystem:
    """Assemble the heat system of ``problem`` (a :class:`~gatetherm.solvers.problem.Problem`)
    on a scikit-fem ``mesh`` with its named boundaries and subdomains; ``fields`` holds the
    element-wise ``k``, ``rho_c`` and ``thickness``. Linear elements use ``simplices``
    (:func:`~gatetherm.solvers.p1.simplices` of the mesh, found if not given)."""
    order = problem.order
    e = element(mesh.dim(), order)
    q = intorder or 2 * order
    th = fields["thickness"]
    s = None
    if order == 1 and problem.plane != "axisymmetric":  # the same matrices, vectorised (solvers/p1.py)
        s = simplices or p1.simplices(mesh)
        M = s.pattern.scalar(p1.mass, s.G, s.vol, fields["rho_c"].values * th.values)
        K = s.pattern.scalar(p1.conduction, s.G, s.vol, fields["k"].values * th.values)
        basis = dof_basis(mesh, e)
    else:
        basis = CellBasis(mesh, e, intorder=q)
        M = asm(capacity, basis, rc=fields["rho_c"].at(basis), t=th.at(basis))
        K = asm(conduction, basis, k=fields["k"].at(basis), t=th.at(basis))

    if problem.contacts:  # thermal contact layers (on a mesh cut open along them)
        from gatetherm.solvers.contact import conductances

        Kc = conductances(basis, mesh, problem.contacts, th)
        K = K if Kc is None else K + Kc

    def cells():  # a basis with quadrature, made only where a volume integral needs it
        return CellBasis(mesh, e, intorder=q) if order == 1 else basis

    loads: list[tuple[np.ndarray, Value, str]] = []
    varying = []
    for fl in problem.films:
        A_f, a_f = boundary_terms(mesh, fl.boundary, e, q, th)
        K = K + fl.h * A_f
        loads.append((fl.h * a_f, fl.ambient, "film"))
        if fl.law is not None:
            varying.append(VaryingFilm(fl.boundary, A_f.tocsr(), a_f, fl.h, fl.law, fl.ambient))
    for fx in problem.fluxes:
        loads.append((boundary_terms(mesh, fx.boundary, e, q, th)[1], fx.value, "flux"))
    if problem.faces is not None and mesh.dim() == 2:
        cb = cells()
        K = K + asm(film, cb, h=problem.faces.h, t=2.0)
        loads.append((asm(film_load, cb, h=problem.faces.h, t=2.0), problem.faces.ambient, "faces"))
    moving = []
    for src in problem.sources:
        if src.on_boundary:  # a power on a surface: ∫ t v over the boundary, normalised to it
            vec = boundary_terms(mesh, src.region, e, q, th)[1]
        else:
            cb = cells()
            on = Field.by_region(mesh, {src.region: 1.0}, 0.0)
            vec = asm(film_load, cb, h=on.at(cb), t=th.at(cb))
        if src.position is not None:
            moving.append(moving_load(mesh, basis, src, vec, order))
            continue
        if src.on_boundary:
            loads.append((vec / vec.sum(), src.density, "source"))
            continue
        loads.append((vec * src.per if src.per != 1.0 else vec, src.density, "source"))
    n_solid = basis.N
    caps, losses, lumped, couplings = [], [], {}, []
    for fluid in problem.fluids:
        lumped[fluid.name] = n_solid + len(caps)
        caps.append(fluid.capacity)
        losses.append((0.0, None))
        couplings.append(boundary_terms(mesh, fluid.boundary, e, q, th))
        if fluid.hose_capacity > 0:
            lumped[fluid.hose_name or f"{fluid.name}_hose"] = n_solid + len(caps)
            caps.append(fluid.hose_capacity)
            losses.append((fluid.hose_loss, fluid.ambient))
    n = n_solid + len(caps)

    pumped = []
    for fluid, (A_ww, c) in zip(problem.fluids, couplings):
        o = lumped[fluid.name]
        i = lumped.get(fluid.hose_name or f"{fluid.name}_hose", o) if fluid.hose_capacity > 0 else o
        A, idx = A_ww.tocoo(), np.flatnonzero(c)
        oo = np.full(len(idx), o)
        wall = sp.csr_matrix((np.r_[A.data, -c[idx], -c[idx], c.sum()],
                              (np.r_[A.row, idx, oo, o], np.r_[A.col, oo, idx, o])), shape=(n, n))
        flow = sp.csr_matrix(([1.0, -1.0, 1.0], ([o, o, i], [o, i, i])), shape=(n, n))
        pumped.append(Pumped(wall, fluid.film_on, fluid.film_off, flow, fluid.conductance, i,
                             fluid.pump, fluid.supply))
        log.info("heat system: fluid %s on %s, wall area %.4g m²", fluid.name, fluid.boundary, c.sum())
    M, K0 = bordered(M, caps), bordered(K, [ua for ua, _ in losses])  # K0: the hoses' losses on its border
    loads = [Load(np.r_[v, np.zeros(len(caps))], value, kind) for v, value, kind in loads]
    for k, (ua, ambient) in enumerate(losses):
        if ua:
            v = np.zeros(n)
            v[n_solid + k] = ua
            loads.append(Load(v, ambient, "hose"))
    fixed = tuple((basis.get_dofs(mesh.boundaries[c.boundary]).all(), c.value) for c in problem.fixed)
    log.info("heat system: %d unknowns (P%d), %d fixed", n, order, len(np.unique(np.concatenate(
        [d for d, _ in fixed]))) if fixed else 0)
    return HeatSystem(basis, M, K0, tuple(pumped), tuple(loads), fixed, n_solid, lumped, problem.T0, s,
                      tuple(varying), tuple(moving))

