"""How ``gatetherm live`` paces its reads between periods (validation/live/link.py, ``Pace``):
exact waits for a steady clock, a clock that speeds up, a gap and a reconnection."""
from __future__ import annotations

import pytest

from gatetherm.validation.live.link import Pace


def test_pace_waits_until_shortly_before_the_next_sample():
    pace = Pace(0.05)
    assert pace.wait(0.0) == 0.05  # nothing seen yet: poll
    pace.handled(0, 10.00)
    assert [pace.wait(10.01) for _ in range(5)] == [0.05, 0.1, 0.2, 0.25, 0.25]  # one period: back off to 0.25 s
    pace.handled(1, 11.00)
    # 1-s periods: wait until 0.1 s (two polls) before the next is due at 12.00
    assert pace.wait(11.02) == pytest.approx(12.00 - 0.10 - 11.02, abs=1e-12)
    assert pace.wait(11.95) == 0.05  # inside the lead: poll
    pace.handled(2, 11.50)  # the clock sped up: the smallest interval rules
    assert pace.wait(11.51) == pytest.approx(11.50 + 0.50 - 0.10 - 11.51, abs=1e-12)
    for k, wall in ((3, 71.5), (4, 131.5)):  # a 60-s period: lead 3 s (a twentieth)
        pace.handled(k, wall)
    assert pace.wait(131.6) == pytest.approx(0.5 - 0.1 - 0.1, abs=1e-12)  # 11.5 -> 71.5 gap: min of the last five
    pace2 = Pace(0.05)
    for k, wall in ((0, 0.0), (1, 60.0), (2, 120.0)):
        pace2.handled(k, wall)
    assert pace2.wait(120.1) == pytest.approx(180.0 - 3.0 - 120.1, abs=1e-12)
    pace2.handled(5, 300.0)  # periods missed: the intervals start again
    assert [pace2.wait(300.1) for _ in range(4)] == [0.05, 0.1, 0.2, 0.25]
    pace2.handled(6, 360.0)
    pace2.reset()  # the link lost
    assert [pace2.wait(360.1) for _ in range(3)] == [0.05, 0.05, 0.05]  # poll until a period is seen


def test_a_clock_not_started_is_read_every_quarter_second_at_most(monkeypatch, tmp_path):
    """While ``time_s`` reads NaN (a twin waiting for its services) the waits between reads double
    from the poll up to NOT_STARTED_S (0.25 s), not further: a 1-s clock's first sample is seen
    within it (up to 1 s before, and the first period of a 1-s clock was late). The waits asked
    for are recorded (the wall clock of a loaded computer is not)."""
    import asyncio

    from gatetherm.studies.control.compensator import CompensatorParams
    from gatetherm.studies.control.stepwise import PaperStepper
    from gatetherm.validation.live import service as sv
    from gatetherm.validation.live.journal import Journal
    from gatetherm.validation.live.nodes import default_map

    columns = ("theta_A_degC", "theta_B_degC", "theta_C_degC", "delta_um")
    waits, stop = [], None

    async def connect(url, nodes, timeout):
        return object(), {}

    async def nothing(*args):
        return None

    async def sample(client, nodes, names, scale):
        if len(waits) >= 10:
            stop.set()
        return None  # the clock not started

    async def wait_for(aw, timeout):
        aw.close()
        waits.append(timeout)
        await asyncio.sleep(0)
        raise asyncio.TimeoutError

    for name, fake in (("_connect", connect), ("_write", nothing), ("_sample", sample), ("_close", nothing)):
        monkeypatch.setattr(sv, name, fake)
    monkeypatch.setattr(sv.asyncio, "wait_for", wait_for)
    journal = Journal(tmp_path, ("time_s", *columns), {"source": "test"})

    async def run():
        nonlocal stop
        stop = asyncio.Event()
        await sv.serve(PaperStepper(2.0, 1.0, CompensatorParams()), journal, "opc.tcp://127.0.0.1:1",
                       default_map(columns), sv.LiveParams(poll_s=0.05), columns, None, stop)

    asyncio.run(run())
    journal.close()
    assert waits == pytest.approx([0.05, 0.1, 0.2] + [0.25] * 8, abs=1e-12)  # before: ... 0.4, 0.8, 1.0


def test_the_heap_is_frozen_while_a_service_runs():
    """``frozen_heap``: the objects alive at its start out of the collector's passes, given back after."""
    import gc

    from gatetherm.process import frozen_heap

    assert gc.get_freeze_count() == 0  # nothing left frozen by an earlier test (a gt.live, a twin)
    with frozen_heap():
        assert gc.get_freeze_count() > 10_000  # the modules of the test run at least
        assert gc.get_count()[2] == 0  # after one full collection
    assert gc.get_freeze_count() == 0
