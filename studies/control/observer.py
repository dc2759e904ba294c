"""Kalman filters on a reduced heat model: the frame's thermal state from a few thermocouples,
and an adaptive correction of δ from the measured δ.

1. **State.** ``z = (x, d)``: the reduced state x and an offset d (K) of the room temperature
   (the reduced model's ``room`` input: the room is rarely measured, and a drifting room is the
   commonest disturbance). Between
   samples (the reduced model's exact step for inputs linear between samples,
   :mod:`gatetherm.solvers.rom_time`)

       x⁺ = Φ_p x + Γ0_p u_k + Γ1_p u_{k+1} + γ_p d + w_x,   d⁺ = d + w_d,

   ``γ_p`` the room column of Γ0 + Γ1. Measured: any subset of the temperature channels
   (rises C_i x from T0, noise ``sensor_K``). Process noise: the inputs are uncertain by
   ``input_K`` per step (through Γ0 + Γ1), the state by ``state_K`` RMS per step (isotropic in the
   M-orthonormal coordinates, i.e. an RMS temperature over the heat capacity), d is a random walk
   of ``room_K`` per step. The initial state is the frame uniformly at the first room
   temperature, uncertain by ``initial_K``. Modes are indices into the reduced model's modes.
2. **Output correction.** δ = C_δ x + Σ_j β_j C_j x + β_0 with the C_j the rows of θ_A, θ_B, θ_C
   and the mounting-face mean (:data:`CORRECTION`): the thermoelastic map the model may have
   wrong (a compliant joint or foundation, a sensor stand) corrected by a few coefficients, the
   role the paper's R_i, R_C play, and a bias β_0. With x the filtered state, δ is linear in β, a
   random walk of ``coefficient_um_per_K`` (β_j) and ``bias_um`` (β_0) per step, measured with
   noise ``delta_um``; β_j start at 0 (uncertain by ``prior_um_per_K``), β_0 at the first reading
   less the model's δ.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gatetherm.solvers.rom import ReducedModel
from gatetherm.solvers.rom_time import Discrete


@dataclass(frozen=True)
class ObserverParams:
    """Tuning of the Kalman filter; per step = per sample of the controller (1 min)."""

    sensor_K: float = 0.05
    """Standard deviation of a temperature reading, K (the paper's thermocouple resolution)."""
    delta_um: float = 0.1
    """Standard deviation of a δ reading, µm (the differential transformer's resolution)."""
    input_K: float = 0.1
    """Standard deviation of the oil and room inputs per step, K."""
    state_K: float = 0.005
    """RMS temperature error of the model per step, K."""
    room_K: float = 0.01
    """Random-walk step of the room-temperature offset d, K."""
    initial_K: float = 1.0
    """Uncertainty of the initial (uniform) frame temperature and of the room offset, K."""
    prior_um_per_K: float = 1.0
    """Initial uncertainty of the correction coefficients β_j, µm/K."""
    coefficient_um_per_K: float = 0.01
    """Random-walk step of the correction coefficients β_j, µm/K."""
    bias_um: float = 0.05
    """Random-walk step of the δ bias β_0, µm."""


CORRECTION = ("theta_A_degC", "theta_B_degC", "theta_C_degC", "T_base_degC")
"""Outputs whose rises the δ correction weighs (β_1..β_4), those of them the model has."""


@dataclass(frozen=True)
class Estimate:
    """The filters' states after each sample's update."""

    z: np.ndarray
    """(samples × (states + 1)): x and the room offset d (K)."""
    beta: np.ndarray
    """(samples × (corrections + 1)): the correction coefficients β_j (µm/K) and β_0 (µm)."""
    correction: np.ndarray
    """Rows of C the β_j weigh, then zeros (β_0 multiplies 1)."""

    def delta_of(self, rom: ReducedModel, k: int, X: np.ndarray) -> np.ndarray:
        """δ (µm) of reduced states ``X`` (rows) with the correction of sample k."""
        return X @ (rom.C[rom.output("delta_um")] + self.beta[k, :-1] @ self.correction) + self.beta[k, -1]


def uniform_state(rom: ReducedModel, disc: Discrete) -> np.ndarray:
    """The reduced state of the body uniformly 1 K above T0: the steady state of the last mode
    (every pump off) for every temperature input 1 K warmer (the static responses are in the basis)."""
    off = len(rom.modes) - 1
    g = sum((disc.G0[off] + disc.G1[off])[:, j] for j, u in enumerate(rom.inputs) if u.offset == rom.T0)
    return np.linalg.solve(np.eye(rom.states) - disc.Phi[off], g)


def room_column(rom: ReducedModel, g: np.ndarray) -> np.ndarray:
    """The column of ``g`` (states × inputs) of the room input (zeros without one)."""
    return g[:, rom.room] if rom.room is not None else np.zeros(len(g))


def kalman(rom: ReducedModel, disc: Discrete, u: np.ndarray, modes: np.ndarray, readings: np.ndarray,
           channels: list[int], delta: np.ndarray | None, params: ObserverParams = ObserverParams()) -> Estimate:
    """Filter a run: inputs ``u`` (samples × inputs, less their offsets), interval mode indices,
    temperature ``readings`` (samples × channels, less the outputs' y0; NaN = missing) of the
    outputs ``channels`` (rows of C), and the measured δ (µm; None: no correction)."""
    r, n = rom.states, rom.states + 1
    x1 = uniform_state(rom, disc)
    iso = (params.state_K * np.linalg.norm(x1)) ** 2 / r  # |x1|² is the total heat capacity
    F, Q = {}, {}
    for p in disc.Phi:
        g = disc.G0[p] + disc.G1[p]
        F[p] = np.eye(n)
        F[p][:r, :r], F[p][:r, r] = disc.Phi[p], room_column(rom, g)
        Q[p] = np.zeros((n, n))
        Q[p][:r, :r] = params.input_K ** 2 * g @ g.T + iso * np.eye(r)
        Q[p][r, r] = params.room_K ** 2
    H = np.zeros((len(channels), n))
    H[:, :r] = rom.C[channels]
    z = np.r_[(u[0, rom.room] if rom.room is not None else 0.0) * x1, 0.0]
    P = np.zeros((n, n))
    P[:r, :r] = params.initial_K ** 2 * np.outer(x1, x1) + iso * np.eye(r)
    P[r, r] = params.initial_K ** 2
    out = np.empty((len(u), n))
    for k in range(len(u)):
        if k:
            p = int(modes[k - 1])
            z = F[p] @ z
            z[:r] += disc.G0[p] @ u[k - 1] + disc.G1[p] @ u[k]
            P = F[p] @ P @ F[p].T + Q[p]
        ok = np.isfinite(readings[k])
        if ok.any():
            z, P = _update(z, P, H[ok], readings[k][ok], np.full(ok.sum(), params.sensor_K ** 2))
        out[k] = z
    correction = np.array([rom.C[rom.output(o)] for o in CORRECTION if o in rom.outputs])
    beta = _correction(rom, out[:, :r], correction, delta, params)
    return Estimate(out, beta, correction)


def _update(z, P, H, y, noise):
    """Kalman measurement update (Joseph form)."""
    S = H @ P @ H.T + np.diag(noise)
    gain = np.linalg.solve(S, H @ P).T
    z = z + gain @ (y - H @ z)
    ImKH = np.eye(len(z)) - gain @ H
    return z, ImKH @ P @ ImKH.T + gain @ np.diag(noise) @ gain.T


def _correction(rom: ReducedModel, X: np.ndarray, correction: np.ndarray, delta, params: ObserverParams) -> np.ndarray:
    """The β of the output correction after each sample (zeros without a δ series)."""
    m = len(correction) + 1
    beta = np.zeros((len(X), m))
    if delta is None:
        return beta
    model = X @ rom.C[rom.output("delta_um")]
    phi = np.column_stack([X @ correction.T, np.ones(len(X))])
    b = np.r_[np.zeros(m - 1), delta[0] - model[0]]
    P = np.diag(np.r_[np.full(m - 1, params.prior_um_per_K ** 2), params.delta_um ** 2])
    Q = np.diag(np.r_[np.full(m - 1, params.coefficient_um_per_K ** 2), params.bias_um ** 2])
    for k in range(len(X)):
        if k:
            P = P + Q
        if np.isfinite(delta[k]):
            b, P = _update(b, P, phi[k][None, :], np.array([delta[k] - model[k]]), np.array([params.delta_um ** 2]))
        beta[k] = b
    return beta
