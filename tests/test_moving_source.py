"""Sources that move (``[sources.REGION] position``): a thin strip heated by a short band moving at
constant speed against the 1-D moving-source solution, a band's power and where it goes, and
the NC-program reader."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import gatetherm as gt
from gatetherm import InputError
from gatetherm.solvers.expr import Value
from gatetherm.solvers.heat import march
from gatetherm.solvers.model import build

STRIP_GEO = """
lc = {lc};
Point(1) = {{0, 0, 0, lc}}; Point(2) = {{{L}, 0, 0, lc}}; Point(3) = {{{L}, {w}, 0, lc}}; Point(4) = {{0, {w}, 0, lc}};
Line(1) = {{1, 2}}; Line(2) = {{2, 3}}; Line(3) = {{3, 4}}; Line(4) = {{4, 1}};
Curve Loop(1) = {{1, 2, 3, 4}};
Plane Surface(1) = {{1}};
Physical Surface("strip") = {{1}};
Physical Curve("ends") = {{2, 4}};
Physical Curve("bottom") = {{1}};
"""
K, RHO, C, T_TH, H, V, P, W = 100.0, 1000.0, 1000.0, 0.002, 10.0, 0.002, 1.0, 0.02
"""Conductivity, density, heat capacity, thickness (m), face film, speed (m/s), power (W), width (m)."""
STRIP = f"""
[case]
order = 2
[mesh]
file = "strip.geo"
[materials.strip]
k = {K}
rho = {RHO}
c = {C}
thickness = {T_TH}
[faces]
film = {H}
ambient = 20.0
[sources.strip]
power = {P}
position = "0.3 + {V}*t"
direction = [1, 0]
length = 0.004
[time]
end = 700.0
step = 4.0
output = 700.0
"""


def one_d(xi):
    """The quasi-steady rise of a thin strip under a point source moving at V (ξ ahead > 0)."""
    a, m2 = K / (RHO * C), 2 * H / (K * T_TH)
    s = math.sqrt(V ** 2 / (4 * a * a) + m2)
    r = np.where(xi > 0, -V / (2 * a) - s, -V / (2 * a) + s)
    return P / (2 * K * W * T_TH * s) * np.exp(r * xi), 1 / (V / (2 * a) + s), 1 / (s - V / (2 * a))


def test_moving_band_on_a_strip_matches_the_1d_solution(tmp_path):
    """After 700 s (1.4 m travelled) the rise along the strip is the 1-D moving-source solution
    θ = P/(2kAs) e^(rξ): within 3 % at the source, 5 % of the peak over ±5 decay lengths."""
    (tmp_path / "strip.geo").write_text(STRIP_GEO.format(lc=0.005, L=2.0, w=W))
    (tmp_path / "c.toml").write_text(STRIP)
    case = gt.load_case(tmp_path / "c.toml")
    model = build(case.problem, case.mesh)
    *_, (t, U) = march(model.heat, case.schedule.drive, case.schedule.times, case.problem.scheme)
    x = model.heat.basis.doflocs[0]
    xi = x - (0.3 + V * t)
    exact, ahead, behind = one_d(xi)
    peak = float(one_d(np.array([0.0]))[0][0])
    at_source = float(np.max(U - 20.0)) / peak - 1
    near = (xi > -5 * behind) & (xi < 5 * ahead)
    spread = float(np.max(np.abs(U[near] - 20.0 - exact[near]))) / peak
    print(f"peak {peak:.4f} K; at the source {at_source:+.4f}; worst over ±5 decay lengths {spread:.4f} of the peak")
    assert at_source == pytest.approx(-0.0111, abs=2e-3)  # band: within ±0.03
    assert spread == pytest.approx(0.0239, abs=3e-3)  # band: < 0.05 of the peak


def _strip(tmp_path, extra="", order=1):
    (tmp_path / "strip.geo").write_text(STRIP_GEO.format(lc=0.05, L=1.0, w=0.1))
    text = STRIP.replace("order = 2", f"order = {order}").replace("end = 700.0", "end = 100.0").replace(
        "output = 700.0", "output = 100.0")
    (tmp_path / "c.toml").write_text(text + extra)
    return gt.load_case(tmp_path / "c.toml")


@pytest.mark.parametrize("order", [1, 2])
def test_band_puts_its_power_where_it_is(tmp_path, order):
    """The band's load sums to the power and its centre of mass is the position (away from the ends)."""
    case = _strip(tmp_path, order=order)
    heat = build(case.problem, case.mesh).heat
    (m,) = heat.moving
    x = heat.basis.doflocs[0][:len(m.weights)]
    for t, pos in ((0.0, 0.3), (100.0, 0.5), (37.0, 0.374)):
        f = m.vector({"t": t}) * m.value({"t": t})
        assert f.sum() == pytest.approx(P, rel=1e-12)
        assert (f @ x) / f.sum() == pytest.approx(pos, abs=1e-9)  # a band shorter than the elements too
        assert np.all(np.abs(x[f != 0] - pos) < 0.002 + m.spacing)


def test_moving_source_outside_its_region_is_refused_and_reduces_to_anchors(tmp_path):
    case = _strip(tmp_path)
    heat = build(case.problem, case.mesh).heat
    with pytest.raises(InputError, match="sources.strip.position.*misses its region"):
        heat.f({"t": 1000.0}, ())
    (m,) = heat.moving
    at, gap = m.anchors()  # a 1-m strip, 50-mm elements, a 4-mm band: anchors an element apart
    assert len(at) == 21 and gap == pytest.approx(0.05, rel=1e-9)
    pairs = m.interpolated()
    env = {"t": 37.0}  # at 0.374 m: the hats of 0.35 and 0.40 m, weights 0.52 and 0.48
    u = np.array([Value.of(text)(env) for text, _ in pairs])
    assert u.sum() == pytest.approx(P, rel=1e-12) and np.count_nonzero(u) == 2
    f = sum(ui * v for ui, (_, v) in zip(u, pairs))
    x = heat.basis.doflocs[0][:len(f)]
    assert (f @ x) / f.sum() == pytest.approx(0.374, abs=1e-9)  # the interpolated load's centre is the position


@pytest.mark.parametrize("change, where", [
    (("direction = [1, 0]", "direction = [1, 0, 0]"), "sources.strip.direction"),
    (("length = 0.004", ""), "sources.strip.length"),
    (("power = 1.0", "density = 1.0"), "sources.strip.density"),
])
def test_bad_moving_source_is_one_line(tmp_path, change, where):
    (tmp_path / "strip.geo").write_text(STRIP_GEO.format(lc=0.05, L=1.0, w=0.1))
    (tmp_path / "c.toml").write_text(STRIP.replace(*change))
    with pytest.raises(InputError) as err:
        gt.load_case(tmp_path / "c.toml")
    assert where in str(err.value) and "\n" not in str(err.value)


PROGRAM = """%
O1000 (a short feed-axis program)
N10 G21 G90 G17
N20 M3 S6000 ; spindle on
N30 G0 X100.
N40 G1 X200 F600
N50 G4 P2000
N60 M5
N70 G91 G1 X-30 Y40 F1200 M8
N80 G4 X1.5
N90 M30
N100 G1 X500
"""


def test_nc_program_becomes_a_schedule():
    """G0 100 mm at 30 m/min (0.2 s), G1 100 mm at 600 mm/min (10 s), 2-s dwell, an incremental
    G1 of 50 mm at 1200 mm/min (2.5 s), a 1.5-s dwell; nothing after M30."""
    from gatetherm.studies.run.ncprogram import nc_series, segments

    segs = segments(PROGRAM.replace("%", "").replace("O1000", ""))
    assert [s.duration for s in segs] == pytest.approx([0.2, 10.0, 2.0, 2.5, 1.5], rel=1e-12)
    ts = nc_series(PROGRAM.replace("%", "").replace("O1000", ""), step_s=0.5)
    t = ts.time_s
    assert t[-1] == pytest.approx(16.2, rel=1e-12) and len(t) == 34
    at = {round(float(x), 6): i for i, x in enumerate(t)}
    i = at[5.0]  # 4.8 s into the G1 at 10 mm/s: X = 148 mm, spindle at 6000
    assert ts["x_m"][i] == pytest.approx(0.148, abs=1e-12) and ts["vx_m_s"][i] == pytest.approx(0.01, rel=1e-12)
    assert ts["spindle_rpm"][i] == 6000.0 and ts["feed_m_s"][i] == pytest.approx(0.01, rel=1e-12)
    i = at[11.0]  # dwelling at X = 200 mm, spindle still on (M5 comes after the dwell)
    assert ts["x_m"][i] == pytest.approx(0.2, abs=1e-12) and ts["vx_m_s"][i] == 0.0 and ts["spindle_rpm"][i] == 6000.0
    i = at[13.5]  # 1.3 s into the 50-mm move at 20 mm/s along (-0.6, 0.8): 26 mm
    np.testing.assert_allclose([ts["x_m"][i], ts["y_m"][i], ts["z_m"][i]], [0.2 - 0.0156, 0.0208, 0.0], atol=1e-12)
    assert ts["feed_m_s"][i] == pytest.approx(0.02, rel=1e-12) and ts["spindle_rpm"][i] == 0.0
    np.testing.assert_allclose([ts["x_m"][-1], ts["y_m"][-1], ts["z_m"][-1]], [0.17, 0.04, 0.0], atol=1e-12)


@pytest.mark.parametrize("text, what", [("G1 X10", "without a feed"), ("G2 X10 Y5 R5 F100", "G2 is not read"),
                                        ("G1 X10 Q3 F100", "word Q"), ("G1 X5 P2 F100", "G4 dwell only"),
                                        ("M6", "M6 is not read"), ("X10", "without G0 or G1")])
def test_bad_nc_program_is_one_line_naming_it(text, what):
    from gatetherm.studies.run.ncprogram import nc_series

    with pytest.raises(InputError, match=what) as err:
        nc_series("G21\n" + text, where="p.nc")
    assert "p.nc, line 2" in str(err.value)


def test_a_carriage_driven_by_an_nc_program(tmp_path):
    """An NC program → schedule (gt.nc_schedule) → a guide's carriage moving with x_m and losing
    (μ F + seal)|v| at its own velocity: the run reports that loss, and the heat goes in."""
    (tmp_path / "p.nc").write_text("G21 G90\nG0 X300\nG1 X700 F1200\nG4 X5\nG1 X400 F2400\nM30\n")
    ts = gt.nc_schedule(tmp_path / "p.nc", step_s=1.0, out=tmp_path / "p.csv")
    assert ts.time_s[-1] == pytest.approx(0.6 + 20.0 + 5.0 + 7.5, rel=1e-12)
    text = STRIP.replace("end = 700.0", "end = 33.0").replace("step = 4.0", "step = 1.0").replace(
        "output = 700.0", "output = 1.0\nschedule = \"p.csv\"").replace("order = 2", "order = 1")
    text = text.replace('power = 1.0\nposition = "0.3 + 0.002*t"',
                        'kind = "guide"\nspeed = "vx_m_s"\nload = 2000.0\nseal = 4.0\nposition = "x_m"')
    (tmp_path / "strip.geo").write_text(STRIP_GEO.format(lc=0.02, L=1.0, w=0.1))
    (tmp_path / "c.toml").write_text(text)
    run = gt.run(gt.load_case(tmp_path / "c.toml"))
    v = np.interp(run.time, ts.time_s, ts["vx_m_s"])
    np.testing.assert_allclose(run["P_strip_W"], (0.003 * 2000.0 + 4.0) * np.abs(v), rtol=1e-12)
    assert run["P_strip_W"][10] == pytest.approx(0.2, rel=1e-12)  # 10 W/m·s × 20 mm/s


@pytest.mark.slow
def test_reduced_model_of_a_moving_source_on_a_program_it_was_not_checked_on(tmp_path):
    """The band's input matrix interpolated over 21 anchors (hats 50 mm apart, the band's length):
    the reduced model (30 states) against FE on a second NC program; the error is that of the
    interpolation (60 states give the same), a few per cent of the rise where the band passes."""
    (tmp_path / "a.nc").write_text("G21 G90\nG0 X100\nG1 X900 F600\nG4 X60\nG1 X300 F300\nG4 X60\nG1 X700 F900\nM30\n")
    (tmp_path / "b.nc").write_text("G21 G90\nG0 X500\nG1 X200 F400\nG4 X100\nG1 X850 F1200\nG4 X30\nG1 X400 F500\n"
                                   "G1 X600 F200\nM30\n")
    for name in ("a", "b"):
        gt.nc_schedule(tmp_path / f"{name}.nc", step_s=2.0, out=tmp_path / f"{name}.csv")
    text = STRIP.replace("end = 700.0", "end = 320.0").replace("step = 4.0", "step = 2.0").replace(
        "output = 700.0", "output = 2.0\nschedule = \"a.csv\"").replace("order = 2", "order = 1").replace(
        "ambient = 20.0", "ambient = 21.0").replace('position = "0.3 + 0.002*t"', 'position = "x_m"').replace(
        "length = 0.004", "length = 0.05")
    text += "\n[probes.p1]\npoint = [0.2, 0.01]\n[probes.p2]\npoint = [0.5, 0.01]\n[probes.p3]\npoint = [0.8, 0.01]\n"
    (tmp_path / "strip.geo").write_text(STRIP_GEO.format(lc=0.02, L=1.0, w=0.02))
    (tmp_path / "c.toml").write_text(text)
    case = gt.load_case(tmp_path / "c.toml")
    red = gt.reduce(case, states=30)
    assert len(red.rom.inputs) == 22  # 21 anchors and the faces' ambient
    other = gt.schedule_file(tmp_path / "b.csv", case, step_s=2.0)
    rise = max(float(np.max(gt.run(case, other)[f"T_{p}_degC"])) - 20.0 for p in ("p1", "p2", "p3"))
    (check,) = gt.check_rom(case, red.rom, [other])
    worst = max(check.errors.values())
    print(f"largest rise {rise:.2f} K; reduced model off by {worst:.3f} K at most ({worst / rise:.1%})")
    assert worst == pytest.approx(0.310, abs=0.02)  # K
    assert worst / rise < 0.05  # band: 5 % of the rise


@pytest.mark.slow
def test_feed_axis_reduced_model_on_an_unseen_program(tmp_path):
    """The feed-axis example: the reduced model (asked for 60 states, it keeps 44; the nut's and the
    carriage's loads interpolated over 12 and 6 anchors) against FE on program_b.nc run 30 times, which the model
    was not made from: δ within 0.5 µm (the issue's acceptance)."""
    here = Path(__file__).resolve().parents[1] / "validation/examples/feed_axis"
    ts = gt.nc_schedule(here / "program_b.nc", step_s=0.5, repeat=30, out=tmp_path / "b.csv")
    case = gt.load_case(here / "case.toml")
    red = gt.reduce(case, states=60)
    assert len(red.rom.inputs) == 21 and red.rom.states == 44  # band: ≤ 60 (the room, constant, is an input)
    (check,) = gt.check_rom(case, red.rom, [gt.schedule_file(tmp_path / "b.csv", case, step_s=1.0)])
    print(f"program_b x30: {ts.time_s[-1]:.0f} s; reduced model of {red.rom.states} states: "
          f"δ off by {check.errors['delta_um']:.3f} um, screw end by {check.errors['T_screw_end_degC']:.3f} K; "
          f"its march {check.rom_ms:.0f} ms, FE {check.fe_seconds:.1f} s")
    assert check.errors["delta_um"] == pytest.approx(0.178, abs=0.02)  # band: < 0.5 um


def test_sources_on_a_boundary_fixed_and_moving(tmp_path):
    """REGION may be a boundary: a power over its area (here 2 W on the strip's ends, ∫ t v of
    each end), or a band on it (3 W travelling along the bottom edge): the loads sum to the power,
    sit on the boundary's nodes only, and the band's centre is the position."""
    case = _strip(tmp_path, '[sources.ends]\npower = 2.0\n[sources.bottom]\nkind = "guide"\nspeed = 1.0\n'
                            'load = 1000.0\nposition = "0.2 + 0.004*t"\ndirection = [1, 0]\nlength = 0.06\n')
    heat = build(case.problem, case.mesh).heat
    ends = next(ld for ld in heat.loads if ld.kind == "source" and ld.value.constant == 2.0)
    x, y = heat.basis.doflocs[:, :heat.n_solid]
    f = ends.vector[:heat.n_solid] * 2.0
    assert f.sum() == pytest.approx(2.0, rel=1e-12) and np.all((f == 0) | np.isclose(x, 0) | np.isclose(x, 1.0))
    assert f[np.isclose(x, 0)].sum() == pytest.approx(1.0, rel=1e-12)  # two equal ends
    band = next(m for m in heat.moving if abs(m.value({}) - 3.0) < 1e-12)
    g = band.vector({"t": 50.0}) * band.value({})
    assert g.sum() == pytest.approx(3.0, rel=1e-12) and np.all(np.isclose(y[g != 0], 0.0))
    assert (g @ x) / g.sum() == pytest.approx(0.4, abs=1e-9)
    text = (tmp_path / "c.toml").read_text()
    (tmp_path / "c.toml").write_text(text.replace("[sources.ends]\npower", "[sources.ends]\ndensity"))
    with pytest.raises(InputError, match="sources.ends.density.*boundary takes power"):
        gt.load_case(tmp_path / "c.toml")



def test_a_moving_band_on_an_insulated_strip_adds_its_energy_exactly(tmp_path):
    """No film: the capacity-weighted rise is the energy put in, P t, to round-off, however the
    band moves between the nodes (the θ-method weights the loads at both ends of a step)."""
    (tmp_path / "strip.geo").write_text(STRIP_GEO.format(lc=0.05, L=1.0, w=0.1))
    text = STRIP.replace("[faces]\nfilm = 10.0\nambient = 20.0\n", "").replace(
        'position = "0.3 + 0.002*t"', 'position = "0.5 + 0.3*sin(t/7)"').replace("end = 700.0", "end = 100.0").replace(
        "output = 700.0", "output = 4.0")
    (tmp_path / "c.toml").write_text(text)
    case = gt.load_case(tmp_path / "c.toml")
    heat = build(case.problem, case.mesh).heat
    for t, U in march(heat, case.schedule.drive, case.schedule.times, case.problem.scheme):
        energy = float(np.sum(heat.M @ (U - 20.0)))
        assert energy == pytest.approx(P * t, rel=1e-10, abs=1e-9)


def test_a_band_whose_centre_leaves_its_region_is_said_once(tmp_path, caplog):
    """A position offset by mistake (a new user's rail at z + 2.2 m on a 0.6 … 2.1 m rail) is read with
    one warning naming the key, when and where; a band that stays on is read without one."""
    import logging

    with caplog.at_level(logging.WARNING):
        _strip(tmp_path)
    assert "band" not in caplog.text
    (tmp_path / "strip.geo").write_text(STRIP_GEO.format(lc=0.05, L=1.0, w=0.1))
    text = STRIP.replace("end = 700.0", "end = 100.0").replace("output = 700.0", "output = 100.0")
    (tmp_path / "c.toml").write_text(text.replace('position = "0.3 + ', 'position = "0.95 + '))
    with caplog.at_level(logging.WARNING):
        gt.load_case(tmp_path / "c.toml").with_order(1)
    assert caplog.text.count("c.toml: sources.strip.position: the band's centre leaves its region (0 to 1 m along "
                             "its direction) from t = 28 s (position 1.006 m): more than half its 0.004 m is off") == 1
