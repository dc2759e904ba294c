"""``gatetherm compensate`` and ``gatetherm diagnose`` are one API call each (issue 52, item 1):
``gt.compensate_run`` / ``gt.diagnose_run`` return a result whose ``write(out)`` writes exactly the
files the command writes and whose ``summary()`` is the lines it prints; progress (issue 55, item 6)
is reported through ``on_progress(i, n)``, i increasing up to n."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import synthetic_record

import gatetherm as gt
from gatetherm.cli import main
from gatetherm.studies.run.timeseries import FORMAT, TimeSeries, write_timeseries

HEADSTOCK = Path(__file__).resolve().parent / "data" / "headstock"


def files(d: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(d.iterdir()) if p.is_file() and not p.name.startswith(".")}


@pytest.fixture(scope="module")
def headstock(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("headstock")
    for name in ("headstock.geo", "schedule.csv", "case.toml"):
        shutil.copy(HEADSTOCK / name, d / name)
    return d / "case.toml"


@pytest.fixture(scope="module")
def machine(tmp_path_factory) -> Path:
    """A machine's record (d_um = 2 theta_1 + noise) and the error model fitted on it."""
    d = tmp_path_factory.mktemp("machine")
    synthetic_record(d / "data.csv")
    assert main(["errormodel", "fit", "--data", str(d / "data.csv"), "--targets", "d_um", "--out", str(d)]) == 0
    return d


def test_compensate_run_is_what_the_command_writes_and_prints(machine, tmp_path, capsys):
    calls = []
    result = gt.compensate_run(str(machine / "data.csv"), model=str(machine / "model.json"), ideal=True,
                               on_progress=lambda i, n: calls.append((i, n)))
    assert calls == [(1, 1)]  # a record: nothing to run, the compensation is the one step
    assert result.wrote(tmp_path / "lib") == f"wrote {tmp_path / 'lib'}/compensated.csv, compensation.png, summary.json"
    assert result.write(tmp_path / "lib") == result.wrote(tmp_path / "lib")
    capsys.readouterr()
    assert main(["compensate", "--model", str(machine / "model.json"), "--data", str(machine / "data.csv"),
                 "--no-actuator", "--out", str(tmp_path / "cli")]) == 0
    printed = capsys.readouterr().out.splitlines()
    assert printed == [result.wrote(tmp_path / "cli"), *result.summary().splitlines()]
    lib, cli = files(tmp_path / "lib"), files(tmp_path / "cli")
    assert sorted(lib) == sorted(cli) == ["compensated.csv", "compensation.png", "summary.json"]
    assert lib["compensated.csv"] == cli["compensated.csv"] and lib["summary.json"] == cli["summary.json"]
    summary = json.loads(cli["summary.json"])
    assert summary["benefit"] == result.record["benefit"] and summary["model"] == str(machine / "model.json")
    assert result.summary().splitlines()[0].startswith(f"{machine / 'data.csv'}: ")


def test_compensate_run_of_a_case_reports_the_runs_samples(headstock):
    calls = []
    result = gt.compensate_run(case=str(headstock), method="mlr", ideal=True, force=True,
                               on_progress=lambda i, n: calls.append((i, n)))
    steps = len(gt.load_case(headstock).schedule.times) + 1  # the run's samples, then the compensation
    assert calls[-1] == (steps, steps) and {n for _, n in calls} == {steps}
    assert [i for i, _ in calls] == sorted(i for i, _ in calls) and len(calls) >= steps - 1
    assert result.record["case"] == str(headstock) and result.what == str(headstock)


def test_compensate_run_checks_its_arguments():
    with pytest.raises(TypeError, match="^on_progress: got int 3, expected a function"):
        gt.compensate_run("x.csv", on_progress=3)
    with pytest.raises(TypeError, match="^case: got int 7, expected a str or path, a Case or None; make one with gt.load_case"):
        gt.compensate_run("x.csv", 7)


@pytest.fixture(scope="module")
def record(tmp_path_factory) -> Path:
    """A coarse frame and a measured run of it with nothing to explain (δ a slow ramp)."""
    d = tmp_path_factory.mktemp("record")
    (d / "c.toml").write_text("[mesh]\nsize = 0.03\nsize_3d = 0.04\n")
    t = 60.0 * np.arange(400)
    write_timeseries(d / "record.csv", TimeSeries({"time_s": t, "oil_degC": 40 + 0 * t, "pump": 1 + 0 * t,
                                                   "delta_um": 0.01 * t / 60}, {"format": FORMAT}))
    return d


def test_diagnose_run_reports_progress_and_writes_what_the_command_writes(record, tmp_path):
    calls = []
    model = gt.diagnosis_model(config=str(record / "c.toml"))
    result = gt.diagnose_run(model, record / "record.csv", config=str(record / "c.toml"), effects=(),
                             parameters=(), sensors=False, on_progress=lambda i, n: calls.append((i, n)))
    done = [i for i, _ in calls]
    assert done == sorted(done) and calls[-1] == (result.diagnosis.runs,) * 2 == (2, 2)  # 2 model runs
    assert all(i <= n for i, n in calls)
    assert result.summary().splitlines()[0] == f"verdict: {result.diagnosis.verdict}"
    assert result.write(tmp_path / "d") == result.wrote(tmp_path / "d")
    written = sorted(files(tmp_path / "d"))
    assert {"residuals.png", "report.md", "diagnosis.json"} <= set(written) <= set(gt.api.DIAGNOSE_OUTPUTS)
    saved = json.loads((tmp_path / "d" / "diagnosis.json").read_text())
    assert saved["verdict"] == result.diagnosis.verdict and saved["data"] == str(record / "record.csv")


def test_diagnosis_model_refuses_what_does_not_go(record):
    with pytest.raises(gt.InputError, match="--mesh-factor: goes with --case only"):
        gt.diagnosis_model(config=str(record / "c.toml"), mesh_factor=0.5)
    with pytest.raises(TypeError, match="^model: got str"):
        gt.diagnose_run("case.toml", record / "record.csv")
    table = gt.diagnosis_hypotheses(gt.diagnosis_model(config=str(record / "c.toml")))
    assert table.splitlines()[0].split() == ["kind", "name", "parameter", "plausible", "range", "unit"]
    listed = json.loads(gt.diagnosis_hypotheses(gt.diagnosis_model(config=str(record / "c.toml")), as_json=True))
    assert len(listed) == sum(1 for line in table.splitlines()[1:-2] if not line.startswith(" "))
    assert table.splitlines()[-1].startswith("A diagnosis tries every hypothesis above")
