"""Export a state for another code: a CalculiX input deck (:mod:`gatetherm.api`)."""
from __future__ import annotations

import os
from pathlib import Path

from gatetherm import InputError, write_text_atomic
from gatetherm.checks import argument, json_text
from gatetherm.api.run import PATH, Case, Schedule, _case


def export_ccx(case: Case, out: str | os.PathLike, time: float | None = None, *, schedule: Schedule | None = None,
               title: str | None = None, run: bool = False) -> dict:
    """Write ``out/job.inp``, a CalculiX 2.20 deck of ``case``'s state at ``time``, and
    ``out/gatetherm.json``, gatetherm's own displacements there (run ``ccx job`` in ``out``).

    The deck holds the mesh (3-D: C3D4/C3D10; 2-D: CPE3/CPE6 for plane strain, and for plane
    stress with the equivalent plane-strain material; CAX3/CAX6 axisymmetric), a material per
    region, the supports (``*BOUNDARY``), the temperature field, gravity (``*DLOAD GRAV``),
    pressures (``*DLOAD Pn`` on element faces), tractions, boundary and point forces (``*CLOAD``
    of gatetherm's nodal forces), bonded contacts tied node to node (``*EQUATION``; a contact
    conductance is in the temperatures) and ``*NODE PRINT`` of ``U`` at every probe (a probe
    that is not a node prints its element's nodes, interpolated back by their weights). What it
    cannot hold is refused before the run, one line each (``InputError``): no E and ν, no fixed
    support, an elastic foundation, a joint stiffness, a pressure on an inner boundary, a
    temperature per region that jumps on shared nodes.

    Parameters
    ----------
    case : Case
        A case file's case or the paper's frame (2-D or 3-D).
    out : path
        The folder (created); ``job.inp`` and ``gatetherm.json`` in it are replaced.
    time : float, optional
        Time of the state, s: a step of the schedule (default its last).
    schedule : Schedule, optional
        The duty cycle (default the case's own).
    title : str, optional
        The deck's heading.
    run : bool
        Also run ``ccx job`` there (InputError if ``ccx`` is not installed) and add its results.

    Returns
    -------
    dict
        The content of ``gatetherm.json``: ``probes_m`` (gatetherm's displacement at every
        probe, m), ``relative_m`` (its relative displacements, m), ``probes`` (each probe's node
        set, 1-based nodes and weights), ``element``, ``vertices``, ``nodes``, ``elements``,
        ``order``, ``time_s``. Compare with CalculiX's ``job.dat`` through
        :func:`gatetherm.studies.run.ccx.probes_from_dat` and ``relative_from_dat``. With
        ``run``: ``calculix``, CalculiX's ``probes_m`` and ``relative_m`` and ``worst`` (the
        largest probe difference over gatetherm's largest displacement).
    """
    from gatetherm.studies.run.ccx import check_time, export_state, run_ccx

    _case(case)
    out = Path(argument("out", out, PATH, "a folder's path"))
    if out.exists() and not out.is_dir():
        raise InputError("out", f"{out} is a file, not a folder", "give the folder to write job.inp into")
    argument("schedule", schedule, (Schedule, type(None)), "a Schedule or None", "gt.condition(n) or gt.schedule_file")
    argument("title", title, (str, type(None)), "a string or None")
    if title is not None and ("\n" in title or "\r" in title or title.lstrip().startswith("*")):
        raise InputError("title", f"{title[:40]!r} is not one line of text: CalculiX would read what follows a line "
                         "break or a leading '*' as a keyword", "give one line not starting with '*'")
    argument("run", run, bool, "True or False")
    schedule = case.schedule if schedule is None else schedule
    t = check_time(schedule, float(schedule.times[-1]) if time is None else float(time))
    inp, info = export_state(case, schedule, t, title or f"gatetherm {case.name}, t = {t / 60:g} min")
    out.mkdir(parents=True, exist_ok=True)
    write_text_atomic(out / "job.inp", inp)
    write_text_atomic(out / "gatetherm.json", json_text(info, "gatetherm.json", indent=2))
    if run:
        info = {**info, "calculix": run_ccx(out, info)}
    return info
