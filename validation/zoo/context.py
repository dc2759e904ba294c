"""What every cell of the machine zoo shares: the machine's context and the numbers of a cell."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
CCX_TOLERANCE = 5e-3
"""|δ_ccx / δ − 1| accepted (issue 51: 0.5 %)."""
TIMEOUT_S = 300.0
"""Default time limit of one cell, s."""
SETTLE_S = 600.0
"""The compensator's settling time the bands skip, s (``CompensatorParams.settle_s``' default)."""


@dataclass
class Context:
    """What the cells of one machine share (made in the parent, inherited by each cell's child)."""

    machine: object
    """The :class:`~gatetherm.validation.zoo.Machine`."""
    case: object
    run: object
    """The case's run on its own schedule (:class:`~gatetherm.studies.run.scenario.ScenarioRun`)."""
    out: Path

    @property
    def columns(self) -> dict:
        return self.run.columns

    @property
    def series(self):
        return self.run.series({"source": f"zoo run of {self.machine.folder}"})

    @property
    def delta(self) -> str:
        """The primary output column: δ, else the first relative displacement, else a temperature."""
        cols = list(self.run.columns)
        if "delta_um" in cols:
            return "delta_um"
        rel = [f"{r.name}_um" for r in self.case.problem.relative]
        um = [c for c in cols if c.endswith("_um")]
        return (rel or um or [c for c in cols if c.endswith("_degC")])[0]


def _one_line(text: str, limit: int = 300) -> str:
    line = " ".join(str(text).split()).replace(str(EXAMPLES), "validation/examples")
    return line if len(line) <= limit else line[:limit - 1] + "…"


def _band(t, x, settle=SETTLE_S) -> float:
    late = np.asarray(t) >= t[0] + settle
    return float(np.nanmax(np.abs(np.asarray(x)[late])))


def _transient(ctx: Context) -> bool:
    return ctx.case.time is not None and len(ctx.columns["time_s"]) > 1
