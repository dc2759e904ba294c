"""Verification of the heat solver's time stepping: numbers only.

An exact modal solution of the semi-discrete heat system (unit square with the oil loop
and a supply hose) gives the time-stepping error, a Fourier series checks a 1-D slab with
a sudden surface film, and the frame model's step energy balance is accounted over a run.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg
from scipy.optimize import brentq
from scipy.sparse.linalg import spsolve

from gatetherm.solvers.heat import HeatSystem, Inputs, ThermalParams, TimeScheme, assemble_heat, energy_step, march
from gatetherm.validation.verification import uniform_fields, rectangle


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
    return assemble_heat(m, order, *uniform_fields(m, 1.0, 1.0, 1.0), p, oil_volume=0.5)


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
    sys = assemble_heat(m, order, *uniform_fields(m, k, rho_c, 1.0), params, oil_volume=1e-6)
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
