"""The element-order check of ``gatetherm run``: is P1 accurate enough for this case?

A P1 case on a mesh small enough (:data:`MAX_NODES`) is solved once more with P2 elements
on the same mesh: a steady case or one without a heat solve entirely; a transient case at
its final state, the P2 mechanics driven by the P1 temperature (exactly representable at
P2: the check measures the elastic discretisation, the usual culprit in bending). An output
whose P2 value differs from the P1 one by more than :data:`TOLERANCE` of its size is named
in one warning with the fix, as ``diagnose``'s discretisation check does.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

log = logging.getLogger(__name__)

TOLERANCE = 0.02
"""Largest admitted |P2 − P1| of an output, relative to the largest output of its unit (the
largest rise above the stress-free temperature for temperatures)."""
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
    """(P2 − P1) relative to the largest output of the unit (:data:`TOLERANCE`)."""

    @property
    def worst(self) -> str | None:
        return max(self.relative, key=lambda k: abs(self.relative[k]), default=None)

    def summary(self) -> dict:
        """What ``summary.json`` records as ``order_check``."""
        return {"tolerance": TOLERANCE, "worst": self.worst,
                "outputs": {k: {"p1": self.p1[k], "p2": self.p2[k], "relative": round(v, 6)}
                            for k, v in self.relative.items()}}


def order_check(case, run) -> OrderCheck | None:
    """The element-order check of a P1 ``run`` of ``case`` (None: not checked: a P2 case or a
    mesh above :data:`MAX_NODES`); logs one warning naming the output that differs most when
    it exceeds :data:`TOLERANCE`."""
    if case.problem.order != 1 or len(case.mesh.points) > MAX_NODES[case.mesh.dim]:
        return None
    p2 = p2_outputs(case, run)
    p1 = {k: float(run.result.columns[k][-1]) for k in p2 if k.endswith(UNITS) and k in run.result.columns}
    base = {u: case.problem.T_ref if u == "_degC" else 0.0 for u in UNITS}
    size = {u: max((abs(p2[k] - base[u]) for k in p1 if k.endswith(u)), default=0.0) for u in UNITS}
    rel = {k: (p2[k] - v) / max(next(s for u, s in size.items() if k.endswith(u)), 1e-300) for k, v in p1.items()}
    check = OrderCheck(p1, {k: p2[k] for k in p1}, rel)
    worst = check.worst
    if worst is not None and abs(rel[worst]) > TOLERANCE:
        log.warning("%s: %s changes from %.4g to %.4g from P1 to P2 on this mesh (%+.1f %% of the largest output "
                    "of its unit, check tolerance %g %%): set order = 2 in [case] or refine the mesh", case.path, worst,
                    p1[worst], p2[worst], 100 * rel[worst], 100 * TOLERANCE)
    return check
