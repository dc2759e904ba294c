"""The iterative path and its choice: AMG-CG equals the factor's solution, its Galerkin start
reproduces a solution sequence that lies in the span of the previous ones, the plan picks by
budget and is logged in one line, a whole run on the iterative path gives the direct path's
outputs, and the rational-Krylov reduced model is as close to FE as balanced truncation's."""
from __future__ import annotations

import numpy as np
import pytest

from gatetherm import InputError
from gatetherm.frame.conditions import CONDITIONS
from gatetherm.solvers import iterative, krylov, plan
from gatetherm.frame.problem import build_model
from gatetherm.solvers.linsolve import planned_solver, spd_factor
from gatetherm.solvers.rom import _weights, linear_heat_model, project, reduce
from gatetherm.solvers.rom_time import simulate_rom
from gatetherm.studies.run.conditions import SupplyParams, condition_drive
from gatetherm.studies.run.reduce import series_inputs
from gatetherm.studies.run.simulate import column, run_model, sample_times

from conftest import FIXED_MODEL


@pytest.fixture(scope="module")
def heat_3d(frame_3d):
    """The coarse 3-D frame's model and its pump-on step matrix of 60-s Crank–Nicolson steps
    (the solid block)."""
    model = build_model(FIXED_MODEL, 3, frame_3d)
    h = model.heat
    A = (h.M / 30.0 + h.K((True,)))[:h.n_solid, :h.n_solid].tocsr()
    return model, A


def test_amg_cg_equals_the_factor_and_raises_when_it_cannot_converge(heat_3d, monkeypatch):
    _, A = heat_3d
    b = A @ np.random.default_rng(0).normal(size=(A.shape[0], 2))
    x = iterative.PCG(A, rtol=1e-12)(b)
    ref = spd_factor(A)[0](b)
    assert np.abs(x - ref).max() < 1e-9 * np.abs(ref).max()
    monkeypatch.setattr(iterative, "MAXITER", 1)
    with pytest.raises(iterative.SolverError, match="did not converge"):
        iterative.PCG(A, rtol=1e-12)(b[:, 0])


def test_coarsening_stops_at_the_bound_and_the_coarsest_level_is_solved_exactly(heat_3d):
    _, A = heat_3d
    assert (iterative.max_coarse(52_812), iterative.max_coarse(961_358)) == (500, 980)  # the 1 × and 20 × heat
    sizes = [lv.A.shape[0] for lv in iterative.AMG(A, coarsest=20).ml.levels]
    assert len(sizes) >= 3 and sizes[-1] <= 20 < sizes[-2], sizes
    b = np.random.default_rng(1).normal(size=A.shape[0])
    whole = iterative.AMG(A, coarsest=A.shape[0])  # one level: the V-cycle is its sparse LU solve
    assert len(whole.ml.levels) == 1
    assert np.linalg.norm(A @ whole(b) - b) < 1e-12 * np.linalg.norm(b)


def test_right_hand_sides_solved_in_two_processes_are_the_factors_solutions(heat_3d, monkeypatch):
    """The later half of the columns solved by a forked copy: the factor's solutions, its
    iterations counted (the first half zero: none of its own), its failure raised here."""
    import os

    _, A = heat_3d
    monkeypatch.setattr(iterative, "SPLIT_UNKNOWNS", 0)
    monkeypatch.setattr(iterative, "can_fork", lambda: True)
    b = np.zeros((A.shape[0], 4))
    b[:, 2:] = A @ np.random.default_rng(2).normal(size=(A.shape[0], 2))
    pid, pcg = os.getpid(), iterative.PCG(A, rtol=1e-12)
    x = pcg(b)
    ref = spd_factor(A)[0](b[:, 2:])
    assert os.getpid() == pid and np.array_equal(x[:, :2], np.zeros_like(x[:, :2]))
    assert np.abs(x[:, 2:] - ref).max() < 1e-9 * np.abs(ref).max()
    assert pcg.solves == 2 and pcg.iterations > 0  # the second process's
    monkeypatch.setattr(iterative, "MAXITER", 1)
    with pytest.raises(iterative.SolverError, match="did not converge"):
        iterative.PCG(A, rtol=1e-12)(b)


def test_galerkin_start_reproduces_a_solution_in_the_span_of_the_last_ones(heat_3d):
    """Solutions on a quadratic path x(k) = x0 + k d1 + k² d2: from the fourth on, the Galerkin
    projection onto the kept solutions is the solution itself, and CG takes no iteration. The
    first three are solved to 1e-12, so that the projection's residual (theirs, times coefficients
    up to 3) is within the later solves' 1e-9."""
    _, A = heat_3d
    rng = np.random.default_rng(1)
    x0, d1, d2 = (rng.normal(size=A.shape[0]) for _ in range(3))
    pcg = iterative.PCG(A, rtol=1e-12)
    counts = []
    for k in range(6):
        pcg.rtol = 1e-12 if k < 3 else 1e-9
        before = pcg.iterations
        x = pcg(A @ (x0 + k * d1 + k ** 2 * d2))
        counts.append(pcg.iterations - before)
        assert np.linalg.norm(x - (x0 + k * d1 + k ** 2 * d2)) < 1e-7 * np.linalg.norm(x)
    assert counts[3:] == [0, 0, 0] and min(counts[:3]) > 0


def test_plan_follows_the_budget_and_the_forced_path(heat_3d, monkeypatch, caplog):
    _, A = heat_3d
    monkeypatch.delenv(plan.PATH_ENV, raising=False)
    monkeypatch.setenv(plan.BUDGET_ENV, "1000")
    assert plan.plan(A.shape[0], A.nnz, 1, 3, 100, held=0.0).path == "direct"  # faster for many solves
    n, nnz = 1_000_000, 13_600_000  # a million-node heat matrix: its factor needs 7 GB, AMG-CG 0.6 GB
    seconds, nbytes = plan.predict(n, nnz, 1, 3, 1000, warm=True)
    assert nbytes["direct"] == pytest.approx(7.3e9, rel=0.05) and nbytes["iterative"] == pytest.approx(5.9e8, rel=0.05)
    assert (seconds["direct"], seconds["iterative"]) == pytest.approx((1290, 1099), rel=1e-3)  # 1000 steps: AMG-CG
    assert plan.plan(n, nnz, 1, 3, 1000, held=0.0, warm=True).path == "iterative"
    seconds, nbytes = plan.predict(A.shape[0], A.nnz, 1, 3, 100)
    assert seconds["direct"] < seconds["iterative"]
    monkeypatch.setenv(plan.BUDGET_ENV, repr((nbytes["direct"] + nbytes["iterative"]) / 2e9))
    assert plan.plan(A.shape[0], A.nnz, 1, 3, 100, held=0.0).path == "iterative"  # the faster factor does not fit
    monkeypatch.setenv(plan.PATH_ENV, "direct")
    with caplog.at_level("INFO", logger="gatetherm.solvers.linsolve"):
        _, path = planned_solver(A, 3, 1, "test system")
    assert path == "direct"
    line = [r.getMessage() for r in caplog.records if "test system" in r.getMessage()]
    assert len(line) == 1 and "forced by the solver option path (GATETHERM_SOLVER)" in line[0] and "iterative" in line[0]
    for env, value in ((plan.PATH_ENV, "fast"), (plan.BUDGET_ENV, "-1")):
        monkeypatch.setenv(env, value)
        with pytest.raises(InputError, match=env):
            plan.plan(A.shape[0], A.nnz, 1, 3, 1)
        monkeypatch.delenv(env)


def test_the_iterative_path_gives_the_direct_paths_outputs(frame_3d, monkeypatch):
    """An hour of condition 1 on the coarse 3-D frame, every system forced onto each path: the
    outputs (δ, temperatures) agree to 1e-4 µm (issue 24's band) and 1e-5 K."""
    times = sample_times(3600.0)
    drive = condition_drive(CONDITIONS[1], SupplyParams())
    out = {}
    for path in ("direct", "iterative"):
        monkeypatch.setenv(plan.PATH_ENV, path)
        model = build_model(FIXED_MODEL, 3, frame_3d)
        out[path] = run_model(model, drive, times).columns
        assert model.elastic.solve.path in (path, None)
    d = np.abs(out["direct"]["delta_um"] - out["iterative"]["delta_um"]).max()
    T = np.abs(out["direct"]["theta_A_degC"] - out["iterative"]["theta_A_degC"]).max()
    assert d < 1e-4 and T < 1e-5, (d, T)  # achieved 2.6e-5 µm, 5.8e-6 K (heat steps to HEAT_RTOL = 1e-7)


@pytest.mark.slow
def test_krylov_basis_reduces_as_well_as_balanced_truncation(frame_2d):
    """The 2-D fixture frame reduced to 20 states both ways: the Krylov basis is M-orthonormal,
    its static δ gains exact, and its condition-1 δ as close to the FE march as balanced
    truncation's."""
    model = build_model(FIXED_MODEL, 2, frame_2d)
    lhm = linear_heat_model(model, column)
    key = [lhm.outputs.index(k) for k in lhm.key_outputs]
    modes = {m: (lhm.K[m], lhm.B[m]) for m in lhm.modes}
    V, info = krylov.basis(lhm.M, modes, _weights(lhm.key_outputs)[:, None] * lhm.C[key], 20, dim=2)
    assert V.shape[1] == 20 and np.abs(V.T @ (lhm.M @ V) - np.eye(20)).max() < 1e-11  # achieved 1.8e-13
    fe = run_model(model, condition_drive(CONDITIONS[1], SupplyParams()), sample_times(5 * 3600.0)).columns
    err = {}
    for name, rom in (("krylov", project(lhm, V)), ("bt", reduce(lhm, 20).rom)):
        y = simulate_rom(rom, 60.0, *series_inputs(rom, fe))
        err[name] = float(np.max(np.abs(y[:, rom.output("delta_um")] - fe["delta_um"])))
    rom, d = project(lhm, V), lhm.outputs.index("delta_um")
    for m in lhm.modes:
        live = np.abs(lhm.B[m]).sum(axis=0) > 0
        gain = lhm.C[d] @ info["static"][m] - rom.C[d] @ np.linalg.solve(-rom.A[m], rom.B[m][:, live])
        assert np.abs(gain).max() < 1e-11, m  # µm/K, achieved 5.6e-14
    assert err["krylov"] == pytest.approx(0.108, abs=0.01) and err["bt"] == pytest.approx(0.105, abs=0.01), err
