"""Marching the heat system in time: :class:`HeatSolver` (the step solvers of one system) and
:func:`march` (Crank–Nicolson, each switch of the pumps started by Rannacher's backward-Euler half
steps: :class:`~gatetherm.solvers.scheme.TimeScheme`), with Picard iterations for the films whose
coefficient follows the temperature (:func:`picard`).

The system and its weak form are :mod:`gatetherm.solvers.heat_system`, its assembly
:mod:`gatetherm.solvers.heat_assembly`; their names are importable from here too.
"""
from __future__ import annotations

import logging
import time
from collections import Counter
from typing import Callable, Iterator, Mapping

import numpy as np
import scipy.sparse as sp

from gatetherm import InputError
from gatetherm.solvers.fem import complement
from gatetherm.solvers.heat_assembly import assemble_heat, bordered, boundary_terms  # noqa: F401 (re-exported)
from gatetherm.solvers.heat_system import (  # noqa: F401 (re-exported)
    Drive, HeatSystem, Load, Mode, Pumped, capacity, conduction, environment, film, film_load)
from gatetherm.solvers.linsolve import Bordered, nd_order, planned_solver, restrict_order
from gatetherm.solvers.pardiso import Analyses
from gatetherm.solvers.scheme import TimeScheme

log = logging.getLogger(__name__)

PICARD_TOL = 1e-10
"""Change of every varying film's boundary-mean temperature, K, at which the Picard iterations stop."""
PICARD_MAX = 200
"""Most Picard iterations of one step (or of a steady state)."""

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
