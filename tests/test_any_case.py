"""Every capability on a machine of the user's: the C-frame example as a case file, through the
public API — its reduced model integrated from ``rom.npz`` alone, the three compensation methods
with the actuator of its case file, a missing heat source diagnosed by its region's name."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import gatetherm as gt
from gatetherm.studies.run.reduce import write_rom
from gatetherm.studies.run.timeseries import FORMAT, OUTPUT_COLUMNS, TimeSeries, write_timeseries
from gatetherm.validation.truth import recorded
from test_rom_cli import integrate

CASE = Path(__file__).resolve().parents[1] / "validation" / "examples" / "c_frame" / "case.toml"


@pytest.fixture(scope="module")
def case():
    return gt.load_case(CASE)


@pytest.fixture(scope="module")
def reduced(case, tmp_path_factory):
    red = gt.reduce(case, 30)
    path = tmp_path_factory.mktemp("rom") / "rom.npz"
    write_rom(red.rom, path)
    with np.load(path) as d:
        return red, {k: d[k] for k in d.files}


def other_duty_cycle(path: Path) -> Path:
    """A different duty cycle of the C-frame: 300 W for 40 min, 60 W for 2 h, off, 150 W; a room
    that cools by 0.5 K/h."""
    t = np.arange(0.0, 6 * 3600.0 + 1, 300.0)
    power = np.select([t < 2400, t < 9600, t < 14400], [300.0, 60.0, 0.0], 150.0)
    write_timeseries(path, TimeSeries({"time_s": t, "spindle_W": power, "ambient_degC": 21.0 - 0.5 * t / 3600},
                                      {"format": FORMAT}))
    return path


def test_reduced_model_of_a_case_integrated_from_its_file_alone(case, reduced, tmp_path):
    red, rom = reduced
    assert [str(u) for u in rom["inputs"]] == ["ambient_degC", "spindle_W"] and list(rom["offsets"]) == [20.0, 0.0]
    assert "A" in rom and "A_on" not in rom and rom["A"].shape == (30, 30) <= (40, 40)  # no pump: one mode
    for schedule, achieved in ((case.schedule, 0.0015), (gt.schedule_file(other_duty_cycle(tmp_path / "d.csv"),
                                                                           case), 0.0018)):
        fe = gt.run(case, schedule, keep=()).scenario.result.columns
        err = np.max(np.abs(integrate(rom, fe) - fe["delta_um"]))
        assert err == pytest.approx(achieved, abs=0.002)  # acceptance: ≤ 0.5 µm
    check, = gt.check_rom(case, red.rom)
    assert check.errors["delta_um"] == pytest.approx(0.0015, abs=0.001) and check.errors["theta_C_degC"] < 1e-3


def test_three_compensation_methods_with_the_cases_actuator(case):
    assert case.actuator is not None and case.actuator.strategy == "reset"  # [actuator] stroke = [-70, 10]
    run = gt.run(case, keep=())
    results = {m: gt.compensate(run, method=m) for m in ("paper", "mlr", "rom")}
    got = {m: r.summary for m, r in results.items()}
    rom = got["rom"]
    loop = results["rom"].loop  # the first command acts one sample late: the piezo rests until then
    assert loop.update_t_s[0] == 60.0 and loop.stroke_um[0] == 0.0 and loop.delta_comp_um[0] == run["delta_um"][0]
    assert rom["residual_band_um"] == pytest.approx(1.10, abs=0.1) and rom["updates"] == 41  # ≤ 3 µm, ≤ 60
    assert rom["piezo_saturated_updates"] == 0 and rom["rom_states"] == 30
    # θ_A and θ_B span 0.47 K, under 10 sensor resolutions: no weight (plain least squares, ±1390 µm/K: 2.56 µm)
    assert got["mlr"]["residual_band_um"] == pytest.approx(3.05, abs=0.1)
    assert got["paper"]["k_source"] == "fit" and got["paper"]["residual_band_um"] == pytest.approx(2.35, abs=0.1)


@pytest.mark.slow
def test_a_missing_source_is_named_by_its_region(case):
    """40 W in the arm (the headstock), which the case does not heat, with noise at the resolution."""
    truth = gt.run(case, effects={"heat_source@arm": 40.0}, keep=())
    ts = recorded(truth.columns, ("time_s", "spindle_W", "ambient_degC", *OUTPUT_COLUMNS), OUTPUT_COLUMNS, 7, {})
    d = gt.diagnose(case, ts)
    assert d.verdict == "explained" and [r.piece.name for r in d.pieces] == ["heat_source@arm"]
    assert d.pieces[0].value == pytest.approx(38.98, abs=0.4)  # band: ±15 % of 40 W (40.31 before the 12-07 changes)


CASE_STUDY = f"""[study]
name = "C-frame: film and table"
case = "{CASE.as_posix()}"

[set]
"time.end" = 7200.0

[grid]
"thermal.free.film" = [6.0, 10.0]
"mesh.parameters.table_height" = [0.08, 0.12]

[[plot]]
x = "thermal.free.film"
y = "delta_final_um"
hue = "mesh.parameters.table_height"
"""


def _case_sweep(tmp_path, *extra) -> tuple[Path, list[dict]]:
    import csv
    import subprocess
    import sys

    study = tmp_path / "study.toml"
    study.write_text(CASE_STUDY)
    out = tmp_path / ("out" + "".join(e.strip("-")[:3] for e in extra))
    done = subprocess.run([sys.executable, "-m", "gatetherm.cli", "sweep", str(study), "--out", str(out), *extra],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    with open(out / "table.csv", newline="") as fh:
        return out, list(csv.DictReader(fh))


def test_a_study_sweeps_keys_of_a_case_file_and_resumes(tmp_path):
    import os
    import signal
    import subprocess
    import sys
    import time

    from gatetherm.studies.sweeps.studyfile import load_study
    from gatetherm.studies.sweeps.sweep import plan

    out, rows = _case_sweep(tmp_path, "--workers", "1")
    assert [(r["thermal.free.film"], r["mesh.parameters.table_height"], r["status"]) for r in rows] == [
        ("6.0", "0.08", "ok"), ("6.0", "0.12", "ok"), ("10.0", "0.08", "ok"), ("10.0", "0.12", "ok")]
    delta = {(r["thermal.free.film"], r["mesh.parameters.table_height"]): float(r["delta_final_um"]) for r in rows}
    nodes = {r["mesh.parameters.table_height"]: int(r["nodes"]) for r in rows}
    assert nodes["0.08"] != nodes["0.12"]  # the .geo parameter meshes the table anew
    assert delta[("6.0", "0.08")] > delta[("10.0", "0.08")]  # a stronger film keeps the column cooler
    assert (out / "delta_final_um_vs_thermal.free.film_by_mesh.parameters.table_height.png").stat().st_size > 1000
    # the same point, run on its own through the case path
    one = gt.load_case(CASE, overrides={"time.end": 7200.0, "thermal.free.film": 10.0,
                                        "mesh.parameters.table_height": 0.12})
    assert gt.run(one, keep=())["delta_um"][-1] == pytest.approx(delta[("10.0", "0.12")], rel=1e-12)
    # killed after its first point, then run again: the points done are kept, the table is the same
    study = tmp_path / "study.toml"
    killed = tmp_path / "killed"
    proc = subprocess.Popen([sys.executable, "-m", "gatetherm.cli", "sweep", str(study), "--out", str(killed),
                             "--workers", "1"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)
    deadline = time.monotonic() + 120
    while not list((killed / "points").glob("*.json")) and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    kept = {p.name for p in (killed / "points").glob("*.json")}
    assert 1 <= len(kept) < 4 and not (killed / "table.csv").exists()
    assert subprocess.run([sys.executable, "-m", "gatetherm.cli", "sweep", str(study), "--out", str(killed),
                           "--workers", "1"], capture_output=True).returncode == 0
    assert (killed / "table.csv").read_text() == (out / "table.csv").read_text()
    assert len(plan(load_study(study))) == 4


def test_a_case_study_on_a_dask_cluster_gives_the_same_table(tmp_path):
    distributed = pytest.importorskip("distributed")
    local, _ = _case_sweep(tmp_path, "--workers", "2")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False, host="127.0.0.1",
                                  protocol="tcp://", dashboard_address=None) as cluster:
        dask, _ = _case_sweep(tmp_path, "--scheduler", cluster.scheduler_address)
    assert (dask / "table.csv").read_text() == (local / "table.csv").read_text()


def test_simulate_and_the_api_give_the_same_run(tmp_path):
    """``gatetherm simulate --condition 1`` and ``gt.run(gt.gate_frame(dim=2), schedule=gt.condition(1))``."""
    from gatetherm.cli import main
    from gatetherm.studies.run.timeseries import read_timeseries

    assert main(["simulate", "--condition", "1", "--out", str(tmp_path), "--no-pictures", "--fields-every", "300"]) == 0
    ts = read_timeseries(tmp_path / "timeseries.csv")
    run = gt.run(gt.gate_frame(dim=2), schedule=gt.condition(1), keep=())
    assert set(ts.names) == set(run.columns)
    for name in ("delta_um", "theta_A_degC", "theta_C_degC", "T_tank_oil_degC"):
        np.testing.assert_allclose(run[name], ts[name], rtol=1e-15, atol=1e-12)
    assert run.summary()["first_peak_um"] == pytest.approx(48.25, abs=5e-3)  # README's `gatetherm simulate --condition 1`: 48.25 µm at 13.0 min
