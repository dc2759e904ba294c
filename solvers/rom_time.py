"""Time stepping of a reduced model: exact per pump mode for inputs linear between samples.

For a step ``dt`` and each mode p, with ``u`` linear from ``u_k`` to ``u_{k+1}`` (the supply
oil and the room, as the FE's trapezoidal load treats them),

    x_{k+1} = Φ_p x_k + Γ0_p u_k + Γ1_p u_{k+1},

Φ = e^{A dt}, Γ0, Γ1 from one matrix exponential of the augmented matrix
[[A dt, B dt, 0], [0, 0, I], [0, 0, 0]] (Van Loan). The pump state of an interval is its
mode; it is fixed within the interval, as the FE march reads it at the interval's midpoint.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm

from gatetherm.solvers.rom import ReducedModel


@dataclass(frozen=True)
class Discrete:
    """The step maps of both modes for one step length."""

    dt: float
    """Step, s."""
    Phi: dict[bool, np.ndarray]
    G0: dict[bool, np.ndarray]
    """Weight of the input at the start of the step."""
    G1: dict[bool, np.ndarray]
    """Weight of the input at the end of the step."""


def discretise(rom: ReducedModel, dt: float) -> Discrete:
    """Exact step maps (see the module docstring) of both modes."""
    r, m = rom.states, rom.B_on.shape[1]
    Phi, G0, G1 = {}, {}, {}
    for p in (True, False):
        Z = np.zeros((r + 2 * m, r + 2 * m))
        Z[:r, :r] = rom.A(p) * dt
        Z[:r, r:r + m] = rom.B(p) * dt
        Z[r:r + m, r + m:] = np.eye(m)
        E = expm(Z)
        Phi[p], ramp = E[:r, :r], E[:r, r + m:]
        G0[p], G1[p] = E[:r, r:r + m] - ramp, ramp
    return Discrete(float(dt), Phi, G0, G1)


def march_rom(disc: Discrete, u: np.ndarray, modes: np.ndarray, x0: np.ndarray | None = None) -> np.ndarray:
    """States (samples × states) for inputs ``u`` (samples × inputs, deviations from T0) and
    the pump state ``modes`` of each interval (samples − 1); ``x0`` = 0: the frame at T0."""
    u = np.asarray(u, float)
    r = disc.Phi[True].shape[0]
    X = np.empty((len(u), r))
    X[0] = 0.0 if x0 is None else x0
    drive = np.empty((len(u) - 1, r))
    for p in (True, False):
        on = np.asarray(modes, bool) == p
        drive[on] = u[:-1][on] @ disc.G0[p].T + u[1:][on] @ disc.G1[p].T
    PhiT = {p: disc.Phi[p].T.copy() for p in (True, False)}
    for k, p in enumerate(np.asarray(modes, bool)):
        X[k + 1] = X[k] @ PhiT[p] + drive[k]
    return X


def simulate_rom(rom: ReducedModel, dt: float, u: np.ndarray, modes: np.ndarray) -> np.ndarray:
    """Outputs (samples × outputs) from the zero state; discretises on every call."""
    return march_rom(discretise(rom, dt), u, modes) @ rom.C.T
