"""The commands run, simulate, mesh, beam, reduce and export as one API call each (issue 52):
their results, what they write and print, and their progress callbacks (issue 55, item 6),
through the library. The command line's exit codes and messages are tested elsewhere
(test_bad_input.py, test_fault_table.py, test_beam.py, test_export.py)."""
from __future__ import annotations

import json

import pytest

import gatetherm as gt
from gatetherm import InputError

COARSE = "[mesh]\nsize = 0.03\nsize_3d = 0.04\n"


@pytest.fixture(scope="module")
def config(tmp_path_factory):
    path = tmp_path_factory.mktemp("model") / "c.toml"
    path.write_text(COARSE)
    return str(path)


def test_beam_normalised_is_the_closed_form_and_checks_its_arguments():
    b = gt.beam_normalised(2.0, 0.1)
    assert (b.ki_norm, b.kc_norm) == pytest.approx((17 / 42, 25 / 14), rel=1e-15)
    assert json.loads(b.summary(as_json=True)) == {"Ki_norm": b.ki_norm, "Kc_norm": b.kc_norm}
    assert gt.beam_normalised(0.5, 1).summary() == ("l/l4 = 0.5, beta = 1: Ki/(3 alpha l^2/8h) = 0.313725, "
                                                    "Kc/(alpha l_C) = 0.294118")
    for a, beta, where in ((0.0, 0.1, "l_over_l4"), (float("inf"), 0.1, "l_over_l4"), (1.0, -0.1, "beta"),
                           (1.0, float("nan"), "beta")):
        with pytest.raises(InputError, match=f"^{where}: "):
            gt.beam_normalised(a, beta)
    with pytest.raises(TypeError, match="^beta: "):
        gt.beam_normalised(1.0, "0.1")
    with pytest.raises(TypeError, match="^l_over_l4: got bool"):
        gt.beam_normalised(True, 0.1)


def test_mesh_frame_writes_the_frame_as_a_case(config, tmp_path):
    made = gt.mesh_frame(2, config, 2)
    assert made.folder is None and made.case.dim == 2
    written = made.write(tmp_path / "m")
    assert written.folder == str(tmp_path / "m")
    assert sorted(p.name for p in (tmp_path / "m").iterdir()) == ["case.toml", "mesh.msh", "mesh.vtu", "schedule.csv"]
    lines = written.summary().splitlines()
    assert lines[0] == f"wrote {tmp_path / 'm' / 'mesh.msh'}" and lines[3].startswith("2-D frame: ")
    assert gt.mesh_frame(2, config, 2, out=tmp_path / "n").summary() == \
        written.summary().replace(str(tmp_path / "m"), str(tmp_path / "n"))
    with pytest.raises(InputError, match="condition"):
        gt.mesh_frame(2, config, 4, out=tmp_path / "bad")
    assert not (tmp_path / "bad").exists()


def test_simulate_reports_progress_and_writes_what_it_prints(config, tmp_path):
    calls = []
    res = gt.simulate(1, config=config, fields_every=36000.0, pictures=False, out=tmp_path / "s",
                      on_progress=lambda i, n: calls.append((i, n)))
    n = len(res.run.time)
    assert [i for i, _ in calls] == list(range(1, n + 1)) and {m for _, m in calls} == {n}
    s = json.loads((tmp_path / "s" / "summary.json").read_text())
    assert s == res.figures
    first, second = res.summary().splitlines()
    assert first == f"wrote {tmp_path / 's'}/timeseries.csv, summary.json, fields/ and plots"
    assert second.startswith(f"first peak {round(s['first_peak_um'], 2)} µm at {s['first_peak_min']} min")
    with pytest.raises(InputError, match="^out: this run was written into .* as a one-shot run"):
        res.write(tmp_path / "again")  # written with out=: its solver is released
    assert not (tmp_path / "again").exists()
    with pytest.raises(InputError, match="^condition/schedule: "):
        gt.simulate(1, "s.csv")


def test_run_case_of_the_frame_as_a_case_writes_later_or_at_once(config, tmp_path):
    case = gt.mesh_frame(2, config, 1, out=tmp_path / "m")
    at_once = gt.run_case(tmp_path / "m" / "case.toml", tmp_path / "a", pictures=False)
    later = gt.run_case(tmp_path / "m" / "case.toml").write(tmp_path / "b", pictures=False)
    assert case.folder and at_once.summary().replace("/a/", "/b/") == later.summary()
    assert (tmp_path / "a" / "timeseries.csv").read_text().replace("/a/", "/b/") \
        == (tmp_path / "b" / "timeseries.csv").read_text()
    assert later.summary().splitlines()[0] == f"wrote {tmp_path / 'b'}/timeseries.csv, summary.json and fields/"


def test_reduce_case_without_checks_runs_no_fe_and_reports_one_step(config):
    calls = []
    none = gt.reduce_case(config=config, states=4, check_fe=False, on_progress=lambda i, n: calls.append((i, n)))
    assert none.checks == [] and none.folder is None and calls == [(1, 1)]  # no full FE run at all
    assert none.reduction.rom.states == 4 and "BT bound" in none.summary()
    with pytest.raises(InputError, match="^states: "):
        gt.reduce_case(config=config, states=1)


@pytest.mark.slow
def test_reduce_case_progress_counts_the_reduction_and_each_check(config, tmp_path):
    calls = []
    res = gt.reduce_case(config=config, states=4, out=tmp_path / "r", on_progress=lambda i, n: calls.append((i, n)))
    n = 1 + len(res.checks)
    assert len(res.checks) == 3  # the model's own condition 1, then 2 and 3
    assert calls == [(i, n) for i in range(1, n + 1)]
    assert sorted(p.name for p in (tmp_path / "r").iterdir()) == ["rom.key", "rom.npz", "summary.json"]
    lines = res.summary().splitlines()
    assert len(lines) == 1 + 2 * len(res.checks) and lines[1].startswith("condition 1: max |δ_rom − δ_FE| = ")


def test_export_case_progress_and_the_deck_written(config, tmp_path):
    calls = []
    res = gt.export_case(condition=1, time=900.0, config=config, on_progress=lambda i, n: calls.append((i, n)))
    assert calls and [i for i, _ in calls] == list(range(1, calls[-1][1] + 1))
    assert res.folder is None and res.deck.startswith("** gatetherm condition 1, t = 15 min\n")
    written = res.write(tmp_path / "x")
    assert (tmp_path / "x" / "job.inp").read_text() == res.deck
    assert json.loads((tmp_path / "x" / "gatetherm.json").read_text())["nodes"] == res.info["nodes"]
    assert written.summary().splitlines()[0] == (f"wrote {tmp_path / 'x'}/job.inp ({res.info['element']}, "
                                                 f"{res.info['nodes']} nodes) and gatetherm.json; run: cd "
                                                 f"{tmp_path / 'x'} && ccx job")
    with pytest.raises(InputError, match="^case/condition: "):
        gt.export_case()
