"""The progress of a diagnosis: model runs done of those planned (issue 55 item 6), through the
library's ``on_progress``, and the plan a long diagnosis announces before its search."""
from __future__ import annotations

import dataclasses
from types import SimpleNamespace


import gatetherm.api as gt
from gatetherm.frame.config import load_config
from gatetherm.frame.geometry import MeshParams
from gatetherm.studies.diagnosis.progress import CHECK_RUNS, FIRST_RUNS, ROUND_RUNS, Budget, plan_line
from gatetherm.studies.run.timeseries import write_timeseries
from gatetherm.validation.truth import Case, measured, truth

SIZE = 0.03
"""Element size of the diagnosis (and truth) mesh, m: coarse, for speed."""


def test_the_callback_sees_every_run_and_ends_at_the_runs_reported(tmp_path):
    """A hidden piezo heat, diagnosed through gt.diagnose_run: ``i`` never falls and goes up by one at
    a time (a call after every model run; between runs, calls where the plan ``n`` changes), ``n``
    stays above ``i`` until the last call, which is (runs, runs) with the runs the result reports."""
    cfg = load_config()
    cfg = dataclasses.replace(cfg, model=dataclasses.replace(cfg.model, mesh=MeshParams(size=SIZE)))
    write_timeseries(tmp_path / "m.csv", measured(truth(cfg, Case("piezo_heat", 3.0, 1, 3), mesh_factor=1.0), 3, 1))
    seen = []
    result = gt.diagnose_run(gt.diagnosis_model(mesh_size=SIZE), tmp_path / "m.csv",
                             on_progress=lambda i, n: seen.append((i, n)), effects=("piezo_heat",), parameters=(),
                             sensors=False, p2_check=False)
    d = result.diagnosis
    assert d.verdict == "explained" and d.named_effects == ["piezo_heat"]
    done = [i for i, _ in seen]
    assert sorted(set(done)) == list(range(done[0], d.runs + 1)) == list(range(1, 10))
    assert all(b - a in (0, 1) for a, b in zip(done, done[1:]))  # monotone, one run at a time
    assert all(n > i for i, n in seen[:-1]) and seen[-1] == (d.runs, d.runs)
    assert d.runs == 9  # achieved: the baseline, the scan and secant steps of the one hypothesis, the checks


def test_a_budget_plans_from_the_runs_measured():
    seen = []
    b = Budget(lambda i, n: seen.append((i, n)), max_pieces=4, first=2)  # the baseline and the P2 check
    b.ran(), b.ran()
    assert seen == [(1, 2), (2, 3)]
    pool = [SimpleNamespace(rerun=r) for r in [True] * 10 + [False] * 5]
    planned = []

    def fit(p):  # six runs a hypothesis that needs runs; the plan seen before the fit
        planned.append(seen[-1])
        for _ in range(6 * p.rerun):
            b.ran()

    b.first_round(pool, fit)
    later = 3 * ROUND_RUNS + CHECK_RUNS
    assert planned[0] == (2, 2 + 10 * FIRST_RUNS + later) and planned[2] == (14, 14 + 8 * 6 + later)
    assert seen[-1] == (62, 62 + later)
    for _ in range(2 * ROUND_RUNS):  # a round twice the prior: the next one planned at that
        b.ran()
    b.round_done(chosen=2)
    assert seen[-1] == (62 + 2 * ROUND_RUNS, 62 + 2 * ROUND_RUNS + 2 * ROUND_RUNS + CHECK_RUNS)
    b.round_done(chosen=3)  # no round left: the checks
    done = 62 + 2 * ROUND_RUNS
    assert seen[-1] == (done, done + CHECK_RUNS)
    for _ in range(CHECK_RUNS + 5):  # more runs than planned: a tenth more planned, n stays ahead of i
        b.ran()
    reached, done = done + CHECK_RUNS, done + CHECK_RUNS + 5
    assert seen[-1] == (done, reached + reached // 10)
    b.finish()
    assert seen[-1] == (done, done) and [i for i, _ in seen] == sorted(i for i, _ in seen)
    assert all(n > i for i, n in seen[:-1])


def test_the_plan_names_the_runs_the_time_and_what_makes_it_cheaper():
    line = plan_line(rerun=30, pieces=43, runs=2, per_run=4.0, order=2, max_pieces=4, p1_run=2.0)
    planned = 2 + 30 * FIRST_RUNS + 3 * ROUND_RUNS + CHECK_RUNS  # 314
    assert line.startswith(f"diagnosis: about {planned} model runs planned (43 hypotheses, 30 of them need model "
                           f"runs), 4.0 s a run (the baseline, P2): about {planned * 4.0 / 60:.0f} min")
    assert "--effects none, --parameters NAME,... or --no-sensors" in line and "--keep-order" in line
    assert "--keep-order" not in plan_line(30, 43, 2, 4.0, 1, 4)
