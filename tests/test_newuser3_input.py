"""A new user's gantry (newuser3): a probe on the surface off by round-off, messages naming the
file or option that lacks a column, a 2-D thickness in mm, the final paths a command prints."""
from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import pytest

from gatetherm import InputError
from gatetherm.geometry.nearest import nearest_on_body
from test_bad_case_input import t3

# ---- 1. probe coordinates on the boundary --------------------------------------------------------


def test_nearest_on_body_closed_form_2d_and_3d():
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    tri = np.array([[0, 1, 2], [0, 2, 3]])
    n = nearest_on_body(square, tri, [0.3, 1.0 + 2e-16])
    assert n.distance == pytest.approx(2e-16, abs=1e-16)  # band: round-off
    assert n.point == pytest.approx([0.3, 1.0], abs=1e-15)
    assert n.tolerance == pytest.approx(np.sqrt(2.0))  # the longest edge of the element, > 1 % of the diagonal
    n = nearest_on_body(square, tri, [2.0, 3.0])
    assert n.point == pytest.approx([1.0, 1.0]) and n.distance == pytest.approx(np.sqrt(5.0))
    cube = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    tet = np.array([[0, 1, 2, 3]])
    n = nearest_on_body(cube, tet, [1.0, 1.0, 1.0])  # above the face x + y + z = 1
    assert n.point == pytest.approx([1 / 3, 1 / 3, 1 / 3]) and n.distance == pytest.approx(2 / np.sqrt(3))
    n = nearest_on_body(cube, tet, [0.2, 0.3, -0.5])  # below the face z = 0
    assert n.point == pytest.approx([0.2, 0.3, 0.0]) and n.distance == pytest.approx(0.5)
    n = nearest_on_body(cube, tet, [-1.0, -1.0, 0.5])  # beside the edge x = y = 0
    assert n.point == pytest.approx([0.0, 0.0, 0.5]) and n.distance == pytest.approx(np.sqrt(2.0))


def test_a_relative_displacement_of_one_point_is_refused():
    """A tool probe written 2 cm in front of a ram's nose, read at the nearest point of the body, which
    was the workpiece's face (a new user's boring mill): δ read 1e-12 µm at exit 0; now refused."""
    import gatetherm as gt

    c_frame = Path(__file__).resolve().parents[1] / "validation" / "examples" / "c_frame" / "case.toml"
    case = gt.load_case(c_frame)
    xyz = [float(v) for v in case.mesh.points[case.mesh.sensors["table_top"]]]
    with pytest.raises(InputError, match=r"case.toml: relative.delta.b: probe 'tool' reads the same point as "
                                         r"'table_top', \[.*\]: the relative displacement would be 0 at all times"):
        gt.load_case(c_frame, overrides={"probes.tool.point": xyz})


def test_probe_on_the_boundary_read_with_a_warning(tmp_path: Path, caplog):
    from gatetherm.studies.run.case import load_case

    path = t3(tmp_path, 'point = "target"', "point = [0.05, 0.010000001]")
    with caplog.at_level(logging.WARNING):
        case = load_case(path)
    (probe,) = case.problem.probes
    assert probe.xyz == pytest.approx((0.05, 0.01), abs=1e-9)
    assert "probes.target.point: [0.05, 0.010000001] lies 1e-09 m outside the mesh (within the tolerance 0.0112 m)" \
        in caplog.text
    assert "read at the nearest point on the body, [0.05, 0.01], in region 'bar'" in caplog.text
    with caplog.at_level(logging.WARNING):
        p2 = case.with_order(2)  # made again on the same mesh (the order check): said once
    assert caplog.text.count("outside the mesh") == 1 and p2.problem.probes[0].xyz == probe.xyz


def test_probe_far_from_the_body_refused_with_the_distance(tmp_path: Path):
    from gatetherm.studies.run.case import load_case

    path = t3(tmp_path, 'point = "target"', "point = [0.2, 0.005]")
    with pytest.raises(InputError) as e:
        load_case(path)
    assert "probes.target.point: [0.2, 0.005] lies outside the mesh, 0.1 m from the body (more than the " \
           "tolerance 0.0112 m); the nearest point on it is [0.1, 0.005]" in str(e.value)


# ---- 2. messages that name the file, or the option, that lacks a column --------------------------

RUN = "# format: gatetherm-timeseries/1\ntime_s,spindle_W,delta_um,theta_A_degC\n0,350,0,20\n60,350,1,21\n"


def test_a_series_read_from_a_file_names_it_when_a_column_is_missing(tmp_path: Path):
    from gatetherm.studies.run.timeseries import read_timeseries, validate_complete

    (tmp_path / "schedule.csv").write_text(RUN)
    ts = read_timeseries(tmp_path / "schedule.csv", required=("time_s",))
    with pytest.raises(InputError) as e:
        validate_complete(ts.slice(slice(0, 2)), ("theta_A_degC", "theta_B_degC"))
    assert str(e.value) == f"{tmp_path / 'schedule.csv'}: column theta_B_degC: missing; add a theta_B_degC " \
                           "column; columns alike: theta_A_degC"


def test_a_column_named_by_an_option_blames_the_option_with_look_alikes(tmp_path: Path):
    from gatetherm.studies.run.timeseries import read_timeseries

    (tmp_path / "run.csv").write_text(RUN)
    with pytest.raises(InputError) as e:
        read_timeseries(tmp_path / "run.csv", required=("time_s", "delta_mu"), named_by={"delta_mu": "--targets"})
    assert str(e.value) == f"--targets: 'delta_mu' is not a column of {tmp_path / 'run.csv'}; name a column of the " \
                           "file; columns alike: delta_um (its columns: time_s, spindle_W, delta_um, theta_A_degC)"


def test_errormodel_fit_with_a_mistyped_target_exits_2_naming_the_option(tmp_path: Path, capsys):
    from gatetherm.cli import main

    (tmp_path / "run.csv").write_text(RUN)
    got = main(["errormodel", "fit", "--data", str(tmp_path / "run.csv"), "--targets", "delta_mu",
                "--candidates", "theta_A_degC", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert got == 2 and err.count("\n") == 1 and "--targets: 'delta_mu' is not a column of" in err
    assert "columns alike: delta_um" in err and "Traceback" not in err


def test_an_expression_naming_a_column_the_schedule_lacks_names_the_schedule(tmp_path: Path):
    from gatetherm.studies.run.case import load_case

    (tmp_path / "s.csv").write_text("time_s,spindle_W,axis_W\n0,1,2\n40,1,2\n")
    path = t3(tmp_path, 'temperature = "100 * sin(pi * t / 40)"', 'temperature = "ambient_degC"',
              extra='schedule = "s.csv"\n')
    with pytest.raises(InputError) as e:
        load_case(path)
    assert str(e.value) == f"{path}: thermal.hot_end.temperature: 'ambient_degC' in 'ambient_degC' is not a column " \
                           f"of the schedule {tmp_path / 's.csv'}; add the column ambient_degC to it " \
                           "(inputs here: axis_W, spindle_W, t)"


# ---- 3. a 2-D thickness in mm ----------------------------------------------------------------------

@pytest.mark.parametrize("thickness, warned", [(350.0, True), (1.05, True), (0.95, False), (0.01, False)])
def test_a_thickness_beyond_ten_times_the_body_is_read_with_a_warning(tmp_path: Path, caplog, thickness, warned):
    from gatetherm.studies.run.case import load_case

    path = t3(tmp_path, "c = 440.5\n", f"c = 440.5\nthickness = {thickness}\n")
    with caplog.at_level(logging.WARNING):
        case = load_case(path)  # a warning, not a refusal: the body is 0.1 m long (0.1 x 0.01 m)
    assert case.problem.thickness["bar"] == thickness
    message = f"materials.bar.thickness: {thickness:g} m is more than 10 times the body's largest in-plane " \
              f"extent (0.1 m); the thickness is in m ({thickness:g} mm = {thickness / 1000:g} m)"
    assert (message in caplog.text) == warned, caplog.text


# ---- 5. diagnose's P2 replay of gatetherm's own run points to --keep-order ----------------------------

def test_the_p2_replay_warning_points_to_keep_order_for_a_gatetherm_run():
    import types

    from gatetherm.api.diagnosis import order_warning

    p2 = types.SimpleNamespace(too_coarse=["delta_um"], order=2)
    made = order_warning(p2, {"source": "gatetherm"})
    assert made.startswith("warning: the model's discretisation error (P2 - P1) exceeds the resolution on delta_um; "
                           "the diagnosis replayed it with P2 elements; the data are a run gatetherm simulated")
    assert "--keep-order replays with P1 (report.md, 1. Replay)" in made
    assert "--keep-order" not in order_warning(p2, {"source": "CMM log"})  # a measurement: no hint
    p1 = types.SimpleNamespace(too_coarse=["delta_um"], order=1)  # --keep-order given: the old advice
    assert order_warning(p1, {"source": "gatetherm"}).endswith("refine the mesh (--mesh-factor) or set order = 2 "
                                                                "(report.md, 1. Replay)")


# ---- 5. the sweep's columns as docs/sweep.md names them --------------------------------------------

def test_a_case_sweeps_temperature_columns_are_named_as_the_runs(tmp_path: Path):
    """docs/sweep.md: the final temperature of a probe is named as its timeseries.csv column:
    theta_A/theta_B for the probes [signals] maps to them, T_PROBE for the rest (a θ_C probe too)."""
    from gatetherm.studies.run.case import load_case
    from gatetherm.studies.sweeps.studyfile import case_columns

    case = load_case(Path(__file__).resolve().parents[1] / "validation" / "examples" / "c_frame" / "case.toml")
    temps = [c for c in case_columns(case) if c.endswith("_final_degC")]
    assert {"T_TS_final_degC", "theta_A_final_degC", "theta_B_final_degC"} <= set(temps)  # TS is θ_C's probe
    assert not {"T_TF_final_degC", "T_TB_final_degC"} & set(temps)  # θ_A's and θ_B's probes: no T_ column
    assert "delta_final_um" in case_columns(case)


def test_compensate_with_a_schedule_for_data_exits_2_naming_the_file(tmp_path: Path, capsys):
    from gatetherm.cli import main

    example = Path(__file__).resolve().parents[1] / "validation" / "examples" / "c_frame"
    got = main(["compensate", "--case", str(example / "case.toml"), "--data", str(example / "schedule.csv"),
                "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert got == 2 and err.count("\n") == 1 and "Traceback" not in err
    assert f"{example / 'schedule.csv'}: column theta_A_degC: missing; add a theta_A_degC column" in err, err


def test_a_fitted_factor_is_printed_without_a_unit():
    """``factor = 1.3 ± 0.00038 1`` read as a stray 1 to a new user: a factor has no unit; others keep theirs."""
    import types

    from gatetherm.api.diagnosis import DiagnosisRun

    def piece(label, param, unit):
        return types.SimpleNamespace(kind="parameter", label=label, param=param, unit=unit)

    found = [types.SimpleNamespace(piece=piece("source_motor", "factor", "1"), value=1.2997, sigma=0.00038, share=0.9,
                                   alternatives=()),
             types.SimpleNamespace(piece=piece("film_free", "h", "W/(m2 K)"), value=7.974, sigma=0.15, share=0.1,
                                   alternatives=())]
    diag = types.SimpleNamespace(verdict="explained", pieces=found, groups=(), dropped=(), cause="", too_coarse=(),
                                 stand_ins=((piece("conductivity", "factor", "1"), 0.9, "a stand-in"),),
                                 summary=lambda: {"best_rejected": None, "rms_after_um": None})
    lines = DiagnosisRun(diag, None, "d.csv", {}, {}, ()).summary().splitlines()
    assert lines[1:] == ["  parameter source_motor: factor = 1.3 ± 0.00038, 90 % of the held-out residual",
                         "  parameter film_free: h = 7.974 ± 0.15 W/(m2 K), 10 % of the held-out residual",
                         "  stand-in, not a cause: conductivity factor = 0.9 (a stand-in)"]
