"""Film coefficients from correlations: natural convection of plates, rotating cylinders and
discs in still air, forced flow along a plate, and linearised radiation.

Each correlation is a small pure function of its operating point (numbers or numpy arrays);
:class:`FilmLaw` is a boundary's film as ``[thermal.BOUNDARY] film = {correlation = …}`` gives it:
the sum of a convective part (a correlation, or a constant) and radiation, a function of the
surface temperature, the ambient and the run's inputs (a speed column). The heat solve takes it
by Picard iterations on the boundary's mean temperature (:mod:`gatetherm.solvers.heat`).
Air at 1 atm: :func:`air`. Formulas and sources: ``docs/model.md`` (Films from correlations).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
import scipy.sparse as sp

from gatetherm.solvers.expr import Value

SIGMA = 5.670374419e-8
"""Stefan–Boltzmann constant, W/(m² K⁴)."""
GRAVITY = 9.80665
"""Standard gravity, m/s²."""
KELVIN = 273.15


def air(T):
    """Dry air at 101 325 Pa and ``T`` °C: ``(k W/(m K), ν m²/s, Pr, β 1/K)``. Ideal gas
    (R = 287.05 J/(kg K), cp = 1006 J/(kg K)), Sutherland's laws for the viscosity (μ0 = 1.716e-5 Pa s,
    S = 110.4 K) and the conductivity (k0 = 0.0241 W/(m K), S = 194 K) from 273.15 K; β = 1/T."""
    TK = np.asarray(T, float) + KELVIN
    rho = 101325.0 / (287.05 * TK)
    mu = 1.716e-5 * (TK / KELVIN) ** 1.5 * (KELVIN + 110.4) / (TK + 110.4)
    k = 0.0241 * (TK / KELVIN) ** 1.5 * (KELVIN + 194.0) / (TK + 194.0)
    return k, mu / rho, mu * 1006.0 / k, 1.0 / TK


def rayleigh(dT, L, Tf):
    """Rayleigh number ``g β |ΔT| L³/(ν a)`` of air at the film temperature ``Tf`` (°C)."""
    k, nu, pr, beta = air(Tf)
    return GRAVITY * beta * np.abs(dT) * L ** 3 / (nu * nu / pr)


def vertical_plate(dT, L, Tf):
    """Churchill and Chu's natural convection of a vertical plate of height ``L`` (m), all Ra:
    ``Nu = (0.825 + 0.387 Ra^(1/6) / (1 + (0.492/Pr)^(9/16))^(8/27))²``, ``h = Nu k/L``, W/(m² K)."""
    k, nu, pr, beta = air(Tf)
    nu_l = (0.825 + 0.387 * rayleigh(dT, L, Tf) ** (1 / 6) / (1 + (0.492 / pr) ** (9 / 16)) ** (8 / 27)) ** 2
    return nu_l * k / L


def horizontal_plate(dT, L, Tf, up: bool):
    """Natural convection of a horizontal plate, ``L`` = area/perimeter (m): the hot face up (or
    cold face down, ``up``) ``Nu = 0.54 Ra^(1/4)`` to Ra = 1e7, ``0.15 Ra^(1/3)`` beyond; the hot
    face down (or cold face up) ``Nu = 0.52 Ra^(1/5)``; ``h = Nu k/L``. ``up`` is the face's
    orientation: an upper face is hot-up while the surface is warmer than the air."""
    k, nu, pr, beta = air(Tf)
    ra = rayleigh(dT, L, Tf)
    enhanced = (np.asarray(dT) > 0) == up
    nu_l = np.where(enhanced, np.where(ra <= 1e7, 0.54 * ra ** 0.25, 0.15 * ra ** (1 / 3)), 0.52 * ra ** 0.2)
    return nu_l * k / L


def rotating_cylinder(n, D, Tf):
    """A cylinder of diameter ``D`` (m) rotating at ``n`` (1/min) in still air: ``Nu = 0.133
    Re^(2/3) Pr^(1/3)``, ``Re = Ω D²/ν`` (< 4.3e5), ``h = Nu k/D``, W/(m² K)."""
    k, nu, pr, beta = air(Tf)
    re = np.abs(n) * 2 * math.pi / 60 * D ** 2 / nu
    return 0.133 * re ** (2 / 3) * pr ** (1 / 3) * k / D


def rotating_disc(n, D, Tf):
    """A disc of diameter ``D`` (m) rotating at ``n`` (1/min) in still air, mean over a face:
    ``Nu = 0.36 Re^(1/2)`` (laminar, Re < 2.4e5), ``0.015 Re^0.8`` beyond, ``Re = Ω r²/ν``,
    ``h = Nu k/r``, ``r = D/2``."""
    k, nu, pr, beta = air(Tf)
    r = D / 2
    re = np.abs(n) * 2 * math.pi / 60 * r ** 2 / nu
    return np.where(re < 2.4e5, 0.36 * re ** 0.5, 0.015 * re ** 0.8) * k / r


def flat_plate(v, L, Tf):
    """Air flowing at ``v`` (m/s) along a plate of length ``L`` (m), mean over it: ``Nu = 0.664
    Re^(1/2) Pr^(1/3)`` (laminar, Re ≤ 5e5), ``(0.037 Re^0.8 − 871) Pr^(1/3)`` (mixed, beyond),
    ``Re = v L/ν``, ``h = Nu k/L``."""
    k, nu, pr, beta = air(Tf)
    re = np.abs(v) * L / nu
    return np.where(re <= 5e5, 0.664 * re ** 0.5, 0.037 * re ** 0.8 - 871.0) * pr ** (1 / 3) * k / L


def radiation(emissivity, Ts, Ta):
    """Linearised radiation to surroundings at the ambient: ``ε σ (Ts² + Ta²)(Ts + Ta)`` (kelvins),
    so that ``h (Ts − Ta)`` is the exchanged ``ε σ (Ts⁴ − Ta⁴)``."""
    s, a = np.asarray(Ts, float) + KELVIN, np.asarray(Ta, float) + KELVIN
    return emissivity * SIGMA * (s * s + a * a) * (s + a)


CORRELATIONS = ("vertical_plate", "horizontal_up", "horizontal_down", "rotating_cylinder", "rotating_disc",
                "flat_plate")
"""The correlations a film may name."""
SPEED = {"rotating_cylinder": "1/min", "rotating_disc": "1/min", "flat_plate": "m/s"}
"""The correlations that read a speed, and its unit."""


@dataclass(frozen=True)
class FilmLaw:
    """A film coefficient that depends on the surface temperature (and the inputs): a correlation
    (or a constant ``h``) plus radiation; ``h(Ts, Ta, env)`` in W/(m² K)."""

    correlation: str = ""
    """One of :data:`CORRELATIONS`, empty: the constant :attr:`h`."""
    h: float = 0.0
    """Constant convective film without a correlation, W/(m² K)."""
    length: float = 1.0
    """Characteristic length, m: a vertical plate's height, a horizontal plate's area/perimeter,
    a cylinder's or disc's diameter, a plate's length along the flow."""
    speed: Value = Value(0.0)
    """Rotational speed, 1/min, or flow velocity, m/s (:data:`SPEED`)."""
    emissivity: float = 0.0
    """Emissivity of the surface for radiation to the ambient (0: none)."""
    minimum: float = 0.0
    """Lower bound of the convective part, W/(m² K) (a rotating part at rest)."""
    factor: float = 1.0
    """Multiplies the correlation's convective part (before :attr:`minimum`): its uncertainty, 1."""

    def convective(self, Ts, Ta, env) -> float:
        dT, Tf, L, c = Ts - Ta, 0.5 * (Ts + Ta), self.length, self.correlation
        if not c:
            return self.h
        if c == "vertical_plate":
            h = vertical_plate(dT, L, Tf)
        elif c in ("horizontal_up", "horizontal_down"):
            h = horizontal_plate(dT, L, Tf, c == "horizontal_up")
        elif c == "rotating_cylinder":
            h = rotating_cylinder(self.speed(env), L, Tf)
        elif c == "rotating_disc":
            h = rotating_disc(self.speed(env), L, Tf)
        else:
            h = flat_plate(self.speed(env), L, Tf)
        return max(float(h) * self.factor, self.minimum)

    def __call__(self, Ts: float, Ta: float, env) -> float:
        """The film coefficient at surface temperature ``Ts`` and ambient ``Ta`` (°C), W/(m² K)."""
        return self.convective(Ts, Ta, env) + (float(radiation(self.emissivity, Ts, Ta)) if self.emissivity else 0.0)


@dataclass(frozen=True)
class VaryingFilm:
    """A film whose coefficient follows its boundary's mean temperature (a FilmLaw): the matrix holds
    ``h_ref``, the load the rest, ``−(h − h_ref)(A U − a T_amb)``, solved by Picard iterations."""

    boundary: str
    A: sp.csr_matrix
    """``∫ t u v`` over the boundary (solid unknowns)."""
    a: np.ndarray
    """``∫ t v`` over the boundary (solid unknowns)."""
    h_ref: float
    """Coefficient in the matrix, W/(m² K)."""
    law: Callable
    """``law(Ts, Ta, env)``: the coefficient at mean surface temperature ``Ts``, W/(m² K)."""
    ambient: Value

    def surface(self, U: np.ndarray) -> float:
        """Area-mean temperature of the boundary, °C."""
        return float(self.a @ U[:len(self.a)] / self.a.sum())

    def h(self, U: np.ndarray, env) -> float:
        return float(self.law(self.surface(U), self.ambient(env), env))

    def correction(self, U: np.ndarray, env) -> np.ndarray:
        """The film's part beyond the matrix, on the left-hand side (solid unknowns)."""
        Ta = self.ambient(env)
        return (self.law(self.surface(U), Ta, env) - self.h_ref) * (self.A @ U[:len(self.a)] - self.a * Ta)


def held_coefficient(t_s, h, excess) -> float:
    """The one coefficient that stands for a film law over a run (a linear model holds it so): the
    law's coefficients ``h`` (W/(m² K)) at the times ``t_s`` (s), averaged with the weights
    ``|excess| dt``, ``excess`` the wall's mean temperature less the ambient (K), so that it is
    right where the film carries heat; the plain time mean where the wall never leaves the ambient."""
    t, h, w = (np.asarray(x, float) for x in (t_s, h, excess))
    dt = np.diff(t)
    dt = 0.5 * (np.r_[dt, 0.0] + np.r_[0.0, dt]) if t.size > 1 else np.ones(1)
    w = np.abs(w) * dt
    return float(h @ w / w.sum()) if w.sum() > 1e-12 * dt.sum() else float(h @ dt / dt.sum())
