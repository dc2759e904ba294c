"""Where a plot of the public API (:mod:`gatetherm.validation.plots.api`) draws: the Axes given, or a
new pyplot figure's; the checks of its arguments and the titles of a run's plots."""
from __future__ import annotations

import numpy as np

from gatetherm.checks import argument

LABELS = {"_um": "displacement [µm]", "_degC": "temperature [°C]", "_MPa": "stress [MPa]"}


def _figure():
    import matplotlib.pyplot as plt

    return plt.figure()


def _axes(ax):
    if ax is not None and not hasattr(ax, "plot"):
        argument("ax", ax, (), "a matplotlib Axes or None", "None draws on a new figure")
    return _figure().subplots() if ax is None else ax


def _panels(axes):
    """The ``fig`` for a plot of several panels: a new pyplot figure unless ``axes`` are given."""
    if axes is not None and not all(hasattr(a, "plot") for a in np.asarray(axes, dtype=object).flat):
        argument("axes", axes, (), "matplotlib Axes (as many as the plot's panels) or None",
                 "None draws on a new figure")
    return _figure() if axes is None else None


def _run(run, what: str = "a Run") -> None:
    """TypeError unless ``run`` is a run of the API (:func:`gatetherm.run`)."""
    if not hasattr(run, "scenario"):
        argument("run", run, (), what, "make one with gt.run(case)")


def _title(run, t: float | None = None) -> str:
    name = getattr(getattr(run, "case", None), "name", "")
    if t is None:
        return name
    when = "steady state" if len(getattr(run, "time", ())) <= 1 else f"t = {t / 3600:.3g} h"
    return f"{name}, {when}" if name else when
