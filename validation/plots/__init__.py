"""Figures of runs and studies (matplotlib): library plots.

Every plot function draws on the Axes it is given (``ax=``, or ``axes=`` for a figure of
several panels) and returns them; given none, it draws on a new :func:`figure`: a bare
:class:`matplotlib.figure.Figure`, outside pyplot's state, that needs no backend. No plot
chooses a backend or writes a file: :func:`save` is the one writer (the CLI, ``Run.write``
and the report call it). ``gt.plot`` (:mod:`gatetherm.validation.plots.api`) is the curated
set for notebooks.
"""
from __future__ import annotations

import os

from gatetherm import InputError, atomic_path


DPI = 200
"""Resolution of every PNG, dots per inch (print quality)."""


def figure(figsize: tuple[float, float], nrows: int = 1, ncols: int = 1, fig=None, **subplots):
    """The subplots of a new bare Figure of size ``figsize`` (inches), or of ``fig`` (resized to
    it) if given: a single Axes, or an array as :meth:`matplotlib.figure.Figure.subplots` gives."""
    from matplotlib.figure import Figure

    if fig is None:
        fig = Figure(figsize=figsize)
    else:
        fig.set_size_inches(*figsize)
    return fig.subplots(nrows, ncols, **subplots)


MAX_DPI = 2400
"""Highest resolution :func:`save` writes, dots per inch."""
MAX_PIXELS = 1e8
"""Most pixels of a picture :func:`save` writes (a 10 x 6 in figure at 1 290 dpi)."""


def save(fig, path: str | os.PathLike, dpi: int = DPI, tight: bool = True) -> None:
    """Write a figure as a PNG, atomically (a temporary file renamed onto ``path``).

    Parameters
    ----------
    fig : Figure, Axes or array of Axes
        A figure, or what a plot returns.
    path : str or path
        The PNG file.
    dpi : int
        Resolution, dots per inch.
    tight : bool
        Apply ``tight_layout`` first.

    Returns
    -------
    None
    """
    import numpy as np

    from gatetherm.checks import Range, argument, number_argument

    argument("path", path, (str, os.PathLike), "the path of a PNG file")
    number_argument("dpi", dpi, Range(1, MAX_DPI), f"e.g. {DPI}")
    first = np.asarray(fig, dtype=object).flat[0] if np.asarray(fig, dtype=object).size else None
    argument("fig", first, type(first) if hasattr(first, "figure") else (), "a Figure, an Axes or what a plot returns")
    fig = first.figure
    pixels = float(np.prod(fig.get_size_inches())) * dpi ** 2
    if pixels > MAX_PIXELS:
        raise InputError("dpi", f"{dpi:g} dots per inch make a picture of {pixels:.2g} pixels, more than "
                         f"{MAX_PIXELS:.2g}", f"lower it to at most {dpi * (MAX_PIXELS / pixels) ** 0.5:.0f}")
    if tight:
        fig.tight_layout()
    with atomic_path(path) as tmp:  # zlib's run-length strategy: the same pixels, encoded faster
        fig.savefig(tmp, format="png", dpi=dpi, pil_kwargs={"compress_type": 3})
