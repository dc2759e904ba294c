"""Shared fixtures: coarse frame meshes, and the observed convergence orders that the
verification tests record and the terminal summary prints."""
from __future__ import annotations

import functools

import pytest

from gatetherm.frame.build import build_mesh
# The verification frame (validation/verification_time.py, also run by `gatetherm report`):
# FIXED, a fixed frame (not the calibrated defaults) so that hand values in tests stay valid,
# COARSE its mesh density, FIXED_MODEL the model whose meshes frame_2d, frame_3d are.
from gatetherm.validation.verification_time import COARSE_MESH as COARSE, FIXED_FRAME as FIXED, FIXED_MODEL

_ORDERS = pytest.StashKey[list]()


@functools.lru_cache(maxsize=1)
def fixed_case(dim: int = 2):
    """The frame of :data:`FIXED_MODEL` as a case (meshed once per session)."""
    from gatetherm.frame.config import Config
    from gatetherm.frame.case import frame_case

    return frame_case(Config(model=FIXED_MODEL), dim)


def fixed_condition(steps: int, condition: int = 1):
    """The frame of :data:`FIXED_MODEL` as a case and the first ``steps`` minutes of a paper
    condition's schedule."""
    import dataclasses

    from gatetherm.frame.conditions import condition_schedule

    sched = condition_schedule(condition)
    return fixed_case(), dataclasses.replace(sched, times=sched.times[:steps + 1])


@pytest.fixture(scope="session")
def frame_2d():
    """The :data:`FIXED` frame meshed in 2-D at :data:`COARSE`."""
    return build_mesh(FIXED, 2, COARSE)


@pytest.fixture(scope="session")
def frame_3d():
    """The :data:`FIXED` frame meshed in 3-D at :data:`COARSE`."""
    return build_mesh(FIXED, 3, COARSE)


@pytest.fixture
def record_order(request, record_property):
    """``record_order(label, observed, expected)``: keep an observed convergence order
    for the session summary and the junit properties."""
    def record(label: str, observed: float, expected: float) -> None:
        request.config.stash.setdefault(_ORDERS, []).append(
            (request.node.nodeid, label, observed, expected))
        record_property(f"order[{label}]", f"{observed:.3f}")
    return record


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    orders = config.stash.get(_ORDERS, [])
    if orders:
        terminalreporter.section("observed convergence orders")
        for nodeid, label, observed, expected in orders:
            terminalreporter.write_line(f"{label:<46} {observed:6.3f}  (expected {expected:g})"
                                        f"   {nodeid.split('::')[0]}")


def synthetic_record(path) -> None:
    """A machine's record at ``path``: d_um = 2 (theta_1 - theta_1(0)) + noise of 0.05 um over 400
    one-minute samples; theta_2 unrelated (a random walk each)."""
    import numpy as np

    from gatetherm.studies.run.timeseries import FORMAT, TimeSeries, write_timeseries

    rng = np.random.default_rng(0)
    t = 60.0 * np.arange(400)
    s1, s2 = 22 + np.cumsum(rng.normal(0, 0.05, t.size)), 22 + np.cumsum(rng.normal(0, 0.05, t.size))
    d_um = 2.0 * (s1 - s1[0]) + rng.normal(0, 0.05, t.size)
    write_timeseries(path, TimeSeries({"time_s": t, "s1_degC": s1, "s2_degC": s2, "d_um": d_um}, {"format": FORMAT}))
