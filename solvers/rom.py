"""Reduced-order heat model: the frame as a switched linear system, reduced by balanced truncation.

In deviations from the reference temperature T0, ``x = U − T0`` (every unknown: solid nodes,
tank oil, hose) and ``u = (T_supply − T0, T_amb − T0)``, the heat model of each pump state p is
the linear descriptor system

    M ẋ = −K_p x + B_p u,    y = C x

with the outputs y rises from T0 (K) at the sensors, and δ, δ_E in µm (δ is a fixed linear
functional of the temperature). :func:`linear_heat_model` is the ONE place that reads these
operators off an assembled frame model; everything else works on :class:`LinearHeatModel`.

:func:`reduce` builds one basis for both modes, so that the reduced state is continuous across
pump switches: per mode, balanced truncation (pyMOR ``BTReductor``) of the system whose inputs
are augmented by the other mode's dominant reachable states (what a switch hands over; the
initial-condition augmentation of Heinkenschloss, Reis and Antoulas 2011), the static responses
``K_p⁻¹ B_p`` of both modes (so that the static gain is exact), then Galerkin projection onto the
M-orthonormal union. With ``Vᵀ M V = I`` the reduced ``A_p = −Vᵀ K_p V`` has a negative definite
symmetric part in both modes (the pump term ``G(x_o² − x_o x_i + x_i²)`` is positive), so
``|x|²`` is a common Lyapunov function: the reduced model is stable under any switching.
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from gatetherm import InputError
from gatetherm.solvers import krylov
from gatetherm.solvers.gramians import ShiftedSolves, gramian_factor

log = logging.getLogger(__name__)

INPUTS = ("oil_degC", "ambient_degC")
"""Input names of a reduced model: supply oil and room temperature, as deviations from T0."""
KEY_OUTPUTS = ("delta_um", "delta_E_um", "theta_A_K", "theta_B_K", "theta_C_K", "T_tank_wall_K", "T_tank_oil_K")
"""The outputs balanced truncation weighs; the others (further sensors) are carried along."""
KRYLOV_ABOVE = 100_000
"""Unknowns above which :func:`reduce` builds its basis by :func:`gatetherm.solvers.krylov.basis`
(a cost linear in the unknowns) instead of balanced truncation of the full model."""
UM_PER_K = 10.0
"""Output weight of a temperature against a displacement in the balancing: 0.1 K ~ 1 µm (the
sensors' resolutions)."""


@dataclass(frozen=True)
class LinearHeatModel:
    """``M ẋ = −K_p x + B_p u``, ``y = C x``, for the pump on and off."""

    M: sp.csr_matrix
    """Capacity matrix, J/K."""
    K_on: sp.csr_matrix
    """Conductance matrix with the pump on, W/K."""
    K_off: sp.csr_matrix
    """Conductance matrix with the pump off, W/K."""
    B_on: np.ndarray
    """Input matrix with the pump on (n × inputs), W/K."""
    B_off: np.ndarray
    """Input matrix with the pump off, W/K."""
    C: np.ndarray
    """Output matrix (outputs × n): K per K, or µm per K for displacements."""
    input_names: tuple[str, ...]
    output_names: tuple[str, ...]
    T0: float
    """Reference temperature, °C: x = 0 is the frame, oil and hose at T0."""

    def K(self, pump: bool) -> sp.csr_matrix:
        return self.K_on if pump else self.K_off

    def B(self, pump: bool) -> np.ndarray:
        return self.B_on if pump else self.B_off


def linear_heat_model(model) -> LinearHeatModel:
    """The seam: read the switched linear system off an assembled model of the paper's frame
    (:func:`gatetherm.solvers.frame.build_model`): one pumped fluid, inputs oil and room."""
    from gatetherm.solvers.frame import AMBIENT, SUPPLY

    h, prob = model.heat, model.problem
    if any(load.kind == "source" for load in h.loads) or h.fixed or len(h.pumped) != 1:
        raise InputError("model heat sources", "a reduced model has the oil and the room as its only inputs",
                         "reduce the model without [model] source / piezo_heat")
    n, ns = h.n, h.n_solid
    B = {}
    for pump in (True, False):
        zero = h.f({SUPPLY: 0.0, AMBIENT: 0.0}, (pump,))  # f is affine in the inputs
        B[pump] = np.column_stack([h.f({SUPPLY: 1.0, AMBIENT: 0.0}, (pump,)) - zero,
                                   h.f({SUPPLY: 0.0, AMBIENT: 1.0}, (pump,)) - zero])
    r = model.readout
    L, W = r.L.toarray(), np.hstack([r.W, np.zeros((len(r.W), n - ns))])
    row = {k: (L[i] if i < r.n_L else W[i - r.n_L]) for i, k in enumerate(r.keys)}
    s = prob.signals
    rows = {"delta_um": row[("relative", "delta")] * 1e6, "delta_E_um": row[("relative", "delta_E")] * 1e6,
            "theta_A_K": row[("T", s.theta_A)], "theta_B_K": row[("T", s.theta_B)],
            "theta_C_K": np.mean([row[("T", c)] for c in s.theta_C], axis=0),
            "T_tank_wall_K": row[("mean", "tank_wall")], "T_tank_oil_K": row[("fluid", "tank_oil")]}
    rows.update({f"T_{p.name}_K": row[("T", p.name)] for p in prob.probes if p.name not in (s.theta_A, s.theta_B)})
    if ("fluid", "hose") in row:
        rows["T_hose_K"] = row[("fluid", "hose")]
    rows["T_base_K"] = row[("mean", "base")]
    return LinearHeatModel(h.M.tocsr(), h.K((True,)).tocsr(), h.K((False,)).tocsr(), B[True], B[False],
                           np.array(list(rows.values())), INPUTS, tuple(rows), float(prob.T0))


@dataclass(frozen=True)
class ReducedModel:
    """``ẋ = A_p x + B_p u``, ``y = C x`` (E = identity); x = 0 is the frame at T0."""

    A_on: np.ndarray
    B_on: np.ndarray
    A_off: np.ndarray
    B_off: np.ndarray
    C: np.ndarray
    T0: float
    """Reference temperature, °C."""
    inputs: tuple[str, ...] = INPUTS
    outputs: tuple[str, ...] = KEY_OUTPUTS

    @property
    def states(self) -> int:
        return self.A_on.shape[0]

    def A(self, pump: bool) -> np.ndarray:
        return self.A_on if pump else self.A_off

    def B(self, pump: bool) -> np.ndarray:
        return self.B_on if pump else self.B_off

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
    """Per mode: largest |static gain of δ, reduced − full|, µm/K."""
    seconds: dict[str, float]


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


def reduce(lhm: LinearHeatModel, states: int = 30, handover: int = 12, horizon_s: float = 3600.0,
           adi_tol: float = 1e-10) -> Reduction:
    """Reduce ``lhm`` to ``states`` states (see the module docstring); ``handover`` dominant
    reachable states of each mode are added to the other mode's inputs, scaled to the state a
    unit input reaches in ``horizon_s``. The Gramian factors come from :mod:`.gramians` (ADI to a
    relative residual ``adi_tol``); pyMOR's ``BTReductor`` balances them."""
    from pymor.core.logger import set_log_levels
    from pymor.models.iosys import LTIModel
    from pymor.reductors.bt import BTReductor

    set_log_levels({"pymor": "WARN"})
    key = [lhm.output_names.index(k) for k in KEY_OUTPUTS]
    Cw = _weights(KEY_OUTPUTS)[:, None] * lhm.C[key]
    modes = {"on": True, "off": False}
    if lhm.M.shape[0] > KRYLOV_ABOVE:  # a large model: rational Krylov, then balanced truncation of its projection
        V, info = krylov.basis(lhm.M, {m: (lhm.K(p), lhm.B(p)) for m, p in modes.items()}, Cw, states, 3, handover,
                               horizon_s)
        rom, d = project(lhm, V), lhm.output_names.index("delta_um")
        dc = {m: float(np.max(np.abs(lhm.C[d] @ info["static"][m] - rom.C[d] @ np.linalg.solve(-rom.A(p), rom.B(p)[
            :, np.abs(lhm.B(p)).sum(axis=0) > 0])))) for m, p in modes.items()}
        return Reduction(rom, V, info["bound"], info["hankel"], dc, info["seconds"])
    B = {m: lhm.B(p)[:, np.abs(lhm.B(p)).sum(axis=0) > 0] for m, p in modes.items()}  # no dead supply column
    secs, t0 = {}, time.perf_counter()
    # the slowest rate of either mode is close to the pump-off frame cooling uniformly to the room
    slowest = float(lhm.B_off[:, 1].sum() / lhm.M.sum())
    solves = {m: ShiftedSolves(lhm.K(p), lhm.M, slowest=slowest) for m, p in modes.items()}
    Zc = {m: gramian_factor(solves[m], B[m], tol=adi_tol) for m in modes}
    Zo = {m: gramian_factor(solves[m], Cw.T, observability=True, tol=adi_tol) for m in modes}
    reach = {}
    for m in modes:
        U, s, _ = np.linalg.svd(Zc[m], full_matrices=False)
        reach[m] = lhm.M @ (U[:, :handover] * (s[:handover] / np.sqrt(horizon_s)))
    secs["gramians"] = time.perf_counter() - t0
    V, bound, hankel = {}, {}, {}
    for m, p in modes.items():
        t0 = time.perf_counter()
        other = "off" if m == "on" else "on"
        Zh = gramian_factor(solves[m], reach[other], tol=adi_tol)
        solves[m] = None  # the factorisations are no longer needed
        aug = LTIModel.from_matrices(-lhm.K(p), np.column_stack([B[m], reach[other]]), Cw, E=lhm.M)
        space = aug.A.source
        aug = aug.with_(presets={"c_lr": space.from_numpy(np.column_stack([Zc[m], Zh])),
                                 "o_lr": space.from_numpy(Zo[m])})
        red = BTReductor(aug)
        hsv = red._hankel_svd()[1]
        r = min(states, len(hsv) - 1)
        red.reduce(r)
        V[m] = red.V.to_numpy()
        bound[m] = [float(b) for b in red.error_bounds()[:r]]
        hankel[m] = [float(x) for x in hsv[:20]]
        secs[f"balancing_{m}"] = time.perf_counter() - t0
        log.info("mode %s: Gramian ranks %d/%d, Hankel singular values %s", m, Zc[m].shape[1] + Zh.shape[1],
                 Zo[m].shape[1], np.array2string(hsv[:8], precision=3))
    t0 = time.perf_counter()
    static = {m: splu(lhm.K(p).tocsc()).solve(lhm.B(p)) for m, p in modes.items()}
    # static responses first, then the balanced directions of the two modes in turn
    r_max = max(V["on"].shape[1], V["off"].shape[1])
    order = [("static", None)] * 4 + [(m, j) for j in range(r_max) for m in modes if j < V[m].shape[1]]
    cols = [*static["on"].T, *static["off"].T] + [V[m][:, j] for m, j in order[4:]]
    Vb, used = _orthonormal_union(lhm.M, np.column_stack(cols), states)
    rom = project(lhm, Vb)
    secs["projection"] = time.perf_counter() - t0
    # each mode's BT bound at the number of its balanced directions the union took
    taken = {m: sum(order[j][0] == m for j in used) for m in modes}
    err_bound = {m: bound[m][taken[m] - 1] if taken[m] else float("inf") for m in modes}
    d = lhm.output_names.index("delta_um")
    dc = {m: float(np.max(np.abs(lhm.C[d] @ static[m] - rom.C[d] @ np.linalg.solve(-rom.A(p), rom.B(p)))))
          for m, p in modes.items()}
    log.info("reduced %d -> %d states in %.1f s (BT bounds %s, static δ gain error %s µm/K)", lhm.M.shape[0],
             rom.states, sum(secs.values()), err_bound, dc)
    return Reduction(rom, Vb, err_bound, hankel, dc, secs)


def project(lhm: LinearHeatModel, V: np.ndarray) -> ReducedModel:
    """Galerkin projection onto an M-orthonormal basis ``V`` (so E_r = Vᵀ M V = I)."""
    A = {p: -(V.T @ (lhm.K(p) @ V)) for p in (True, False)}
    B = {p: V.T @ lhm.B(p) for p in (True, False)}
    return ReducedModel(A[True], B[True], A[False], B[False], lhm.C @ V, lhm.T0, lhm.input_names, lhm.output_names)
