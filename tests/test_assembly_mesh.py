"""Assemblies and group rules of a case's geometry: several solids made conformal (one
connected mesh, the interface ``A/B``), regions named by CAD label or ``solid1`` …, the
file's own physical groups kept through the fragments, groups by a union of boxes, by
outward normal and as the rest of the boundary, the connected parts of a mesh, and the
element-count estimate against gmsh's counts."""
from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from gatetherm import InputError
from gatetherm.geometry.gmshfile import MeshSpec, mesh_geometry
from gatetherm.geometry.groups import GroupRule
from gatetherm.geometry.mesh import FrameMesh, components
from gatetherm.cli import main

from test_geometry import _measure


def _step(path: Path, boxes, labels=()) -> Path:
    """Write boxes (x, y, z, dx, dy, dz) as one STEP with gmsh's OCC API; ``labels`` replace
    the translator's product names (gmsh writes no names of its own)."""
    from gatetherm.geometry.isolate import gmsh_session

    with gmsh_session() as gmsh:
        for b in boxes:
            gmsh.model.occ.addBox(*b)
        gmsh.model.occ.synchronize()
        gmsh.write(str(path))
    if labels:  # the solids' products are 'Open CASCADE STEP translator <version> <n>.<i>'
        name = re.compile(r"'Open CASCADE STEP translator [\d.]+ \d+\.(\d+)'")
        path.write_text(name.sub(lambda m: f"'{labels[int(m.group(1)) - 1]}'", path.read_text()))
    return path


TWO = [(0, 0, 0, 1, 1, 1), (1, 0, 0, 1, 1, 1)]


def test_two_touching_boxes_from_one_step_make_one_connected_mesh(tmp_path):
    fm = mesh_geometry(MeshSpec(_step(tmp_path / "two.step", TWO, ("column", "sleeve")), 0.25))
    assert list(fm.regions) == ["column", "sleeve"]
    assert components(fm) == [{"column", "sleeve"}]
    iface = fm.boundaries["column/sleeve"]
    assert _measure(fm.points, iface) == pytest.approx(1.0, rel=1e-12)
    assert np.allclose(fm.points[np.unique(iface)][:, 0], 1.0)
    shared = set(np.unique(fm.cells[fm.regions["column"]])) & set(np.unique(fm.cells[fm.regions["sleeve"]]))
    assert shared == set(np.unique(iface))  # the interface's nodes are nodes of both solids' elements
    for r in fm.regions:
        assert _measure(fm.points, fm.cells[fm.regions[r]]) == pytest.approx(1.0, rel=1e-12)


def test_unlabelled_solids_are_solid1_solid2_and_a_gap_gives_two_parts(tmp_path):
    fm = mesh_geometry(MeshSpec(_step(tmp_path / "two.step", TWO), 0.25))
    assert list(fm.regions) == ["solid1", "solid2"] and "solid1/solid2" in fm.boundaries
    gap = mesh_geometry(MeshSpec(_step(tmp_path / "gap.step", [TWO[0], (1.1, 0, 0, 1, 1, 1)]), 0.25))
    assert sorted(map(sorted, components(gap))) == [["solid1"], ["solid2"]]
    assert not any("/" in b for b in gap.boundaries)


def test_the_files_groups_survive_the_fragments(tmp_path):
    """Two rectangles meeting along half an edge (not fragmented by the script): the
    right edge of 'a' is split by the fragments and still measures 1."""
    (tmp_path / "a.geo").write_text('SetFactory("OpenCASCADE");\nRectangle(1) = {0, 0, 0, 1, 1};\n'
                                    'Rectangle(2) = {1, 0.5, 0, 1, 1};\nPhysical Surface("a") = {1};\n'
                                    'Physical Surface("b") = {2};\nPhysical Curve("right_a") = {2};\n'
                                    'Physical Curve("left_a") = {4};\n')
    fm = mesh_geometry(MeshSpec(tmp_path / "a.geo", 0.1))
    assert list(fm.regions) == ["a", "b"] and components(fm) == [{"a", "b"}]
    got = {b: _measure(fm.points, f) for b, f in fm.boundaries.items()}
    assert got == pytest.approx({"right_a": 1.0, "left_a": 1.0, "a/b": 0.5}, rel=1e-12)


def test_a_case_names_the_interface_in_its_tables(tmp_path, capsys):
    """Steady conduction through column (k = 50) and sleeve (k = 25), 100 °C and 0 °C at the
    far ends: the interface's mean temperature is 100 k1 / (k1 + k2) = 66.67 °C, exact at P1."""
    _step(tmp_path / "two.step", TWO, ("column", "sleeve"))
    (tmp_path / "case.toml").write_text(
        '[mesh]\nfile = "two.step"\nsize = 0.25\n'
        '[mesh.groups.hot]\ndim = 2\nnormal = [-1, 0, 0]\n[mesh.groups.cold]\ndim = 2\nnormal = [1, 0, 0]\n'
        '[materials.column]\nk = 50.0\n[materials.sleeve]\nk = 25.0\n'
        '[thermal.hot]\ntemperature = 100.0\n[thermal.cold]\ntemperature = 0.0\n'
        '[means]\ninterface = "column/sleeve"\n[probes.mid]\npoint = [1.0, 0.5, 0.5]\n')
    assert main(["run", str(tmp_path / "case.toml"), "--out", str(tmp_path / "out")]) == 0, capsys.readouterr().err
    rows = [r for r in (tmp_path / "out" / "timeseries.csv").read_text().splitlines() if not r.startswith("#")]
    head, last = rows[0].split(","), rows[-1].split(",")
    assert float(last[head.index("T_interface_degC")]) == pytest.approx(200 / 3, rel=1e-9)
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["probes"]["mid"]["T_degC"] == pytest.approx(200 / 3, rel=1e-9)


BOX = 'SetFactory("OpenCASCADE");\nBox(1) = {0, 0, 0, 1, 2, 3};\n'
"""Faces: x = 0, 1 of area 6; y = 0, 2 of area 3; z = 0, 3 of area 2."""


def _areas(tmp_path, *rules) -> dict[str, float]:
    (tmp_path / "box.geo").write_text(BOX)
    fm = mesh_geometry(MeshSpec(tmp_path / "box.geo", 0.5, groups=rules))
    assert list(fm.regions) == ["solid"]
    return {b: _measure(fm.points, f) for b, f in fm.boundaries.items()}


def test_groups_by_boxes_normal_and_rest(tmp_path):
    e = 1e-6
    got = _areas(tmp_path,
                 GroupRule("ends", 2, boxes=((-e, -e, -e, e, 2 + e, 3 + e), (1 - e, -e, -e, 1 + e, 2 + e, 3 + e))),
                 GroupRule("top", 2, normal=(0, 0, 1)),
                 GroupRule("front_low", 2, boxes=((-e, -e, -e, 1 + e, 2 + e, 1.5),), normal=(0, 0, -1)),
                 GroupRule("others", 2, rest=True),
                 GroupRule("origin", 0, boxes=((-e, -e, -e, e, e, e),)))
    assert got == pytest.approx({"ends": 12.0, "top": 2.0, "front_low": 2.0, "others": 6.0}, rel=1e-12)


def test_the_normal_tolerance(tmp_path):
    """[0, 0.01, 1] is 0.01 rad off the top face's normal: outside the default 1e-3 rad, inside 0.02."""
    with pytest.raises(InputError, match=r"mesh\.groups\.top: no 2-D entity with outward normal \[0, 0\.01, 1\]"):
        _areas(tmp_path, GroupRule("top", 2, normal=(0, 0.01, 1)))
    assert _areas(tmp_path, GroupRule("top", 2, normal=(0, 0.01, 1), tolerance=0.02)) == {"top": pytest.approx(2.0)}


CASE_GROUPS = """[mesh]
file = "box.geo"
size = 0.5
[mesh.groups.hot]
dim = 2
box = [-1e-6, -1e-6, -1e-6, 1e-6, 2.000001, 3.000001]
[mesh.groups.ends]
dim = 2
box = [[-1e-6, -1e-6, -1e-6, 1.000001, 1e-6, 3.000001], [-1e-6, 1.999999, -1e-6, 1.000001, 2.000001, 3.000001]]
[mesh.groups.cooled]
dim = 2
rest = true
[materials.solid]
k = 50.0
[thermal.hot]
temperature = 100.0
[thermal.cooled]
film = 10.0
ambient = 20.0
"""


def test_case_group_keys_old_and_new_forms(tmp_path, capsys):
    """The single box of before, a list of boxes and rest = true from a case file; bad forms in one line."""
    from gatetherm.studies.run.case import load_case

    (tmp_path / "box.geo").write_text(BOX)
    (tmp_path / "case.toml").write_text(CASE_GROUPS)
    fm = load_case(tmp_path / "case.toml").mesh
    got = {b: _measure(fm.points, f) for b, f in fm.boundaries.items()}
    assert got == pytest.approx({"hot": 6.0, "ends": 6.0, "cooled": 10.0}, rel=1e-12)
    hot = "box = [-1e-6, -1e-6, -1e-6, 1e-6, 2.000001, 3.000001]"
    for old, new, needle in [
            (hot, "box = [1, 2]", "mesh.groups.hot.box: expected [xmin, ymin, zmin, xmax, ymax, zmax] or a list"),
            ("rest = true", "rest = 1", "mesh.groups.cooled.rest: expected true or false"),
            (hot, "normal = [0, 0, 0]", "mesh.groups.hot.normal: expected a direction"),
            (hot, f"{hot}\ntolerance = 0.1", "mesh.groups.hot.tolerance: goes with normal only")]:
        (tmp_path / "bad.toml").write_text(CASE_GROUPS.replace(old, new))
        with pytest.raises(InputError, match=re.escape(needle)):
            load_case(tmp_path / "bad.toml")


def test_components_of_a_mesh():
    """Two triangles sharing an edge and a third one apart: regions 'a' (both sides) and 'b'."""
    pts = np.array([[0, 0], [1, 0], [0, 1], [1, 1], [3, 0], [4, 0], [3, 1]], dtype=float)
    cells = np.array([[0, 1, 2], [1, 3, 2], [4, 5, 6]])
    fm = FrameMesh(2, pts, cells, {"a": np.array([0, 2]), "b": np.array([1])}, {}, {})
    assert components(fm) == [{"a", "b"}, {"a"}]


@pytest.mark.parametrize("case, low, high", [("nafems/t4.toml", 1.2, 1.35), ("nafems/t1.toml", 1.9, 2.1),
                                             ("examples/c_frame/case.toml", 1.45, 1.65)])
def test_the_element_estimate_against_gmsh(case, low, high):
    """The estimate (before meshing) over gmsh's count (after): 1.26 on T4 (sizes at points),
    2.03 on T1 (a Threshold field of the script), 1.54 on the C-frame (a refinement of the case)."""
    import tomllib

    from gatetherm.geometry import gmshfile, groups
    from gatetherm.geometry.isolate import gmsh_session
    from gatetherm.geometry.sizing import model_estimate
    from gatetherm.studies.run.case import load_case

    path = Path(__file__).resolve().parents[1] / "validation" / case
    m = tomllib.loads(path.read_text())["mesh"]
    spec = MeshSpec(path.parent / m["file"], m.get("size"), m.get("parameters", {}),
                    tuple(gmshfile.Refinement(**r) for r in m.get("refine", [])))
    with gmsh_session() as gmsh:
        dim = gmshfile._read(gmsh, spec)
        groups.regions(gmsh, spec.groups, dim)
        if spec.size:
            gmsh.option.setNumber("Mesh.MeshSizeMax", spec.size)
        gmshfile._refine(gmsh, spec, groups.physical(gmsh))
        estimate = sum(n for n, _, _ in model_estimate(gmsh, dim))
    assert low < estimate / len(load_case(path).mesh.cells) < high


def test_the_mesh_factor_scales_the_scripts_own_sizes():
    """T4 takes its sizes from its points (no size in the case): --mesh-factor 0.5 halves them,
    about four times the triangles (it changed nothing before)."""
    from gatetherm.studies.run.case import load_case

    t4 = Path(__file__).resolve().parents[1] / "validation" / "nafems" / "t4.toml"
    ratio = len(load_case(t4, 0.5).mesh.cells) / len(load_case(t4).mesh.cells)
    assert ratio == pytest.approx(3.92, abs=0.05)  # achieved 5241 / 1337 = 3.920; band: 4 ± 10 %
    assert 3.6 < ratio < 4.4


def test_a_composite_wall_from_one_step_with_a_contact_conductance(tmp_path, capsys):
    """The same two solids with a thermal contact of 500 W/(m² K) between them: q = ΔT / (L/k1 +
    1/h + L/k2), the column's face of the interface at 100 − q L/k1, the jump q/h (1-D, exact at P1)."""
    _step(tmp_path / "two.step", TWO, ("column", "sleeve"))
    (tmp_path / "case.toml").write_text(
        '[mesh]\nfile = "two.step"\nsize = 0.25\n'
        '[mesh.groups.hot]\ndim = 2\nnormal = [-1, 0, 0]\n[mesh.groups.cold]\ndim = 2\nnormal = [1, 0, 0]\n'
        '[materials.column]\nk = 50.0\n[materials.sleeve]\nk = 25.0\n'
        '[thermal.hot]\ntemperature = 100.0\n[thermal.cold]\ntemperature = 0.0\n'
        '[contacts.fit]\nbetween = ["column", "sleeve"]\nconductance = 500.0\n'
        '[means]\ninterface = "column/sleeve"\n[probes.a]\npoint = [0.5, 0.5, 0.5]\n[probes.b]\npoint = [1.5, 0.5, 0.5]\n')
    assert main(["run", str(tmp_path / "case.toml"), "--out", str(tmp_path / "out"), "--no-pictures"]) == 0, \
        capsys.readouterr().err
    probes = json.loads((tmp_path / "out" / "summary.json").read_text())["probes"]
    q = 100.0 / (1 / 50 + 1 / 500 + 1 / 25)
    a, b = probes["a"]["T_degC"], probes["b"]["T_degC"]
    assert a == pytest.approx(100 - q * 0.5 / 50, rel=1e-9) and b == pytest.approx(q * 0.5 / 25, rel=1e-9)
    jump = (a - q * 0.5 / 50) - (b + q * 0.5 / 25)  # both sides extrapolated to the interface
    assert abs(jump / (q / 500) - 1) < 0.005 and jump / (q / 500) - 1 == pytest.approx(0.0, abs=1e-9)
