"""Frame geometry and meshing: named groups, sensor positions, region and boundary
measures by hand, the .msh/.vtu round trip, gmsh clean-up, and one-line input errors."""
from __future__ import annotations

import dataclasses

import gmsh
import numpy as np
import pytest

import gatetherm.frame.build
from gatetherm.frame.build import build_mesh
from gatetherm import InputError
from gatetherm.frame.geometry import FrameParams, MeshParams, sensor_points, tie_depth, validate, width
from gatetherm.geometry.mesh import load_mesh, save_mesh

from conftest import COARSE, FIXED as P
REGIONS = {"column_L", "column_R", "arm_L", "arm_R", "tie_bar", "tie_joint_L", "tie_joint_R"}
BOUNDARIES = {"mounting_face", "tank_wall", "free_surface"}
SENSORS = {"A", "B", *(f"C{i}" for i in range(1, 11)), "E_L", "E_R", "F_L", "F_R"}


@pytest.fixture(params=[2, 3], ids=["2D", "3D"])
def frame(request, frame_2d, frame_3d):
    return frame_2d if request.param == 2 else frame_3d


def _measure(points, simplices) -> float:
    """Total length/area/volume of simplices given by node indices (m, m², m³)."""
    X = points[simplices]
    E = X[:, 1:] - X[:, :1]
    if E.shape[1] == E.shape[2]:  # full-dimensional cells
        return float(np.abs(np.linalg.det(E)).sum() / (2.0 if E.shape[1] == 2 else 6.0))
    if E.shape[1] == 1:  # segments
        return float(np.linalg.norm(E[:, 0], axis=1).sum())
    return float(0.5 * np.linalg.norm(np.cross(E[:, 0], E[:, 1]), axis=1).sum())


def expected_regions(p: FrameParams, dim: int) -> dict[str, float]:
    """Region areas (2-D) or volumes (3-D) from the parameters by hand."""
    arm = 0.5 * (width(p) - p.gap) - p.h          # arm length, column face to tip
    mid = p.l_C - 2 * p.joint_layer                # tie bar between its end layers
    col = p.h * p.column_height
    tank = p.tank_width * p.tank_height
    d_col, d_arm, d_tie = (1.0, 1.0, 1.0) if dim == 2 else (p.depth, p.arm_depth, tie_depth(p))
    out = {"column_L": (col * d_col - tank * (1.0 if dim == 2 else p.tank_depth)),
           "column_R": col * d_col, "arm_L": arm * p.arm_thickness * d_arm,
           "arm_R": arm * p.arm_thickness * d_arm}
    for sfx in ("", "_2") if p.l4_2 else ("",):
        out |= {f"tie_bar{sfx}": mid * p.t_C * d_tie,
                f"tie_joint_L{sfx}": p.joint_layer * p.t_C * d_tie,
                f"tie_joint_R{sfx}": p.joint_layer * p.t_C * d_tie}
    return out


def expected_boundaries(p: FrameParams, dim: int) -> dict[str, float]:
    """Boundary lengths (2-D) or areas (3-D) by hand: the surface of two columns, two
    arms and the tie bars less their contact faces; the tank wall inside column_L."""
    arm = 0.5 * (width(p) - p.gap) - p.h
    H, n = p.column_height, 2 if p.l4_2 else 1
    if dim == 2:
        free = 2 * (2 * (p.h + H) - p.arm_thickness - n * p.t_C) \
            + 2 * (2 * arm + p.arm_thickness) + n * 2 * p.l_C - 2 * p.h
        return {"mounting_face": 2 * p.h, "free_surface": free,
                "tank_wall": 2 * (p.tank_width + p.tank_height)}
    d, a, td = p.depth, p.arm_thickness * p.arm_depth, tie_depth(p)
    free = 2 * (2 * (p.h * H + p.h * d + H * d) - a - n * p.t_C * td) \
        + 2 * (2 * arm * (p.arm_thickness + p.arm_depth) + a) \
        + n * 2 * p.l_C * (p.t_C + td) - 2 * p.h * d
    w, ht, dt = p.tank_width, p.tank_height, p.tank_depth
    return {"mounting_face": 2 * p.h * d, "free_surface": free,
            "tank_wall": 2 * (w * ht + ht * dt + w * dt)}


def test_named_groups(frame):
    assert set(frame.regions) == REGIONS
    assert set(frame.boundaries) == BOUNDARIES
    assert set(frame.sensors) == SENSORS
    assert all(len(v) > 0 for v in (*frame.regions.values(), *frame.boundaries.values()))
    cells = np.concatenate(list(frame.regions.values()))
    assert np.array_equal(np.sort(cells), np.arange(len(frame.cells)))  # a partition


def test_sensor_positions(frame):
    want = sensor_points(P, frame.dim)
    for name in SENSORS:
        np.testing.assert_allclose(frame.sensor_xyz(name), want[name][:frame.dim], rtol=0, atol=1e-12)
    # spot checks by hand: A on the outer face, B on the inner face at sensor_height
    np.testing.assert_allclose(frame.sensor_xyz("B")[:2], [0.12, 0.125], atol=1e-12)
    np.testing.assert_allclose(frame.sensor_xyz("F_R")[:2], [0.33, 0.50], atol=1e-12)


def test_region_measures(frame):
    want = expected_regions(P, frame.dim)
    got = {k: _measure(frame.points, frame.cells[v]) for k, v in frame.regions.items()}
    assert got == pytest.approx(want, rel=1e-10)
    if frame.dim == 2:  # h * column_height - tank area = 0.12*0.53 - 0.05*0.21
        assert got["column_L"] == pytest.approx(0.0531, rel=1e-10)


def test_boundary_measures(frame):
    want = expected_boundaries(P, frame.dim)
    got = {k: _measure(frame.points, v) for k, v in frame.boundaries.items()}
    assert got == pytest.approx(want, rel=1e-10)
    assert (got["free_surface"], got["tank_wall"]) == pytest.approx(
        (3.84, 0.52) if frame.dim == 2 else (0.704, 0.0626), rel=1e-10)


@pytest.mark.parametrize("suffix", [".msh", ".vtu"])
def test_round_trip(frame, suffix, tmp_path):
    path = tmp_path / f"frame{suffix}"
    save_mesh(frame, path)
    back = load_mesh(path)
    assert [p.name for p in tmp_path.iterdir()] == [path.name]  # no temporary left
    assert back.dim == frame.dim
    np.testing.assert_array_equal(back.points, frame.points)
    assert list(back.regions) == list(frame.regions)
    for name, idx in frame.regions.items():
        np.testing.assert_array_equal(back.cells[back.regions[name]], frame.cells[idx])
    assert set(back.boundaries) == set(frame.boundaries)
    for name, fac in frame.boundaries.items():
        np.testing.assert_array_equal(back.boundaries[name], fac)
    assert back.sensors == frame.sensors


def test_gmsh_finalised_after_build():
    build_mesh(P, 2, COARSE)
    assert not gmsh.isInitialized()


def test_gmsh_finalised_when_build_raises(monkeypatch):
    def fail(*args, **kwargs):
        assert gmsh.isInitialized()
        raise RuntimeError("extraction failed")
    monkeypatch.setattr(gatetherm.frame.build, "extract_mesh", fail)
    with pytest.raises(RuntimeError, match="extraction failed"):
        build_mesh(P, 2, COARSE)
    assert not gmsh.isInitialized()


def _fields_set_to(value):
    for f in dataclasses.fields(FrameParams):
        v = -0.1 if f.name == "l4_2" else value
        yield pytest.param({f.name: v}, None, f.name, id=f"{f.name}={v}")


BAD = [
    *_fields_set_to(0.0),
    *_fields_set_to(-0.05),
    pytest.param({"l1": 0.6}, None, "l1", id="l1>l"),
    pytest.param({"l": 0.52}, None, "l", id="arm-above-column"),
    pytest.param({"l4": 0.52}, None, "l4", id="l4-above-column"),
    pytest.param({"l4": 0.01}, None, "l4", id="l4-below-mounting"),
    pytest.param({"l4": 0.48}, 2, "l4", id="tie-on-arms-2D"),
    pytest.param({"l4_2": 0.27}, None, "l4_2", id="ties-overlap"),
    pytest.param({"l4_2": 0.49}, 2, "l4_2", id="tie2-on-arms-2D"),
    pytest.param({"tank_width": 0.105}, None, "tank_width", id="tank-to-inner-face"),
    pytest.param({"tank_height": 0.52}, None, "tank_height", id="tank-through-top"),
    pytest.param({"tank_depth": 0.12}, None, "tank_depth", id="tank-through-depth"),
    pytest.param({"A_C": 2.8e-3}, 3, "A_C", id="tie-too-deep-3D"),
    pytest.param({"gap": 0.4}, None, "gap", id="gap>=l_C"),
    pytest.param({"joint_layer": 0.2}, None, "joint_layer", id="joint-layers-fill-tie"),
    pytest.param({"sensor_height": 0.6}, None, "sensor_height", id="sensors-above-column"),
]


@pytest.mark.parametrize("changes, dim, field", BAD)
def test_bad_parameters(changes, dim, field):
    """Each refusal is an InputError whose message is one line 'field: problem[; fix]';
    build_mesh refuses before starting gmsh. Dimension-specific refusals pass in the
    other dimension."""
    p = dataclasses.replace(P, **changes)
    with pytest.raises(InputError) as err:
        validate(p, dim)
    assert err.value.field == field
    msg = str(err.value)
    assert msg.startswith(f"{field}: ") and "\n" not in msg and len(msg) < 200
    with pytest.raises(InputError, match=f"^{field}: "):
        build_mesh(p, dim or 2, COARSE)
    assert not gmsh.isInitialized()
    if dim is not None:
        assert validate(p, 5 - dim) is p
    if dim is None:
        with pytest.raises(InputError, match=f"^{field}: "):
            P.replace(**changes)


@pytest.mark.parametrize("mesh", [MeshParams(size=0.0), MeshParams(size=-0.01),
                                  MeshParams(size=0.02, refine=0.0)], ids=["size=0", "size<0", "refine=0"])
def test_bad_mesh_parameters(mesh):
    with pytest.raises(InputError, match=r"^mesh\.(size|refine): "):
        build_mesh(P, 2, mesh)
    assert not gmsh.isInitialized()


def test_second_tie_bar():
    p = P.replace(l4_2=0.40)
    fm = build_mesh(p, 2, COARSE)
    assert set(fm.regions) == REGIONS | {"tie_bar_2", "tie_joint_L_2", "tie_joint_R_2"}
    got = {k: _measure(fm.points, fm.cells[v]) for k, v in fm.regions.items()}
    assert got == pytest.approx(expected_regions(p, 2), rel=1e-10)
    assert got["tie_bar_2"] == pytest.approx(0.39 * 0.04, rel=1e-10)  # (l_C - 2 joint_layer) t_C
    got_b = {k: _measure(fm.points, v) for k, v in fm.boundaries.items()}
    assert got_b == pytest.approx(expected_boundaries(p, 2), rel=1e-10)
    # the second bar really sits at l4_2: its cells lie within l4_2 ± t_C/2
    y = fm.points[fm.cells[fm.regions["tie_bar_2"]]][..., 1]
    assert y.min() == pytest.approx(0.38, abs=1e-12) and y.max() == pytest.approx(0.42, abs=1e-12)


def test_facet_keys_order_rows_alike_past_int64():
    """Boundary facets are matched by key (``to_skfem``, ``check_mesh``); past 2 million nodes in 3-D the integer
    key n²a + nb + c would overflow int64, so the key is then a record of the sorted row. Both
    kinds order rows alike, and each row is found again."""
    from gatetherm.geometry.mesh import facet_keys as _keys

    rows = np.random.default_rng(1).integers(0, 50, (400, 3))
    small, big = _keys(rows, 50), _keys(rows, 3_000_000)
    assert small.dtype == np.int64 and big.dtype.names == ("n0", "n1", "n2")
    assert np.array_equal(np.argsort(small, kind="stable"), np.argsort(big, kind="stable"))
    ordered = np.sort(big)
    assert np.array_equal(ordered[np.searchsorted(ordered, big)], big)
    assert _keys(np.array([[2_999_999] * 3]), 3_000_000)[0].tolist() == (2_999_999,) * 3  # no wrap-around


SQUARE_MSH = """$MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
2
1 1 "edge"
2 2 "plate"
$EndPhysicalNames
$Nodes
{nodes}
$EndNodes
$Elements
{elements}
$EndElements
"""


def _msh(nodes, tris, edges=((1, 2),)) -> str:
    n = [f"{i + 1} {x} {y} 0" for i, (x, y) in enumerate(nodes)]
    e = [f"{i + 1} 1 2 1 1 {a} {b}" for i, (a, b) in enumerate(edges)]
    e += [f"{len(e) + i + 1} 2 2 2 1 {a} {b} {c}" for i, (a, b, c) in enumerate(tris)]
    return SQUARE_MSH.format(nodes="\n".join([str(len(n))] + n), elements="\n".join([str(len(e))] + e))


GOOD = _msh([(0, 0), (1, 0), (1, 1), (0, 1)], [(1, 2, 3), (1, 3, 4)])


def test_binary_msh_is_read_as_meshio_reads_it_and_other_msh_is_left_to_meshio(frame, tmp_path):
    """``save_mesh``'s binary gmsh 2.2 is read in whole arrays: meshio's points, cell blocks,
    physical tags and names; ASCII is left to meshio; a cut binary file is one InputError."""
    import meshio

    from gatetherm.geometry import msh22

    path = tmp_path / "frame.msh"
    save_mesh(frame, path)
    got, want = msh22.read_binary(path.read_bytes()), meshio.gmsh.read(str(path))
    np.testing.assert_array_equal(got.points, want.points)
    assert [b.type for b in got.cells] == [b.type for b in want.cells] == \
        (["triangle", "line", "vertex"] if frame.dim == 2 else ["tetra", "triangle", "vertex"])
    for a, b, ta, tb in zip(got.cells, want.cells, got.cell_data["gmsh:physical"], want.cell_data["gmsh:physical"]):
        np.testing.assert_array_equal(a.data, b.data)
        np.testing.assert_array_equal(ta, tb)
    assert {k: list(v) for k, v in got.field_data.items()} == {k: list(v) for k, v in want.field_data.items()}
    meshio.write(tmp_path / "ascii.msh", want, file_format="gmsh22", binary=False)
    assert msh22.read_binary((tmp_path / "ascii.msh").read_bytes()) is None
    (tmp_path / "cut.msh").write_bytes(path.read_bytes()[:-1000])
    with pytest.raises(InputError, match="cut.msh: is not a readable .msh file"):
        load_mesh(tmp_path / "cut.msh")


def _binary_msh(nodes: dict, elements: list) -> bytes:
    """A binary gmsh 2.2 file: ``nodes`` {number: xyz}, ``elements`` [(gmsh type, physical, numbers)];
    physical group 1 is the volume "solid", 2 the surface "face"."""
    out = [b"$MeshFormat\n2.2 1 8\n", np.int32(1).tobytes(), b"\n$EndMeshFormat\n",
           b'$PhysicalNames\n2\n3 1 "solid"\n2 2 "face"\n$EndPhysicalNames\n', f"$Nodes\n{len(nodes)}\n".encode()]
    out += [np.int32(k).tobytes() + np.asarray(x, dtype="<f8").tobytes() for k, x in nodes.items()]
    out.append(f"\n$EndNodes\n$Elements\n{len(elements)}\n".encode())
    for i, (kind, phys, numbers) in enumerate(elements, start=1):
        out.append(np.array([kind, 1, 2, i, phys, phys, *numbers], dtype="<i4").tobytes())
    return b"".join(out + [b"\n$EndElements\n"])


def test_binary_msh_numbered_sparsely_loads_and_a_missing_node_is_one_input_error(tmp_path):
    """Node numbers need not be 1..n: a tetrahedron numbered up to 2e9 loads; an element naming
    a node that ``$Nodes`` does not list is refused, naming the file and the node."""
    xyz = {7: (0, 0, 0), 2_000_000_000: (1, 0, 0), 40: (0, 1, 0), 3: (0, 0, 1)}
    tet, face = (4, 1, [7, 2_000_000_000, 40, 3]), (2, 2, [7, 40, 2_000_000_000])
    (tmp_path / "sparse.msh").write_bytes(_binary_msh(xyz, [tet, face]))
    fm = load_mesh(tmp_path / "sparse.msh")
    np.testing.assert_array_equal(fm.points[fm.cells[0]], [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)])
    np.testing.assert_array_equal(fm.points[fm.boundaries["face"][0]], [(0, 0, 0), (0, 1, 0), (1, 0, 0)])
    assert list(fm.regions) == ["solid"]
    (tmp_path / "missing.msh").write_bytes(_binary_msh(xyz, [(4, 1, [7, 2_000_000_000, 40, 5]), face]))
    with pytest.raises(InputError, match=r"missing\.msh: is not a readable \.msh file \(ValueError: an element has "
                                         r"node 5, which \$Nodes does not list\)"):
        load_mesh(tmp_path / "missing.msh")


@pytest.mark.parametrize("name, body", [
    ("truncated.msh", GOOD[: len(GOOD) // 2]),
    ("garbage.msh", bytes(range(256)) * 4),
    ("latin1.msh", GOOD.replace('"plate"', '"pl\xe4te"').encode("latin-1")),
    ("empty.msh", b""),
    ("text.vtu", "not a VTU file\n"),
    ("broken.vtu", '<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid"><UnstructuredGrid>'),
], ids=["truncated", "garbage", "not-utf8", "empty", "vtu-text", "vtu-cut"])
def test_a_broken_mesh_file_is_one_input_error_naming_it(tmp_path, name, body):
    path = tmp_path / name
    path.write_bytes(body if isinstance(body, bytes) else body.encode())
    with pytest.raises(InputError) as err:
        load_mesh(path)
    assert err.value.field == str(path) and "\n" not in str(err.value)


def test_zero_area_elements_are_refused():
    """A triangle on three collinear nodes (x = 0, 0.5, 1 on y = 0)."""
    from gatetherm.geometry.mesh import check_mesh, from_groups

    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0, 0]], dtype=float)
    fm = from_groups(2, pts, [("plate", 2, np.array([[0, 1, 2], [0, 2, 3], [0, 4, 1]]))])
    with pytest.raises(InputError, match=r"^m\.msh: has 1 element\(s\) of zero area \(the first at \(0\.5, 0\)\)"):
        check_mesh(fm, "m.msh")


def test_a_stray_patch_is_refused_naming_the_boundary(tmp_path):
    """A 3-D body whose group 'flap' holds a surface outside it (built-in kernel: not fragmented)."""
    from gatetherm.geometry.gmshfile import MeshSpec, mesh_geometry

    (tmp_path / "a.geo").write_text(
        'Point(1) = {0,0,0,0.5}; Point(2) = {1,0,0,0.5}; Point(3) = {1,1,0,0.5}; Point(4) = {0,1,0,0.5};\n'
        'Line(1) = {1,2}; Line(2) = {2,3}; Line(3) = {3,4}; Line(4) = {4,1};\n'
        'Curve Loop(1) = {1,2,3,4}; Plane Surface(1) = {1};\n'
        'v[] = Extrude {0,0,1} { Surface{1}; };\n'
        'Point(50) = {2,0,0,0.5}; Point(51) = {3,0,0,0.5}; Point(52) = {3,1,0,0.5};\n'
        'Line(60) = {50,51}; Line(61) = {51,52}; Line(62) = {52,50};\n'
        'Curve Loop(60) = {60,61,62}; Plane Surface(60) = {60};\n'
        'Physical Volume("body") = {v[1]}; Physical Surface("base") = {1}; Physical Surface("flap") = {60};\n')
    with pytest.raises(InputError, match=r"a\.geo: boundary flap: has facets that are not facets of the mesh's "):
        mesh_geometry(MeshSpec(tmp_path / "a.geo"))


POINTS = """SetFactory("OpenCASCADE");
Rectangle(1) = {0, 0, 0, 1, 1};
Point(10) = {0.5037, 0.4991, 0};
Physical Surface("plate") = {1};
Physical Point("loose") = {10};
"""


def test_a_point_group_off_the_nodes_is_snapped_or_refused(tmp_path, caplog):
    """A Physical Point not embedded in the surface: read at the nearest node with a warning
    giving the distance (it was read at the last node before); far off the body, refused."""
    from gatetherm.geometry.gmshfile import MeshSpec, mesh_geometry

    (tmp_path / "a.geo").write_text(POINTS)
    fm = mesh_geometry(MeshSpec(tmp_path / "a.geo", 0.1))
    got = fm.points[fm.sensors["loose"]]
    d = np.linalg.norm(fm.points - [0.5037, 0.4991], axis=1)
    assert np.linalg.norm(got - [0.5037, 0.4991]) == d.min() < 0.1  # the nearest node of the mesh
    assert "mesh point loose at (0.5037, 0.4991) is not a node of the mesh's elements: read at the nearest node, " \
           f"{d.min():.3g} m away" in caplog.text
    (tmp_path / "c.geo").write_text(POINTS.replace("0.5037, 0.4991", "1.02, 0.5"))  # off the plate, within tolerance
    fm = mesh_geometry(MeshSpec(tmp_path / "c.geo", 0.1))
    assert fm.points[fm.sensors["loose"]].tolist() == [1.0, 0.5]  # a new user read δ 25 mm from its point
    assert "mesh point loose at (1.02, 0.5) lies outside the meshed body: read at its nearest node, 0.02 m away; move " \
           "the point onto the body" in caplog.text
    (tmp_path / "b.geo").write_text(POINTS.replace("0.5037, 0.4991", "3, 3"))
    with pytest.raises(InputError, match=r"mesh point loose: at \(3, 3\) is 2\.83 m from the nearest node .* more "
                                         r"than the tolerance 0\.\d+ m"):
        mesh_geometry(MeshSpec(tmp_path / "b.geo", 0.1))


@pytest.mark.parametrize("dim", [2, 3])
def test_enclosed_volume_of_the_tank_is_its_box(dim, frame_2d, frame_3d):
    """The oil volume from the tank wall's facets (divergence theorem) is the tank's box, to
    round-off: the box's faces are flat and meshed exactly."""
    from gatetherm.frame.geometry import tank_box
    from gatetherm.geometry.measure import enclosed_volume

    fm = frame_2d if dim == 2 else frame_3d
    p = fm.meta["frame"]
    x0, x1, y0, y1, z0, z1 = tank_box(p, dim)
    depth = p.depth if dim == 2 else 1.0
    assert enclosed_volume(fm, "tank_wall", depth) == pytest.approx((x1 - x0) * (y1 - y0) * (z1 - z0), rel=1e-12)
