"""Figures of runs and studies (matplotlib, off screen); every file is written atomically."""
from __future__ import annotations

import os

from gatetherm import atomic_path


DPI = 200
"""Resolution of every PNG, dots per inch (print quality)."""


def save(fig, path: str | os.PathLike, dpi: int = DPI, tight: bool = True) -> None:
    """Write ``fig`` as a PNG at ``path`` atomically and release it (pyplot figures are closed)."""
    if tight:
        fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=dpi)
    import matplotlib.pyplot as plt

    if plt.fignum_exists(fig.number if hasattr(fig, "number") else -1):
        plt.close(fig)
