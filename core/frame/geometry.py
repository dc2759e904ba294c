"""Parameters of the gate-type frame and the boxes its parts occupy.

Coordinates: ``x`` horizontal from the outer (A) face of the tool-side column
towards the workpiece side, ``y`` vertical up from the mounting face, ``z``
depth (3-D only, front face at ``z = 0``). The paper gives no dimensions
(its Fig. 2 is not in the text); the defaults are a bench-size cast-iron model
fitted to the paper's reported figures (``validation/calibrate_paper.py``);
``studies/data/paper.toml`` repeats them explicitly.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from gatetherm import InputError
from gatetherm.checks import POSITIVE, Range, admissible, check_fields

Box = tuple[float, float, float, float, float, float]  # x0, x1, y0, y1, z0, z1


MAX_LENGTH = 100.0
"""Largest dimension of a frame, m: beyond any machine tool (a length in mm read as m is refused)."""
LENGTH = Range(0.0, MAX_LENGTH, lo_open=True, unit="m")


@admissible(LENGTH, l4_2=Range(0.0, MAX_LENGTH, unit="m"), A_C=Range(0.0, MAX_LENGTH, lo_open=True, unit="m²"))
@dataclass(frozen=True)
class FrameParams:
    """Dimensions of the frame, all in metres (areas in m²)."""

    h: float = 0.225
    """Column width in x, the distance between sensor faces A and B, m."""
    depth: float = 0.12
    """Column depth in z (out-of-plane thickness of columns and arms in 2-D), m."""
    column_height: float = 0.70
    """Height of the column tops above the mounting face, m."""
    l: float = 0.67
    """Height of the cutting area (arm centreline, points E and F) above the mounting face, m."""
    l1: float = 0.25
    """Heated height of the tool-side column assumed by the beam theory, m."""
    l4: float = 0.34
    """Height of the tie-bar centreline above the mounting face, m."""
    l_C: float = 0.40
    """Tie-bar length, the clear span between the inner column faces, m."""
    A_C: float = 5.9e-4
    """Tie-bar cross-section, m²."""
    t_C: float = 0.04
    """Tie-bar height in the x-y plane, m (its depth is ``A_C / t_C``)."""
    arm_thickness: float = 0.06
    """Height of the horizontal arms in y, m."""
    arm_depth: float = 0.06
    """Depth of the arms in z from the front face (3-D); the tie bar sits behind them, m."""
    gap: float = 0.02
    """Gap between tool tip and workpiece tip, m."""
    tank_wall: float = 0.0145
    """Wall thickness between the outer face A and the oil tank, m."""
    tank_width: float = 0.026
    """Oil-tank extent in x, m."""
    tank_bottom: float = 0.02
    """Height of the tank floor above the mounting face, m."""
    tank_height: float = 0.21
    """Oil-tank extent in y, m."""
    tank_depth: float = 0.08
    """Oil-tank extent in z, centred in the column depth (3-D), m."""
    sensor_height: float = 0.125
    """Height of the thermocouples A and B above the mounting face, m."""
    l4_2: float = 0.0
    """Height of an optional second tie bar (0 = none), m; same section as the first."""
    joint_layer: float = 0.005
    """Length of the tie-bar end layers kept as separate regions (joint physics), m."""

    def replace(self, **changes) -> "FrameParams":
        """Return a validated copy with ``changes`` applied."""
        return validate(dataclasses.replace(self, **changes))


@admissible(size=POSITIVE, size_3d=POSITIVE, refine=Range(0.0, 1.0, lo_open=True))
@dataclass(frozen=True)
class MeshParams:
    """Mesh density controls."""

    size: float = 0.008
    """Target element size away from refinement zones in 2-D, m."""
    size_3d: float = 0.009
    """Target element size away from refinement zones in 3-D, m."""
    refine: float = 0.5
    """Element size at the tank wall and the member joints, as a fraction of ``size``."""


def tie_depth(p: FrameParams) -> float:
    """Depth (z extent, or 2-D thickness) of a tie bar, m."""
    return p.A_C / p.t_C


def width(p: FrameParams) -> float:
    """Overall frame width in x, m."""
    return p.l_C + 2.0 * p.h


def tie_heights(p: FrameParams) -> tuple[float, ...]:
    """Centreline heights of the tie bars present, m."""
    return (p.l4,) + ((p.l4_2,) if p.l4_2 > 0 else ())


def part_boxes(p: FrameParams, dim: int) -> dict[str, Box]:
    """Axis-aligned boxes of the solid parts (before the tank is cut), by region name.

    Tie bars are split into a middle part and two end layers of length
    ``joint_layer`` (regions ``tie_joint_L``/``tie_joint_R``) so that joint
    physics can act on them.
    """
    W, d = width(p), p.depth
    xl, xr = 0.5 * (W - p.gap), 0.5 * (W + p.gap)
    ya0, ya1 = p.l - 0.5 * p.arm_thickness, p.l + 0.5 * p.arm_thickness
    za = (0.0, d) if dim == 2 else (0.0, p.arm_depth)
    zt = (0.0, d) if dim == 2 else (0.5 * (p.arm_depth + d) - 0.5 * tie_depth(p),
                                    0.5 * (p.arm_depth + d) + 0.5 * tie_depth(p))
    boxes = {
        "column_L": (0.0, p.h, 0.0, p.column_height, 0.0, d),
        "column_R": (W - p.h, W, 0.0, p.column_height, 0.0, d),
        "arm_L": (p.h, xl, ya0, ya1, *za),
        "arm_R": (xr, W - p.h, ya0, ya1, *za),
    }
    j = p.joint_layer
    for k, y in enumerate(tie_heights(p)):
        sfx = "" if k == 0 else "_2"
        y0, y1 = y - 0.5 * p.t_C, y + 0.5 * p.t_C
        boxes[f"tie_bar{sfx}"] = (p.h + j, W - p.h - j, y0, y1, *zt)
        boxes[f"tie_joint_L{sfx}"] = (p.h, p.h + j, y0, y1, *zt)
        boxes[f"tie_joint_R{sfx}"] = (W - p.h - j, W - p.h, y0, y1, *zt)
    return boxes


def tank_box(p: FrameParams, dim: int) -> Box:
    """The oil-tank cavity inside the tool-side column leg."""
    z0 = 0.0 if dim == 2 else 0.5 * (p.depth - p.tank_depth)
    z1 = p.depth if dim == 2 else z0 + p.tank_depth
    return (p.tank_wall, p.tank_wall + p.tank_width,
            p.tank_bottom, p.tank_bottom + p.tank_height, z0, z1)


def sensor_points(p: FrameParams, dim: int) -> dict[str, tuple[float, float, float]]:
    """Named sensor locations.

    A, B: outer and inner face of the tool-side column at ``sensor_height``;
    C1–C10: tie-bar upper (odd) and lower (even) faces near each joint and at
    the quarter points; E_L, E_R: column centrelines at height ``l``;
    F_L, F_R: tool tip and workpiece tip.
    """
    W = width(p)
    zc = 0.5 * p.depth if dim == 3 else 0.0
    zt = 0.5 * (p.arm_depth + p.depth) if dim == 3 else 0.0
    za = 0.5 * p.arm_depth if dim == 3 else 0.0
    pts = {"A": (0.0, p.sensor_height, zc), "B": (p.h, p.sensor_height, zc)}
    near = min(p.l_C / 20.0, 0.02)
    xs = (p.h + near, p.h + 0.25 * p.l_C, p.h + 0.5 * p.l_C, p.h + 0.75 * p.l_C, W - p.h - near)
    for i, x in enumerate(xs):
        pts[f"C{2 * i + 1}"] = (x, p.l4 + 0.5 * p.t_C, zt)
        pts[f"C{2 * i + 2}"] = (x, p.l4 - 0.5 * p.t_C, zt)
    pts["E_L"] = (0.5 * p.h, p.l, zc)
    pts["E_R"] = (W - 0.5 * p.h, p.l, zc)
    pts["F_L"] = (0.5 * (W - p.gap), p.l, za)
    pts["F_R"] = (0.5 * (W + p.gap), p.l, za)
    return pts


TIE_SENSORS = tuple(f"C{i}" for i in range(1, 11))


def _overlap(a0: float, a1: float, b0: float, b1: float) -> bool:
    return a0 < b1 and b0 < a1


def validate(p: FrameParams, dim: int | None = None) -> FrameParams:
    """Return ``p`` if it describes a buildable frame, else raise :class:`InputError`.

    ``dim=2`` adds the plane-section check that tie bars and arms do not overlap
    (in 3-D the tie bar sits behind the arms, so any ``l4`` is buildable).
    """
    check_fields(p)
    if p.l1 > p.l:
        raise InputError("l1", f"heated height {p.l1} m exceeds the cutting-area height l = {p.l} m",
                         "choose l1 <= l")
    if p.l + 0.5 * p.arm_thickness > p.column_height + 1e-12:
        raise InputError("l", f"arm top {p.l + 0.5 * p.arm_thickness:g} m is above the column top "
                         f"{p.column_height} m", "lower l or raise column_height")
    if p.gap >= p.l_C:
        raise InputError("gap", f"tool gap {p.gap} m is not smaller than the span l_C = {p.l_C} m")
    if 2 * p.joint_layer >= p.l_C:
        raise InputError("joint_layer", "joint layers fill the whole tie bar", "make it much smaller than l_C")
    for name, y in (("l4", p.l4), ("l4_2", p.l4_2)):
        if name == "l4_2" and y == 0:
            continue
        if y - 0.5 * p.t_C < 0 or y + 0.5 * p.t_C > p.column_height + 1e-12:
            raise InputError(name, f"tie bar at {y} m (height t_C = {p.t_C} m) lies outside the column "
                             f"(0 to column_height = {p.column_height} m)",
                             "move it or raise column_height")
    if p.l4_2 > 0 and _overlap(p.l4 - 0.5 * p.t_C, p.l4 + 0.5 * p.t_C,
                               p.l4_2 - 0.5 * p.t_C, p.l4_2 + 0.5 * p.t_C):
        raise InputError("l4_2", "the second tie bar overlaps the first", "move it apart by at least t_C")
    if p.tank_wall + p.tank_width >= p.h - 1e-3:
        raise InputError("tank_width", f"the tank reaches the inner column face (tank_wall + tank_width "
                         f"= {p.tank_wall + p.tank_width:g} m, h = {p.h} m)", "leave at least 1 mm of wall")
    if p.tank_bottom + p.tank_height >= p.column_height:
        raise InputError("tank_height", "the tank reaches the column top", "make it lower")
    if p.tank_depth >= p.depth:
        raise InputError("tank_depth", "the tank is as deep as the column", "make it smaller than depth")
    if p.sensor_height >= p.column_height:
        raise InputError("sensor_height", "sensors A/B are above the column top", "lower it")
    if dim == 2:
        for name, y in (("l4", p.l4), ("l4_2", p.l4_2)):
            if y > 0 and abs(y - p.l) < 0.5 * (p.t_C + p.arm_thickness):
                raise InputError(name, f"in 2-D the tie bar at {y} m overlaps the arms at l = {p.l} m",
                                 "move it clear of the arms or use --dim 3")
    if dim == 3 and tie_depth(p) > p.depth - p.arm_depth:
        raise InputError("A_C", f"tie-bar depth A_C/t_C = {tie_depth(p):g} m does not fit behind the arms "
                         f"({p.depth - p.arm_depth:g} m)", "raise t_C or lower A_C")
    return p


def validate_mesh(m: MeshParams) -> MeshParams:
    """Return ``m`` if its sizes are usable, else raise :class:`InputError`."""
    return check_fields(m, "mesh.")


def check_tie_depth(p: FrameParams) -> FrameParams:
    """Return ``p`` if its tie bars are no deeper than the columns (as a built frame needs;
    a 2-D beam-theory study may set a deeper plane-section tie bar through ``A_C``)."""
    if tie_depth(p) > p.depth:
        raise InputError("A_C", f"tie-bar depth A_C/t_C = {tie_depth(p):g} m exceeds the column depth {p.depth:g} m",
                         "lower A_C or raise t_C")
    return p
