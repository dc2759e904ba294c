"""The δ-peak finder equals scipy.signal.find_peaks with a prominence, plateaus included."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import find_peaks

from gatetherm.studies.run.simulate import delta_figures, prominent_peaks


@pytest.mark.parametrize("seed", range(40))
def test_prominent_peaks_equal_scipy(seed):
    rng = np.random.default_rng(seed)
    x = np.round(np.cumsum(rng.normal(size=rng.integers(3, 400))), 0 if seed % 2 else 3)  # plateaus when rounded
    x = np.concatenate([[-np.inf], x, [-np.inf]]) if seed % 3 == 0 else x
    for prominence in (0.0, 1.0, 3.0):
        assert prominent_peaks(x, prominence) == find_peaks(x, prominence=prominence)[0].tolist()


def test_delta_figures_of_a_known_history():
    t = np.arange(0, 301) * 60.0
    delta = 10 * np.sin(2 * np.pi * t / 9600.0) + t / 6000.0  # peaks near 40 and 200 min, rising
    f = delta_figures(t, delta)
    i, j = 40 + np.argmax(delta[40:60]), 180 + np.argmax(delta[180:220])
    assert (f["first_peak_min"], f["first_peak_um"], f["second_peak_um"]) == (i, delta[i], delta[j])
    assert f["swing_um"] == delta.max() - delta.min()
