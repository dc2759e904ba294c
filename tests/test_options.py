"""Solver options: one object, read from the environment in one place, from a ``[solver]`` file
and the command line, each bad value refused naming where it came from; the solvers follow the
options in force."""
from __future__ import annotations

import os

import numpy as np
import pytest
import scipy.sparse as sp

import gatetherm as gt
from gatetherm import InputError
from gatetherm.options import current
from gatetherm.solvers import linsolve, plan


def test_environment_is_read_in_one_place():
    env = {"GATETHERM_SOLVER": "iterative", "GATETHERM_MEMORY_GB": "8", "GATETHERM_SPD_BACKEND": "superlu",
           "GATETHERM_BLAS_THREADS": "3"}
    assert gt.SolverOptions.from_environment(env) == gt.SolverOptions("iterative", 8.0, "superlu", 3)
    assert gt.SolverOptions.from_environment({}) == gt.SolverOptions()


@pytest.mark.parametrize("var, value", [("GATETHERM_SOLVER", "fast"), ("GATETHERM_MEMORY_GB", "-1"),
                                        ("GATETHERM_MEMORY_GB", "nan"), ("GATETHERM_SPD_BACKEND", "mumps"),
                                        ("GATETHERM_BLAS_THREADS", "1.5")])
def test_a_bad_environment_value_names_its_variable(var, value):
    with pytest.raises(InputError, match=f"^environment variable {var}: got '{value}'"):
        gt.SolverOptions.from_environment({var: value})


@pytest.mark.parametrize("field, value", [("path", "fast"), ("memory_gb", 0), ("memory_gb", float("inf")),
                                          ("backend", "lu"), ("blas_threads", 0), ("blas_threads", True)])
def test_a_bad_option_names_its_field(field, value):
    with pytest.raises(InputError, match=f"^solver option {field}: got"):
        gt.SolverOptions(**{field: value})


def test_file_overrides_the_base_and_refuses_unknown_keys(tmp_path):
    f = tmp_path / "solver.toml"
    f.write_text('[solver]\npath = "direct"\nmemory_gb = 2.5\n')
    assert gt.SolverOptions.from_file(f, gt.SolverOptions(backend="superlu")) == \
        gt.SolverOptions("direct", 2.5, "superlu", None)
    f.write_text('[solver]\npaths = "direct"\n')
    with pytest.raises(InputError, match=r"solver.toml: \[solver\]: unknown keys \['paths'\]"):
        gt.SolverOptions.from_file(f)
    f.write_text('[solver]\nmemory_gb = -3\n')
    with pytest.raises(InputError, match=r"solver.toml: \[solver\]: solver option memory_gb: got -3"):
        gt.SolverOptions.from_file(f)


def test_threads_adapt_to_the_machine():
    assert gt.SolverOptions().threads() == max(1, (os.cpu_count() or 1) // 2)
    assert gt.SolverOptions(blas_threads=5).threads() == 5


def test_the_plan_and_the_factoriser_follow_the_options_in_force(monkeypatch):
    monkeypatch.delenv("GATETHERM_SOLVER", raising=False)
    monkeypatch.setenv("GATETHERM_MEMORY_GB", "4")
    assert plan.forced_path() is None and plan.budget() == 4e9
    with gt.SolverOptions(path="iterative", memory_gb=2).use():
        assert current().path == "iterative" and plan.forced_path() == "iterative" and plan.budget() == 2e9
    assert plan.forced_path() is None and plan.budget() == 4e9
    A = sp.diags([2.0, 3.0, 4.0]).tocsc()
    with gt.SolverOptions(backend="superlu").use():
        solve, name = linsolve.spd_factor(A)
    assert name == "superlu" and np.allclose(solve(np.array([2.0, 3.0, 4.0])), 1.0)


def test_configure_puts_given_options_in_force_and_checks_the_environment(monkeypatch):
    monkeypatch.setenv("GATETHERM_BLAS_THREADS", "x")
    with pytest.raises(InputError, match="GATETHERM_BLAS_THREADS"):
        gt.configure()
    with pytest.raises(TypeError, match="options: got dict"):
        gt.configure({"path": "direct"})
    with gt.SolverOptions().use():  # the context ends with the test
        assert gt.configure(gt.SolverOptions(blas_threads=1, path="direct")) == current()
        assert current().path == "direct"


def test_the_command_line_refuses_a_bad_solver_file_in_one_line(tmp_path, capsys):
    from gatetherm.cli import main

    f = tmp_path / "s.toml"
    f.write_text('[solver]\nbackend = "mumps"\n')
    assert main(["--solver-options", str(f), "mesh", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "s.toml: [solver]: solver option backend: got 'mumps'" in err
    assert not (tmp_path / "o").exists()
