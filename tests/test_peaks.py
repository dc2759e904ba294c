"""The δ-peak finder equals scipy.signal.find_peaks with a prominence, plateaus included."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import find_peaks

from gatetherm.studies.run.simulate import delta_figures, prominent_peaks, settled_first_peak


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


def test_a_settled_first_peak_is_the_whole_historys():
    """Each first part of a random δ history (plateaus when rounded) that settles a first peak
    settles the one :func:`delta_figures` finds in the whole; of 40 histories, 39 settle theirs
    before their end."""
    settles = 0
    for seed in range(40):
        rng = np.random.default_rng(seed)
        x = np.round(np.cumsum(rng.normal(size=rng.integers(3, 200))) + 2.0, 0 if seed % 2 else 2)
        first = delta_figures(60.0 * np.arange(len(x)), x)["first_peak_min"]  # min: the index
        settled = {settled_first_peak(x[:k]) for k in range(1, len(x))} - {None}
        assert settled <= ({int(first)} if first is not None else set()), seed
        settles += bool(settled)
    assert settles == 39


def test_a_first_peak_settles_once_delta_has_fallen_by_the_prominence():
    """δ rising to a peak at 12 min and falling as in condition 1 settles its peak once it has
    fallen by the prominence, 1 µm: two samples later here (35.14, 34.70, 33.76 µm)."""
    t = np.arange(0, 61) * 60.0
    delta = 45 * np.sin(np.pi * np.minimum(t, 1560.0) / 1560.0) * np.exp(-t / 3000.0)
    k = next(k for k in range(1, 62) if settled_first_peak(delta[:k]) is not None)
    assert settled_first_peak(delta[:k]) == delta_figures(t, delta)["first_peak_min"] == 12
    assert k - 1 - 12 == 2
