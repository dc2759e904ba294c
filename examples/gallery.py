"""What every example shares: the folder its figure goes to (the first argument, else a new
temporary folder outside the checkout), the shipped data files, and a field plot."""
from __future__ import annotations

import sys
import tempfile
from pathlib import Path

from matplotlib.figure import Figure

import gatetherm.validation


def output_folder() -> Path:
    """The folder named on the command line, or a new temporary one."""
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp(prefix="gatetherm-example-"))
    out.mkdir(parents=True, exist_ok=True)
    return out


def shipped(name: str) -> Path:
    """A data file of ``gatetherm.validation`` (the NAFEMS and C-frame cases)."""
    return Path(gatetherm.validation.__file__).parent / name


def save(fig: Figure, out: Path, name: str) -> Path:
    fig.tight_layout()
    fig.savefig(out / name, dpi=120)
    print(f"figure: {out / name}")
    return out / name


def field_axes(ax, mesh, values, label: str, cmap: str = "inferno"):
    """A 2-D nodal field on its mesh's triangles, with a colour bar."""
    art = ax.tripcolor(mesh.points[:, 0], mesh.points[:, 1], mesh.cells, values, shading="gouraud", cmap=cmap)
    ax.set_aspect("equal")
    ax.set(xlabel="x [m]", ylabel="y [m]")
    ax.figure.colorbar(art, ax=ax, label=label)
    return ax
