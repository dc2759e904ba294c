"""An assembled problem: mesh, heat and elastic operators, and every output as a linear
read-out of the heat state.

Everything here is set up once per problem; a time step costs one sparse and one dense
matrix-vector product for all outputs: temperatures at probes, fluid and hose
temperatures and boundary means (sparse rows on the state), and displacements,
relative displacements and stresses at probes (dense weight rows on the temperature
rise, one adjoint elastic solve each). A problem with a prescribed temperature field
has no heat state: it is solved once (:meth:`Model.static`).
"""
from __future__ import annotations

import dataclasses
import logging
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from skfem import CellBasis, asm

from gatetherm.geometry.mesh import FrameMesh
from gatetherm.solvers.axisym import Revolution
from gatetherm.solvers.contact import split_contacts
from gatetherm.solvers.elasticity import ElasticSystem, assemble_elastic, moduli, support_dofs, thermal_load_at
from gatetherm.solvers.loads import Terms, mechanical_terms, unit_responses
from gatetherm.solvers import p1
from gatetherm.solvers.fem import Field, dof_basis, element, to_skfem
from gatetherm.solvers.heat import HeatSystem, assemble_heat, boundary_terms
from gatetherm.solvers.helper import Pending
from gatetherm.solvers.plan import plan
from gatetherm.solvers.problem import AXES, Problem
from gatetherm.solvers.stress import Recovery, recovery, von_mises

log = logging.getLogger(__name__)

Key = tuple
"""An output: ("T", probe), ("u", probe, axis), ("sigma", probe, component), ("relative", name),
("fluid", name), ("mean", name)."""
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


def boundary_mean(mesh, basis: CellBasis, name: str, thickness: Field) -> np.ndarray:
    """Weights giving the area-mean of a nodal field over a named boundary."""
    a = boundary_terms(mesh, name, basis.elem, 2 * basis.elem.maxdeg, thickness)[1]
    return a / a.sum()


@dataclass(frozen=True)
class Readout:
    """``y = L @ U + W @ (U_solid − T_ref) + R @ loads(env)``: the outputs :attr:`keys` of a
    heat state and the mechanical loads' values (:class:`~gatetherm.solvers.loads.Terms`)."""

    keys: tuple[Key, ...]
    L: sp.csr_matrix
    """Rows on the whole state (temperatures, °C)."""
    weights: Pending
    """:attr:`W`, solved beside the caller where the elastic solver runs in a helper process."""
    n_L: int
    """The first ``n_L`` keys are rows of ``L``, the rest rows of ``W``."""
    R: np.ndarray | None = None
    """Rows of ``W``'s outputs on the mechanical loads' values (None: no loads)."""
    terms: Terms | None = None

    @property
    def W(self) -> np.ndarray:
        """Rows on the solid's temperature rise (displacements in m, stresses in Pa)."""
        return self.weights.result()

    def __call__(self, U: np.ndarray, n_solid: int, T_ref: float, env=None) -> np.ndarray:
        y = self.L @ U
        if len(self.keys) == self.n_L:
            return y
        mech = self.R @ self.terms.at(env or {}) if self.R is not None else 0.0
        return np.concatenate([y, self.W @ (U[:n_solid] - T_ref) + mech])


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


def static_displacement(model: Model, env=None, loads: bool = True) -> np.ndarray:
    """The displacement (m) of a problem without a heat solve for the inputs ``env`` (only
    the prescribed temperature's if not ``loads``)."""
    p, el = model.problem, model.elastic
    u = el.from_load(_prescribed_load(model)) if p.thermal else np.zeros(el.basis.N)
    return u + model.loads_displacement(env) if loads else u


def static_fields(model: Model, env=None) -> dict[str, np.ndarray]:
    """Nodal temperature (°C, interpolated at the nodes; none without a temperature),
    displacement (m, 3 components) and stress (Pa) of a problem without a heat solve."""
    X = model.fmesh.points.T
    out = {"T": prescribed_at(model, X)} if model.problem.thermal else {}
    if model.elastic is not None:
        u_dofs = static_displacement(model, env)
        u = np.zeros((X.shape[1], 3))
        u[:, :model.dim] = u_dofs[model.elastic.basis.nodal_dofs].T
        out["u"] = u
        out.update({f"sigma_{k}" if k != "von_mises" else k: v for k, v in model.stress_field(u_dofs).items()})
    return out


def prescribed_at(model: Model, X: np.ndarray) -> np.ndarray:
    """The prescribed temperature (°C) at points ``X`` (dim, n)."""
    p = model.problem
    if p.prescribed is not None:
        return np.broadcast_to(p.prescribed(dict(zip("xyz", X))), X.shape[1:]).astype(float)
    cells = model.mesh.element_finder()(*X)
    regions = {int(e): r for r, els in model.mesh.subdomains.items() for e in els}
    return np.array([p.prescribed_regions.get(regions.get(int(c)), 0.0) for c in cells])


def _prescribed_rise(model: Model):
    """``basis -> prescribed rise above T_ref`` at the basis's quadrature points."""
    p = model.problem

    def at(basis):
        if p.prescribed is not None:
            X = basis.global_coordinates().value
            return np.broadcast_to(p.prescribed(dict(zip("xyz", X))), X.shape[1:]) - p.T_ref
        per = Field.by_region(model.mesh, p.prescribed_regions, np.nan)
        return per.at(basis) - p.T_ref
    return at


def _prescribed_load(model: Model) -> np.ndarray:
    from gatetherm.solvers import axisym

    el, f, p = model.elastic, model.fields, model.problem
    vb = CellBasis(model.mesh, el.basis.elem, intorder=2 * p.order + p.axisymmetric)
    b = moduli(f["E"].values, f["nu"].values, f["alpha"].values, model.dim, p.plane)[2]
    return asm(axisym.thermal_load_at if p.axisymmetric else thermal_load_at, vb, b=Field(b).at(vb),
               t=f["thickness"].at(vb), T=_prescribed_rise(model)(vb))


def _recovery_for(model: Model, elements) -> Recovery:
    T_at = None if model.heat is not None else _prescribed_rise(model)
    return _recovery(model.problem, model.mesh, model.fields, model.simplices, elements, T_at)


def _recovery(p: Problem, mesh, fields, simplices, elements, T_at=None) -> Recovery:
    """The stress projection over ``elements`` (None: all) of a problem's mesh; the temperature
    on the heat basis where there is a heat solve, else ``T_at``."""
    T_elem = element(p.dim, p.order) if p.heat else None
    return recovery(mesh, p.order, fields, p.dim, p.plane, T_elem, elements, T_at, simplices)


def _probe_recovery(model: Model, region: str | None) -> Recovery:
    return _recovery_for(model, None if region is None else model.mesh.subdomains[region])


def field_recovery(model: Model) -> Recovery:
    """The stress projection over the whole mesh (set up once, used for every field state)."""
    return _recovery_for(model, None)


@dataclass(frozen=True)
class _Rows:
    """The outputs of a displacement field: their keys, rows ``G`` on the displacement and
    rows ``GT`` (or None) on the temperature rise (a stress's thermal part)."""

    keys: list
    G: list
    GT: list


def _mechanical_rows(problem: Problem, mesh, fields, el: ElasticSystem, simplices) -> _Rows:
    """The relative displacements, displacements and stresses at probes, as rows."""
    keys, G, GT, recoveries = [], [], [], {}
    xyz = {pr.name: pr.xyz for pr in problem.probes}
    for r in problem.relative:
        keys.append(("relative", r.name))
        G.append(el.point_functional(xyz[r.a], r.axis) - el.point_functional(xyz[r.b], r.axis))
        GT.append(None)
    for pr in problem.probes:
        if "u" in pr.quantities:
            for c in range(problem.dim):
                keys.append(("u", pr.name, AXES[c]))
                G.append(el.point_functional(pr.xyz, c))
                GT.append(None)
        if "sigma" in pr.quantities:
            if pr.region not in recoveries:
                recoveries[pr.region] = _recovery(problem, mesh, fields, simplices,
                                                  None if pr.region is None else mesh.subdomains[pr.region])
            for c, (gu, gT) in recoveries[pr.region].point(pr.xyz).items():
                keys.append(("sigma", pr.name, c))
                G.append(gu)
                GT.append(gT)
    return _Rows(keys, G, GT)


def _weights(el: ElasticSystem, mech: _Rows, n_T: int) -> Pending:
    """The rows of :attr:`Readout.W`, from one adjoint solve of all outputs (beside the caller
    where the elastic solver runs in a helper)."""
    if not mech.G:
        return Pending.of(np.zeros((0, n_T)))

    def add_thermal(W):
        for i, gT in enumerate(mech.GT):
            if gT is not None:
                W[i] += gT
        return W
    return el.weights_later(np.array(mech.G)).then(add_thermal)


def _readout(model: Model, mech: _Rows, weights: Pending) -> Readout:
    """Sparse rows (temperatures) and the adjoint weight rows ``weights`` (mechanics) of every output."""
    p, heat = model.problem, model.heat
    keys, rows = [], []
    probes = [pr for pr in p.probes if "T" in pr.quantities]
    if probes:
        P = p1.probes(heat.basis, np.array([pr.xyz for pr in probes]).T)
        keys += [("T", pr.name) for pr in probes]
        rows.append(sp.hstack([P, sp.csr_matrix((len(probes), heat.n - heat.n_solid))]))
    for name, index in heat.lumped.items():
        keys.append(("fluid", name))
        rows.append(sp.csr_matrix(([1.0], ([0], [index])), shape=(1, heat.n)))
    for name, boundary in p.means:
        keys.append(("mean", name))
        w = boundary_mean(model.mesh, heat.basis, boundary, model.fields["thickness"])
        rows.append(sp.csr_matrix(np.r_[w, np.zeros(heat.n - heat.n_solid)][None, :]))
    L = sp.vstack(rows).tocsr() if rows else sp.csr_matrix((0, heat.n))
    R = np.array(mech.G) @ model.unit if mech.G and model.terms is not None else None
    return Readout(tuple(keys + mech.keys), L, weights, len(keys), R, model.terms)


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
    el, terms, unit, mech, weights = None, None, None, _Rows([], [], []), None
    if problem.elastic:
        T_basis = dof_basis(mesh, element(problem.dim, problem.order))  # the heat basis's DOFs
        el = assemble_elastic(mesh, problem.order, T_basis, f["E"], f["nu"], f["alpha"], f["thickness"],
                              problem.supports, problem.plane, simplices=s, lines=fmesh.lines,
                              contacts=problem.contacts)
        if problem.heat:  # the read-out's solver set up now, in a helper where it can be
            mech = _mechanical_rows(problem, mesh, f, el, s)
            el.solve.start(max(1, len(mech.G)))
        terms = mechanical_terms(problem, mesh, el.basis, f, fmesh.sensors, lambda sup, c: support_dofs(
            el.basis, mesh, sup.boundary, (c,), fmesh.lines))
        unit = unit_responses(el, terms) if terms is not None else None
        weights = _weights(el, mech, T_basis.N) if problem.heat else None
    lap("elastic_setup")
    heat = assemble_heat(mesh, problem, f, 2 * problem.order + 1 if axi else None, s) if problem.heat else None
    lap("heat_assembly")
    model = Model(problem, fmesh, mesh, f, heat, el, None, config, timings, s, terms, unit)
    if heat is not None:
        model = dataclasses.replace(model, readout=_readout(model, mech, weights or _weights(el, mech, heat.n_solid)))
    lap("adjoint_solves")
    return model
