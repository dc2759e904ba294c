"""The seam of the reduced-order heat model to the finite elements: :func:`linear_heat_model` reads
the switched linear system ``M ẋ = −K_p x + B_p u``, ``y = C x + D u + y0`` of every pump mode p
(:class:`LinearHeatModel`, its :class:`Input` values) off an assembled model; it is the ONE place
that reads these operators, everything else works on :class:`LinearHeatModel`. The variables,
units and the reduction are :mod:`gatetherm.solvers.rom`.
"""
from __future__ import annotations

from dataclasses import dataclass
from itertools import product

import numpy as np
import scipy.sparse as sp

from gatetherm import InputError
from gatetherm.solvers.expr import Value
from gatetherm.solvers.fem import complement

TEMPERATURE_KINDS = ("film", "faces", "hose", "supply", "fixed")
"""Load kinds whose value is a temperature: their inputs are deviations from T0."""


@dataclass(frozen=True)
class Input:
    """One input of a reduced model: a value the problem reads."""

    text: str
    """The expression it is (a schedule column, an expression of ``t`` and columns, or a number)."""
    offset: float
    """Subtracted from the value: the input is ``value − offset`` (T0 for a temperature, else 0)."""


@dataclass(frozen=True)
class LinearHeatModel:
    """``M ẋ = −K_p x + B_p u``, ``y = C x + D u + y0`` for every pump mode p."""

    M: sp.csr_matrix
    """Capacity matrix, J/K."""
    K: dict[str, sp.csr_matrix]
    """Conductance matrix of every mode, W/K."""
    B: dict[str, np.ndarray]
    """Input matrix of every mode (n × inputs), W per input unit."""
    C: np.ndarray
    """Output matrix (outputs × n), output unit per K."""
    D: np.ndarray
    """Feed-through (outputs × inputs)."""
    y0: np.ndarray
    """Outputs of the state x = 0 with u = 0 (every unknown at T0)."""
    inputs: tuple[Input, ...]
    outputs: tuple[str, ...]
    key_outputs: tuple[str, ...]
    """The outputs balanced truncation weighs: relative displacements, the signals θ, fluids and
    the means of their walls (else every output)."""
    pumps: tuple[str, ...]
    """The pump expression of every fluid; a mode is their on/off states."""
    T0: float

    @property
    def modes(self) -> tuple[str, ...]:
        return tuple(self.K)


def mode_name(states) -> str:
    """``"on"``/``"off"`` per fluid, joined by ``_`` (``""`` without fluids)."""
    return "_".join("on" if s else "off" for s in states)


def _heat_inputs(h, T0: float):
    """The heat system's inputs and, per pump mode, its stiffness and input columns (over all
    unknowns): every source, flux and film ambient by its value, each fixed temperature."""
    n = h.n
    groups: dict = {}  # (value, temperature?) -> [vector over n]
    for p in h.pumped:
        groups.setdefault((p.supply, True), [])
    for load in h.loads:
        groups.setdefault((load.value, load.kind in TEMPERATURE_KINDS), []).append(load.vector)
    for m in h.moving:  # a moving source: its vector interpolated over positions (MovingLoad.interpolated)
        for text, vector in m.interpolated():
            groups.setdefault((Value.of(text, m.position.key), False), []).append(
                np.r_[vector, np.zeros(n - len(vector))])
    modes = {mode_name(s): s for s in product((True, False), repeat=len(h.pumped))}
    K = {m: h.K(s).tocsr() for m, s in modes.items()}
    inputs, cols = [], {m: [] for m in modes}
    for (value, temp), vectors in groups.items():
        if value.is_constant and not temp and value.constant == 0.0:
            continue  # a zero source or flux: drives nothing
        # a temperature (a film's ambient, a fixed value) stays an input even when constant, even at
        # T0: its column is the loss to it, which the Gramians, the room of an observer and the
        # body's uniform state all need; a constant input is a constant u in every series
        inputs.append(Input(value.text or repr(value.constant), T0 if temp else 0.0))
        base = np.zeros(n)
        for v in vectors:
            base += v
        for m, states in modes.items():
            col = base.copy()
            for p, on in zip(h.pumped, states):
                if p.supply == value:
                    col[p.inlet] += p.coefficients(on)[1]
            cols[m].append(col)
    for dofs, value in h.fixed:  # a fixed temperature drives the free unknowns through K
        inputs.append(Input(value.text or repr(value.constant), T0))
        held = np.zeros(n)
        held[dofs] = 1.0
        for m in modes:
            cols[m].append(-(K[m] @ held))
    return modes, K, inputs, cols


def _outputs(model, columns, terms):
    """The read-out rows (data-format scale) over all unknowns, their names, their parts from
    the mechanical load terms, and which act on the rise above ``T_ref`` (W rows)."""
    h, prob, r = model.heat, model.problem, model.readout
    L, W = r.L.toarray(), np.hstack([r.W, np.zeros((len(r.W), h.n - h.n_solid))])
    rows, names, mech, is_W = [], [], [], []
    for i, key in enumerate(r.keys):
        if key[0] == "sigma" and key[2] == "von_mises":
            continue
        name, scale = columns(prob, key)
        rows.append((L[i] if i < r.n_L else W[i - r.n_L]) * scale)
        mech.append(r.R[i - r.n_L] * scale if i >= r.n_L and terms else np.zeros(len(terms)))
        names.append(name)
        is_W.append(i >= r.n_L)
    if prob.signals.theta_C:
        rows.append(np.mean([rows[names.index(columns(prob, ("T", c))[0])] for c in prob.signals.theta_C], axis=0))
        mech.append(np.zeros(len(terms)))
        names.append("theta_C_degC")
        is_W.append(False)
    return np.array(rows), names, np.array(mech).reshape(len(names), len(terms)), np.array(is_W)


def _key_outputs(model, columns, names) -> tuple:
    """The outputs a reduction is judged on: relative displacements, θ, tank walls and fluids."""
    prob, r = model.problem, model.readout
    walls = {f"T_{m}_degC" for m, b in prob.means if b in {f.boundary for f in prob.fluids}}
    key = [nm for nm in names if nm.endswith("_um") and any(k[0] == "relative" and columns(prob, k)[0] == nm
                                                            for k in r.keys)]
    key += [c for c in ("theta_A_degC", "theta_B_degC", "theta_C_degC") if c in names]
    key += [nm for nm in names if nm in walls] + [f"T_{f.name}_degC" for f in prob.fluids if f"T_{f.name}_degC" in names]
    return tuple(key) or tuple(names)


def linear_heat_model(model, columns) -> LinearHeatModel:
    """The seam: read the switched linear system off an assembled model (heat solve with a read-out).
    ``columns(problem, key) -> (name, scale)`` names each read-out key as a data-format column."""
    h, prob, r = model.heat, model.problem, model.readout
    if h.varying:
        at = ", ".join(f"{v.boundary} {v.h_ref:.3g}" for v in h.varying)
        raise InputError(f"film of '{h.varying[0].boundary}'", "follows the temperature (a correlation or radiation): "
                         "the reduced model is linear and would hold it at its reference",
                         f"give each such film as a number to reduce the case (at the law's reference: {at} "
                         "W/(m² K); the law at a run's mean wall temperature and speed is closer: docs/case-file.md)")
    T0, n = float(prob.T0), h.n
    fixed = h.fixed_dofs
    free = complement(n, fixed)
    modes, K, inputs, cols = _heat_inputs(h, T0)
    n_heat = len(inputs)
    terms = r.terms.values if r.terms is not None and r.R is not None else ()
    varying = [j for j, v in enumerate(terms) if not v.is_constant]
    for j in varying:  # a mechanical load that follows the schedule: an input read out directly (D)
        inputs.append(Input(terms[j].text, 0.0))
        for m in modes:
            cols[m].append(np.zeros(n))
    B = {m: np.column_stack(c)[free] if c else np.zeros((len(free), 0)) for m, c in cols.items()}
    R, names, mech, is_W = _outputs(model, columns, terms)
    constant = np.array([v.constant if v.is_constant else 0.0 for v in terms])
    ref = np.where(is_W, R.sum(axis=1) * prob.T_ref, 0.0)  # W acts on the rise above T_ref
    D = np.zeros((len(names), len(inputs)))
    for j, (dofs, _) in enumerate(h.fixed):
        D[:, n_heat - len(h.fixed) + j] = R[:, dofs].sum(axis=1)
    for k, j in enumerate(varying):
        D[:, n_heat + k] = mech[:, j]
    M = h.M.tocsr()
    if fixed.size:
        M, K = M[free][:, free].tocsr(), {m: k[free][:, free].tocsr() for m, k in K.items()}
    y0 = R.sum(axis=1) * T0 - ref + (mech @ constant if len(terms) else 0.0)  # constant loads: gravity's sag
    return LinearHeatModel(M, K, B, R[:, free], D, y0, tuple(inputs), tuple(names), _key_outputs(model, columns, names),
                           tuple(p.pump.text or repr(p.pump.constant) for p in h.pumped), T0)
