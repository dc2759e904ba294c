"""Time stepping of a reduced model: exact per pump mode for inputs linear between samples.

For a step ``dt`` and each mode p, with ``u`` linear from ``u_k`` to ``u_{k+1}`` (as the FE's
trapezoidal load treats it),

    x_{k+1} = Φ_p x_k + Γ0_p u_k + Γ1_p u_{k+1},

Φ = e^{A dt}, Γ0, Γ1 from one matrix exponential of the augmented matrix
[[A dt, B dt, 0], [0, 0, I], [0, 0, 0]] (Van Loan). The mode of an interval (its index in
:attr:`ReducedModel.modes`) is fixed within it, as the FE march reads it at the interval's midpoint.

A long stretch of one mode is marched in Φ's eigenvectors, Φ = V Λ V⁻¹, where each state is a
first-order recursion z_{k+1} = λ z_k + (V⁻¹ drive)_k run by :func:`scipy.signal.lfilter`: the same
states to round-off (times the condition of V, at most :data:`MODAL_COND`), without a Python step
per sample. Short stretches, and a Φ whose eigenvectors are ill-conditioned, step as written.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.linalg import expm
from scipy.signal import lfilter

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
    modal: dict = field(default_factory=dict)
    """Mode index -> (λ, V, V⁻¹ Γ0, V⁻¹ Γ1, V⁻¹) of its Φ = V diag(λ) V⁻¹, where V's condition is at most :data:`MODAL_COND`."""


MODAL_COND = 1e6
"""Largest condition number of Φ's eigenvectors with which a stretch is marched in them."""
MODAL_MIN = 64
"""Fewest steps of one mode marched in Φ's eigenvectors (fewer: a step at a time)."""


def _eigen(Phi: np.ndarray, G0: np.ndarray, G1: np.ndarray):
    """(λ, V, V⁻¹ Γ0, V⁻¹ Γ1, V⁻¹) of ``Phi`` = V diag(λ) V⁻¹, or None where V is ill-conditioned
    (or Φ defective)."""
    lam, V = np.linalg.eig(Phi)
    if not np.all(np.isfinite(lam)) or np.linalg.cond(V) > MODAL_COND:
        return None
    if np.all(lam.imag == 0):
        lam, V = lam.real, V.real
    Vinv = np.linalg.inv(V)
    return lam, V, Vinv @ G0, Vinv @ G1, Vinv


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
    modal = {p: e for p in Phi if (e := _eigen(Phi[p], G0[p], G1[p])) is not None}
    return Discrete(float(dt), Phi, G0, G1, modal)


def march_rom(disc: Discrete, u: np.ndarray, modes: np.ndarray, x0: np.ndarray | None = None) -> np.ndarray:
    """States (samples × states) for inputs ``u`` (samples × inputs, less their offsets) and the
    mode index of each interval (samples − 1); ``x0`` = 0: every unknown at T0."""
    u = np.asarray(u, float)
    modes = np.asarray(modes, int)
    r = disc.Phi[0].shape[0]
    X = np.empty((len(u), r))
    X[0] = 0.0 if x0 is None else x0
    PhiT = {p: disc.Phi[p].T.copy() for p in disc.Phi}
    cuts = np.flatnonzero(np.diff(modes)) + 1
    for a, b in zip([0, *cuts], [*cuts, len(modes)]):  # stretches of one mode
        p = int(modes[a]) if b > a else 0
        if b - a >= MODAL_MIN and p in disc.modal:
            X[a + 1:b + 1] = _modal_march(disc.modal[p], X[a], u[a:b + 1])
            continue
        drive = u[a:b] @ disc.G0[p].T + u[a + 1:b + 1] @ disc.G1[p].T
        for k in range(a, b):
            X[k + 1] = X[k] @ PhiT[p] + drive[k - a]
    return X


def _modal_march(modal, x0: np.ndarray, u: np.ndarray) -> np.ndarray:
    """States 1 … n of x_{k+1} = Φ x_k + Γ0 u_k + Γ1 u_{k+1} from x0 (inputs u_0 … u_n), in Φ's
    eigenvectors ``modal`` = (λ, V, V⁻¹ Γ0, V⁻¹ Γ1, V⁻¹)."""
    lam, V, VG0, VG1, Vinv = modal
    z0, D = Vinv @ x0, u[:-1] @ VG0.T + u[1:] @ VG1.T
    Z = np.empty_like(D)
    for i, li in enumerate(lam):
        Z[:, i] = lfilter([1.0], [1.0, -li], D[:, i], zi=[li * z0[i]])[0]
    return (Z @ V.T).real


def outputs(rom: ReducedModel, X: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Outputs (samples × outputs) of states ``X`` with inputs ``u``."""
    return X @ rom.C.T + np.asarray(u, float) @ rom.D.T + rom.y0


def simulate_rom(rom: ReducedModel, dt: float, u: np.ndarray, modes: np.ndarray) -> np.ndarray:
    """Outputs (samples × outputs) from the zero state; discretises on every call."""
    return outputs(rom, march_rom(discretise(rom, dt), u, modes), u)
