"""The assembled frame model: mesh, heat and elastic operators, sensor read-outs.

Everything here is set up once per configuration; the time loop only calls
``march`` and the cheap read-outs (a sparse probe for temperatures, fixed
weight vectors for displacements).
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import logging
import time
from dataclasses import dataclass, field

import numpy as np

from gatetherm import InputError
from gatetherm.checks import POSITIVE, Range, admissible
from gatetherm.geometry.build import build_mesh
from gatetherm.geometry.frame import (FrameParams, MeshParams, TIE_SENSORS, part_boxes, tank_box, tie_depth,
                                      width)
from gatetherm.geometry.mesh import FrameMesh
from gatetherm.solvers import linsolve
from gatetherm.solvers.elasticity import ElasticSystem, assemble_elastic
from gatetherm.solvers.fem import Field, to_skfem
from skfem import FacetBasis, asm

from gatetherm.solvers.heat import HeatSystem, ThermalParams, TimeScheme, assemble_heat, film_load
from gatetherm.solvers.material import FC300, Material

log = logging.getLogger(__name__)

def scheme_digest(cfg: ModelConfig) -> str:
    """Eight hex digits naming the numerical scheme: element order, time stepping and the
    linear solvers' settings (not the physics)."""
    blob = json.dumps({"order": cfg.order, "time": dataclasses.asdict(cfg.scheme), "linear": linsolve.SETTINGS},
                      sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()[:8]


GEOMETRY_FREE = ("l1",)
"""FrameParams fields the mesh does not depend on (the beam theory's heated height)."""
#: Displacement outputs: relative x-displacement (left minus right, m) of a sensor pair.
OUTPUTS = {"delta": ("F_L", "F_R"), "delta_E": ("E_L", "E_R")}


@admissible(order=Range(1, 2, whole=True), k_base=POSITIVE, joint_conductance=POSITIVE, joint_stiffness=POSITIVE)
@dataclass(frozen=True)
class ModelConfig:
    """Everything that defines a frame model (the TOML file mirrors it)."""

    frame: FrameParams = FrameParams()
    mesh: MeshParams = MeshParams()
    material: Material = FC300
    tie_material: Material | None = None
    """Material of the tie bars (default: same as ``material``)."""
    thermal: ThermalParams = ThermalParams()
    order: int = 1
    """Polynomial degree of temperature and displacement (1 or 2)."""
    k_base: float | None = None
    """Foundation stiffness of the mounting face, N/m³ (None: clamped)."""
    joint_conductance: float | None = None
    """Thermal contact conductance at the tie-bar joints, W/(m² K) (None: perfect contact)."""
    joint_stiffness: float | None = None
    """Normal contact stiffness of the tie-bar joints per unit area, N/m³ (None: rigid contact)."""
    source: dict = field(default_factory=dict)
    """Volumetric heat sources by region name, W/m³."""
    scheme: TimeScheme = TimeScheme()
    """Time stepping of the heat equation."""


def is_tie(region: str) -> bool:
    return region.startswith("tie_")


def region_fields(cfg: ModelConfig, fm: FrameMesh, mesh) -> dict[str, Field]:
    """Element-wise coefficients: thickness (m, 2-D), k, ρc, E, ν, α, q."""
    tie_m = cfg.tie_material or cfg.material
    ties = [r for r in fm.regions if is_tie(r)]
    props = {"k": lambda m: m.k, "rho_c": lambda m: m.rho * m.c, "E": lambda m: m.E,
             "nu": lambda m: m.nu, "alpha": lambda m: m.alpha}
    per_region = {name: {r: get(tie_m) for r in ties} for name, get in props.items()}
    if cfg.joint_conductance is not None:  # contact resistance in series with the end layer
        L = cfg.frame.joint_layer
        per_region["k"].update({r: L / (L / tie_m.k + 1.0 / cfg.joint_conductance)
                                for r in ties if "joint" in r})
    if cfg.joint_stiffness is not None:  # contact compliance in series with the end layer
        L = cfg.frame.joint_layer
        per_region["E"].update({r: L / (L / tie_m.E + 1.0 / cfg.joint_stiffness)
                                for r in ties if "joint" in r})
    out = {name: Field.by_region(mesh, per_region[name], get(cfg.material))
           for name, get in props.items()}
    thick = (cfg.frame.depth, tie_depth(cfg.frame)) if fm.dim == 2 else (1.0, 1.0)
    out["thickness"] = Field.by_region(mesh, {r: thick[1] for r in ties}, thick[0])
    out["source"] = Field.by_region(mesh, cfg.source, 0.0)
    return out


def oil_volume(p: FrameParams, dim: int) -> float:
    """Oil volume in the tank, m³ (2-D: the tank runs through the column depth)."""
    b = tank_box(p, dim)
    return (b[1] - b[0]) * (b[3] - b[2]) * (b[5] - b[4])


@dataclass(frozen=True)
class FrameModel:
    """A meshed and assembled frame, ready to march and read out."""

    config: ModelConfig
    fmesh: FrameMesh
    mesh: object
    heat: HeatSystem
    elastic: ElasticSystem
    sensor_names: tuple[str, ...]
    probe: object
    weights: dict[str, np.ndarray]
    surface_means: dict[str, np.ndarray]
    """Weight vectors giving the area-mean temperature of the tank wall and the mounting face."""
    timings: dict[str, float] = field(default_factory=dict, compare=False)
    """Seconds spent building: mesh, heat_assembly, elastic_setup, adjoint_solves."""

    @property
    def dim(self) -> int:
        return self.fmesh.dim

    def temperatures(self, U: np.ndarray) -> dict[str, float]:
        """Sensor temperatures (°C), θ_C as the mean of C1–C10, tank oil, supply hose
        (``hose``, if modelled), and the area means of the tank wall and the mounting face."""
        T = U[:self.heat.n_solid]
        out = dict(zip(self.sensor_names, map(float, self.probe @ T)))
        out["C"] = float(np.mean([out[c] for c in TIE_SENSORS]))
        out["oil"] = float(U[self.heat.oil])
        if self.heat.inlet != self.heat.oil:
            out["hose"] = float(U[self.heat.inlet])
        out.update({k: float(v @ T) for k, v in self.surface_means.items()})
        return out

    def rise(self, U: np.ndarray) -> np.ndarray:
        """Temperature rise of the solid above the stress-free T0, K."""
        return U[:self.heat.n_solid] - self.config.thermal.T0

    def displacements(self, U: np.ndarray) -> dict[str, float]:
        """The outputs of :data:`OUTPUTS` in metres for the state ``U``."""
        dT = self.rise(U)
        return {k: float(w @ dT) for k, w in self.weights.items()}

    def displacement_field(self, U: np.ndarray) -> np.ndarray:
        """Full displacement field (m) on the elastic basis: one elastic solve."""
        return self.elastic.displacement(self.rise(U))


def check_mesh(fm: FrameMesh, p: FrameParams, dim: int) -> FrameMesh:
    """``fm`` if it is a mesh of the frame ``p`` in ``dim`` dimensions, else InputError naming
    the first field (a mesh built here) or region (a mesh read from a file) that differs."""
    if fm.dim != dim:
        raise InputError("--dim", f"the mesh is {fm.dim}-D, the model {dim}-D", "mesh and model must agree")
    built = fm.meta.get("frame")
    if built is not None:
        for f in dataclasses.fields(p):
            if f.name not in GEOMETRY_FREE and getattr(built, f.name) != getattr(p, f.name):
                raise InputError(f"geometry.{f.name}", f"the mesh was built with {getattr(built, f.name)!r}, the "
                                 f"model says {getattr(p, f.name)!r}", "mesh the model's own geometry")
        return fm
    tol = 1e-6 * max(width(p), p.column_height)
    boxes = {**part_boxes(p, dim), "tank_wall": tank_box(p, dim)}
    for name, box in boxes.items():
        where = fm.regions.get(name) if name != "tank_wall" else None
        if name == "tank_wall":
            nodes = np.unique(fm.boundaries.get(name, np.zeros((0, dim), int)))
        else:
            nodes = np.unique(fm.cells[where]) if where is not None else np.zeros(0, int)
        if nodes.size == 0:
            raise InputError(f"mesh region {name}", "missing from the mesh", "mesh the model's own geometry")
        lo, hi = fm.points[nodes].min(axis=0), fm.points[nodes].max(axis=0)
        want = np.array(box[:2 * dim]).reshape(dim, 2)
        if not (np.allclose(lo, want[:, 0], atol=tol) and np.allclose(hi, want[:, 1], atol=tol)):
            raise InputError(f"mesh region {name}", f"spans {np.round(lo, 6).tolist()}..{np.round(hi, 6).tolist()} m, "
                             f"the model's geometry puts it at {want[:, 0].tolist()}..{want[:, 1].tolist()} m",
                             "mesh the model's own geometry")
    return fm


def build_model(cfg: ModelConfig, dim: int, fmesh: FrameMesh | None = None) -> FrameModel:
    """Mesh (unless ``fmesh`` is given, which must be a mesh of ``cfg.frame``) and assemble the frame model."""
    clock = [time.perf_counter()]
    timings = {}

    def lap(name):
        now = time.perf_counter()
        timings[name] = now - clock[0]
        clock[0] = now

    fm = build_mesh(cfg.frame, dim, cfg.mesh) if fmesh is None else check_mesh(fmesh, cfg.frame, dim)
    lap("mesh")
    mesh = to_skfem(fm)
    f = region_fields(cfg, fm, mesh)
    src = f["source"] if cfg.source else None
    heat = assemble_heat(mesh, cfg.order, f["k"], f["rho_c"], f["thickness"], cfg.thermal,
                         oil_volume(cfg.frame, dim), source=src)
    lap("heat_assembly")
    el = assemble_elastic(mesh, cfg.order, heat.basis, f["E"], f["nu"], f["alpha"],
                          f["thickness"], cfg.k_base)
    lap("elastic_setup")
    names = tuple(fm.sensors)
    xyz = np.array([fm.points[fm.sensors[n]] for n in names]).T
    probe = heat.basis.probes(xyz).tocsr()
    gx = {s: el.point_functional(fm.points[fm.sensors[s]], 0) for s in ("F_L", "F_R", "E_L", "E_R")}
    weights = {k: el.weights(gx[a] - gx[b]) for k, (a, b) in OUTPUTS.items()}
    lap("adjoint_solves")
    means = {}
    for key, bnd in (("wall", "tank_wall"), ("base", "mounting_face")):
        fb = FacetBasis(mesh, heat.basis.elem, facets=mesh.boundaries[bnd])
        a = asm(film_load, fb, h=1.0, t=f["thickness"].at(fb))
        means[key] = a / a.sum()
    return FrameModel(cfg, fm, mesh, heat, el, names, probe, weights, means, timings)
