"""Time stepping of a reduced model: exact per pump mode for inputs linear between samples.

For a step ``dt`` and each mode p, with ``u`` linear from ``u_k`` to ``u_{k+1}`` (as the FE's
trapezoidal load treats it),

    x_{k+1} = Φ_p x_k + Γ0_p u_k + Γ1_p u_{k+1},

Φ = e^{A dt}, Γ0, Γ1 from one matrix exponential of the augmented matrix
[[A dt, B dt, 0], [0, 0, I], [0, 0, 0]] (Van Loan). The mode of an interval (its index in
:attr:`ReducedModel.modes`) is fixed within it, as the FE march reads it at the interval's midpoint.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm

from gatetherm.solvers.rom import ReducedModel


@dataclass(frozen=True)
class Discrete:
    """The step maps of every mode (by index) for one step length."""

    dt: float
    """Step, s."""
    Phi: dict[int, np.ndarray]
    G0: dict[int, np.ndarray]
    """Weight of the input at the start of the step."""
    G1: dict[int, np.ndarray]
    """Weight of the input at the end of the step."""


def discretise(rom: ReducedModel, dt: float) -> Discrete:
    """Exact step maps (see the module docstring) of every mode."""
    r, m = rom.states, len(rom.inputs)
    Phi, G0, G1 = {}, {}, {}
    for p, mode in enumerate(rom.modes):
        Z = np.zeros((r + 2 * m, r + 2 * m))
        Z[:r, :r] = rom.A[mode] * dt
        Z[:r, r:r + m] = rom.B[mode] * dt
        Z[r:r + m, r + m:] = np.eye(m)
        E = expm(Z)
        Phi[p], ramp = E[:r, :r], E[:r, r + m:]
        G0[p], G1[p] = E[:r, r:r + m] - ramp, ramp
    return Discrete(float(dt), Phi, G0, G1)


def march_rom(disc: Discrete, u: np.ndarray, modes: np.ndarray, x0: np.ndarray | None = None) -> np.ndarray:
    """States (samples × states) for inputs ``u`` (samples × inputs, less their offsets) and the
    mode index of each interval (samples − 1); ``x0`` = 0: every unknown at T0."""
    u = np.asarray(u, float)
    modes = np.asarray(modes, int)
    r = disc.Phi[0].shape[0]
    X = np.empty((len(u), r))
    X[0] = 0.0 if x0 is None else x0
    drive = np.empty((len(u) - 1, r))
    for p in disc.Phi:
        on = modes == p
        drive[on] = u[:-1][on] @ disc.G0[p].T + u[1:][on] @ disc.G1[p].T
    PhiT = {p: disc.Phi[p].T.copy() for p in disc.Phi}
    for k, p in enumerate(modes):
        X[k + 1] = X[k] @ PhiT[p] + drive[k]
    return X


def outputs(rom: ReducedModel, X: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Outputs (samples × outputs) of states ``X`` with inputs ``u``."""
    return X @ rom.C.T + np.asarray(u, float) @ rom.D.T + rom.y0


def simulate_rom(rom: ReducedModel, dt: float, u: np.ndarray, modes: np.ndarray) -> np.ndarray:
    """Outputs (samples × outputs) from the zero state; discretises on every call."""
    return outputs(rom, march_rom(discretise(rom, dt), u, modes), u)
