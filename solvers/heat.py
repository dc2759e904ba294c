"""Transient heat conduction in the frame, coupled to a lumped oil tank.

Unknowns are the nodal temperatures of the solid (°C) followed by the tank oil
temperature and, if the supply hose has a heat capacity, the hose temperature.
Per unit of the 2-D out-of-plane thickness ``t`` (``t = 1`` in 3-D) the weak form is

    ∫ t ρc Ṫ v + ∫ t k ∇T·∇v + Σ_Γ ∫ t h_Γ (T − T_amb) v + ∫ h_s (T − T_amb) v
        + ∫_wall t h_oil (T − T_oil) v = ∫ t q v
    C_oil Ṫ_oil + ∫_wall t h_oil (T_oil − T) + G (T_oil − T_in) = 0
    C_hose Ṫ_hose + G (T_hose − T_supply) + UA_hose (T_hose − T_amb) = 0

with ``h_s`` the out-of-plane loss (2 h_air for the front and back faces of a
2-D section), ``h_oil`` and the pump conductance ``G = ρc_oil Q`` following the
pump state, and ``T_in`` the oil reaching the tank: ``T_hose`` (``T_supply``
without a hose). The hose is one well-mixed lump, the simplest model of the oil
that stands and cools in it while the pump is off and reaches the tank first
when it restarts. Integrated with the θ-method (:class:`TimeScheme`); each
distinct (θ dt, pump) matrix is factorised once.
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from typing import Callable, Iterator, NamedTuple

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu
from skfem import BilinearForm, CellBasis, FacetBasis, LinearForm, asm
from skfem.helpers import dot, grad

from gatetherm.checks import CELSIUS, NONNEGATIVE, POSITIVE, Range, admissible
from gatetherm.solvers.fem import Field, element

log = logging.getLogger(__name__)


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


@admissible(T0=CELSIUS, h_air=NONNEGATIVE, h_base=NONNEGATIVE, h_oil_on=NONNEGATIVE, h_oil_off=NONNEGATIVE,
            oil_rho_c=POSITIVE, flow_rate=NONNEGATIVE, hose_capacity=NONNEGATIVE, hose_loss=NONNEGATIVE)
@dataclass(frozen=True)
class ThermalParams:
    """Heat-transfer coefficients of the frame and the oil tank."""

    T0: float = 20.0
    """Initial temperature of frame, oil and room, and the stress-free reference, °C."""
    h_air: float = 8.0
    """Film coefficient of the free surfaces to room air (convection + linearised radiation), W/(m² K)."""
    h_base: float = 0.0
    """Film coefficient of the mounting face to a foundation at room temperature, W/(m² K)."""
    h_oil_on: float = 260.0
    """Tank-wall film coefficient while the pump circulates the oil, W/(m² K)."""
    h_oil_off: float = 28.0
    """Tank-wall film coefficient of standing oil, W/(m² K)."""
    oil_rho_c: float = 1.7e6
    """Volumetric heat capacity of the oil, J/(m³ K)."""
    flow_rate: float = 3.3e-5
    """Oil flow through the tank while the pump runs, m³/s."""
    out_of_plane: bool = True
    """2-D only: the front and back faces of the section lose heat with ``h_air``."""
    hose_capacity: float = 1800.0
    """Heat capacity of the supply hose from the oil unit to the tank, its oil and its wall,
    J/K (0: no hose). Default: 2 m of 13 mm-bore rubber hose, 0.27 L of oil (450 J/K) and
    0.68 kg of rubber (1360 J/K)."""
    hose_loss: float = 0.9
    """Heat loss of the supply hose to the room, W/K. Default: 2 m of 23 mm outer diameter,
    8 W/(m² K) outside, 5 mm of rubber (k = 0.2 W/(m K))."""


class Inputs(NamedTuple):
    """What drives the model at one instant."""

    T_supply: float
    """Temperature of the oil supplied to the tank, °C."""
    pump: bool
    """Oil circulation on."""
    T_amb: float
    """Room temperature, °C."""


Drive = Callable[[float], Inputs]


@admissible(theta=Range(0.5, 1.0), restart=Range(1, 1000, whole=True), restart_intervals=Range(0, 1000, whole=True))
@dataclass(frozen=True)
class TimeScheme:
    """The θ-method with Rannacher start-up at input switches."""

    theta: float = 0.5
    """1: backward Euler; 0.5: Crank–Nicolson (second order)."""
    restart: int = 4
    """Steps into which each of the ``restart_intervals`` intervals after a pump switch (and
    at the start) is divided; for θ < 1 the very first of them is two backward-Euler half
    steps, which damp the stiff modes the switch excites (oil, wall film) instead of
    letting CN ring. 1: no grading."""
    restart_intervals: int = 3
    """How many intervals after a switch are divided."""


@dataclass(frozen=True)
class HeatSystem:
    """Assembled operators; the unknowns are the solid's (``n_solid``), then the tank
    oil, then the hose (if ``params.hose_capacity > 0``). Immutable: the factorisations
    of its step matrices live in a :class:`HeatSolver`."""

    basis: CellBasis
    M: sp.csr_matrix
    K0: sp.csr_matrix
    K_wall: sp.csr_matrix
    f_amb: np.ndarray
    f_src: np.ndarray
    params: ThermalParams
    n_solid: int

    @property
    def n(self) -> int:
        return self.M.shape[0]

    @property
    def oil(self) -> int:
        """Index of the tank-oil unknown."""
        return self.n_solid

    @property
    def inlet(self) -> int:
        """Index of the unknown the supplied oil enters: the hose, or the tank without one."""
        return self.n - 1

    def coefficients(self, pump: bool) -> tuple[float, float]:
        """(tank-wall film coefficient, pump conductance in W/K) for a pump state."""
        p = self.params
        return (p.h_oil_on, p.oil_rho_c * p.flow_rate) if pump else (p.h_oil_off, 0.0)

    def K(self, pump: bool) -> sp.csr_matrix:
        """Conductance matrix for a pump state."""
        h, G = self.coefficients(pump)
        o, i = self.oil, self.inlet  # G (T_oil − T_in) and G T_in, summed if the same unknown
        e = sp.csr_matrix(([G, -G, G], ([o, o, i], [o, i, i])), shape=(self.n, self.n))
        return (self.K0 + h * self.K_wall + e).tocsr()

    def f(self, t: float, drive: Drive, pump: bool) -> np.ndarray:
        u = drive(t)
        out = self.f_amb * u.T_amb + self.f_src
        out[self.inlet] += self.coefficients(pump)[1] * u.T_supply
        return out

    def initial(self, T0: float | None = None) -> np.ndarray:
        return np.full(self.n, self.params.T0 if T0 is None else T0)


class HeatSolver:
    """Step solves of one :class:`HeatSystem`: the conductance matrix of each pump state
    and the factor of each distinct (θ dt, pump) step matrix, made on first use and kept
    (four per paper condition: 60-s and 15-s steps, pump on and off)."""

    def __init__(self, system: HeatSystem):
        self.system = system
        self._K: dict[bool, sp.csr_matrix] = {}
        self._lu: dict[tuple[float, bool], object] = {}
        self.factor_seconds = 0.0
        """Seconds spent factorising so far."""

    def K(self, pump: bool) -> sp.csr_matrix:
        if pump not in self._K:
            self._K[pump] = self.system.K(pump)
        return self._K[pump]

    @property
    def factorisations(self) -> int:
        """How many step matrices were factorised so far."""
        return len(self._lu)

    def solve(self, dt: float, theta: float, pump: bool, rhs: np.ndarray) -> np.ndarray:
        """Solve ``(M/dt + θ K) U = rhs`` with the factor of ``M/(θ dt) + K``, which backward
        Euler over dt/2 and Crank–Nicolson over dt share."""
        key = (round(theta * dt, 9), pump)
        if key not in self._lu:
            t0 = time.perf_counter()
            A = (self.system.M / (theta * dt) + self.K(pump)).tocsc()
            self._lu[key] = splu(A, permc_spec="COLAMD")
            seconds = time.perf_counter() - t0
            self.factor_seconds += seconds
            log.debug("factorised heat matrix for θdt=%g s, pump=%s in %.2f s", theta * dt, pump, seconds)
        return self._lu[key].solve(rhs / theta)


def assemble_heat(mesh, order: int, k: Field, rho_c: Field, thickness: Field,
                  params: ThermalParams, oil_volume: float,
                  source: Field | None = None, extra_films: dict[str, float] | None = None,
                  intorder: int | None = None) -> HeatSystem:
    """Assemble the heat operators on a scikit-fem ``mesh`` with named boundaries
    ``free_surface``, ``mounting_face`` and ``tank_wall``.

    ``oil_volume`` (m³) sets the oil capacity; ``source`` is a volumetric heat
    source (W/m³); ``extra_films`` adds film coefficients on further boundaries.
    """
    dim = mesh.dim()
    e = element(dim, order)
    q = intorder or 2 * order
    basis = CellBasis(mesh, e, intorder=q)
    t = thickness.at(basis)
    M = asm(capacity, basis, rc=rho_c.at(basis), t=t)
    K = asm(conduction, basis, k=k.at(basis), t=t)
    f_amb = np.zeros(basis.N)
    films = {"free_surface": params.h_air, "mounting_face": params.h_base, **(extra_films or {})}
    for name, h in films.items():
        if h:
            fb = FacetBasis(mesh, e, facets=mesh.boundaries[name], intorder=q)
            tf = thickness.at(fb)
            K = K + asm(film, fb, h=h, t=tf)
            f_amb += asm(film_load, fb, h=h, t=tf)
    if dim == 2 and params.out_of_plane and params.h_air:
        K = K + asm(film, basis, h=params.h_air, t=2.0)
        f_amb += asm(film_load, basis, h=params.h_air, t=2.0)
    f_src = asm(film_load, basis, h=source.at(basis), t=t) if source is not None else np.zeros(basis.N)
    wb = FacetBasis(mesh, e, facets=mesh.boundaries["tank_wall"], intorder=q)
    tw = thickness.at(wb)
    A_ww = asm(film, wb, h=1.0, t=tw)
    c = asm(film_load, wb, h=1.0, t=tw)
    K_wall = sp.bmat([[A_ww, -c[:, None]], [-c[None, :], np.array([[c.sum()]])]]).tocsr()
    caps, loss = [params.oil_rho_c * oil_volume], [0.0]
    if params.hose_capacity > 0:
        caps, loss = caps + [params.hose_capacity], loss + [params.hose_loss]
        K_wall = sp.block_diag([K_wall, sp.csr_matrix((1, 1))]).tocsr()
    M = sp.block_diag([M, sp.diags(caps)]).tocsr()
    K0 = sp.block_diag([K, sp.diags(loss)]).tocsr()
    f_amb, f_src = np.concatenate([f_amb, loss]), np.concatenate([f_src, np.zeros(len(caps))])
    log.info("heat system: %d unknowns (P%d), wall area %.4g m²", M.shape[0], order, c.sum())
    return HeatSystem(basis, M, K0, K_wall, f_amb, f_src, params, basis.N)


def theta_step(solver: HeatSolver, drive: Drive, U: np.ndarray, t0: float, t1: float, theta: float,
               pump: bool) -> np.ndarray:
    """One θ-method step from ``U`` at ``t0`` to ``t1`` with the pump state ``pump``."""
    sys, dt = solver.system, t1 - t0
    rhs = sys.M @ U / dt + theta * sys.f(t1, drive, pump)
    if theta < 1:
        rhs += (1 - theta) * (sys.f(t0, drive, pump) - solver.K(pump) @ U)
    return solver.solve(dt, theta, pump, rhs)


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


def march(system: HeatSystem | HeatSolver, drive: Drive, times: np.ndarray, scheme: TimeScheme = TimeScheme(),
          U0: np.ndarray | None = None) -> Iterator[tuple[float, np.ndarray]]:
    """Yield ``(t, U)`` at every entry of ``times``, starting with the initial state.

    Pass a :class:`HeatSolver` to reuse its factorisations across runs; a bare
    :class:`HeatSystem` gets a solver of its own for this run.

    The pump state of an interval is read at its midpoint, so a switch at a sample
    time takes effect for the whole following interval; that interval (and the
    first) is refined as :class:`TimeScheme` says.
    """
    solver = system if isinstance(system, HeatSolver) else HeatSolver(system)
    U = solver.system.initial() if U0 is None else np.array(U0, dtype=float)
    yield float(times[0]), U
    last, since = None, 0
    for t0, t1 in zip(times[:-1], times[1:]):
        pump = bool(drive(0.5 * (t0 + t1)).pump)
        since = 0 if pump != last else since + 1
        for a, b, theta in substeps(float(t0), float(t1), scheme, since):
            U = theta_step(solver, drive, U, a, b, theta, pump)
        last = pump
        yield float(t1), U


def energy_step(sys: HeatSystem, U0: np.ndarray, U1: np.ndarray, t0: float, t1: float,
                drive: Drive, theta: float = 1.0) -> dict[str, float]:
    """Heat (J) over one step: into the solid through the tank wall, stored in the
    solid, lost to the room/foundation, and added by sources, with the same
    θ-weighting as the scheme, so that ``wall + source = stored + lost`` holds
    to round-off."""
    dt = t1 - t0
    pump = bool(drive(0.5 * (t0 + t1)).pump)
    h, _ = sys.coefficients(pump)
    Um = theta * U1 + (1 - theta) * U0
    solid = np.zeros(sys.n)
    solid[:sys.n_solid] = 1.0
    f_amb = theta * drive(t1).T_amb + (1 - theta) * drive(t0).T_amb
    return {
        "wall": -dt * h * float(solid @ (sys.K_wall @ Um)),
        "stored": float(solid @ (sys.M @ (U1 - U0))),
        "lost": dt * float(solid @ (sys.K0 @ Um) - solid @ sys.f_amb * f_amb),
        "source": dt * float(solid @ sys.f_src),
    }
