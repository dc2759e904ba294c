"""The paper's frame as files, and its beam theory's normalised coefficients: what
``gatetherm mesh`` and ``gatetherm beam`` do (:mod:`gatetherm.api`)."""
from __future__ import annotations

import dataclasses
import json
import math
import numbers
import os
from pathlib import Path
from typing import Annotated

from gatetherm import InputError
from gatetherm.api.boundary import INFINITE
from gatetherm.api.case import PATH, Case, gate_frame
from gatetherm.checks import argument

MESH_FILES = ("mesh.msh", "mesh.vtu")
"""The frame's mesh as written by :meth:`FrameFiles.write`."""
OUTPUTS = (*MESH_FILES, "case.toml", "schedule.csv")
"""What :meth:`FrameFiles.write` writes; writing again replaces all of it."""


@dataclasses.dataclass(frozen=True)
class FrameFiles:
    """The paper's frame made by :func:`mesh_frame`, and the folder it was written into."""

    case: Case
    """The frame as a case (its mesh: ``case.mesh``)."""
    condition: int
    """The paper's condition written as the case's ``schedule.csv``."""
    folder: str | None = None
    """The folder it was written into, as given (None: not written)."""
    config: str | os.PathLike | None = None
    """The model file it was made from (None: the shipped paper model)."""

    def write(self, out: str | os.PathLike) -> "FrameFiles":
        """Write ``out/mesh.msh``, ``out/mesh.vtu`` and the frame as a case file,
        ``out/case.toml`` with ``out/schedule.csv``, in one transaction.

        Returns
        -------
        FrameFiles
            This result with :attr:`folder` ``out``.
        """
        from gatetherm.outdir import output_dir

        argument("out", out, PATH, "a folder's path")
        with output_dir(out, OUTPUTS, keep=(self.config,)) as stage:
            self._write(stage)
        return dataclasses.replace(self, folder=str(out))

    def _write(self, stage: Path) -> None:
        from gatetherm.geometry.mesh import save_mesh
        from gatetherm.frame.case import write_frame_case

        for name in MESH_FILES:
            save_mesh(self.case.mesh, stage / name)
        write_frame_case(self.case, self.condition, stage)

    def summary(self) -> str:
        """The lines ``gatetherm mesh`` prints (no final newline)."""
        fm, out = self.case.mesh, Path(self.folder or ".")
        c = fm.counts()
        return "\n".join([
            *(f"wrote {out / name}" for name in MESH_FILES),
            f"wrote {out / 'case.toml'} and {out / 'schedule.csv'} (the frame as a case: gatetherm run "
            f"{out / 'case.toml'})",
            f"{self.case.dim}-D frame: {c['nodes']} nodes, {c['elements']} elements",
            f"regions ({len(fm.regions)}): " + ", ".join(f"{k}={len(v)}" for k, v in fm.regions.items()),
            f"boundaries ({len(fm.boundaries)}): " + ", ".join(f"{k}={len(v)}" for k, v in fm.boundaries.items()),
            f"sensors ({len(fm.sensors)}): " + ", ".join(fm.sensors)])


def mesh_frame(dim: int = 2, config: str | os.PathLike | None = None, condition: int = 1,
               out: str | os.PathLike | None = None) -> FrameFiles:
    """Mesh the paper's frame and, with ``out``, write it as ``gatetherm mesh`` does.

    Parameters
    ----------
    dim : int
        2 (plane-stress section) or 3 (solid).
    config : str or path, optional
        A model file (default: the shipped paper model).
    condition : int
        The paper's condition (1, 2 or 3) that the case's ``schedule.csv`` holds.
    out : str or path, optional
        Also write it there (:meth:`FrameFiles.write`), the folder checked and locked before
        the mesh is made.

    Returns
    -------
    FrameFiles
    """
    from gatetherm.outdir import output_dir
    from gatetherm.frame.conditions import condition as check_condition

    argument("config", config, (*PATH, type(None)), "a model file's path or None")
    check_condition(condition)  # a bad number fails (naming it) before the model is built
    if out is None:
        return FrameFiles(gate_frame(dim, config, condition), condition, None, config)
    with output_dir(out, OUTPUTS, keep=(config,)) as stage:
        made = FrameFiles(gate_frame(dim, config, condition), condition, str(out), config)
        made._write(stage)
    return made


@dataclasses.dataclass(frozen=True)
class BeamCoefficients:
    """The beam theory's normalised coefficients (eqs 27-29) at one tie bar: :func:`beam_normalised`."""

    l_over_l4: float
    """a = l/l4, the cutting area's height over the tie bar's (1)."""
    beta: float
    """β = 3 I l_C / (A_C l³), the stiffness ratio (1; inf: no tie bar)."""
    ki_norm: float
    """K_i / (3 α l² / 8h) (1)."""
    kc_norm: float
    """K_C / (α l_C) (1)."""

    def summary(self, as_json: bool = False) -> str:
        """The line ``gatetherm beam`` prints (``--json``: one JSON object)."""
        if as_json:
            return json.dumps({"Ki_norm": self.ki_norm, "Kc_norm": self.kc_norm})
        return (f"l/l4 = {self.l_over_l4:g}, beta = {self.beta:g}: Ki/(3 alpha l^2/8h) = {self.ki_norm:.6g}, "
                f"Kc/(alpha l_C) = {self.kc_norm:.6g}")


def beam_normalised(l_over_l4: float, beta: Annotated[float, INFINITE]) -> BeamCoefficients:
    """The paper's normalised beam-theory coefficients for a tie bar at ``l/l4`` and stiffness
    ratio ``beta`` (l1 = l/2, one material; eqs 27-29, Figs. 7-8).

    Parameters
    ----------
    l_over_l4 : float
        a = l/l4, finite and > 0.
    beta : float
        β = 3 I l_C / (A_C l³), >= 0 (``math.inf``: no tie bar).

    Returns
    -------
    BeamCoefficients
    """
    from gatetherm.frame.beam import normalised

    a = float(argument("l_over_l4", l_over_l4, numbers.Real, "a number", "pass l/l4, e.g. 1.5"))
    b = float(argument("beta", beta, numbers.Real, "a number", "pass e.g. 0.1"))
    if isinstance(l_over_l4, bool) or not (math.isfinite(a) and a > 0):
        raise InputError("l_over_l4", f"must be a finite number > 0, got {l_over_l4!r}", "pass l/l4, e.g. 1.5")
    if isinstance(beta, bool) or not b >= 0:  # also rejects nan
        raise InputError("beta", f"must be >= 0, got {beta!r}", "pass e.g. 0.1")
    ki, kc = (float(v) for v in normalised(a, b))
    return BeamCoefficients(a, b, ki, kc)
