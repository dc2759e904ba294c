"""The piezo stack in its spring member: stroke, dead band, hysteresis, drive strategies.

Model (paper section 2, Fig. 5), from voltage ``V`` to the tool stroke ``x``:

1. Hysteresis, rate independent: a Prandtl-Ishlinskii sum of play operators
   ``z_i <- max(V - r_i, min(V + r_i, z_i))`` with thresholds ``r_i`` (V) and weights
   ``w_i``; the free stroke is ``G * sum_i w_i (z_i - r_i)`` with ``G`` the free-stroke gain.
   The weights are scaled so that the curve from the reset state reaches ``G * V_max``
   at ``V_max`` (:func:`weights`).
2. Elastic loading: the stack (stiffness ``k_p``) works against the spring member
   (``k_s`` = 32.34e6 N/m): the stroke is the free stroke times ``k_p / (k_p + k_s)``.
   The constant preload only shifts the working point.
3. Dead band: a seating gap ``g`` between stack and spring member, a play operator of
   half width ``g/2`` on the stroke. Preload closes it: ``g = g0 exp(-F_pre / F_seat)``
   (3 um unloaded, 0.009 um at 580 N with the defaults).

The reset state is the one reached by lowering the voltage to 0 V: ``z_i = r_i`` and the
gap open on the advancing side. Every play operator stays at or above that value for
``V >= 0``, so returning to 0 V restores it exactly: with the "return to 0 V before each
new voltage" strategy the same voltage always gives the same stroke (:func:`reset_curve`),
and the controller's inverse (:func:`voltage_for`) is calibrated on that curve. Driven
directly (one step from the previous voltage) the stroke depends on the history and the
voltage-stroke loop is open by the hysteresis plus the dead band.

The stack is mounted so that extension moves the tool away from the workpiece, which
offsets the thermal approach: the displacement added to delta at the cutting area is
``-transmission * (x - x_bias)``, with ``x_bias`` the reset-state stroke at the bias voltage.

Range (assumptions; the paper gives neither figure). Against the 32.34e6 N/m spring the
stack gives 29.2 um, and from a 0 V reference it can only pull the tool away, while the
paper compensated delta from about +44 um (approach) to about -16 um (apart, condition 3's
60 um swing) and was left with +-7 um. The defaults therefore assume

* ``transmission = 3``: the spring-shaped member is a flexure lever (the stack acts low in
  the column, the tool sits higher), the smallest half-integer ratio for which
  3 x 29.2 = 87.6 um covers that 60 um swing plus the +-7 um band on both sides (74 um);
* ``bias_voltage_V = 50`` (one third of the 150 V range): zero compensation sits at
  7.9 um of stroke, so the tool can be pushed 23.6 um towards the workpiece (>= 16 + 7) and
  pulled 64.0 um away (>= 44 + 7), the 1 : 2.7 split of the paper's swing.

The paper's reset strategy is kept: before each new voltage the drive returns to 0 V, which
with a bias moves the tool briefly by ``transmission * x_bias`` towards the workpiece.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from gatetherm import InputError


STRATEGIES = ("reset", "direct")


@dataclass(frozen=True)
class ActuatorParams:
    """Piezo stack (Tokin NLA-10x10x36-like) in its spring member; defaults documented inline."""

    free_stroke_um_per_V: float = 40.0 / 150.0
    """Free (unloaded) stroke per volt on the reset curve, um/V: 40 um at 150 V (assumed for a 36
    mm stack; the paper gives no figure)."""
    max_voltage_V: float = 150.0
    """Drive voltage limit, V; the stroke limits follow from it (0 V .. max_voltage_V)."""
    stack_stiffness_N_per_m: float = 87.5e6
    """Stack stiffness, N/m: assumed 3500 N blocked force / 40 um free stroke."""
    spring_stiffness_N_per_m: float = 32.34e6
    """Stiffness of the spring member the stack works against, N/m (paper)."""
    preload_N: float = 580.0
    """Static preload on the stack, N (paper: 580 N; 0 = the unloaded case of Fig. 5)."""
    dead_band_unloaded_um: float = 3.0
    """Seating gap of the unloaded stack, um (assumed)."""
    seating_force_N: float = 100.0
    """Preload that shrinks the seating gap by a factor e, N (assumed)."""
    play_thresholds_V: tuple[float, ...] = (0.0, 8.0, 16.0, 24.0, 32.0)
    """Prandtl-Ishlinskii play thresholds r_i, V."""
    play_weights: tuple[float, ...] = (1.0, 0.25, 0.2, 0.15, 0.1)
    """Relative play weights w_i, dimensionless (scaled by weights(); gives ~10 % open loop)."""
    transmission: float = 3.0
    """Tool motion at the cutting area per unit of stack stroke, dimensionless (assumed lever ratio
    of the spring-shaped member; see the module docstring)."""
    bias_voltage_V: float = 50.0
    """Voltage at which the compensation is zero, V (assumed, one third of max_voltage_V so that
    the stroke works both ways; 0 = corrections away from the workpiece only)."""
    strategy: str = "reset"
    """"reset": return to 0 V before each new voltage (paper); "direct": step to it."""

    def __post_init__(self):
        if self.strategy not in STRATEGIES:
            raise InputError("strategy", f"unknown {self.strategy!r}", f"use one of {STRATEGIES}")
        if len(self.play_thresholds_V) != len(self.play_weights) or not self.play_weights:
            raise InputError("play_weights", "need one weight per threshold", "give equal-length tuples")
        if min(self.play_thresholds_V) < 0 or min(self.play_weights) < 0 or self.play_weights[0] <= 0:
            raise InputError("play_weights", "thresholds and weights must be >= 0, the first weight > 0",
                             "the first play (r = 0) keeps the curve strictly increasing")
        if 2 * max(self.play_thresholds_V) >= self.max_voltage_V:
            raise InputError("play_thresholds_V", "2 r_i must stay below max_voltage_V", "lower them")
        if self.transmission <= 0 or not 0 <= self.bias_voltage_V <= self.max_voltage_V:
            raise InputError("transmission", "must be > 0 with 0 <= bias_voltage_V <= max_voltage_V",
                             "check the actuator parameters")


@dataclass(frozen=True)
class ActuatorState:
    """Memory of the rate-independent model."""

    plays_V: tuple[float, ...]
    """Play-operator outputs z_i, V."""
    gap_um: float
    """Play output of the seating gap (stroke domain), um."""


def weights(p: ActuatorParams) -> np.ndarray:
    """Play weights scaled so the reset curve reaches max_voltage_V at max_voltage_V."""
    w, r = np.array(p.play_weights, float), np.array(p.play_thresholds_V, float)
    return w * p.max_voltage_V / np.sum(w * (p.max_voltage_V - 2 * r))


def load_factor(p: ActuatorParams) -> float:
    """Stroke against the spring member per unit free stroke, k_p / (k_p + k_s)."""
    return p.stack_stiffness_N_per_m / (p.stack_stiffness_N_per_m + p.spring_stiffness_N_per_m)


def dead_band_um(p: ActuatorParams) -> float:
    """Seating gap left at the preload, um: g0 exp(-F_pre / F_seat)."""
    return p.dead_band_unloaded_um * math.exp(-p.preload_N / p.seating_force_N)


def play(z, v, r):
    """Play (backlash) operator of half width r: new output for input v after output z."""
    return np.maximum(v - r, np.minimum(v + r, z))


def reset_state(p: ActuatorParams) -> ActuatorState:
    """State after lowering the voltage to 0 V (the 'return to 0 V' reset)."""
    return ActuatorState(tuple(float(r) for r in p.play_thresholds_V), dead_band_um(p) / 2)


def step(p: ActuatorParams, state: ActuatorState, voltage_V: float) -> tuple[ActuatorState, float]:
    """Move monotonically to ``voltage_V``; return the new state and the tool stroke (um)."""
    r = np.array(p.play_thresholds_V, float)
    z = play(np.array(state.plays_V), voltage_V, r)
    stroke = load_factor(p) * p.free_stroke_um_per_V * float(np.dot(weights(p), z - r))
    half_gap = dead_band_um(p) / 2
    gap = float(play(state.gap_um, stroke, half_gap))
    return ActuatorState(tuple(z.tolist()), gap), gap - half_gap


def sweep(p: ActuatorParams, voltages_V, state: ActuatorState | None = None) -> np.ndarray:
    """Tool strokes (um) for a voltage sequence driven with ``p.strategy``, from ``state``."""
    v = np.asarray(voltages_V, float)
    if v.size and (np.isnan(v).any() or v.min() < 0 or v.max() > p.max_voltage_V):
        raise InputError("voltage", f"outside 0..{p.max_voltage_V:g} V", "clip the drive voltages")
    state = state or reset_state(p)
    strokes = np.empty(v.shape)
    for k, volts in enumerate(v):
        if p.strategy == "reset":
            state, _ = step(p, state, 0.0)
        state, strokes[k] = step(p, state, volts)
    return strokes


def loaded_stroke(p: ActuatorParams, voltages_V) -> np.ndarray:
    """Stroke against the spring (um) reached from the reset state, before the dead band."""
    v = np.asarray(voltages_V, float)[..., None]
    y = np.sum(weights(p) * np.maximum(v - 2 * np.array(p.play_thresholds_V), 0.0), axis=-1)
    return load_factor(p) * p.free_stroke_um_per_V * y


def reset_curve(p: ActuatorParams, voltages_V) -> np.ndarray:
    """Tool stroke (um) for each voltage reached from the reset state (single valued)."""
    return np.maximum(loaded_stroke(p, voltages_V) - dead_band_um(p), 0.0)


def voltage_for(p: ActuatorParams, strokes_um) -> np.ndarray:
    """Inverse of :func:`reset_curve`, clipped to 0 .. max_voltage_V (exact, piecewise linear)."""
    knots = np.unique(np.r_[0.0, 2 * np.array(p.play_thresholds_V), p.max_voltage_V])
    x = np.asarray(strokes_um, float)
    return np.where(x > 0, np.interp(x + dead_band_um(p), loaded_stroke(p, knots), knots), 0.0)


def stroke_range(p: ActuatorParams) -> tuple[float, float]:
    """Reachable displacement at the cutting area (um), (most negative, most positive):
    ``-transmission (x_max - x_bias)`` (away) .. ``transmission x_bias`` (towards)."""
    x_bias = float(reset_curve(p, p.bias_voltage_V))
    return -p.transmission * (float(reset_curve(p, p.max_voltage_V)) - x_bias), p.transmission * x_bias


def saturated_commands(p: ActuatorParams, commands_um) -> np.ndarray:
    """True where a displacement command (um) lies outside :func:`stroke_range` (1e-9 um slack)."""
    lo, hi = stroke_range(p)
    u = np.asarray(commands_um, float)
    return (u < lo - 1e-9) | (u > hi + 1e-9)


def apply_commands(p: ActuatorParams, commands_um) -> tuple[np.ndarray, np.ndarray]:
    """Voltages and achieved cutting-area displacements (um) for displacement commands (um).

    Commands are the displacement to add to delta (``-delta_et``); each is converted with
    the reset-calibrated inverse and then driven with ``p.strategy`` in sequence; those beyond
    :func:`stroke_range` are clipped (:func:`saturated_commands` says which).
    """
    u = np.asarray(commands_um, float)
    x_bias = float(reset_curve(p, p.bias_voltage_V))
    volts = voltage_for(p, x_bias - u / p.transmission)
    return volts, -p.transmission * (sweep(p, volts) - x_bias)


def hysteresis_loop(p: ActuatorParams, steps: int = 30) -> tuple[np.ndarray, np.ndarray]:
    """Voltages 0 -> max -> 0 in ``steps`` increments each way and the strokes (um)."""
    up = np.linspace(0.0, p.max_voltage_V, steps + 1)
    volts = np.r_[up, up[-2::-1]]
    return volts, sweep(p, volts)


def loop_width_um(p: ActuatorParams, steps: int = 30) -> float:
    """Open-loop width: largest stroke difference, descending minus ascending, at one voltage."""
    _, x = hysteresis_loop(p, steps)
    return float(np.max(np.abs(x[steps:][::-1] - x[: steps + 1])))


def hysteresis_cost_um(p: ActuatorParams, steps: int = 30) -> float:
    """What the hysteresis costs at the cutting area without the reset strategy, um:
    transmission x the open-loop width of the direct-drive loop."""
    return p.transmission * loop_width_um(replace(p, strategy="direct"), steps)


def with_stroke(p: ActuatorParams, lo_um: float, hi_um: float) -> ActuatorParams:
    """``p`` with the transmission and bias voltage that make its reach at the cutting area
    ``lo_um`` (away, < 0) .. ``hi_um`` (towards, > 0): the whole reset-curve stroke times the
    transmission spans the range, the bias voltage sits where its stroke times the transmission is
    ``hi_um``."""
    if not (math.isfinite(lo_um) and math.isfinite(hi_um) and lo_um < 0 <= hi_um):
        raise InputError("actuator.stroke", f"[{lo_um:g}, {hi_um:g}] um is not a range around 0",
                         "give [most negative (away), most positive (towards)], e.g. [-60, 20]")
    full = float(reset_curve(p, p.max_voltage_V))
    transmission = (hi_um - lo_um) / full
    bias = float(voltage_for(replace(p, transmission=transmission), hi_um / transmission))
    return replace(p, transmission=transmission, bias_voltage_V=bias)
