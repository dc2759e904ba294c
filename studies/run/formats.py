"""Output formats: a state written for another code (``gatetherm export FORMAT``, ``gt.export_case(format=)``).

A format is a writer module and one :class:`Format` in :data:`FORMATS`; the API
(:mod:`gatetherm.api.export`) and the command (``core/cli/export.py``: its ``format`` choices, help
and description) read them from here. The writer module offers
``export_state(case, schedule, t, title, on_step) -> (deck text, info)`` (``info`` is
``gatetherm.json``: gatetherm's own results, at least ``element``, ``nodes`` and ``relative_m``)
and, where the other code can be run, the function :attr:`Format.runner` names,
``(folder, info) -> dict`` of that code's ``relative_m`` and ``worst``.

This module imports no writer (the command line's parser reads it).
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass

from gatetherm import InputError

INFO = "gatetherm.json"
"""The file of gatetherm's own results beside every deck."""


@dataclass(frozen=True)
class Format:
    """An output format: a deck for another code."""

    name: str
    """The word after ``gatetherm export``."""
    code: str
    """The other code, as the summary names it."""
    title: str
    """What the deck is, a few words (the command's help)."""
    module: str
    """The writer module (dotted)."""
    deck: str
    """The deck's file name in the output folder."""
    command: str
    """How to run the other code in the folder (the summary's hint)."""
    log: str = ""
    """The file the other code's run leaves in the folder (written by the runner), if any."""
    runner: str = ""
    """The writer module's function that runs the other code (``--run``); "" none."""
    about: str = ""
    """What the deck holds and what is refused (the command's description)."""

    @property
    def outputs(self) -> tuple[str, ...]:
        """What a written export holds (an output directory's file set)."""
        return (self.deck, INFO, *((self.log,) if self.log else ()))

    def writer(self):
        """The writer module, imported."""
        return importlib.import_module(self.module)


CCX_ABOUT = (
    "Write DIR/job.inp for CalculiX 2.20 (run 'ccx job' in DIR) and DIR/gatetherm.json with gatetherm's own "
    "displacements at the probes. Written: the mesh (3-D: C3D4, C3D10 at order 2; 2-D plane strain: CPE3/CPE6 of "
    "each region's thickness; 2-D plane stress: CPE3/CPE6 with the equivalent material E(1+2nu)/(1+nu)^2, "
    "nu/(1+nu), alpha(1+nu)/(1+2nu), the same in-plane displacements (CalculiX's CPS3/CPS6 are a slab of the "
    "section's thickness, plane stress only as it goes to 0); axisymmetric: CAX3/CAX6, x = r, y = z, loads of the "
    "whole ring), a material per region, fixed and prescribed supports (*BOUNDARY), the temperature field at one "
    "time (*TEMPERATURE; a contact conductance is the temperature jump on the two sides' nodes), gravity (*DLOAD "
    "GRAV), pressures (*DLOAD Pn on the element faces), tractions, boundary and point forces (*CLOAD of gatetherm's "
    "consistent nodal forces), bonded contacts (the two sides tied node to node, *EQUATION), a static step and "
    "*NODE PRINT of U at every probe (a probe that is not a node prints its element's nodes; gatetherm.json holds "
    "their shape-function weights, and the probe's displacement is their weighted sum, as gatetherm interpolates "
    "it). Refused, one line each: a case without E and nu, without a fixed support (no empty *BOUNDARY), an "
    "elastic foundation ([supports] foundation), a joint stiffness ([contacts] stiffness), a pressure on an inner "
    "boundary, a temperature per region ([temperature.regions]) that jumps on nodes two regions share.")

FORMATS: dict[str, Format] = {
    "ccx": Format("ccx", "CalculiX", "CalculiX input deck", "gatetherm.studies.run.ccx", "job.inp", "ccx job",
                  log="ccx.log", runner="run_ccx", about=CCX_ABOUT),
}
"""Every output format by name, in the command's order."""


def register(fmt: Format) -> Format:
    """Add ``fmt`` to :data:`FORMATS` (a format of a plug-in; the shipped ones are listed above)."""
    FORMATS[fmt.name] = fmt
    return fmt


def get(name: str) -> Format:
    """The format ``name``; InputError naming those there are."""
    if not isinstance(name, str) or name not in FORMATS:
        raise InputError("format", f"unknown format {name!r}", f"choose from {', '.join(FORMATS)}")
    return FORMATS[name]


def check_time(schedule, t: float) -> float:
    """The step of ``schedule`` at ``t`` (s, within 1e-6 s); InputError if there is none."""
    near = [float(s) for s in schedule.times if abs(t - s) < 1e-6]
    if not near:
        raise InputError("--time", f"{t / 60:g} min is not a step of the run", "give a whole minute of the run")
    return near[0]
