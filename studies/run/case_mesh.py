"""The ``[mesh]`` table of a case file: a mesh file read, or a geometry (``.geo``, CAD) meshed
through gmsh with its parameters, refinements, named groups and included files."""
from __future__ import annotations

import logging
import math
import re
from pathlib import Path

from gatetherm import InputError
from gatetherm.checks import Range
from gatetherm.geometry.gmshfile import CAD, SCRIPT, MeshSpec, Refinement, mesh_geometry
from gatetherm.geometry.groups import NORMAL_TOLERANCE, GroupRule
from gatetherm.geometry.mesh import FrameMesh, load_mesh
from gatetherm.studies.run.tables import Table

log = logging.getLogger(__name__)

KEYS = {"mesh": ("file", "size", "parameters", "refine", "groups", "include"),
        "mesh.refine": ("near", "size", "distance"),
        "mesh.groups.NAME": ("dim", "box", "rest", "normal", "tolerance")}
"""The keys of the mesh tables (as :data:`gatetherm.studies.run.case.KEYS`)."""
METRES = Range(0.0, lo_open=True, unit="m")


def read_mesh(top: Table, base: Path, factor: float = 1.0) -> FrameMesh:
    m = top.sub("mesh", KEYS["mesh"])
    path = base / m.string("file")
    if not path.is_file():
        m.fail("file", f"no such file '{path}'", "give a .msh, .geo or CAD file beside the case")
    suffix = path.suffix.lower()
    if suffix in (".msh", ".vtu"):
        for k in ("size", "parameters", "refine", "groups", "include"):
            if k in m.data:
                m.fail(k, f"applies only to a geometry that gatetherm meshes ({SCRIPT}, {', '.join(CAD)})",
                       "mesh the file again in gmsh, or give the .geo")
        if factor != 1.0:
            m.fail("file", "a mesh file cannot be refined", "give the .geo or CAD file to mesh it finer")
        return _in_case(top, load_mesh, path)
    if suffix not in (SCRIPT, *CAD):
        m.fail("file", f"unknown mesh or geometry format '{suffix}'", f"use .msh, {SCRIPT} or {', '.join(CAD)}")
    params = m.sub("parameters")
    refine = []
    for i, r in enumerate(m.data.get("refine", [])):
        rt = Table(top.file, f"mesh.refine[{i + 1}]", r, KEYS["mesh.refine"], top.said)
        refine.append(Refinement(rt.string("near"), factor * rt.number("size", METRES),
                                 rt.number("distance", METRES)))
    include = m.data.get("include", [])
    if not (isinstance(include, list) and all(isinstance(f, str) for f in include)):
        m.fail("include", f"expected a list of file names, got {include!r}", 'e.g. include = ["../common.geo"]')
    for f in include:
        if not (base / f).is_file():
            m.fail("include", f"no such file '{base / f}'",
                   "name files the geometry script reads, relative to the case")
    groups = tuple(_group(m.sub("groups").sub(name, KEYS["mesh.groups.NAME"]), name)
                   for name in m.data.get("groups", {}))
    size = factor * m.number("size", METRES, 0.0) or None
    if suffix == SCRIPT and params.data:
        _parameters_read(params, [path, *(base / f for f in include)])
    for i, r in enumerate(refine):
        if size and r.size >= size:
            top.said.warn(log, "%s: mesh.refine[%d].size %g m is not finer than [mesh] size %g m: it changes nothing; "
                          "give a smaller size, or remove the refinement", top.file, i + 1, r.size / factor,
                          size / factor)
    return _in_case(top, mesh_geometry, MeshSpec(path, size, {k: params.number(k) for k in params.data},
                                                 tuple(refine), groups, tuple(base / f for f in include), base, factor))


def _parameters_read(params: Table, scripts) -> None:
    """InputError for a ``[mesh.parameters]`` name that no script (the .geo, its included files)
    mentions: a misspelt parameter would leave the geometry at its default without a word."""
    text = "\n".join(f.read_text(encoding="utf-8", errors="replace") for f in scripts)
    for name in params.data:
        if not re.search(rf"(?<![A-Za-z0-9_]){re.escape(name)}(?![A-Za-z0-9_])", text):
            params.fail(name, f"is not a variable of {scripts[0].name}{' or its includes' if len(scripts) > 1 else ''}"
                        ": the geometry would not change", "name a variable the script reads (check the spelling)")


def _in_case(top: Table, read, arg) -> FrameMesh:
    """``read(arg)``, its errors about case keys (``mesh.…``, ``--mesh-factor``) naming the case file;
    where ``[mesh.parameters]`` shaped the geometry, the fix names them too (a point off the body
    may be a parameter's doing: its value is the cause the message can name)."""
    try:
        return read(arg)
    except InputError as err:
        given = ", ".join(f"{k} = {v:g}" for k, v in getattr(arg, "parameters", {}).items())
        if given:
            err = type(err)(err.field, err.problem, "; ".join(filter(None, (
                err.fix, f"the geometry was made with [mesh.parameters] {given}: check them"))))
        raise err.at(str(top.file)) if err.field.startswith(("mesh", "--")) else err from None


def _group(g: Table, name: str) -> GroupRule:
    """A [mesh.groups.NAME] rule: box (one or a list), rest, normal (with tolerance)."""
    box = g.data.get("box", [])
    boxes = [box] if box and all(isinstance(b, (int, float)) for b in box) else box
    if not (isinstance(boxes, list) and all(numbers(b, (6,)) for b in boxes)):
        g.fail("box", f"expected [xmin, ymin, zmin, xmax, ymax, zmax] or a list of them, got {box!r}",
               "give six numbers in m per box")
    rest = g.data.get("rest", False)
    if not isinstance(rest, bool):
        g.fail("rest", f"expected true or false, got {rest!r}")
    normal = g.data.get("normal")
    if normal is not None and not (numbers(normal, (2, 3)) and any(normal)):
        g.fail("normal", f"expected a direction [nx, ny(, nz)], got {normal!r}", "e.g. normal = [0, 0, 1]")
    if not (boxes or rest or normal):
        g.fail("box", "the group selects nothing", "give box, normal or rest = true")
    if "tolerance" in g.data and normal is None:
        g.fail("tolerance", "goes with normal only", "remove it or give normal")
    return GroupRule(name, int(g.number("dim", Range(0, 3, whole=True))), tuple(tuple(map(float, b)) for b in boxes),
                     rest, tuple(map(float, normal)) if normal else None,
                     g.number("tolerance", Range(0.0, math.pi, lo_open=True, unit="rad"), NORMAL_TOLERANCE))


def numbers(v, lengths) -> bool:
    """Whether ``v`` is a list of finite numbers of one of ``lengths``."""
    return isinstance(v, list) and len(v) in lengths and all(
        isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in v)
