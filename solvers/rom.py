"""Reduced-order heat model of any problem: a switched linear system, reduced by balanced truncation.

In deviations from the initial temperature T0, ``x = U_free − T0`` (every unknown not held by a
fixed temperature: solid nodes, fluids, hoses), and inputs ``u_j = value_j − offset_j`` (every
value the problem's heat transfer reads: a film's or the faces' ambient, a fluid's supply, a
hose's ambient, a fixed temperature (offset T0), a flux or a source density (offset 0); a
temperature is an input even when constant, as a constant ``u``: a film to a constant room is a
loss like any other), the heat model of each pump mode p (every fluid's pump on or off) is the descriptor system

    M ẋ = −K_p x + B_p u,    y = C x + D u + y0

with y every output in the data format's units (temperatures °C, displacements µm, stresses
MPa; von Mises, not linear, is left out). The displacements are fixed linear functionals of the
temperature (the adjoint read-out of :mod:`gatetherm.solvers.model`). :func:`linear_heat_model`
(:mod:`gatetherm.solvers.rom_seam`) is the ONE place that reads these operators off an assembled
model; everything else works on :class:`LinearHeatModel`.

:func:`reduce` builds one basis for all modes, so that the reduced state is continuous across
pump switches: per mode, balanced truncation (pyMOR ``BTReductor``) of the system whose inputs
are augmented by the other modes' dominant reachable states (what a switch hands over; the
initial-condition augmentation of Heinkenschloss, Reis and Antoulas 2011), the static responses
``K_p⁻¹ B_p`` of every mode (so that the static gains are exact), then Galerkin projection onto
the M-orthonormal union. With ``Vᵀ M V = I`` the reduced ``A_p = −Vᵀ K_p V`` has a negative
definite symmetric part in every mode, so ``|x|²`` is a common Lyapunov function: the reduced
model is stable under any switching.
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.sparse.linalg import splu

from gatetherm import InputError
from gatetherm.solvers import krylov
from gatetherm.solvers.gramians import ShiftedSolves, gramian_factor
from gatetherm.solvers.rom_seam import (  # noqa: F401 (re-exported)
    TEMPERATURE_KINDS, Input, LinearHeatModel, linear_heat_model, mode_name)

log = logging.getLogger(__name__)

KRYLOV_ABOVE = 100_000
"""Unknowns above which :func:`reduce` builds its basis by :func:`gatetherm.solvers.krylov.basis`
(a cost linear in the unknowns) instead of balanced truncation of the full model."""
UM_PER_K = 10.0
"""Output weight of a temperature against a displacement in the balancing: 0.1 K ~ 1 µm (the
sensors' resolutions)."""


@dataclass(frozen=True)
class ReducedModel:
    """``ẋ = A_p x + B_p u``, ``y = C x + D u + y0`` (E = identity); x = 0 is every unknown at T0."""

    A: dict[str, np.ndarray]
    B: dict[str, np.ndarray]
    C: np.ndarray
    D: np.ndarray
    y0: np.ndarray
    inputs: tuple[Input, ...]
    outputs: tuple[str, ...]
    pumps: tuple[str, ...] = ()
    T0: float = 20.0
    defaults: dict = field(default_factory=dict)
    """Input columns a series may leave out, with the value they keep (the frame's room)."""
    room: int | None = None
    """Index of the input that is the room temperature (the films' ambient), if one is."""
    notes: tuple[str, ...] = ()
    """What a user of the model should know (films held at constants, and what that costs)."""

    @property
    def states(self) -> int:
        return self.C.shape[1]

    @property
    def modes(self) -> tuple[str, ...]:
        return tuple(self.A)

    def output(self, name: str) -> int:
        """Row of C of an output."""
        if name not in self.outputs:
            raise InputError("reduced model output", f"no {name!r}", f"choose from {', '.join(self.outputs)}")
        return self.outputs.index(name)


@dataclass(frozen=True)
class Reduction:
    """A reduced model and what its making measured."""

    rom: ReducedModel
    basis: np.ndarray = field(repr=False)
    """M-orthonormal basis V (n × states): the full state is ≈ V x."""
    error_bound: dict[str, float]
    """Per mode: balanced truncation's H∞ bound 2 Σ σ_i of the discarded Hankel singular values of
    the augmented per-mode system, in the weighted output norm (µm, or 0.1 K)."""
    hankel: dict[str, list[float]]
    """Per mode: the leading Hankel singular values."""
    static_gain_error: dict[str, float]
    """Per mode: largest |static gain of the first key output, reduced − full| per input unit."""
    seconds: dict[str, float]
    held: dict[str, float] = field(default_factory=dict)
    """Films that follow the temperature, held at one coefficient each, W/(m² K), by boundary
    (what that costs: ``rom.notes``)."""


def _weights(names) -> np.ndarray:
    return np.array([1.0 if n.endswith("_um") else UM_PER_K for n in names])


def _orthonormal_union(M, columns, count: int, tol: float = 1e-8) -> tuple[np.ndarray, list[int]]:
    """The first ``count`` M-orthonormal directions of the columns taken in order (twice-run
    Gram–Schmidt; a column adding less than ``tol`` of its own M-norm is skipped), and the
    indices of the columns used."""
    basis, used = [], []
    for j, x in enumerate(columns.T):
        norm = np.sqrt(x @ (M @ x))
        if not norm > 0:
            continue
        v = x / norm
        for _ in range(2):
            if basis:
                Q = np.column_stack(basis)
                v = v - Q @ (Q.T @ (M @ v))
        rest = np.sqrt(v @ (M @ v))
        if rest > tol:
            basis.append(v / rest)
            used.append(j)
        if len(basis) == count:
            break
    return np.column_stack(basis), used


def _slowest(lhm: LinearHeatModel) -> float:
    """The slowest rate of every mode is close to the body cooling uniformly to its temperature
    inputs with every pump off (the last mode); a body with none never settles. The loss is read
    off the conductance matrix (``1ᵀ K 1``: what a uniform 1 K rise loses to films, fixed
    temperatures and fluids' supplies), so it counts a loss whether its temperature is an input or not."""
    K = lhm.K[lhm.modes[-1]]
    loss = float(K @ np.ones(K.shape[0]) @ np.ones(K.shape[0]))
    if not loss > 1e-10 * float(np.abs(K.diagonal()).sum()):  # conduction alone sums to round-off
        loss = 0.0
    if not loss > 0:
        raise InputError("reduced model", "the case loses no heat to an ambient or a fixed temperature: it never "
                         "settles", "give a film, a fixed temperature or a fluid with a supply")
    return loss / float(lhm.M.sum())


def reduce(lhm: LinearHeatModel, states: int = 30, handover: int = 12, horizon_s: float = 3600.0,
           adi_tol: float = 1e-10) -> Reduction:
    """Reduce ``lhm`` to ``states`` states (see the module docstring); ``handover`` dominant
    reachable states of each mode are added to the other modes' inputs, scaled to the state a
    unit input reaches in ``horizon_s``. The Gramian factors come from :mod:`.gramians` (ADI to a
    relative residual ``adi_tol``); pyMOR's ``BTReductor`` balances them."""
    from pymor.core.logger import set_log_levels
    from pymor.models.iosys import LTIModel
    from pymor.reductors.bt import BTReductor

    set_log_levels({"pymor": "WARN"})
    key = [lhm.outputs.index(k) for k in lhm.key_outputs]
    Cw = _weights(lhm.key_outputs)[:, None] * lhm.C[key]
    modes = lhm.modes
    B = {m: lhm.B[m][:, np.abs(lhm.B[m]).sum(axis=0) > 0] for m in modes}  # no dead supply column
    if lhm.M.shape[0] > KRYLOV_ABOVE:  # large: rational Krylov, then balanced truncation of its projection
        V, info = krylov.basis(lhm.M, {m: (lhm.K[m], lhm.B[m]) for m in modes}, Cw, states, 3, handover, horizon_s)
        rom = project(lhm, V)
        dc = {m: float(np.max(np.abs(lhm.C[key[0]] @ info["static"][m] - rom.C[key[0]] @ np.linalg.solve(
            -rom.A[m], V.T @ B[m])))) if B[m].shape[1] else 0.0 for m in modes}
        return Reduction(rom, V, info["bound"], info["hankel"], dc, info["seconds"])
    secs, t0 = {}, time.perf_counter()
    slowest = _slowest(lhm)
    solves = {m: ShiftedSolves(lhm.K[m], lhm.M, slowest=slowest) for m in modes}
    Zc = {m: gramian_factor(solves[m], B[m], tol=adi_tol) for m in modes}
    Zo = {m: gramian_factor(solves[m], Cw.T, observability=True, tol=adi_tol) for m in modes}
    reach = {}
    for m in modes:
        U, s, _ = np.linalg.svd(Zc[m], full_matrices=False)
        reach[m] = lhm.M @ (U[:, :handover] * (s[:handover] / np.sqrt(horizon_s)))
    secs["gramians"] = time.perf_counter() - t0
    V, bound, hankel = {}, {}, {}
    for m in modes:
        t0 = time.perf_counter()
        others = [reach[o] for o in modes if o != m]
        Zh = [gramian_factor(solves[m], np.column_stack(others), tol=adi_tol)] if others else []
        solves[m] = None  # the factorisations are no longer needed
        aug = LTIModel.from_matrices(-lhm.K[m], np.column_stack([B[m], *others]), Cw, E=lhm.M)
        space = aug.A.source
        aug = aug.with_(presets={"c_lr": space.from_numpy(np.column_stack([Zc[m], *Zh])),
                                 "o_lr": space.from_numpy(Zo[m])})
        red = BTReductor(aug)
        hsv = red._hankel_svd()[1]
        r = min(states, len(hsv) - 1)
        red.reduce(r)
        V[m] = red.V.to_numpy()
        bound[m] = [2.0 * float(np.sum(hsv))] + [float(b) for b in red.error_bounds()[:r]]  # [0]: no direction
        hankel[m] = [float(x) for x in hsv[:20]]
        secs[f"balancing_{m or 'single'}"] = time.perf_counter() - t0
        log.info("mode %s: Gramian ranks %d/%d, Hankel singular values %s", m or "-",
                 Zc[m].shape[1] + sum(z.shape[1] for z in Zh), Zo[m].shape[1], np.array2string(hsv[:8], precision=3))
    t0 = time.perf_counter()
    static = {m: splu(lhm.K[m].tocsc()).solve(lhm.B[m]) for m in modes}
    # static responses first, then the balanced directions of the modes in turn
    r_max = max(V[m].shape[1] for m in modes)
    n_static = sum(static[m].shape[1] for m in modes)
    order = [("static", None)] * n_static + [(m, j) for j in range(r_max) for m in modes if j < V[m].shape[1]]
    cols = [c for m in modes for c in static[m].T] + [V[m][:, j] for m, j in order[n_static:]]
    Vb, used = _orthonormal_union(lhm.M, np.column_stack(cols), states)
    rom = project(lhm, Vb)
    secs["projection"] = time.perf_counter() - t0
    # each mode's BT bound at the number of its balanced directions the union took
    taken = {m: sum(order[j][0] == m for j in used) for m in modes}
    err_bound = {m: bound[m][taken[m]] for m in modes}
    for m in (m for m in modes if not taken[m]):
        log.warning("states: %d states hold only the inputs' static responses, no balanced direction%s: its error "
                    "bound is that of none (%.3g); give more states (e.g. 30)", states, f" of mode {m}" if m else "",
                    err_bound[m])
    d = key[0]
    dc = {m: float(np.max(np.abs(lhm.C[d] @ static[m] - rom.C[d] @ np.linalg.solve(-rom.A[m], rom.B[m]))))
          if lhm.B[m].shape[1] else 0.0 for m in modes}
    log.info("reduced %d -> %d states in %.1f s (BT bounds %s, static gain error of %s %s)", lhm.M.shape[0],
             rom.states, sum(secs.values()), err_bound, lhm.key_outputs[0], dc)
    return Reduction(rom, Vb, err_bound, hankel, dc, secs)


def project(lhm: LinearHeatModel, V: np.ndarray) -> ReducedModel:
    """Galerkin projection onto an M-orthonormal basis ``V`` (so E_r = Vᵀ M V = I)."""
    A = {m: -(V.T @ (lhm.K[m] @ V)) for m in lhm.modes}
    B = {m: V.T @ lhm.B[m] for m in lhm.modes}
    return ReducedModel(A, B, lhm.C @ V, lhm.D, lhm.y0, lhm.inputs, lhm.outputs, lhm.pumps, lhm.T0)
