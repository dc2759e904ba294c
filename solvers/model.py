"""An assembled problem: mesh, heat and elastic operators, and every output as a linear
read-out of the heat state.

Everything here is set up once per problem; a time step costs one sparse and one dense
matrix-vector product for all outputs: temperatures at probes, fluid and hose
temperatures and boundary means (sparse rows on the state), and displacements,
relative displacements and stresses at probes (dense weight rows on the temperature
rise, one adjoint elastic solve each). A problem with a prescribed temperature field
has no heat state: it is solved once (:meth:`Model.static`).

The read-outs are :mod:`gatetherm.solvers.readout`, the fields of a problem without a heat solve
:mod:`gatetherm.solvers.static`; their names are importable from here too.
"""
from __future__ import annotations

import dataclasses
import logging
import time
from dataclasses import dataclass, field

import numpy as np

from gatetherm.geometry.mesh import FrameMesh
from gatetherm.solvers.axisym import Revolution
from gatetherm.solvers.contact import split_contacts
from gatetherm.solvers.elasticity import ElasticSystem, assemble_elastic, support_dofs
from gatetherm.solvers.loads import Terms, mechanical_terms, unit_responses
from gatetherm.solvers import p1
from gatetherm.solvers.fem import Field, dof_basis, element, to_skfem
from gatetherm.solvers.heat import HeatSystem, assemble_heat
from gatetherm.solvers.helper import Pending
from gatetherm.solvers.plan import plan
from gatetherm.solvers.problem import AXES, Problem
from gatetherm.solvers.readout import (  # noqa: F401 (re-exported)
    Key, Readout, Rows, adjoint_weights, boundary_mean, build_readout, mechanical_rows, recovery_over)
from gatetherm.solvers.static import (  # noqa: F401 (re-exported)
    prescribed_at, prescribed_rise, static_displacement, static_fields)
from gatetherm.solvers.stress import Recovery, von_mises

log = logging.getLogger(__name__)

ORDER_BESIDE = {"nodes": 20_000, "steps": 100}
"""A mesh's METIS order is found in a process beside the set-up (:meth:`~gatetherm.solvers.p1.
Simplices.find_order_beside`) from this many nodes (below, it takes under 0.1 s), where the plan
would factor a heat step matrix for this many steps: then the first factor finds it made (the 3-D
frame: 0.3 s off the caller's set-up)."""


def region_fields(problem: Problem, mesh) -> dict[str, Field]:
    """Element-wise coefficients: k, ρc, E, ν, α and the 2-D thickness (m; 1 in 3-D)."""
    m = problem.materials
    out = {name: Field.by_region(mesh, {r: get(mat) for r, mat in m.items()}, np.nan) for name, get in (
        ("k", lambda a: a.k), ("rho_c", lambda a: a.rho * a.c), ("E", lambda a: a.E), ("nu", lambda a: a.nu),
        ("alpha", lambda a: a.alpha), ("rho", lambda a: a.rho))}
    thick = problem.thickness if problem.dim == 2 else {}
    out["thickness"] = Revolution.of(mesh) if problem.axisymmetric else Field.by_region(mesh, thick, 1.0)
    if not problem.thermal:  # no thermal strain
        out["alpha"] = Field(np.zeros(mesh.nelements))
    return out


@dataclass(frozen=True)
class Model:
    """An assembled :class:`~gatetherm.solvers.problem.Problem` on its mesh."""

    problem: Problem
    fmesh: FrameMesh
    mesh: object
    fields: dict[str, Field]
    heat: HeatSystem | None
    elastic: ElasticSystem | None
    readout: Readout | None
    """None for a prescribed temperature (see :meth:`static`)."""
    config: object = None
    """What the problem was generated from, if anything (the frame's ModelConfig)."""
    timings: dict[str, float] = field(default_factory=dict, compare=False)
    """Seconds spent building: mesh, elastic_setup, heat_assembly, adjoint_solves (the read-out; its solves where
    they are solved here)."""
    simplices: p1.Simplices | None = field(default=None, compare=False)
    """Linear elements: what all P1 matrices and factors on the mesh share."""
    terms: Terms | None = None
    """The mechanical loads (None: none)."""
    unit: np.ndarray | None = field(default=None, compare=False)
    """The displacement of every load term for a unit value (elastic DOFs × terms)."""

    @property
    def dim(self) -> int:
        return self.fmesh.dim

    def read(self, U: np.ndarray, env=None) -> np.ndarray:
        """All outputs of the heat state ``U`` with the inputs ``env`` (the variables of
        the load values; order of ``readout.keys``)."""
        return self.readout(U, self.heat.n_solid, self.problem.T_ref, env)

    def loads_displacement(self, env) -> np.ndarray | float:
        """The displacement (m) of the mechanical loads for the inputs ``env`` (0 without loads)."""
        return self.unit @ self.terms.at(env or {}) if self.terms is not None else 0.0

    def rise(self, U: np.ndarray) -> np.ndarray:
        """Temperature rise of the solid above the stress-free temperature, K."""
        return U[:self.heat.n_solid] - self.problem.T_ref

    def displacement_field(self, U: np.ndarray, envs=None) -> np.ndarray:
        """Full displacement field (m) on the elastic basis: one elastic solve (``U`` (n, k): k
        fields), plus the mechanical loads' for the inputs ``envs`` (one, or k of them)."""
        return self.displacement_later(U, envs).result()

    def displacement_later(self, U: np.ndarray, envs=None) -> Pending:
        """:meth:`displacement_field` as a :class:`~gatetherm.solvers.helper.Pending`: solved
        beside the caller where the elastic solver runs in a helper process."""
        u = self.elastic.later(self.elastic.B @ self.rise(U))
        if self.terms is None:
            return u
        loads = self.loads_displacement(envs) if np.ndim(U) == 1 else \
            np.column_stack([self.loads_displacement(e) for e in (envs or [None] * np.shape(U)[1])])
        return u.then(lambda x: x + loads)

    def stress_field(self, u: np.ndarray, U: np.ndarray | None = None,
                     rec: Recovery | None = None) -> dict[str, np.ndarray]:
        """Stress components and von Mises (Pa) at the nodes, projected over the whole mesh
        (``rec``: :func:`field_recovery` of this model, set up once for many states)."""
        rec = rec or field_recovery(self)
        rhs = rec.thermal_rhs(self.rise(U)) if U is not None else \
            rec.thermal_rhs(np.ones(1)) if self.problem.thermal else {}  # the prescribed rise, or none
        comps = rec.field(u, rhs)
        nodal = {c: v[rec.scalar.nodal_dofs[0]] for c, v in comps.items()}
        return {**nodal, "von_mises": von_mises(nodal)}

    def static(self, envs=(None,)) -> list[dict[Key, float]]:
        """The outputs of a problem without a heat solve (a prescribed temperature, or none)
        for each of the inputs ``envs`` of its loads: one elastic solve in all."""
        p = self.problem
        out: dict[Key, float] = {}
        T = prescribed_at(self, np.array([pr.xyz for pr in p.probes]).T) if p.probes and p.thermal else []
        for pr, Tp in zip(p.probes, T):
            if "T" in pr.quantities:  # on a region's side where the prescribed temperature jumps
                out[("T", pr.name)] = float(p.prescribed_regions.get(pr.region, Tp))
        if self.elastic is None:
            return [out for _ in envs]
        recoveries: dict = {}
        out.update(self._mechanical(static_displacement(self, None, loads=False), p.thermal, recoveries))
        units = [self._mechanical(u, False, recoveries) for u in (self.unit.T if self.terms is not None else ())]
        rows = []
        for env in envs:
            values = self.terms.at(env or {}) if units else ()
            rows.append({k: y + sum(unit[k] * v for unit, v in zip(units, values) if k in unit)
                         for k, y in out.items()})
        return rows

    def _mechanical(self, u: np.ndarray, thermal: bool, recoveries: dict) -> dict[Key, float]:
        """Displacement, stress and relative outputs of the displacement ``u`` (with the
        prescribed thermal strain if ``thermal``); ``recoveries`` by region, filled on use."""
        p, out = self.problem, {}
        for pr in p.probes:
            if "u" in pr.quantities:
                for c in range(self.dim):
                    out[("u", pr.name, AXES[c])] = float(self.elastic.point_functional(pr.xyz, c) @ u)
            if "sigma" in pr.quantities:
                if pr.region not in recoveries:
                    recoveries[pr.region] = _probe_recovery(self, pr.region)
                rec = recoveries[pr.region]
                comps = rec.field(u, rec.thermal_rhs(np.ones(1)) if thermal else {})
                phi = rec.at(pr.xyz)
                out.update({("sigma", pr.name, c): float(phi @ v) for c, v in comps.items()})
        for r in p.relative:
            a, b = (next(x for x in p.probes if x.name == n).xyz for n in (r.a, r.b))
            out[("relative", r.name)] = float((self.elastic.point_functional(a, r.axis)
                                               - self.elastic.point_functional(b, r.axis)) @ u)
        return out


def _recovery_for(model: Model, elements) -> Recovery:
    T_at = None if model.heat is not None else prescribed_rise(model)
    return recovery_over(model.problem, model.mesh, model.fields, model.simplices, elements, T_at)


def _probe_recovery(model: Model, region: str | None) -> Recovery:
    return _recovery_for(model, None if region is None else model.mesh.subdomains[region])


def field_recovery(model: Model) -> Recovery:
    """The stress projection over the whole mesh (set up once, used for every field state)."""
    return _recovery_for(model, None)


def build(problem: Problem, fmesh: FrameMesh, config=None, mesh_seconds: float = 0.0) -> Model:
    """Assemble ``problem`` on ``fmesh``. The elastic system first: where its solver runs in a
    helper process (:meth:`~gatetherm.solvers.linsolve.SPDSolver.start`: AMG-CG on a large 3-D
    mesh), its set-up and the adjoint read-out are made there while the heat system is
    assembled and marched."""
    clock = [time.perf_counter()]
    timings = {"mesh": mesh_seconds}

    def lap(name):
        now = time.perf_counter()
        timings[name] = now - clock[0]
        clock[0] = now

    if problem.contacts:
        fmesh = split_contacts(fmesh, problem.contacts)
    mesh = to_skfem(fmesh)
    f = region_fields(problem, mesh)
    s = p1.simplices(mesh) if problem.order == 1 else None
    if s is not None and problem.heat and s.pattern.n >= ORDER_BESIDE["nodes"] and plan(
            s.pattern.n, s.pattern.nnz, 1, problem.dim, ORDER_BESIDE["steps"], warm=True).path == "direct":
        s.find_order_beside()
    axi = problem.axisymmetric
    el, terms, unit, mech, weights = None, None, None, Rows([], [], []), None
    if problem.elastic:
        T_basis = dof_basis(mesh, element(problem.dim, problem.order))  # the heat basis's DOFs
        el = assemble_elastic(mesh, problem.order, T_basis, f["E"], f["nu"], f["alpha"], f["thickness"],
                              problem.supports, problem.plane, simplices=s, lines=fmesh.lines,
                              contacts=problem.contacts)
        if problem.heat:  # the read-out's solver set up now, in a helper where it can be
            mech = mechanical_rows(problem, mesh, f, el, s)
            el.solve.start(max(1, len(mech.G)))
        terms = mechanical_terms(problem, mesh, el.basis, f, fmesh.sensors, lambda sup, c: support_dofs(
            el.basis, mesh, sup.boundary, (c,), fmesh.lines))
        unit = unit_responses(el, terms) if terms is not None else None
        weights = adjoint_weights(el, mech, T_basis.N) if problem.heat else None
    lap("elastic_setup")
    heat = assemble_heat(mesh, problem, f, 2 * problem.order + 1 if axi else None, s) if problem.heat else None
    lap("heat_assembly")
    model = Model(problem, fmesh, mesh, f, heat, el, None, config, timings, s, terms, unit)
    if heat is not None:
        weights = weights or adjoint_weights(el, mech, heat.n_solid)
        model = dataclasses.replace(model, readout=build_readout(model, mech, weights))
    lap("adjoint_solves")
    return model
