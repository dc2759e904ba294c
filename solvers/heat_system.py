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

The assembly is :mod:`gatetherm.solvers.heat_assembly`, the march :mod:`gatetherm.solvers.heat`.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Callable, Mapping

import numpy as np
import scipy.sparse as sp
from skfem import BilinearForm, CellBasis, LinearForm
from skfem.helpers import dot, grad

from gatetherm.solvers import p1
from gatetherm.solvers.convection import VaryingFilm
from gatetherm.solvers.expr import Value
from gatetherm.solvers.moving import MovingLoad


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
    """Films whose coefficient follows the temperature (Picard iterations: :func:`~gatetherm.solvers.heat.picard`)."""
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
