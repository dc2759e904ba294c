"""Export a state for another code: a deck of an output format of
:mod:`gatetherm.studies.run.formats` (CalculiX's ``ccx``), :mod:`gatetherm.api`."""
from __future__ import annotations

import dataclasses
import os
from pathlib import Path

from gatetherm import InputError, write_text_atomic
from gatetherm.checks import argument, json_text
from gatetherm.api.run import PATH, Case, Schedule, _case
from gatetherm.studies.run.formats import FORMATS, INFO, check_time, get

PUBLIC = ("Export", "export_case", "export_ccx")  # offered as gt.NAME (gatetherm.api finds them here)


def export_ccx(case: Case, out: str | os.PathLike, time: float | None = None, *, schedule: Schedule | None = None,
               title: str | None = None, run: bool = False, on_step=None) -> dict:
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
    on_step : callable, optional
        ``on_step(i, n)`` after each of the ``n`` samples of the run to ``time``.

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
    fmt = FORMATS["ccx"]
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
    inp, info = fmt.writer().export_state(case, schedule, t, title or f"gatetherm {case.name}, t = {t / 60:g} min",
                                          on_step)
    out.mkdir(parents=True, exist_ok=True)
    return _write_deck(fmt.name, out, inp, info, run)


def _write_deck(format: str, out: Path, inp: str, info: dict, run: bool) -> dict:
    """``out/DECK`` and ``out/gatetherm.json``; with ``run``, the other code run there (its results in
    the dict under the format's code, lower case: ``calculix``)."""
    fmt = FORMATS[format]
    write_text_atomic(out / fmt.deck, inp)
    write_text_atomic(out / INFO, json_text(info, INFO, indent=2))
    if run:
        if not fmt.runner:
            raise InputError("run", f"gatetherm cannot run {fmt.code}", f"run '{fmt.command}' in {out} yourself")
        info = {**info, fmt.code.lower(): getattr(fmt.writer(), fmt.runner)(out, info)}
    return info


OUTPUTS = FORMATS["ccx"].outputs
"""What :meth:`Export.write` of a CalculiX deck writes (each format's: ``Format.outputs``); writing
again replaces all of it (CalculiX's own files are left)."""


@dataclasses.dataclass(frozen=True)
class Export:
    """A state exported for another code (CalculiX) by :func:`export_case`, and the folder it was
    written into."""

    deck: str
    """``job.inp``'s text."""
    info: dict
    """``gatetherm.json``'s content (:func:`export_ccx`'s result; with a CalculiX run, ``calculix`` too)."""
    run: bool = False
    """CalculiX runs (ran) in the folder written."""
    files: tuple = ()
    """Input files the written folder must keep."""
    folder: str | None = None
    """The folder it was written into, as given (None: not written)."""
    format: str = "ccx"
    """The output format (:mod:`gatetherm.studies.run.formats`)."""

    def write(self, out: str | os.PathLike) -> "Export":
        """Write ``out/job.inp`` (the format's deck) and ``out/gatetherm.json`` (with :attr:`run`, run
        ``ccx job`` there) in one transaction.

        Returns
        -------
        Export
            This result with :attr:`folder` ``out`` (and CalculiX's results in :attr:`info`).
        """
        from gatetherm.outdir import output_dir

        with output_dir(out, FORMATS[self.format].outputs, keep=self.files) as stage:
            info = _write_deck(self.format, stage, self.deck, self.info, self.run)
        return dataclasses.replace(self, info=info, folder=str(out))

    def summary(self) -> str:
        """The lines ``gatetherm export ccx`` prints (no final newline)."""
        fmt = FORMATS[self.format]
        info, other = self.info, self.info.get(fmt.code.lower())
        lines = [f"wrote {self.folder}/{fmt.deck} ({info['element']}, {info['nodes']} nodes) and {INFO}"
                 + ("" if self.run else f"; run: cd {self.folder} && {fmt.command}")]
        for name, v in info["relative_m"].items():
            lines.append(f"gatetherm {name}: {v * 1e6:.6g} um" + (
                f", {fmt.code} {other['relative_m'][name] * 1e6:.6g} um ({other['relative_m'][name] / v - 1:+.1e})"
                if other and v else ""))
        if other:
            lines.append(f"{fmt.code} against gatetherm at the probes: largest difference {other['worst']:.1e} of the "
                         "largest displacement")
        return "\n".join(lines)


def export_case(case: Case | str | os.PathLike | None = None, *, condition: int | None = None,
                time: float | None = None, dim: int = 2, config: str | os.PathLike | None = None, run: bool = False,
                out: str | os.PathLike | None = None, on_progress=None, format: str = "ccx") -> Export:
    """A case file's state (or the paper's frame's under a condition) as a deck for another code:
    what ``gatetherm export FORMAT`` does (:func:`export_ccx` for what CalculiX's deck holds and refuses).

    Parameters
    ----------
    case : Case or str or path, optional
        A case, or a case file's path (give this or ``condition``).
    condition : int, optional
        The paper's frame (``dim``, ``config``) under its condition 1, 2 or 3.
    time : float, optional
        Time of the state, s: a step of the schedule (default its last).
    dim : int
        The frame's 2 or 3 (with ``condition``).
    config : str or path, optional
        The frame's model file (with ``condition``).
    run : bool
        Also run ``ccx job`` in ``out`` and compare.
    out : str or path, optional
        Also write it there (:meth:`Export.write`), the folder checked and locked before the run
        to ``time``.
    on_progress : callable, optional
        ``on_progress(i, n)`` after each of the ``n`` samples of the run to ``time``.
    format : str
        The output format, a name of :data:`gatetherm.studies.run.formats.FORMATS` (``"ccx"``: CalculiX).

    Returns
    -------
    Export
    """
    from gatetherm import InputError
    from gatetherm.api.case import PATH, gate_frame, load_case
    from gatetherm.checks import argument
    from gatetherm.outdir import output_dir
    from gatetherm.frame.conditions import condition as check_condition

    fmt = get(format)
    argument("case", case, (Case, *PATH, type(None)), "a Case, a case file's path or None")
    argument("run", run, bool, "True or False")
    if (case is None) == (condition is None):
        raise InputError("case/condition", "give one of the two", "e.g. condition=1, time=900")
    if condition is not None:  # 0 is no condition (it would run condition 1)
        check_condition(condition)
    what = str(case) if case is not None and not isinstance(case, Case) else f"condition {condition}"
    if isinstance(case, Case):
        what = case.name
    else:
        case = load_case(case) if case is not None else gate_frame(dim, config, condition)
    schedule = case.schedule
    t = check_time(schedule, float(schedule.times[-1]) if time is None else time)
    title = f"gatetherm {what}, t = {t / 60:g} min"
    files = (config, *case.files)

    def made() -> Export:
        return Export(*fmt.writer().export_state(case, schedule, t, title, on_progress), run, files, format=fmt.name)

    if out is None:
        return made()
    with output_dir(out, fmt.outputs, keep=files) as stage:
        result = made()
        info = _write_deck(fmt.name, stage, result.deck, result.info, run)
    return dataclasses.replace(result, info=info, folder=str(out))
