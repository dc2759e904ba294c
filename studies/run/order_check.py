"""The element-order check of ``gatetherm run``: is P1 accurate enough for this case?

A P1 case on a mesh small enough (:data:`MAX_NODES`) is solved once more with P2 elements
on the same mesh: a steady case or one without a heat solve entirely; a transient case at
its final state, the P2 mechanics driven by the P1 temperature (exactly representable at
P2: the check measures the elastic discretisation, the usual culprit in bending). An output
whose P2 value differs from the P1 one by more than :data:`TOLERANCE` of its scale is named
in one warning with the fix, as ``diagnose``'s discretisation check does. The scale of an
output is that of its kind (unit): the largest of the kind's outputs over the run (P1, every
sample) and at P2, and never less than the kind's :data:`RESOLUTION`; an output whose P1 and
P2 values both lie within the resolution is not judged (a stress of a free body, zero up to
round-off at P2, is no percentage of zero).
"""
from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

log = logging.getLogger(__name__)

TOLERANCE = 0.02
"""Largest admitted |P2 − P1| of an output, relative to its kind's scale: the largest output of
its unit over the run and at P2 (the largest rise above the stress-free temperature for
temperatures), at least the unit's :data:`RESOLUTION`."""
RESOLUTION = {"_degC": 0.05, "_um": 0.1, "_MPa": 0.1}
"""The floor of each kind, by unit suffix: a thermocouple's 0.05 K and a displacement sensor's
0.1 µm (as the diagnosis' sensors), 0.1 MPa of stress (a strain gauge's 0.5 µm/m on steel).
An output whose P1 and P2 values both lie within it is not judged."""
MAX_NODES = {2: 30_000, 3: 8_000}
"""Largest mesh (nodes) on which the check solves P2 once more, by dimension."""
UNITS = ("_degC", "_um", "_MPa")


def p2_outputs(case, run) -> dict[str, float]:
    """The case's outputs at P2 on the same mesh, at the final time of the P1 ``run``
    (:class:`~gatetherm.studies.run.scenario.ScenarioRun`), in the data-format columns;
    a transient case: the displacement and stress columns only."""
    from gatetherm.solvers.model import build
    from gatetherm.studies.run.scenario import Schedule, run_scenario
    from gatetherm.studies.run.simulate import output_columns

    p2 = case.with_order(2)
    model1 = run.model
    if model1.heat is None or case.time is None:
        sched = run.schedule
        last = Schedule(sched.drive, sched.times[-1:], sched.label)
        return {k: float(v[-1]) for k, v in run_scenario(p2, last).result.columns.items()}
    t, U1 = run.result.states[-1]
    model2 = build(p2.problem, case.mesh)
    n1, n2 = model1.heat.n_solid, model2.heat.n_solid
    U2 = np.empty(model2.heat.n)
    b1, b2 = model1.heat.basis, model2.heat.basis
    U2[b2.nodal_dofs[0]] = U1[b1.nodal_dofs[0]]
    mesh = model2.mesh  # a linear field on every edge: its midpoint value (2-D: the edges are the facets)
    edges, mid = (mesh.facets, b2.facet_dofs[0]) if mesh.dim() == 2 else (mesh.edges, b2.edge_dofs[0])
    U2[mid] = U1[b1.nodal_dofs[0][edges]].mean(axis=0)
    U2[n2:] = U1[n1:]
    y = model2.read(U2, run.result.envs.get(t))
    cols = output_columns(p2.problem, model2.readout.keys, y[None, :])
    return {k: float(v[-1]) for k, v in cols.items() if k.endswith(("_um", "_MPa"))}


@dataclass(frozen=True)
class OrderCheck:
    """The final outputs of a P1 run and at P2 on the same mesh (data-format columns)."""

    p1: dict[str, float]
    p2: dict[str, float]
    relative: dict[str, float]
    """(P2 − P1) relative to the output's scale (:data:`TOLERANCE`)."""
    scale: dict[str, float]
    """The scale of each output (its unit's), at least the unit's :data:`RESOLUTION`."""
    below: tuple[str, ...] = ()
    """The outputs whose P1 and P2 values both lie within their :data:`RESOLUTION`: not judged."""

    @property
    def worst(self) -> str | None:
        """The judged output that changes most relative to its scale (None: none judged)."""
        judged = [k for k in self.relative if k not in self.below]
        return max(judged, key=lambda k: abs(self.relative[k]), default=None)

    def summary(self) -> dict:
        """What ``summary.json`` records as ``order_check``."""
        return {"tolerance": TOLERANCE, "resolution": RESOLUTION, "worst": self.worst,
                "outputs": {k: {"p1": self.p1[k], "p2": self.p2[k], "relative": round(v, 6),
                                "scale": self.scale[k], "below_resolution": k in self.below}
                            for k, v in self.relative.items()}}


def _unit(key: str) -> str:
    return next(u for u in UNITS if key.endswith(u))


def scales(p1_series: dict[str, np.ndarray], p2: dict[str, float], T_ref: float) -> dict[str, float]:
    """The scale of each unit: the largest |output − base| of the unit over the P1 series (every
    sample) and the P2 values (base: ``T_ref`` for temperatures, else 0), at least its
    :data:`RESOLUTION`."""
    out = {}
    for u in UNITS:
        base = T_ref if u == "_degC" else 0.0
        vals = [np.abs(np.asarray(v, float) - base).max(initial=0.0) for k, v in p1_series.items() if k.endswith(u)]
        vals += [abs(v - base) for k, v in p2.items() if k.endswith(u)]
        out[u] = float(max(max(vals, default=0.0), RESOLUTION[u]))
    return out


def order_check(case, run) -> OrderCheck | None:
    """The element-order check of a P1 ``run`` of ``case`` (None: not checked: a P2 case or a
    mesh above :data:`MAX_NODES`); logs one warning naming the output that differs most when
    it exceeds :data:`TOLERANCE`."""
    if case.problem.order != 1 or len(case.mesh.points) > MAX_NODES[case.mesh.dim]:
        return None
    p2 = p2_outputs(case, run)
    cols = run.result.columns
    keys = [k for k in p2 if k.endswith(UNITS) and k in cols]
    p1 = {k: float(cols[k][-1]) for k in keys}
    base = {u: case.problem.T_ref if u == "_degC" else 0.0 for u in UNITS}
    size = scales({k: cols[k] for k in keys}, {k: p2[k] for k in keys}, case.problem.T_ref)
    scale = {k: size[_unit(k)] for k in keys}
    rel = {k: float((p2[k] - v) / scale[k]) for k, v in p1.items()}
    below = tuple(k for k in keys
                  if max(abs(p1[k] - base[_unit(k)]), abs(p2[k] - base[_unit(k)])) <= RESOLUTION[_unit(k)])
    check = OrderCheck(p1, {k: p2[k] for k in p1}, rel, scale, below)
    worst = check.worst
    if worst is not None and abs(rel[worst]) > TOLERANCE:
        log.warning("%s: %s changes from %.4g to %.4g from P1 to P2 on this mesh (%+.1f %% of %.4g, the scale of "
                    "its unit's outputs over the run, check tolerance %g %%): set order = 2 in [case] or refine the "
                    "mesh", case.path, worst, p1[worst], p2[worst], 100 * rel[worst], scale[worst], 100 * TOLERANCE)
    return check
