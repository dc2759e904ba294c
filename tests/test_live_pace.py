"""How ``gatetherm live`` paces its reads between periods (validation/live/link.py, ``Pace``):
exact waits for a steady clock, a clock that speeds up, a gap and a reconnection."""
from __future__ import annotations

import pytest

from gatetherm.validation.live.link import Pace


def test_pace_waits_until_shortly_before_the_next_sample():
    pace = Pace(0.05)
    assert pace.wait(0.0) == 0.05  # nothing seen yet: poll
    pace.handled(0, 10.00)
    assert pace.wait(10.01) == 0.05  # one period seen: no interval yet
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
    assert pace2.wait(300.1) == 0.05
    pace2.handled(6, 360.0)
    pace2.reset()  # the link lost
    assert pace2.wait(360.1) == 0.05
