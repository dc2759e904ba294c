"""The paper's gate frame as a problem: its parameters and the case they generate.

:class:`ModelConfig` holds everything that defines a frame model (a model file mirrors
it); :func:`frame_problem` turns it and the frame's mesh into a
:class:`~gatetherm.solvers.problem.Problem`: FC300 per region (tie bars and their joint
layers with their own material), films to the room, the out-of-plane loss of the 2-D
section, the oil tank with its supply hose, the clamped (or elastically bedded)
mounting face, the sensors as probes and δ, δ_E as relative displacements.
"""
from __future__ import annotations

import dataclasses
import logging
import time
from dataclasses import dataclass, field

import numpy as np

from gatetherm import InputError
from gatetherm.checks import CELSIUS, NONNEGATIVE, POSITIVE, Range, admissible
from gatetherm.frame.build import build_mesh
from gatetherm.frame.geometry import FrameParams, MeshParams, TIE_SENSORS, part_boxes, tank_box, tie_depth, width
from gatetherm.geometry.measure import enclosed_volume, region_volume
from gatetherm.geometry.mesh import FrameMesh
from gatetherm.solvers.effects import JointLayer, Named, Targets
from gatetherm.solvers.expr import Value
from gatetherm.solvers.heat import TimeScheme
from gatetherm.solvers.material import FC300, Material
from gatetherm.solvers.model import Model, build
from gatetherm.solvers.problem import FaceFilm, Film, Fluid, Problem, Probe, Relative, Signals, Source, Support
from gatetherm.studies.run.timeseries import AMBIENT, PUMP, SUPPLY  # noqa: F401 (the frame's inputs; re-exported)

log = logging.getLogger(__name__)

GEOMETRY_FREE = ("l1",)
"""FrameParams fields the mesh does not depend on (the beam theory's heated height)."""
RELATIVE = {"delta": ("F_L", "F_R"), "delta_E": ("E_L", "E_R")}
"""Relative x-displacements (left minus right) of sensor pairs: δ at the tips and at E."""
EFFECTS = ("ambient_drift", "joint_resistance", "joint_compliance", "compliant_base", "base_conduction",
           "piezo_heat", "thermocouple_lag", "stand_drift")
"""The frame's catalogue of effects, in the order the studies list them."""
TARGETS = Targets(
    named={"piezo_heat": Named("heat_source", "arm_R", "heat released in the workpiece-side arm by the piezo stack, "
                               "its spring member and drive, constant from the start of the run", 0.5, 5.0,
                               log_scale=True)},
    defaults={"joint_resistance": "tie", "joint_compliance": "tie", "compliant_base": "mounting_face",
              "base_conduction": "mounting_face"}, candidates=EFFECTS)
"""The names the frame's effects act on (the tie-bar joints' layers are added per mesh: :func:`frame_targets`)."""


@admissible(T0=CELSIUS, h_air=NONNEGATIVE, h_base=NONNEGATIVE, h_oil_on=NONNEGATIVE, h_oil_off=NONNEGATIVE,
            oil_rho_c=POSITIVE, flow_rate=NONNEGATIVE, hose_capacity=NONNEGATIVE, hose_loss=NONNEGATIVE)
@dataclass(frozen=True)
class ThermalParams:
    """Heat-transfer coefficients of the frame and the oil tank."""

    T0: float = 20.0
    """Initial temperature of frame, oil and room, and the stress-free reference, °C."""
    h_air: float = 8.0
    """Film coefficient of the free surfaces to room air (convection + linearised radiation), W/(m² K)."""
    h_base: float = 0.0
    """Film coefficient of the mounting face to a foundation at room temperature, W/(m² K)."""
    h_oil_on: float = 260.0
    """Tank-wall film coefficient while the pump circulates the oil, W/(m² K)."""
    h_oil_off: float = 28.0
    """Tank-wall film coefficient of standing oil, W/(m² K)."""
    oil_rho_c: float = 1.7e6
    """Volumetric heat capacity of the oil, J/(m³ K)."""
    flow_rate: float = 3.3e-5
    """Oil flow through the tank while the pump runs, m³/s."""
    out_of_plane: bool = True
    """2-D only: the front and back faces of the section lose heat with ``h_air``."""
    hose_capacity: float = 1800.0
    """Heat capacity of the supply hose from the oil unit to the tank, its oil and its wall,
    J/K (0: no hose). Default: 2 m of 13 mm-bore rubber hose, 0.27 L of oil (450 J/K) and
    0.68 kg of rubber (1360 J/K)."""
    hose_loss: float = 0.9
    """Heat loss of the supply hose to the room, W/K. Default: 2 m of 23 mm outer diameter,
    8 W/(m² K) outside, 5 mm of rubber (k = 0.2 W/(m K))."""


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
    power: dict = field(default_factory=dict)
    """Heat released uniformly in a region, by region name, W."""
    scheme: TimeScheme = TimeScheme()
    """Time stepping of the heat equation."""


def is_tie(region: str) -> bool:
    return region.startswith("tie_")


def frame_materials(cfg: ModelConfig, regions) -> dict[str, Material]:
    """FC300 (``cfg.material``) for the columns and arms, the tie material for the tie bars,
    with the joint layers' contact resistance and compliance in series (``joint_*``)."""
    tie = cfg.tie_material or cfg.material
    joint, L = tie, cfg.frame.joint_layer
    if cfg.joint_conductance is not None:  # contact resistance in series with the end layer
        joint = dataclasses.replace(joint, k=L / (L / tie.k + 1.0 / cfg.joint_conductance))
    if cfg.joint_stiffness is not None:  # contact compliance in series with the end layer
        joint = dataclasses.replace(joint, E=L / (L / tie.E + 1.0 / cfg.joint_stiffness))
    return {r: (joint if "joint" in r else tie) if is_tie(r) else cfg.material for r in regions}


def frame_targets(cfg: ModelConfig, regions) -> Targets:
    """:data:`TARGETS` with the joint ``tie``: both tie-bar end layers of the mesh's ``regions``, in
    series with the tie material."""
    tie = cfg.tie_material or cfg.material
    layers = tuple(JointLayer(r, cfg.frame.joint_layer, tie) for r in regions if is_tie(r) and "joint" in r)
    return dataclasses.replace(TARGETS, joints={"tie": layers})


def frame_problem(cfg: ModelConfig, fm: FrameMesh) -> Problem:
    """The problem of the frame ``cfg`` on its mesh ``fm`` (2-D section or 3-D solid)."""
    p, th, dim = cfg.frame, cfg.thermal, fm.dim
    thickness = {r: (tie_depth(p) if is_tie(r) else p.depth) for r in fm.regions} if dim == 2 else {}
    heat = paper_heat(th, enclosed_volume(fm, "tank_wall", p.depth if dim == 2 else 1.0))
    sources = tuple(Source(r, Value(q)) for r, q in cfg.source.items())
    sources += tuple(Source(r, Value(w / region_volume(fm, r, thickness.get(r, 1.0)))) for r, w in cfg.power.items())
    support = Support("mounting_face", tuple(range(dim)), cfg.k_base)  # None: clamped
    probes = tuple(Probe(name, tuple(fm.points[node])) for name, node in fm.sensors.items())
    return Problem(dim, frame_materials(cfg, fm.regions), cfg.order, thickness, T0=th.T0, T_ref=th.T0,
                   sources=sources, supports=(support,), probes=probes,
                   relative=tuple(Relative(k, a, b, 0) for k, (a, b) in RELATIVE.items()),
                   means=(("tank_wall", "tank_wall"), ("base", "mounting_face")),
                   signals=Signals("A", "B", TIE_SENSORS, "delta"), scheme=cfg.scheme, **heat)


def paper_heat(th: ThermalParams, oil_volume: float) -> dict:
    """The paper's heat transfer as problem fields: films of the free surfaces (and the
    mounting face) to the room, the 2-D section's front and back faces, and the oil tank
    (``oil_volume``, m³) on ``tank_wall`` with its supply hose, driven by the inputs
    :data:`SUPPLY`, :data:`PUMP`, :data:`AMBIENT`."""
    ambient = Value(0.0, AMBIENT)
    films = (Film("free_surface", th.h_air, ambient),) if th.h_air else ()
    films += (Film("mounting_face", th.h_base, ambient),) if th.h_base else ()
    tank = Fluid("tank_oil", "tank_wall", th.oil_rho_c * oil_volume, th.h_oil_on, th.h_oil_off,
                 th.oil_rho_c * th.flow_rate, Value(0.0, SUPPLY), Value(0.0, PUMP), th.hose_capacity, th.hose_loss,
                 ambient, "hose")
    return {"films": films, "faces": FaceFilm(th.h_air, ambient) if th.out_of_plane and th.h_air else None,
            "fluids": (tank,)}


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


def build_model(cfg: ModelConfig, dim: int, fmesh: FrameMesh | None = None) -> Model:
    """Mesh (unless ``fmesh`` is given, which must be a mesh of ``cfg.frame``) and assemble the frame model."""
    t0 = time.perf_counter()
    fm = build_mesh(cfg.frame, dim, cfg.mesh) if fmesh is None else check_mesh(fmesh, cfg.frame, dim)
    return build(frame_problem(cfg, fm), fm, cfg, time.perf_counter() - t0)
