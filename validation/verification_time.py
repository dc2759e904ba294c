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

from gatetherm.frame.geometry import FrameParams, MeshParams
from gatetherm.solvers.expr import Value
from gatetherm.frame.problem import AMBIENT, PUMP, SUPPLY, ModelConfig, ThermalParams, build_model, paper_heat
from gatetherm.solvers.heat import HeatSolver, HeatSystem, TimeScheme, assemble_heat, environment, march
from gatetherm.solvers.problem import Film, Problem
from gatetherm.validation.verification import observed_order, rectangle, uniform_fields

FIXED_FRAME = FrameParams(h=0.12, column_height=0.53, l=0.50, l4=0.25, A_C=2.4e-3, tank_wall=0.015, tank_width=0.05)
"""The verification frame: fixed (not the calibrated defaults), so that hand values stay valid."""
COARSE_MESH = MeshParams(size=0.02, size_3d=0.02)
"""Mesh density of the verification frame (about 1.6k triangles / 24k tetrahedra)."""
FIXED_MODEL = ModelConfig(frame=FIXED_FRAME, mesh=COARSE_MESH)
"""The verification frame's model (the tests' fixtures ``frame_2d``, ``frame_3d`` are its meshes)."""


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

    def __call__(self, t: float) -> dict[str, float]:
        c = np.cos(self.omega * t)
        return {SUPPLY: self.sup0 + self.sup1 * c, PUMP: float(self.pump(t)), AMBIENT: self.amb0 + self.amb1 * c}


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
    return _heat(m, Problem(2, {}, order, T0=p.T0, T_ref=p.T0, **paper_heat(p, oil_volume=0.5)), 1.0, 1.0)


def _heat(mesh, problem: Problem, k: float, rho_c: float) -> HeatSystem:
    fields = dict(zip(("k", "rho_c", "thickness"), uniform_fields(mesh, k, rho_c, 1.0)))
    return assemble_heat(mesh, problem, fields)


def steady_state(sys: HeatSystem, drive, t: float = 0.0) -> np.ndarray:
    """The state in equilibrium with the inputs frozen at time ``t``."""
    return HeatSolver(sys).steady(environment(drive, t))


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
    modes = {}
    U = sys.initial() if U0 is None else np.array(U0, float)
    out = [U]
    for t0, t1 in zip(times[:-1], times[1:]):
        pump = drive.pump(0.5 * (t0 + t1))
        if pump not in modes:
            mode = (pump,)
            lam, phi = scipy.linalg.eig(sys.K(mode).toarray(), M)
            lam, phi = lam.real, phi.real  # real: the hose feeds the symmetric solid-oil block one way
            # f is affine in the inputs: f = a + c cos(ωt)
            a = sys.f({SUPPLY: drive.sup0, AMBIENT: drive.amb0}, mode)
            c = sys.f({SUPPLY: drive.sup1, AMBIENT: drive.amb1}, mode) - sys.f({SUPPLY: 0.0, AMBIENT: 0.0}, mode)
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
        "left": "mounting_face", "right": "free_surface", "top": "free_surface", "bottom": "free_surface"})
    sys = _heat(m, Problem(2, {}, order, T0=T_i, films=(Film("mounting_face", h, Value(T_amb)),)), k, rho_c)
    drive = lambda t: {}  # noqa: E731
    times = np.arange(0.0, t_end + 0.5 * dt, dt)
    xi = (L - sys.basis.doflocs[0]) / L
    err = 0.0
    for t, U in march(sys, drive, times, scheme):
        if t >= every and abs(t / every - round(t / every)) < 1e-9:
            exact = slab_film_series(xi, k / rho_c * t / L ** 2, h * L / k)
            err = max(err, float(np.abs((U[:sys.n_solid] - T_amb) / (T_i - T_amb) - exact).max()))
    return err


def energy_step(sys: HeatSystem, U0: np.ndarray, U1: np.ndarray, env0, env1, mode, theta: float = 1.0,
                dt: float = 1.0) -> dict[str, float]:
    """Heat (J) over one step of the solid: in through the fluid's wall, stored, lost to
    the room and the foundation (films, faces) and added by sources, with the same
    θ-weighting as the scheme, so that ``wall + source = stored + lost`` holds to round-off."""
    Um = theta * U1 + (1 - theta) * U0
    solid = np.zeros(sys.n)
    solid[:sys.n_solid] = 1.0
    p, = sys.pumped
    h = p.coefficients(mode[0])[0]

    def loads(kinds):
        return sum(float(solid @ ld.vector) * (theta * ld.value(env1) + (1 - theta) * ld.value(env0))
                   for ld in sys.loads if ld.kind in kinds)

    return {"wall": -dt * h * float(solid @ (p.wall @ Um)),
            "stored": float(solid @ (sys.M @ (U1 - U0))),
            "lost": dt * (float(solid @ (sys.K0 @ Um)) - loads(("film", "faces"))),
            "source": dt * loads(("source",))}


def energy_balance(sys: HeatSystem, drive, times: np.ndarray, theta: float) -> dict[str, np.ndarray]:
    """Per-step heat (J) over a θ-method march without start-up grading: the terms of
    :func:`energy_step` (solid: ``wall + source = stored + lost``), the oil's own account
    (``supply`` brought by the flow, ``supply = oil_stored + wall``) and, with a hose, the
    hose's (``hose_in = hose_stored + hose_lost``; enthalpy flows G (T_supply − T_hose) into
    the hose, G (T_hose − T_oil) into the tank)."""
    states = list(march(sys, drive, times, TimeScheme(theta, restart=1)))
    p, = sys.pumped
    o = sys.lumped["tank_oil"]
    i = p.inlet
    ua = next((ld.vector[i] for ld in sys.loads if ld.kind == "hose"), 0.0)
    out: dict[str, list[float]] = {}
    for (t0, U0), (t1, U1) in zip(states[:-1], states[1:]):
        dt = t1 - t0
        env0, env1 = environment(drive, t0), environment(drive, t1)
        mode = sys.mode(environment(drive, 0.5 * (t0 + t1)))
        G = p.coefficients(mode[0])[1]
        Um = theta * U1 + (1 - theta) * U0
        u = {k: theta * env1[k] + (1 - theta) * env0[k] for k in (SUPPLY, AMBIENT)}
        terms = {**energy_step(sys, U0, U1, env0, env1, mode, theta, dt),
                 "oil_stored": sys.M[o, o] * (U1[o] - U0[o])}
        if i == o:
            terms["supply"] = dt * G * (u[SUPPLY] - Um[o])
        else:
            terms["supply"] = dt * G * (Um[i] - Um[o])
            terms["hose_in"] = dt * G * (u[SUPPLY] - Um[i])
            terms["hose_lost"] = dt * ua * (Um[i] - u[AMBIENT])
            terms["hose_stored"] = sys.M[i, i] * (U1[i] - U0[i])
        for key, v in terms.items():
            out.setdefault(key, []).append(float(v))
    return {key: np.array(v) for key, v in out.items()}


SMOOTH = HarmonicDrive(amb0=20.0, amb1=3.0, sup0=40.0, sup1=5.0, omega=2.0)
"""Harmonic room and supply, the pump always on."""
SWITCHED = HarmonicDrive(amb0=20.0, amb1=3.0, sup0=40.0, sup1=5.0, omega=2.0, period=1.0)
"""The same with the pump stopping at t = 1."""
TIME_CASES = {
    "BE": (TimeScheme(1.0, 1), SMOOTH, (10, 20, 40, 80, 160), False),
    "CN": (TimeScheme(0.5, 1), SMOOTH, (10, 20, 40, 80, 160), False),
    "BE pump off at t=1": (TimeScheme(1.0, 1), SWITCHED, (10, 20, 40, 80, 160), True),
    "CN pump off at t=1": (TimeScheme(0.5, 1), SWITCHED, (80, 160, 320, 640), True),
    "CN+Rannacher pump off at t=1": (TimeScheme(0.5, 2, 1), SWITCHED, (10, 20, 40, 80, 160), True),
}
"""Time-order studies on :func:`unit_heat_system` over t = 0..2: label -> (scheme, drive, step
counts, error at t = 2 only). Without switching the error is the max over all steps."""


def time_order(label: str):
    """(dt, errors, observed order, expected order) of :data:`TIME_CASES` ``label``, started in
    equilibrium with the inputs at t = 0."""
    scheme, drive, steps, final_only = TIME_CASES[label]
    sys = unit_heat_system()
    dt, err = time_errors(sys, drive, 2.0, steps, scheme, steady_state(sys, drive), final_only)
    return dt, err, observed_order(dt, err), 1.0 if scheme.theta == 1.0 else 2.0


FRAME_SOURCE = 2.0e4
"""Heat source in arm_L of the energy-balance run, W/m³."""


def frame_drive(t: float) -> dict[str, float]:
    """Pump on for the first 20 min of every 40, supply and room both varying."""
    return {SUPPLY: 40.0 + 5.0 * np.sin(t / 900.0), PUMP: float((t // 1200.0) % 2 == 0),
            AMBIENT: 20.0 + 2.0 * np.sin(t / 1500.0)}


FRAME_TIMES = np.concatenate([np.arange(0.0, 3600.0, 60.0), np.arange(3600.0, 10800.0 + 1, 150.0)])
"""3 h in uneven steps: 60 s, then 150 s."""


def frame_energy(theta: float, fmesh=None) -> dict[str, np.ndarray]:
    """:func:`energy_balance` of the 2-D verification frame with :data:`FRAME_SOURCE` in arm_L
    under :func:`frame_drive` over :data:`FRAME_TIMES` (``fmesh``: its mesh, if built)."""
    import dataclasses

    model = build_model(dataclasses.replace(FIXED_MODEL, source={"arm_L": FRAME_SOURCE}), 2, fmesh=fmesh)
    return energy_balance(model.heat, frame_drive, FRAME_TIMES, theta)


def imbalances(e: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Per step, relative to the largest term of the step: the solid's, the oil's and the hose's
    account (``wall + source − stored − lost``, ``supply − oil_stored − wall``,
    ``hose_in − hose_stored − hose_lost``)."""
    scale = np.max(np.abs(np.array(list(e.values()))), axis=0)
    return {"solid": (e["wall"] + e["source"] - e["stored"] - e["lost"]) / scale,
            "oil": (e["supply"] - e["oil_stored"] - e["wall"]) / scale,
            "hose": (e["hose_in"] - e["hose_stored"] - e["hose_lost"]) / scale}


def pump_switch_errors(fmesh=None) -> dict[str, float]:
    """Condition 2 on the verification frame sampled every minute: the largest |δ − δ_ref| (µm)
    of the default scheme and of backward Euler at 60 s, δ_ref by CN at 3.75 s."""
    from gatetherm.frame.conditions import CONDITIONS
    from gatetherm.studies.run.conditions import SupplyParams, condition_drive
    from gatetherm.studies.run.simulate import run_model, sample_times

    model = build_model(FIXED_MODEL, 2, fmesh=fmesh)
    drive, times = condition_drive(CONDITIONS[2], SupplyParams()), sample_times(5 * 3600.0)
    ref = run_model(model, drive, sample_times(5 * 3600.0, 3.75), scheme=TimeScheme(0.5, 1)).columns["delta_um"][::16]
    default = run_model(model, drive, times).columns["delta_um"]
    be = run_model(model, drive, times, scheme=TimeScheme(1.0, 1)).columns["delta_um"]
    return {"default": float(np.abs(default - ref).max()), "backward Euler 60 s": float(np.abs(be - ref).max())}
