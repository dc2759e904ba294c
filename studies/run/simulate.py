"""Run a frame model through a schedule and collect what the sensors see.

Consumes the heat-step generator; per step it reads the sensor temperatures
(a sparse probe) and the displacement outputs (fixed weight vectors), so a
run costs one heat solve per step and no elastic solve.
"""
from __future__ import annotations

import logging
import time as _time
from dataclasses import dataclass, field
from typing import Callable, Mapping

import numpy as np

from gatetherm import InputError
from gatetherm.checks import CELSIUS, show
from gatetherm.solvers.heat import Drive, HeatSolver, TimeScheme, environment, march
from gatetherm.solvers.model import Model
from gatetherm.solvers.problem import Problem
from gatetherm.solvers.stress import von_mises

log = logging.getLogger(__name__)

#: Smallest prominence (µm) of a δ peak that counts, ten times the sensor resolution.
PEAK_PROMINENCE_UM = 1.0


@dataclass(frozen=True)
class RunResult:
    """Columns in the units of the time-series format, plus saved states."""

    columns: dict[str, np.ndarray]
    states: list[tuple[float, np.ndarray]] = field(default_factory=list)
    seconds: float = 0.0
    envs: dict[float, dict] = field(default_factory=dict)
    """The inputs (``t`` and the drive's) at the times of :attr:`states`: the mechanical
    loads' values there."""
    solved: dict[float, object] = field(default_factory=dict)
    """The displacement fields of states solved during the march, by time
    (:class:`~gatetherm.solvers.helper.Pending`)."""


def sample_times(duration_s: float, step_s: float = 60.0) -> np.ndarray:
    n = int(round(duration_s / step_s))
    return np.linspace(0.0, n * step_s, n + 1)


def column(problem: Problem, key) -> tuple[str, float]:
    """Data-format column name of an output and the factor from SI units to the column's:
    temperatures °C, displacements µm, stresses MPa. θ_A, θ_B and δ carry their
    data-format names when the problem's signals map them."""
    s, kind, name = problem.signals, key[0], key[1]
    if kind == "T":
        return {s.theta_A: "theta_A_degC", s.theta_B: "theta_B_degC"}.get(name, f"T_{name}_degC"), 1.0
    if kind == "relative":
        return ("delta_um" if name == s.delta else f"{name}_um"), 1e6
    if kind == "u":
        return f"u{key[2]}_{name}_um", 1e6
    if kind == "sigma":
        return f"sigma_{key[2]}_{name}_MPa", 1e-6
    return f"T_{name}_degC", 1.0


def signal_columns(problem: Problem) -> tuple[str, ...]:
    """The data format's θ_A, θ_B, θ_C and δ columns (in that order) that the problem's runs have:
    those its signals map."""
    s = problem.signals
    return tuple(c for c, on in zip(("theta_A_degC", "theta_B_degC", "theta_C_degC", "delta_um"),
                                    (s.theta_A, s.theta_B, s.theta_C, s.delta)) if on)


def output_columns(problem: Problem, keys, Y: np.ndarray) -> dict[str, np.ndarray]:
    """Data-format columns of the outputs ``Y`` (samples × ``keys``, SI units), by
    :func:`column`: the signals θ_A, θ_B, θ_C (the mean of its probes) and δ first, then
    the other relative displacements, temperatures, displacements, stresses and von
    Mises at probes, fluids and boundary means."""
    Y = np.atleast_2d(Y)
    at = {k: Y[:, i] for i, k in enumerate(keys)}
    s = problem.signals

    def put(out, key):
        name, scale = column(problem, key)
        out[name] = at[key] * scale

    out: dict[str, np.ndarray] = {}
    for probe in (s.theta_A, s.theta_B):
        if probe:
            put(out, ("T", probe))
    if s.theta_C:
        out["theta_C_degC"] = np.mean([at[("T", c)] for c in s.theta_C], axis=0)
    order = [k for k in keys if k[0] == "relative"]
    order.sort(key=lambda k: k[1] != s.delta)
    for pr in problem.probes:
        order += [k for k in keys if k[1] == pr.name and k[0] in ("T", "u", "sigma")
                  and not (k[0] == "T" and pr.name in (s.theta_A, s.theta_B))]
    for key in order:
        put(out, key)
        if key[0] == "sigma" and key == [k for k in keys if k[:2] == key[:2]][-1]:
            out[f"von_mises_{key[1]}_MPa"] = von_mises({k[2]: at[k] / 1e6 for k in keys if k[:2] == key[:2]})
    for key in keys:
        if key[0] in ("fluid", "mean"):
            put(out, key)
    return out


def loss_columns(problem: Problem, cols: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The power of every source that reports it (a machine element's loss, W:
    :attr:`~gatetherm.solvers.problem.Source.loss`) at the times of the input columns ``cols``
    (``time_s`` and the drive's inputs)."""
    t = np.asarray(cols["time_s"], float)
    env = {"t": t, **{k: np.asarray(v, float) for k, v in cols.items() if k != "time_s"}}
    return {s.loss: np.broadcast_to(np.asarray(s.density(env), float), t.shape).copy()
            for s in problem.sources if s.loss}


def loss_summary(problem: Problem, cols: Mapping[str, np.ndarray]) -> dict:
    """``{"losses": {COLUMN: {"mean_W", "max_W", "last_W", "energy_J"}}}`` of the sources that report
    their power (:func:`loss_columns`; empty without them); the energy by the trapezoidal rule."""
    t, out = np.asarray(cols["time_s"], float), {}
    for s in problem.sources:
        if s.loss and s.loss in cols:
            P = np.asarray(cols[s.loss], float)
            energy = float(np.sum(0.5 * (P[1:] + P[:-1]) * np.diff(t))) if len(t) > 1 else 0.0
            out[s.loss] = {"mean_W": energy / float(t[-1] - t[0]) if len(t) > 1 else float(P[0]),
                           "max_W": float(P.max()), "last_W": float(P[-1]), "energy_J": energy}
    return {"losses": out} if out else {}


def check_temperatures(U: np.ndarray, t: float) -> None:
    """InputError unless every temperature of the state ``U`` (°C) at ``t`` (s) is admissible
    (:data:`~gatetherm.checks.CELSIUS`): a run that leaves the range has met heat inputs out of
    all proportion, or a steady problem without a solution."""
    lo, hi = float(U.min()), float(U.max())
    if not (CELSIUS.holds(lo) and CELSIUS.holds(hi)):
        raise InputError("temperature", f"the solution reaches {show(hi if CELSIUS.holds(lo) else lo)} °C at "
                         f"t = {t:g} s, must be {CELSIUS}", "check the heat inputs (sources, fluxes: units and "
                         "size) and, for a steady state, that a boundary holds a temperature or a film")


def run_model(model: Model, drive: Drive, times: np.ndarray, keep_times=(),
              on_step: Callable[[int, int], None] | None = None, scheme: TimeScheme | None = None,
              U0: np.ndarray | None = None, solver: HeatSolver | None = None, solve_at=(),
              solve_first_peak: bool = False, on_state: Callable | None = None) -> RunResult:
    """March ``model`` over ``times`` (s) under ``drive`` from ``U0`` (default: uniform T0)
    with ``scheme`` (default: the problem's); keep full states at ``keep_times``. A
    ``solver`` of ``model.heat`` carries its factorisations over from earlier runs. Where the
    elastic solver runs in a helper process, the steps are read out once its adjoint weights
    are in (the states kept till then), and the displacement fields of the kept states at
    ``solve_at`` but the last are solved there during the march (:attr:`RunResult.solved`);
    so is, with ``solve_first_peak``, the kept state of δ's first peak (the deformed
    picture's) as soon as the samples settle it (:func:`settled_first_peak`). ``on_state(t, U, env)``
    sees every sample's state (not to be kept: it may be overwritten).
    Columns: ``time_s``, the drive's inputs, then :func:`output_columns`."""
    keep = {float(t) for t in keep_times}
    inputs, Y, states, envs, waiting, solved = [], [], [], {}, [], {}
    t0 = _time.perf_counter()
    scheme = model.problem.scheme if scheme is None else scheme
    ahead, peak = set(), None
    if model.elastic is not None:  # outputs come from adjoint weights: room for the heat factors
        model.elastic.solve.release()
        if model.elastic.solve.background:
            # not the last sample's: a caller's first wish after the march may be another (a picture's)
            ahead = ({float(t) for t in solve_at} & keep) - {float(times[-1])}
            delta = ("relative", model.problem.signals.delta)
            peak = model.readout.keys.index(delta) if solve_first_peak and delta in model.readout.keys else None
    delta_um, look_every = [], max(1, len(times) // 300)  # looked for at most 300 times: each look is O(samples)
    weights, ready = model.readout.weights, False
    steps = march(solver or HeatSolver(model.heat), drive, np.asarray(times, float), scheme, U0)
    for i, (t, U) in enumerate(steps):
        env = environment(drive, t)
        check_temperatures(U, t)
        if on_state:
            on_state(t, U, env)
        inputs.append({"time_s": t, **drive(t)})
        if t in keep:
            U = U.copy()
            states.append((t, U))
            envs[t] = env
        if not ready and weights.done():  # asked until it is; then the steps so far read out
            ready = True
            log.debug("read-out weights in at step %d of %d (%.2f s)", i, len(times) - 1, _time.perf_counter() - t0)
            for k, Uk, ek in waiting:
                Y[k] = model.read(Uk, ek)
            waiting = []
        if ready:
            Y.append(model.read(U, env))
        else:
            waiting.append((i, U if t in keep else U.copy(), env))
            Y.append(None)
        if peak is not None and ready:
            delta_um += [1e6 * y[peak] for y in Y[len(delta_um):]]
            first = settled_first_peak(delta_um) if i % look_every == 0 else None
            if first is not None:  # the kept state nearest it (the earlier of two), as the picture takes
                tp, peak = inputs[first]["time_s"], None
                ahead |= {min(sorted(keep), key=lambda s: abs(s - tp))} - {float(times[-1])}
                solved.update({s: model.displacement_later(Us, envs[s]) for s, Us in states
                               if s in ahead and s not in solved})  # reached already
        if t in ahead and t not in solved:
            solved[t] = model.displacement_later(U, env)
        if on_step:
            on_step(i + 1, len(times))
    for k, Uk, ek in waiting:  # the weights waited for here if not in yet
        Y[k] = model.read(Uk, ek)
    cols = {k: np.array([row[k] for row in inputs]) for k in inputs[0]}
    cols.update(loss_columns(model.problem, cols))
    cols.update(output_columns(model.problem, model.readout.keys, np.array(Y)))
    secs = _time.perf_counter() - t0
    log.info("marched %d steps in %.2f s%s", len(Y) - 1, secs,
             f" ({len(ahead)} displacement fields solved beside)" if ahead else "")
    return RunResult(cols, states, secs, envs, solved)


def prominent_peaks(x: np.ndarray, prominence: float) -> list[int]:
    """Indices of the local maxima of ``x`` (a plateau: its middle, rounded down; not the
    ends) whose prominence is at least ``prominence``, as ``scipy.signal.find_peaks``
    finds them (``tests/test_peaks.py`` compares), without its 2 s of imports."""
    n, out, i = len(x), [], 1
    while i < n - 1:
        if x[i - 1] < x[i]:
            ahead = i + 1
            while ahead < n - 1 and x[ahead] == x[i]:
                ahead += 1
            if x[ahead] < x[i]:
                peak = (i + ahead - 1) // 2
                lowest = []
                for step in (-1, 1):  # the lowest point on each side before a higher one
                    j, low = peak, x[peak]
                    while 0 <= j < n and x[j] <= x[peak]:
                        low = min(low, x[j])
                        j += step
                    lowest.append(low)
                if x[peak] - max(lowest) >= prominence:
                    out.append(peak)
                i = ahead
        i += 1
    return out


def settled_first_peak(delta_um) -> int | None:
    """The index of the first peak :func:`delta_figures` will find in a δ history (µm) of which
    these are the first samples, once they settle it, else None. Settled: it is prominent on
    the samples so far (more of them can only lower the minima beside it), and every earlier
    positive local maximum is followed by a higher sample (its prominence is final)."""
    x = np.asarray(delta_um, dtype=float)
    seen = np.concatenate([[-np.inf], x, [np.inf]])  # what comes next may be higher than anything
    first = next((p - 1 for p in prominent_peaks(seen, PEAK_PROMINENCE_UM) if x[p - 1] > 0), None)
    if first is None:
        return None
    later = np.r_[np.maximum.accumulate(x[::-1])[::-1][1:], -np.inf]  # the highest sample after each
    earlier = [q for q in (p - 1 for p in prominent_peaks(seen, 0.0)) if q < first and x[q] > 0]
    return first if all(later[q] > x[q] for q in earlier) else None


def delta_figures(time_s: np.ndarray, delta_um: np.ndarray) -> dict[str, float | None]:
    """The paper's figures of a δ history: first and second positive peak (µm)
    and time of the first (min), full swing (µm)."""
    peaks = prominent_peaks(np.concatenate([[-np.inf], delta_um, [-np.inf]]), PEAK_PROMINENCE_UM)
    peaks = [p - 1 for p in peaks if delta_um[p - 1] > 0]
    first = peaks[0] if peaks else None
    return {
        "first_peak_um": float(delta_um[first]) if first is not None else None,
        "first_peak_min": float(time_s[first] / 60.0) if first is not None else None,
        "second_peak_um": float(delta_um[peaks[1]]) if len(peaks) > 1 else None,
        "swing_um": float(delta_um.max() - delta_um.min()),
    }
