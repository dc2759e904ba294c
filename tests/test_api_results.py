"""The API functions behind the commands (issue 52): each returns a result that writes the
command's files (``.write(out)``) and says what the command prints (``.summary()``), and the long
ones report their progress through ``on_progress(i, n)`` (issue 55), tested through the library."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from conftest import synthetic_record

import gatetherm as gt
from gatetherm import InputError


def increasing_to_the_end(calls: list) -> bool:
    """``on_progress`` was called with i = 1, 2, ... n and one n throughout."""
    return bool(calls) and [i for i, _ in calls] == list(range(1, len(calls) + 1)) \
        and {n for _, n in calls} == {len(calls)}


@pytest.fixture(scope="module")
def record(tmp_path_factory) -> Path:
    """A machine's record: d_um = 2 (theta_1 - theta_1(0)) + noise of 0.05 um; theta_2 unrelated."""
    d = tmp_path_factory.mktemp("record")
    synthetic_record(d / "data.csv")
    return d / "data.csv"


def test_errormodel_fit_reports_progress_and_writes_what_the_command_writes(record, tmp_path):
    calls = []
    fit = gt.errormodel_fit(record, ["d_um"], on_progress=lambda i, n: calls.append((i, n)))
    assert calls == [(1, 2), (2, 2)] and increasing_to_the_end(calls)  # the file read, then the fit
    (m,) = fit.model.targets
    assert m.sensors == ("s1_degC",) and m.form == "static"
    assert m.coefficients[0] == pytest.approx(1.958, abs=0.005)  # band: within 5 % of the 2 um/K made
    how = "blocked, chosen on the latest forward-chaining blocks"  # ROBUST.choose_latest
    assert fit.runs == 1 and fit.held_out == how and fit.files == (str(record),)
    lines = fit.summary(tmp_path / "o").splitlines()
    assert lines[0] == (f"wrote {tmp_path / 'o' / 'model.json'} (fitted on 1 run(s), 400 samples; "
                        f"held-out error: {how}; readings smoothed over 0 s)")
    assert lines[1].startswith("d_um: static; sensors s1_degC; time constants none; held-out MAE 0.092 um")
    assert fit.write(tmp_path / "o") == tmp_path / "o" / "model.json"
    assert sorted(p.name for p in (tmp_path / "o").iterdir()) == ["model.json"]
    assert json.loads((tmp_path / "o" / "model.json").read_text())["targets"]


def test_errormodel_fit_settings_are_checked_by_name(record):
    with pytest.raises(TypeError, match="max_sensorz: not a setting of the fit"):
        gt.errormodel_fit(record, ["d_um"], max_sensorz=2)
    with pytest.raises(InputError, match="^candidates d_um: is a target"):
        gt.errormodel_fit(record, ["d_um"], ["d_um", "s1_degC"])
    with pytest.raises(InputError, match="^--candidates d_um: is a target"):
        gt.errormodel_fit(record, ["d_um"], ["d_um"], named_as=("--targets", "--candidates", "--inputs"))


def test_prediction_and_refit_write_and_say_what_the_commands_do(record, tmp_path):
    fit = gt.errormodel_fit(record, ["d_um"])
    model = fit.model
    p = gt.errormodel_predict(model, record)
    assert gt.errormodel_predict(fit, record).scores == p.scores  # a fit's result is a model to predict with
    p.write(tmp_path / "p")
    assert sorted(x.name for x in (tmp_path / "p").iterdir()) == ["prediction.csv", "prediction.png", "summary.json"]
    assert p.summary().splitlines() == ["d_um: MAE 0.0366 um, RMS 0.0477 um over 400 samples, 96% inside the 90 % "
                                        "interval"]  # band: RMS near the 0.05 um of noise; 94 % before the
    # interval became the conformal quantile over the forward blocks (issue 56)
    refit = gt.errormodel_refit(model, record, 3 * 3600.0)
    new, report = refit  # unpacks as before
    assert report["d_um"]["kept"] and new is refit.model
    assert refit.summary().startswith("d_um: kept the current coefficients: on the window's last quarter 0.0432 um")
    from gatetherm.studies.run.timeseries import read_timeseries

    t = read_timeseries(record, required=("time_s",)).time_s
    span = float(t[-1] - t[0])  # a window longer than the file: all of it, and said so
    whole = gt.errormodel_refit(model, record, 10 * span)
    assert whole.window_s == span and whole.summary(tmp_path / "r").startswith(f"wrote {tmp_path / 'r' / 'model.json'} "
                                                                                f"(refitted on the last {span / 3600:g} h)")
    with pytest.raises(InputError, match="^applied: 2 columns for 1 targets"):
        gt.errormodel_refit(model, record, 3600.0, ["a_um", "b_um"])


BLOCKS = Path(__file__).parent / "data" / "two_blocks.geo"


def test_sensor_placement_reports_progress(tmp_path):
    """Two blocks (153 nodes), 3 generated loads and 2 held out: one step for the reduction, one
    per load marched, one for the selection."""
    from tests.test_placement import BLOCKS as CASE, SCHEDULE

    shutil.copy(BLOCKS, tmp_path)
    (tmp_path / "case.toml").write_text(CASE)
    (tmp_path / "schedule.csv").write_text(SCHEDULE)
    calls = []
    study = gt.sensor_study(gt.load_case(tmp_path / "case.toml"), 1, loads=3, held_out_loads=2, states=8,
                            on_progress=lambda i, n: calls.append((i, n)))
    assert increasing_to_the_end(calls)
    assert calls[-1][1] == 1 + len(study.placement.training) + len(study.placement.held_out) + 1
    assert study.check is None and len(study.placement.sensors) == 1
    study.write(tmp_path / "o")
    assert sorted(p.name for p in (tmp_path / "o").iterdir()) == sorted(gt.api.sensors.OUTPUTS)
    excluded, k1 = study.summary(tmp_path / "o").splitlines()[1:3]
    assert excluded.endswith("a face a support holds): cold (4 candidate nodes left out)") and k1.startswith("K=1 ")


def test_report_reports_progress_over_the_sections(tmp_path, monkeypatch):
    from gatetherm.validation.report.registry import SECTIONS
    from gatetherm.validation.report.sections import speed

    monkeypatch.setattr(speed, "BENCHMARKS", tmp_path)
    calls, seen = [], []
    done = gt.report(tmp_path / "R", sections=["speed"], on_section=lambda *a: seen.append(a[:2]),
                     on_progress=lambda i, n: calls.append((i, n)))
    assert increasing_to_the_end(calls) and len(calls) == len(SECTIONS) == len(seen)
    assert ("speed", "computed") in seen and done.results["speed"] is not None
    assert done.summary().startswith(f"wrote {tmp_path / 'R'}/index.html and validation.md in ")
    with pytest.raises(InputError, match="^sections nosuch: is not a section of the report"):
        gt.report(tmp_path / "R", sections=["nosuch"])


def test_validate_and_sweep_refuse_bad_arguments_by_name(tmp_path):
    with pytest.raises(InputError, match="^target: 'nosuch' is not a validation study; choose from beam, "):
        gt.validate("nosuch", tmp_path / "v")
    with pytest.raises(InputError, match="^effects: unknown nosuch"):
        gt.validate("hidden-effects", tmp_path / "v", effects=["nosuch"])
    (tmp_path / "s.toml").write_text('[study]\ncompute = ["coefficients"]\n[grid]\n"geometry.l4" = [0.25]\n')
    with pytest.raises(InputError, match="^workers: "):
        gt.sweep(tmp_path / "s.toml", tmp_path / "o", workers=0)
    assert not (tmp_path / "o").exists() and not (tmp_path / "v").exists()


def test_sweep_reports_progress_and_writes_its_table_again_elsewhere(tmp_path):
    """Two points of the frame's coefficients on a coarse mesh (the fault table's study)."""
    (tmp_path / "s.toml").write_text('[study]\ncompute = ["coefficients"]\n[set]\n"mesh.size" = 0.03\n'
                                     '[grid]\n"geometry.l4" = [0.25, 0.3]\n')
    calls = []
    result = gt.sweep(tmp_path / "s.toml", tmp_path / "o", on_progress=lambda i, n: calls.append((i, n)))
    assert calls[-1] == (2, 2) and [i for i, _ in calls] == sorted(i for i, _ in calls)
    assert len(result.rows) == 2 and not result.failed and result.skipped == 0
    assert result.summary(tmp_path / "o") == f"wrote {tmp_path / 'o' / 'table.csv'}: 2 points, 2 done, 0 skipped " \
                                             "(frame cannot be built), 0 failed"
    result.raise_failed()  # nothing failed: no exception
    result.write(tmp_path / "again")
    assert (tmp_path / "again" / "table.csv").read_text() == (tmp_path / "o" / "table.csv").read_text()
    assert sorted(p.name for p in (tmp_path / "again").iterdir()) == ["study.json", "table.csv"]


def test_validate_refuses_a_setting_its_study_does_not_take(tmp_path):
    with pytest.raises(TypeError, match="^dims: not a setting of the beam study; it takes config, dim, workers"):
        gt.validate("beam", tmp_path / "v", dims=[2])
    assert not (tmp_path / "v").exists()


def test_every_validate_target_of_the_command_passes_settings_its_study_takes(tmp_path, monkeypatch, capsys):
    """``gatetherm validate TARGET`` calls gt.validate with the target's settings (the studies
    replaced by a stand-in that records them)."""
    from gatetherm.api import validate_study
    from gatetherm.cli import main

    seen = {}
    for name, (text, _) in list(validate_study.TARGETS.items()):
        def study(out, options, on_line, on_progress, name=name):
            seen[name] = set(options)
            on_line(f"{name} streamed")
            return f"{name} done\n", None
        monkeypatch.setitem(validate_study.TARGETS, name, (text, study))
    for name in validate_study.TARGETS:
        assert main(["validate", name, "--out", str(tmp_path / name)]) == 0
        assert capsys.readouterr().out == f"{name} streamed\n{name} done\n"
    assert seen == {k: set(v) for k, v in validate_study.OPTIONS.items()}


@pytest.mark.parametrize("command", ["errormodel", "sensors", "sweep", "report", "validate"])
def test_the_command_imports_only_the_api_and_the_standard_library(command):
    """Issue 52: a command parses, calls gatetherm.api and prints (every import, also inside functions)."""
    import ast
    import sys

    path = Path(__file__).parents[1] / "core" / "cli" / f"{command}.py"
    modules = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            modules |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            modules.add(node.module)
    others = sorted(m for m in modules if m.split(".")[0] not in sys.stdlib_module_names
                    and not m.startswith(("gatetherm.api", "gatetherm.cli")))
    assert others == []
