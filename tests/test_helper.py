"""The elastic solver in a helper process beside the caller: the helper's solutions are the
factor's, several in flight come back each to its own, a failure (of a solve, of the set-up,
of the process) is raised in the caller, the helper holds none of the caller's other pipes
open, and a run with the helper gives the outputs and fields of a run without it."""
from __future__ import annotations

import gc
import os
import pickle
import select
import signal
import time

import numpy as np
import pytest
import scipy.sparse as sp

from gatetherm import process
from gatetherm.frame.conditions import CONDITIONS
from gatetherm.solvers import iterative, p1, plan
from gatetherm.frame.problem import build_model
from gatetherm.solvers import model as model_module
from gatetherm.solvers.helper import Pending, SolveHelper, forked
from gatetherm.solvers.iterative import PCG, SolverError
from gatetherm.solvers.linsolve import nd_order, spd_factor
from gatetherm.studies.run.conditions import SupplyParams, condition_drive
from gatetherm.studies.run.output import displacements
from gatetherm.studies.run.simulate import delta_figures, run_model, sample_times

from conftest import FIXED_MODEL


def _laplacian(n: int = 40) -> sp.csr_matrix:
    """The 5-point Laplacian of an n × n grid plus the identity (SPD)."""
    T = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
    return (sp.kronsum(T, T) + sp.identity(n * n)).tocsr()


def test_helper_solutions_are_the_factors_each_to_its_own_submission():
    A = _laplacian()
    rng = np.random.default_rng(0)
    bs = [rng.normal(size=A.shape[0]), rng.normal(size=(A.shape[0], 3)), rng.normal(size=A.shape[0])]
    helper = SolveHelper(lambda: PCG(A, rtol=1e-12, split=False), "test system")
    try:
        pending = [helper.submit(b) for b in bs]  # all in flight, then looked up last first
        xs = [p.result() for p in reversed(pending)][::-1]
        assert helper.pid != os.getpid() and all(p.done() for p in pending)
    finally:
        helper.close()
    ref = spd_factor(A)[0]
    for b, x in zip(bs, xs):
        assert x.shape == b.shape and np.abs(x - ref(b)).max() < 1e-9 * np.abs(ref(b)).max()
    with pytest.raises(SolverError, match="closed"):
        helper.submit(bs[0])


def _ends(pid: int, within_s: float = 10.0) -> bool:
    """Whether the child ``pid`` ends (a zombie: not reaped, so its number is not reused) within ``within_s``."""
    deadline = time.monotonic() + within_s
    while time.monotonic() < deadline:
        with open(f"/proc/{pid}/stat") as f:
            if f.read().rsplit(")", 1)[1].split()[0] == "Z":
                return True
        time.sleep(0.01)
    return False


def test_a_finished_helper_answers_what_it_was_given_then_ends():
    """After ``finish`` the helper answers the jobs queued (their values readable after it has
    ended), then its process ends by itself, its folder left for ``close``; nothing more is taken."""
    helper = SolveHelper(_Spy, "spy")
    try:
        slow, b = -np.ones(4), np.arange(1.0, 5.0)
        pending = [helper.submit(x) for x in (slow, b, 3 * b)]
        helper.finish()
        assert not helper.open
        with pytest.raises(SolverError, match="closed"):
            helper.submit(b)
        assert [p.result().tolist() for p in pending] == [slow.tolist(), b.tolist(), (3 * b).tolist()]
        assert _ends(helper.pid) and os.path.isdir(helper._dir)  # without being killed
    finally:
        helper.close()
    assert not os.path.exists(helper._dir)


def test_a_retired_solver_ends_its_helper_and_solves_here_after(monkeypatch):
    """``SPDSolver.retire``: the solutions submitted before come from the helper, which then
    ends by itself; a later solve is made in the caller, the same to the solver's tolerance."""
    from gatetherm.solvers.linsolve import SPDSolver

    monkeypatch.setenv(plan.PATH_ENV, "iterative")
    monkeypatch.setattr(process, "can_fork", lambda: True)
    A = _laplacian()
    b = A @ np.random.default_rng(2).normal(size=A.shape[0])
    solver = SPDSolver(A, 2)
    assert solver.start(1) and solver.background
    before = solver.submit(b)
    solver.retire()
    assert not solver.background and solver.path is None
    after = solver(b)
    assert solver.path == "iterative"
    x = before.result()
    assert _ends(solver._helper.pid)
    assert np.abs(x - after).max() < 1e-6 * np.abs(after).max()


class _Spy:
    """A 'solver' giving ``b`` while its ``split`` is off, ``2 b`` while on (as the helper sets
    it), sleeping 0.5 s on a right-hand side starting with -1."""

    split = False

    def __call__(self, b):
        if np.ravel(b)[0] == -1.0:
            time.sleep(0.5)
        return b * (2.0 if self.split else 1.0)


def test_what_the_helper_has_when_the_caller_waits_is_solved_together_in_two_processes(monkeypatch):
    """Jobs queued behind a slow one while the caller works are solved one at a time, as they
    come; once the caller waits, those queued are solved in one call with the solver's split on
    (its columns in two processes); the AMG-CG helper's answers so are the factor's."""
    spy = SolveHelper(_Spy, "spy")
    try:
        slow, b = -np.ones(4), np.arange(1.0, 5.0)
        first = [spy.submit(x) for x in (slow, b)]
        time.sleep(1.0)  # the caller works: each solved alone
        assert [np.array_equal(p.result(), x) for p, x in zip(first, (slow, b))] == [True, True]
        queued = [spy.submit(slow)]
        time.sleep(0.2)  # the slow one taken up
        queued += [spy.submit(x) for x in (b, 2 * b, np.column_stack([b, b]))]
        got = [p.result() for p in reversed(queued)][::-1]  # the caller waits behind the slow one
    finally:
        spy.close()
    assert np.array_equal(got[0], slow)  # being solved when the caller began to wait
    assert np.array_equal(got[1], 2 * b) and np.array_equal(got[2], 4 * b)  # stacked, split on
    assert np.array_equal(got[3], 2 * np.column_stack([b, b]))  # alone, split on
    monkeypatch.setattr(iterative, "SPLIT_UNKNOWNS", 0)  # the coarse system splits too
    A = _laplacian()
    rng = np.random.default_rng(1)
    bs = [rng.normal(size=A.shape[0]) for _ in range(4)]
    helper = SolveHelper(lambda: PCG(A, rtol=1e-12, split=False), "test system")
    try:
        xs = [p.result() for p in [helper.submit(x) for x in bs]]
    finally:
        helper.close()
    ref = spd_factor(A)[0]
    assert max(np.abs(x - ref(x_b)).max() / np.abs(ref(x_b)).max() for x, x_b in zip(xs, bs)) < 1e-9


def test_a_failure_in_the_helper_is_raised_in_the_caller():
    A = _laplacian(10)
    b = np.ones(A.shape[0])

    def failing():
        raise ValueError("no such matrix")
    bad = SolveHelper(failing, "set-up")
    solver = SolveHelper(lambda: PCG(A, rtol=1e-12, split=False, recycle=0), "solve")
    try:
        with pytest.raises(SolverError, match="set-up: ValueError: no such matrix"):
            bad.submit(b).result()
        first = solver.submit(b).result()  # made and working
        assert np.abs(A @ first - b).max() < 1e-10
        os.kill(solver.pid, signal.SIGKILL)
        os.waitpid(solver.pid, 0)
        with pytest.raises(SolverError, match="ended without its solutions"):
            solver.submit(2 * b).result()
    finally:
        bad.close()
        solver.close()


def test_the_helper_holds_none_of_the_callers_pipes_open():
    """A pipe the caller opened before the helper and then closed its writing end of: its
    reader sees the end at once (the painter's processes end so), the helper alive."""
    r, w = os.pipe()
    helper = SolveHelper(lambda: (lambda b: b), "identity")
    try:
        os.close(w)
        assert select.select([r], [], [], 2.0)[0] and os.read(r, 1) == b""
        assert np.array_equal(helper.submit(np.arange(3.0)).result(), np.arange(3.0))
    finally:
        os.close(r)
        helper.close()


def test_a_pending_value_pickles_as_the_value_and_maps():
    p = Pending(lambda: np.arange(4.0)).then(lambda x: 2 * x)
    assert np.array_equal(pickle.loads(pickle.dumps(p)), [0.0, 2.0, 4.0, 6.0])
    assert Pending.of(3).done() and Pending.of(3).then(str).result() == "3"


def test_a_forked_value_comes_back_a_failure_is_raised_and_a_dropped_one_leaves_no_process():
    got = forked(lambda: np.arange(300_000), "a value")  # 2.4 MB: more than the widened pipe holds
    assert np.array_equal(got.result(), np.arange(300_000)) and got.done()
    with pytest.raises(SolverError, match=r"^a failure: ZeroDivisionError: division by zero$"):
        forked(lambda: 1 / 0, "a failure").result()

    def children() -> set[str]:
        return set(open(f"/proc/{os.getpid()}/task/{os.getpid()}/children").read().split())
    before = children()
    dropped = forked(lambda: time.sleep(60), "dropped")
    assert len(children() - before) == 1
    del dropped
    gc.collect()
    assert children() - before == set()  # killed and reaped


def test_the_order_found_beside_the_set_up_is_the_one_found_here(frame_3d, monkeypatch):
    """Where the plan would factor a heat step, ``build`` starts the mesh's METIS order in a forked
    process (from any size here); the order it gives is the caller's own."""
    from gatetherm.solvers import helper

    started = []
    monkeypatch.setitem(model_module.ORDER_BESIDE, "nodes", 0)
    monkeypatch.setattr(process, "can_fork", lambda: True)
    monkeypatch.setattr(helper, "forked", lambda make, what, f=helper.forked: started.append(what) or f(make, what))
    model = build_model(FIXED_MODEL, 3, frame_3d)  # its elastic factor (for the read-out) takes the order
    assert started == ["METIS order"] and "_order_beside" not in model.simplices.__dict__
    assert np.array_equal(model.simplices.order, nd_order(model.simplices.pattern.graph()))


def test_a_run_with_the_elastic_helper_gives_the_outputs_and_fields_of_one_without(frame_3d, monkeypatch):
    """An hour of condition 1 on the coarse 3-D frame on the iterative path, with the elastic
    solver in a helper (its stiffness assembled there, never in the caller; its read-out waited
    for, the 30-min field solved during the march) and in the process: δ agrees to 1e-9 µm, the
    fields to 1e-8 of their size; the plan's size of the stiffness, found without it, is its own."""
    monkeypatch.setenv(plan.PATH_ENV, "iterative")
    times, drive = sample_times(3600.0), condition_drive(CONDITIONS[1], SupplyParams())
    keep = (0.0, 1800.0, 3600.0)
    out = {}
    assembled = []  # by this process
    monkeypatch.setattr(p1, "stiffness", lambda *a, f=p1.stiffness: assembled.append(1) or f(*a))
    for beside in (True, False):
        monkeypatch.setattr(process, "can_fork", lambda: beside)  # whatever threads earlier tests left
        model = build_model(FIXED_MODEL, 3, frame_3d)
        assert model.elastic.solve.background is beside
        res = run_model(model, drive, times, keep, solve_at=keep)
        assert len(assembled) == (0 if beside else 1)
        if not beside:
            assert model.elastic.solve.size == (model.elastic.K.shape[0], model.elastic.K.nnz) == (16905, 605853)
        assert sorted(res.solved) == ([0.0, 1800.0] if beside else [])  # not the last sample's
        u = displacements(model, res.states, res.envs, res.solved)
        out[beside] = res.columns["delta_um"], np.column_stack([u[t] for t in keep])
    d = np.abs(out[True][0] - out[False][0]).max()
    du = np.abs(out[True][1] - out[False][1]).max() / np.abs(out[False][1]).max()
    assert d < 1e-9 and du < 1e-8, (d, du)


def test_the_state_of_the_first_peak_is_solved_during_the_march(frame_3d, monkeypatch):
    """With the read-out's weights in before the march (δ known step by step), an hour of
    condition 1 on the coarse 3-D frame, states kept every 5 min: ``solve_first_peak`` solves
    beside the march the kept state nearest δ's first peak (the deformed picture's), and its
    displacement is the one solved afterwards."""
    monkeypatch.setenv(plan.PATH_ENV, "iterative")
    monkeypatch.setattr(process, "can_fork", lambda: True)
    model = build_model(FIXED_MODEL, 3, frame_3d)
    model.readout.weights.result()
    times, drive = sample_times(3600.0), condition_drive(CONDITIONS[1], SupplyParams())
    keep = [float(t) for t in times[::5]]
    res = run_model(model, drive, times, keep, solve_at=(0.0,), solve_first_peak=True)
    peak = 60.0 * delta_figures(res.columns["time_s"], res.columns["delta_um"])["first_peak_min"]
    nearest = min(keep, key=lambda t: abs(t - peak))
    assert sorted(res.solved) == [0.0, nearest] == [0.0, 300.0]
    u = res.solved[nearest].result()
    assert np.abs(u - model.displacement_field(dict(res.states)[nearest])).max() < 1e-8 * np.abs(u).max()


def test_a_written_run_with_the_helper_has_the_fields_and_pictures_of_one_without(tmp_path, monkeypatch):
    """``gt.run`` and ``Run.write`` (a painter) on the coarse 3-D frame, 30 min of condition 1,
    fields every 10 min, the iterative path with and without the helper: the same displacement
    fields in ``fields.h5`` (to 1e-8 of their size), every picture written; written with
    ``release``, the helper ends once it has solved them."""
    import dataclasses

    import h5py

    import gatetherm as gt
    from conftest import fixed_case
    from gatetherm.frame.conditions import condition_schedule

    monkeypatch.setenv(plan.PATH_ENV, "iterative")
    case = fixed_case(3)
    sched = condition_schedule(1)
    sched = dataclasses.replace(sched, times=sched.times[:31])
    u = {}
    for beside in (True, False):
        monkeypatch.setattr(process, "can_fork", lambda: beside)
        run = gt.run(case, sched, fields_every=600.0)
        assert sorted(run.scenario.result.solved) == ([0.0, 600.0, 1200.0] if beside else [])
        with gt.plot.Painter() as painter:
            run.write(tmp_path / str(beside), fields_every=600.0, painter=painter, release=beside)
        helper = run.scenario.model.elastic.solve._helper
        assert not run.scenario.model.elastic.solve.background and (helper is None or _ends(helper.pid))
        with h5py.File(tmp_path / str(beside) / "fields" / "fields.h5") as f:
            u[beside] = np.array([f[f"step{n}/u"][()] for n in range(4)])
        assert (tmp_path / str(beside) / "deformed.png").stat().st_size > 10_000
        assert (tmp_path / str(beside) / "response.png").stat().st_size > 10_000
    assert np.abs(u[True] - u[False]).max() < 1e-8 * np.abs(u[False]).max()


def test_the_memory_a_plan_counts_holds_the_child_processes_own():
    """A child process holding 200 MB of its own: the budget's ``resident_bytes`` counts it."""
    import subprocess
    import sys
    import time

    before = plan.resident_bytes()
    child = subprocess.Popen([sys.executable, "-c", "import sys, numpy as np; a = np.ones(25_000_000); "
                              "print(1, flush=True); sys.stdin.read()"], stdin=subprocess.PIPE, stdout=subprocess.PIPE)
    try:
        assert child.stdout.readline().strip() == b"1"
        time.sleep(0.2)
        held = plan.resident_bytes() - before
    finally:
        child.communicate(b"")
    assert 0.19e9 < held < 0.4e9, held  # the 200 MB array and the child's own interpreter
