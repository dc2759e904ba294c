"""Mechanical loads, joints of an assembly and axisymmetric sections, through case files
written as a user writes them from docs/case-file.md: closed forms with the achieved
values pinned beside the bands, and the refusals of a part held by nothing."""
from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from gatetherm.cli import main
from gatetherm.studies.run.case import load_case
from gatetherm.studies.run.output import probe_summary
from gatetherm.studies.run.scenario import run_scenario

DATA = Path(__file__).resolve().parent / "data"

RECTANGLE = """SetFactory("OpenCASCADE");
Rectangle(1) = {{{x0}, 0, 0, {L}, {H}}};
e = 1e-6;
Physical Surface("body") = {{1}};
Physical Curve("left") = {{Curve In BoundingBox {{{x0} - e, -e, -e, {x0} + e, {H} + e, e}}}};
Physical Curve("right") = {{Curve In BoundingBox {{{x0} + {L} - e, -e, -e, {x0} + {L} + e, {H} + e, e}}}};
Physical Curve("bottom") = {{Curve In BoundingBox {{{x0} - e, -e, -e, {x0} + {L} + e, e, e}}}};
Physical Curve("top") = {{Curve In BoundingBox {{{x0} - e, {H} - e, -e, {x0} + {L} + e, {H} + e, e}}}};
Physical Point("corner") = {{Point In BoundingBox {{{x0} + {L} - e, -e, -e, {x0} + {L} + e, e, e}}}};
Mesh.MeshSizeMax = {h};
"""


def solve(path: Path) -> dict:
    """The probes' summary of a case (as ``gatetherm run`` computes it)."""
    case = load_case(path)
    return probe_summary(case.problem, run_scenario(case).columns)


def write(tmp: Path, case: str, geo: str = "", **dims) -> Path:
    if geo:
        (tmp / "body.geo").write_text(geo.format(**dims))
    (tmp / "case.toml").write_text(case)
    return tmp / "case.toml"


def test_cantilever_under_gravity_against_beam_theory(tmp_path):
    """A steel cantilever 1 m long, 25 mm deep, clamped at x = 0, under its own weight
    (plane stress, P2): tip deflection ρ g A L⁴ / (8 E I) = 3 ρ g L⁴ / (2 E h²); Timoshenko's
    shear term adds 0.07 % at L/h = 40. Purely mechanical: no k, no alpha."""
    L, h, rho, E = 1.0, 0.025, 7850.0, 2.1e11
    path = write(tmp_path, f"""
[case]
order = 2
[mesh]
file = "body.geo"
[materials.body]
E = {E}
nu = 0.3
rho = {rho}
thickness = 0.02
[gravity]
acceleration = [0, -9.81]
[supports.left]
type = "clamped"
[probes.tip]
point = [{L}, {h / 2}]
quantities = ["u"]
""", RECTANGLE, x0=0, L=L, H=h, h=h / 2)
    got = -solve(path)["probes"]["tip"]["uy_um"] * 1e-6
    beam = 3 * rho * 9.81 * L ** 4 / (2 * E * h ** 2)
    assert abs(got / beam - 1) < 0.01
    assert got / beam - 1 == pytest.approx(-0.00020, abs=1e-4)


def test_cantilever_under_a_point_force_against_beam_theory(tmp_path):
    """The same cantilever with 100 N on its tip's bottom corner (a point group): the tip
    deflects P L³ / (3 E I), I = t h³/12, to 1 % at P2."""
    L, h, t, E, P = 1.0, 0.025, 0.02, 2.1e11, 100.0
    path = write(tmp_path, f"""
[case]
order = 2
[mesh]
file = "body.geo"
[materials.body]
E = {E}
nu = 0.3
thickness = {t}
[loads.corner]
force = [0, {-P}]
[supports.left]
type = "clamped"
[probes.tip]
point = [{L}, {h / 2}]
quantities = ["u"]
""", RECTANGLE, x0=0, L=L, H=h, h=h / 2)
    got = -solve(path)["probes"]["tip"]["uy_um"] * 1e-6
    beam = P * L ** 3 / (3 * E * t * h ** 3 / 12)
    assert abs(got / beam - 1) < 0.01
    assert got / beam - 1 == pytest.approx(-0.00016, abs=1e-4)


COMPOSITE = """
[mesh]
file = "two_blocks.geo"
[materials.left]
k = 50.0
[materials.right]
k = 15.0
[thermal.hot]
temperature = 100.0
[thermal.cold]
temperature = 0.0
[contacts.joint]
between = ["right", "left"]
conductance = 2000.0
[means]
face = "left/right"
[probes.a]
point = [0.05, 0.025]
[probes.b]
point = [0.15, 0.025]
"""


@pytest.mark.parametrize("order", [1, 2])
def test_composite_wall_with_contact_conductance_against_the_1d_closed_form(tmp_path, order):
    """Two blocks, 0.1 m each, k = 50 and 15 W/(m K), touching through a contact conductance
    h = 2000 W/(m² K), 100 °C and 0 °C on the outer faces: q = ΔT / (L/k₁ + 1/h + L/k₂), a
    jump q/h at the interface. Temperatures at the blocks' middles and on the left face of
    the interface (the mean over the boundary ``left/right``), to round-off (T is linear)."""
    shutil.copy(DATA / "two_blocks.geo", tmp_path)
    (tmp_path / "case.toml").write_text(f"[case]\norder = {order}\n{COMPOSITE}")
    res = solve(tmp_path / "case.toml")
    L, k1, k2, hc = 0.1, 50.0, 15.0, 2000.0
    q = 100.0 / (L / k1 + 1 / hc + L / k2)
    T_face = 100.0 - q * L / k1
    cols = run_scenario(load_case(tmp_path / "case.toml")).columns
    assert cols["T_face_degC"][-1] == pytest.approx(T_face, rel=1e-9)
    a, b = res["probes"]["a"]["T_degC"], res["probes"]["b"]["T_degC"]
    assert a == pytest.approx(100.0 - q * L / 2 / k1, rel=1e-9)
    assert b == pytest.approx(q * L / 2 / k2, rel=1e-9)
    jump = (a - q * L / 2 / k1) - (b + q * L / 2 / k2)  # both sides extrapolated to the interface
    assert abs(jump / (q / hc) - 1) < 0.005
    assert jump / (q / hc) - 1 == pytest.approx(0.0, abs=1e-9)


def test_a_contact_without_stiffness_is_a_bond(tmp_path):
    """A bimetal of the two blocks (α 12 and 23 µm/(m K)) warmed uniformly by 10 K, one end
    clamped: with a contact conductance only, the blocks stay bonded; the end displacement
    equals the conformal mesh's (no contact) to 10⁻⁶."""
    shutil.copy(DATA / "two_blocks.geo", tmp_path)
    mats = "".join(f"[materials.{r}]\nk = 50.0\nE = 1e11\nnu = 0.3\nalpha = {a}\n" for r, a in
                   (("left", 1.2e-5), ("right", 2.3e-5)))
    body = (f'[mesh]\nfile = "two_blocks.geo"\n{mats}[initial]\ntemperature = 20.0\nreference = 10.0\n'
            '[thermal.hot]\ntemperature = 20.0\n[supports.hot]\ntype = "clamped"\n[probes.end]\npoint = [0.2, 0.05]\n'
            'quantities = ["u"]\n')
    (tmp_path / "case.toml").write_text(body)
    bonded = solve(tmp_path / "case.toml")["probes"]["end"]
    (tmp_path / "case.toml").write_text(body + '[contacts.c]\nbetween = ["left", "right"]\nconductance = 1e3\n')
    joined = solve(tmp_path / "case.toml")["probes"]["end"]
    for k in ("ux_um", "uy_um"):
        assert abs(joined[k] / bonded[k] - 1) < 1e-6  # achieved 2e-10 (ux), 2e-8 (uy)
    assert abs(bonded["uy_um"]) > 1.0  # it bends


def test_elastic_joint_adds_its_compliance(tmp_path):
    """The same blocks in tension: x = 0 held in x, the bottom in y, 1 kN on the right end
    (plane stress, 10 mm thick), joined by a normal stiffness k_n: the end moves
    F (2L/E + 1/k_n) / A, exactly (uniform stress)."""
    shutil.copy(DATA / "two_blocks.geo", tmp_path)
    F, E, kn, A = 1e3, 2e11, 1e12, 0.05 * 0.01
    mat = f"E = {E}\nnu = 0.3\nthickness = 0.01\n"
    (tmp_path / "case.toml").write_text(f"""
[mesh]
file = "two_blocks.geo"
[materials.left]
{mat}[materials.right]
{mat}[contacts.joint]
between = ["left", "right"]
stiffness = [{kn}, 1e11]
[supports.hot]
type = "normal"
[supports.bottom]
type = "normal"
[loads.cold]
force = [{F}, 0]
[probes.end]
point = [0.2, 0.05]
quantities = ["u"]
""")
    got = solve(tmp_path / "case.toml")["probes"]["end"]["ux_um"] * 1e-6
    assert got == pytest.approx(F * (0.2 / E + 1 / kn) / A, rel=1e-9)


def test_axisymmetric_cylinder_log_temperature_and_free_expansion(tmp_path):
    """A hollow cylinder r = 50…100 mm, 50 mm long (axisymmetric, P2), the bore at 80 °C and
    the outside at 20 °C: T(r) = T_i + (T_o − T_i) ln(r/r_i)/ln(r_o/r_i); both at 30 °C
    (10 K above the stress-free 20 °C), held axially on one end: u_r = α ΔT r, no stress."""
    geo = RECTANGLE.replace('"left"', '"bore"').replace('"right"', '"outside"')
    body = """
[case]
order = 2
plane = "axisymmetric"
[mesh]
file = "body.geo"
[materials.body]
k = 45.0
E = 2.1e11
nu = 0.3
alpha = 1.2e-5
[initial]
temperature = 20.0
[thermal.bore]
temperature = {Ti}
[thermal.outside]
temperature = 30.0
[supports.bottom]
type = "normal"
[probes.mid]
point = [0.075, 0.025]
"""
    path = write(tmp_path, body.format(Ti=80.0).replace("temperature = 30.0", "temperature = 20.0"), geo,
                 x0=0.05, L=0.05, H=0.05, h=0.005)
    T = solve(path)["probes"]["mid"]["T_degC"]
    exact = 80.0 - 60.0 * math.log(1.5) / math.log(2.0)
    assert abs(T / exact - 1) < 1e-3
    assert T / exact - 1 == pytest.approx(0.0, abs=2e-6)
    write(tmp_path, body.format(Ti=30.0))
    q = solve(path)["probes"]["mid"]
    assert q["ux_um"] == pytest.approx(1e6 * 1.2e-5 * 10.0 * 0.075, rel=1e-9)
    assert max(abs(q[f"sigma_{c}_MPa"]) for c in ("xx", "yy", "tt", "xy")) < 1e-6


def test_axisymmetric_section_left_of_the_axis_is_refused(tmp_path, capsys):
    path = write(tmp_path, '[case]\nplane = "axisymmetric"\n[mesh]\nfile = "body.geo"\n[materials.body]\nk = 1.0\n'
                 '[thermal.left]\ntemperature = 1.0\n', RECTANGLE, x0=-0.01, L=0.05, H=0.05, h=0.01)
    assert main(["run", str(path), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "case.plane: the section reaches x = -0.01 m < 0" in err


GAP = """SetFactory("OpenCASCADE");
Rectangle(1) = {0, 0, 0, 0.1, 0.05};
Rectangle(2) = {0.11, 0, 0, 0.1, 0.05};
Physical Surface("column") = {1};
Physical Surface("sleeve") = {2};
Physical Curve("base") = {4};
Mesh.MeshSizeMax = 0.02;
"""


@pytest.mark.parametrize("what, case, message", [
    ("gap", '[mesh]\nfile = "body.geo"\n[materials.column]\nk = 1.0\n[materials.sleeve]\nk = 1.0\n'
     '[thermal.base]\ntemperature = 1.0\n',
     "mesh.file: region sleeve touches no other region (the mesh falls into 2 pieces)"),
    ("slide", '[mesh]\nfile = "two_blocks.geo"\n[materials.left]\nE = 1e11\nnu = 0.3\n[materials.right]\nE = 1e11\n'
     'nu = 0.3\n[contacts.guide]\nbetween = ["left", "right"]\nstiffness = [1e12, 0]\n'
     '[supports.hot]\ntype = "clamped"\n'
     '[loads.cold]\npressure = 1e5\n', "supports: the part made of region right is free to move (translation y)"),
])
def test_a_part_held_by_nothing_is_refused_by_name(tmp_path, capsys, what, case, message):
    """A gap between two solids (nothing joins them), and a part on a joint without
    tangential stiffness (a frictionless slide, nothing else holds it): one line, exit 2."""
    shutil.copy(DATA / "two_blocks.geo", tmp_path)
    (tmp_path / "body.geo").write_text(GAP)
    (tmp_path / "case.toml").write_text(case)
    assert main(["run", str(tmp_path / "case.toml"), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and message in err, err


def test_time_varying_load_and_prescribed_displacement_read_out_without_a_solve_per_step(tmp_path):
    """A bar (plane stress, ν = 0) stretched by its right end moved by u(t) = 1 µm · t/10 s: the
    outputs at every step are the term's unit response times its value (one solve in all),
    and the fields at the end carry the displacement."""
    path = write(tmp_path, """
[mesh]
file = "body.geo"
[materials.body]
E = 2e11
nu = 0.0
[supports.left]
type = "normal"
[supports.bottom]
type = "normal"
[supports.right]
type = "displacement"
value = ["1e-6 * t / 10", "free"]
[time]
end = 10.0
step = 5.0
output = 5.0
[probes.mid]
point = [0.5, 0.05]
""", RECTANGLE, x0=0, L=1.0, H=0.1, h=0.05)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--no-pictures"]) == 0
    rows = [r.split(",") for r in (out / "timeseries.csv").read_text().splitlines() if not r.startswith("#")]
    head, ux = rows[0], [float(r[rows[0].index("ux_mid_um")]) for r in rows[1:]]
    assert head[0] == "time_s" and ux == pytest.approx([0.0, 0.25, 0.5], abs=1e-9)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["probes"]["mid"]["sigma_xx_MPa"] == pytest.approx(2e11 * 1e-6 / 1e6, rel=1e-9)
    import meshio

    last = sorted((out / "fields").glob("fields_*.vtu"))[-1]
    u = meshio.read(last).point_data["u"]
    assert np.abs(u[:, 0]).max() == pytest.approx(1e-6, rel=1e-9)


def test_run_warns_when_p1_is_too_coarse_for_bending(tmp_path, caplog):
    """The cantilever under gravity at P1 with two elements through its depth: ``run`` solves
    it once more at P2 on the same mesh and names the output in one warning line with the
    fix; P2 itself is not checked."""
    case = """
[mesh]
file = "body.geo"
[materials.body]
E = 2.1e11
nu = 0.3
rho = 7850.0
[gravity]
acceleration = [0, -9.81]
[supports.left]
type = "clamped"
[probes.tip]
point = [1.0, 0.0125]
quantities = ["u"]
"""
    path = write(tmp_path, case, RECTANGLE, x0=0, L=1.0, H=0.025, h=0.0125)
    with caplog.at_level("WARNING"):
        assert main(["run", str(path), "--out", str(tmp_path / "o"), "--no-pictures"]) == 0
    warned = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    assert len(warned) == 1 and "uy_tip_um changes from" in warned[0] and "set order = 2 in [case]" in warned[0]
    assert "\n" not in warned[0]
    caplog.clear()
    check = json.loads((tmp_path / "o" / "summary.json").read_text())["order_check"]
    assert check["worst"] == "uy_tip_um"
    assert check["outputs"]["uy_tip_um"]["relative"] == pytest.approx(-0.3256, abs=0.003)
    write(tmp_path, case.replace("[mesh]", "[case]\norder = 2\n[mesh]"))
    with caplog.at_level("WARNING"):
        assert main(["run", str(path), "--out", str(tmp_path / "o"), "--no-pictures"]) == 0
    assert not [r for r in caplog.records if r.levelname == "WARNING"]
    assert "order_check" not in json.loads((tmp_path / "o" / "summary.json").read_text())


def test_mechanical_tables_written_back_read_the_same(tmp_path):
    """``case_toml`` of LE1 (a pressure, symmetry) and of a joined, pulled, moved assembly reads
    back to the same problem."""
    from gatetherm.studies.run.casefile import case_toml

    NAFEMS = DATA.parents[1] / "validation" / "nafems"
    shutil.copy(NAFEMS / "le1.geo", tmp_path)
    shutil.copy(DATA / "two_blocks.geo", tmp_path)
    joined = """[mesh]\nfile = "two_blocks.geo"\n[materials.left]\nE = 1e11\nnu = 0.3\nrho = 7800.0
[materials.right]\nE = 1e11\nnu = 0.3\nrho = 7800.0\n[contacts.c]\nbetween = ["left", "right"]\nstiffness = [1e12, 1e11]
[supports.hot]\ntype = "clamped"\n[supports.cold]\ntype = "displacement"\nvalue = ["free", "1e-6 * t"]
[gravity]\nacceleration = [0, -9.81]\n[loads.top]\ntraction = [0, -1e4]\n[loads.mid]\nforce = [10.0, 0]\n"""
    (tmp_path / "joined.toml").write_text(joined)
    for src, mesh in ((NAFEMS / "le1.toml", "le1.geo"), (tmp_path / "joined.toml", "two_blocks.geo")):
        case = load_case(src)
        (tmp_path / "back.toml").write_text(case_toml(case.problem, case.name, mesh))
        assert repr(load_case(tmp_path / "back.toml").problem) == repr(case.problem)


def test_axisymmetric_thick_cylinder_under_internal_pressure_against_lame(tmp_path):
    """The same hollow cylinder, 10 MPa in the bore, both ends held axially (plane strain),
    purely mechanical: Lamé's σ_θθ = p a²/(b² − a²) (1 + b²/r²) and σ_rr = p a²/(b² − a²)
    (1 − b²/r²), u_r = (1 + ν) p a²/(E (b² − a²)) ((1 − 2ν) r + b²/r) at r = 75 mm (P2)."""
    geo = RECTANGLE.replace('"left"', '"bore"').replace('"right"', '"outside"')
    path = write(tmp_path, """
[case]
order = 2
plane = "axisymmetric"
[mesh]
file = "body.geo"
[materials.body]
E = 2.1e11
nu = 0.3
[loads.bore]
pressure = 10e6
[supports.bottom]
type = "normal"
[supports.top]
type = "normal"
[probes.mid]
point = [0.075, 0.025]
""", geo, x0=0.05, L=0.05, H=0.05, h=0.005)
    q = solve(path)["probes"]["mid"]
    a, b, r, p = 0.05, 0.1, 0.075, 10.0
    c = p * a ** 2 / (b ** 2 - a ** 2)
    err = {k: q[f"sigma_{k}_MPa"] / exact - 1 for k, exact in (
        ("tt", c * (1 + b ** 2 / r ** 2)), ("xx", c * (1 - b ** 2 / r ** 2)),
        ("yy", 0.3 * 2 * c))}  # σ_zz = ν (σ_rr + σ_θθ)
    assert max(abs(e) for e in err.values()) < 0.005
    assert err["xx"] == pytest.approx(-0.00272, abs=2e-4)  # the largest; 1e-4 at h = 2.5 mm
    u_r = (1 + 0.3) * c * 1e6 / 2.1e11 * ((1 - 2 * 0.3) * r + b ** 2 / r)
    assert q["ux_um"] * 1e-6 == pytest.approx(u_r, rel=1e-5)


@pytest.mark.parametrize("backend", ["superlu", "pardiso"])
def test_a_zero_pivot_is_bad_input_not_a_traceback(monkeypatch, backend):
    """A singular stiffness that the checks before it missed: the factorisation's failure is
    an InputError naming the likely cause."""
    import scipy.sparse as sp

    from gatetherm import InputError
    from gatetherm.solvers.elasticity import _Solver

    if backend == "pardiso":
        pytest.importorskip("pymklpardiso")
    monkeypatch.setenv("GATETHERM_SPD_BACKEND", backend)
    K = sp.csr_matrix(np.array([[1.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 1.0]]))
    with pytest.raises(InputError, match="the elastic system is singular .*a part is not held"):
        _Solver(K, 2)(np.ones(3))


THREE = """SetFactory("OpenCASCADE");
Rectangle(1) = {0, 0, 0, 0.1, 0.05};
Rectangle(2) = {0.1, 0, 0, 0.1, 0.05};
Rectangle(3) = {0, 0.05, 0, 0.2, 0.02};
BooleanFragments{ Surface{1, 2}; Delete; }{ Surface{3}; Delete; }
e = 1e-6;
Physical Surface("left") = {Surface In BoundingBox {-e, -e, -e, 0.1 + e, 0.05 + e, e}};
Physical Surface("right") = {Surface In BoundingBox {0.1 - e, -e, -e, 0.2 + e, 0.05 + e, e}};
Physical Surface("cover") = {Surface In BoundingBox {-e, 0.05 - e, -e, 0.2 + e, 0.07 + e, e}};
Physical Curve("left/right") = {Curve In BoundingBox {0.1 - e, -e, -e, 0.1 + e, 0.05 + e, e}};
Physical Curve("bottom") = {Curve In BoundingBox {-e, -e, -e, 0.2 + e, e, e}};
Physical Point("corner") = {Point In BoundingBox {0.1 - e, -e, -e, 0.1 + e, e, e}};
Mesh.MeshSizeMax = 0.01;
"""


def test_split_interface_cuts_between_two_regions_only():
    """Cutting ``left/right`` open: the right block gets copies of the interface's nodes, but
    not of the node where the cover joins both blocks (the cut ends there); the bottom edge
    follows its cells, the point group stays on the left, and the mesh stays one piece."""
    import tempfile

    from gatetherm.geometry.gmshfile import MeshSpec, mesh_geometry
    from gatetherm.geometry.interface import parts, split_interface
    from gatetherm.solvers.fem import to_skfem

    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "three.geo").write_text(THREE)
        fm = mesh_geometry(MeshSpec(Path(tmp) / "three.geo"))
    cut, pairs = split_interface(fm, "left", "right")
    nodes = np.unique(fm.boundaries["left/right"])
    top = nodes[np.argmax(fm.points[nodes, 1])]
    assert len(pairs) == len(nodes) - 1 and top not in pairs[:, 0]
    assert np.allclose(cut.points[pairs[:, 1]], fm.points[pairs[:, 0]]) and len(parts(cut)) == 1
    right = np.unique(cut.cells[cut.regions["right"]])
    assert not np.isin(pairs[:, 0], right).any() and np.isin(pairs[:, 1], right).all()
    assert np.isin(pairs[:, 1], cut.boundaries["bottom"]).sum() == 1  # the bottom corner node, on the right's side
    assert cut.sensors == fm.sensors and to_skfem(cut).nvertices == len(fm.points) + len(pairs)


def test_a_joint_resistance_effect_on_a_bonded_interface_is_its_contact(tmp_path):
    """``joint_resistance@left/right`` on the wall bonded at its interface runs as the wall with
    ``[contacts]`` of that conductance; on the contact itself it replaces its conductance."""
    import gatetherm as gt

    shutil.copy(DATA / "two_blocks.geo", tmp_path)
    bonded = COMPOSITE.replace("[contacts.joint]\nbetween = [\"right\", \"left\"]\nconductance = 2000.0\n", "")
    (tmp_path / "bonded.toml").write_text(bonded)
    (tmp_path / "contact.toml").write_text(COMPOSITE)
    case = gt.load_case(tmp_path / "bonded.toml")
    assert case.targets.interfaces == ("left/right",)
    with_effect = gt.run(case, effects={"joint_resistance@left/right": 2000.0})["T_face_degC"]
    assert with_effect[-1] == pytest.approx(gt.run(gt.load_case(tmp_path / "contact.toml"))["T_face_degC"][-1],
                                            rel=1e-12)
    half = gt.run(gt.load_case(tmp_path / "contact.toml"), effects={"joint_resistance@joint": 1000.0})
    L, k1, k2 = 0.1, 50.0, 15.0
    assert half["T_face_degC"][-1] == pytest.approx(100.0 - 100.0 / (L / k1 + 1 / 1000.0 + L / k2) * L / k1, rel=1e-9)
    from gatetherm.studies.diagnosis.hypotheses import effect_keys

    assert "joint_resistance@left/right" in effect_keys(case)
