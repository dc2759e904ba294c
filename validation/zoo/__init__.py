"""The machine zoo: every capability on every shipped machine, as one matrix.

    gatetherm validate zoo --out DIR [--machines NAME,...] [--timeout S]

Each machine of :data:`MACHINES` is a case file under ``validation/examples/`` (a ``.geo``, a
``case.toml``, a duty cycle ``schedule.csv``). Each capability of :data:`CAPABILITIES` runs on it
through the library functions its command calls, each cell in a child process of its own with a
time limit, so that the matrix always completes: a cell is a number with one line of context, a
one-line refusal (``refused: …``, an :class:`~gatetherm.InputError`) or ``FAILED: …`` (any other
exception, a crash or the time limit, in one line). Writes ``DIR/zoo.md`` and ``DIR/zoo.json``,
and each cell's files under ``DIR/<machine>/<capability>/``.

What each cell's number is (the capability's key, then its value):

* ``run``: the swing (max − min) of δ over the run, µm (steady: its value);
* ``reduce``: the largest error of δ of the reduced model ``gatetherm reduce`` makes (its default
  30 states) against the FE run on the case's own schedule, µm;
* ``paper``, ``mlr``, ``rom``: the residual band (max |δ_comp| after the compensator's settling
  time) of ``gatetherm compensate``'s method, µm, beside the same band of δ uncompensated;
* ``errormodel comp``: the same of an error model fitted on the first half of the run
  (``errormodel fit``'s defaults, every thermocouple a candidate, the case's power and room
  columns as inputs) and replayed as ``compensate --model`` on the whole run;
* ``sweep``: the change of δ's swing (steady: of its value) between the two points of a
  one-key study (``gatetherm sweep``, a ``[study] case =`` file), µm;
* ``sensors``: the held-out error (MAE of δ, µm) of three thermocouples placed by
  ``gatetherm sensors``' placement (small settings: 20 states, 8 training loads, 3 held out), beside the
  same error of the case's own three (θ_A, θ_B, θ_C: a designer's choice), and how many of the
  placed ones lie on a moving part (the machine's :attr:`Machine.moving` regions);
* ``diagnose``: the factor the diagnosis fits to the one hidden piece (a heat source made
  :attr:`Machine.factor` times stronger in a P2 truth with noise, ``validate case-diagnosis``'s
  recording), with the default hypotheses and at most two pieces, and whether it named that
  piece and nothing else;
* ``errormodel``: ``errormodel fit`` on the first 60 % of the run, ``errormodel predict`` on
  the rest: the RMS of δ's prediction error on the held-out 40 %, µm;
* ``report``: ``report --data`` on the run's time series: the largest drift of δ, µm;
* ``export ccx``: ``export ccx`` at the run's end and CalculiX on the deck: the largest
  |δ_ccx / δ − 1| over the case's relative displacements, % (acceptance 0.5 %).
"""
from __future__ import annotations

import dataclasses
import json
import logging
import math
import multiprocessing
import signal
import time
import traceback
from dataclasses import dataclass
from pathlib import Path

from gatetherm import InputError, write_text_atomic
from gatetherm.validation.zoo.context import CCX_TOLERANCE, EXAMPLES, SETTLE_S, TIMEOUT_S, Context, _band, _one_line, \
    _transient  # noqa: F401 - the cells' shared parts

log = logging.getLogger(__name__)

@dataclass(frozen=True)
class Machine:
    """One machine of the zoo."""

    folder: str
    """Its folder under ``validation/examples/``."""
    kind: str
    """What it is, for the table."""
    sweep: tuple[str, tuple[float, float]]
    """The swept case key and its two values (in the key's unit)."""
    hidden: str = ""
    """The diagnosis' hidden piece: a hypothesis label (``gatetherm diagnose --case … --list-effects``)."""
    factor: float = 1.3
    """Its value in the truth."""
    moving: tuple[str, ...] = ()
    """Regions that rotate or move (no thermocouple can be mounted on them)."""

    @property
    def case_path(self) -> Path:
        return EXAMPLES / self.folder / "case.toml"


MACHINES = {
    "c_frame": Machine("c_frame", "C-frame machining centre, 2-D plane stress",
                       ("thermal.free.film", (6.0, 12.0)), "source_spindle", 1.3, ("spindle",)),
    "joint": Machine("joint", "two blocks and a joint, 2-D steady", ("contacts.joint.conductance", (1000.0, 4000.0)),
                     "conductivity", 1.3),
    "lathe_headstock": Machine("lathe_headstock", "lathe headstock, 2-D plane stress",
                               ("thermal.free.film", (6.0, 12.0)), "source_bearing_rear", 1.6, ("spindle",)),
    "gantry": Machine("gantry", "gantry milling machine, 3-D assembly",
                      ("thermal.free.film", (6.0, 12.0)), "source_head", 1.3),
    "grinding_wheelhead": Machine("grinding_wheelhead", "grinding wheel head, 2-D plane stress",
                                  ("thermal.coolant.film", (150.0, 400.0)), "source_motor", 1.3,
                                  ("spindle", "wheel")),
    "ballscrew_axis": Machine("ballscrew_axis", "ball-screw feed axis, 2-D plane stress",
                              ("thermal.free.film", (6.0, 14.0)), "source_nut", 1.4, ("screw", "nut")),
    "vertical_column": Machine("vertical_column", "vertical column, moving head, joint, gravity, 2-D",
                               ("mesh.parameters.head_height", (0.9, 1.3)), "source_head", 1.3, ("spindle",)),
    "rotary_table": Machine("rotary_table", "rotary table, axisymmetric",
                            ("thermal.free.film", (6.0, 12.0)), "source_stator", 1.3, ("table",)),
    "spindle_unit": Machine("spindle_unit", "motor spindle, bearing losses, a rotating nose's film, axisymmetric",
                            ("thermal.jacket.film", (300.0, 600.0)), "source_front_bearing", 1.3, ("shaft",)),
}

CAPABILITIES = ("run", "reduce", "paper", "mlr", "rom", "errormodel comp", "sweep", "sensors", "diagnose",
                "errormodel", "report", "export ccx")


# --- guarded cells -------------------------------------------------------------------------------

def _outcome(fn, *args) -> dict:
    """``fn(*args)`` as a cell: {status, value, text}; never raises."""
    try:
        value, text = fn(*args)
        value = None if value is None or not math.isfinite(value) else float(value)
        return {"status": "ok", "value": value, "text": _one_line(text)}
    except InputError as err:
        return {"status": "refused", "value": None, "text": "refused: " + _one_line(str(err))}
    except Exception as err:  # noqa: BLE001 - a cell reports, the matrix completes
        log.debug("%s", traceback.format_exc())
        return {"status": "failed", "value": None,
                "text": "FAILED: " + _one_line(f"{type(err).__name__}: {err}")}


def _child(conn, fn, args) -> None:
    # A kill of the command (Ctrl-C reaches the whole process group) ends a cell quietly: not the
    # command's handlers, inherited by the fork, whose exception multiprocessing prints as a traceback.
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    logging.getLogger().setLevel(logging.ERROR)
    try:
        conn.send(_outcome(fn, *args))
    finally:
        conn.close()


def guarded(fn, *args, timeout_s: float = TIMEOUT_S) -> dict:
    """Run the cell ``fn(*args)`` in a forked child with a time limit; a crash, a hang or an
    exception is a ``FAILED`` cell of one line. Without fork (not POSIX), in this process."""
    t0 = time.perf_counter()
    if "fork" not in multiprocessing.get_all_start_methods():
        out = _outcome(fn, *args)
    else:
        mp = multiprocessing.get_context("fork")
        here, there = mp.Pipe(duplex=False)
        proc = mp.Process(target=_child, args=(there, fn, args), daemon=True)
        proc.start()
        there.close()
        if here.poll(timeout_s):
            try:
                out = here.recv()
            except EOFError:
                out = None
            proc.join(5.0)
        else:
            out = {"status": "failed", "value": None, "text": f"FAILED: no result within the {timeout_s:g}-s limit"}
        if proc.is_alive():
            proc.kill()
            proc.join()
        if out is None:
            out = {"status": "failed", "value": None, "text": f"FAILED: the cell's process ended ({proc.exitcode})"}
    out["seconds"] = round(time.perf_counter() - t0, 1)
    return out


def _machine_cells(name: str, machine: Machine, out: Path, capabilities, timeout_s: float, on_cell) -> dict:
    from gatetherm.studies.run.case import load_case
    from gatetherm.studies.run.scenario import run_scenario
    from gatetherm.validation.zoo.cells import CELLS

    folder = out / name
    folder.mkdir(parents=True, exist_ok=True)
    cells = {}
    t0 = time.perf_counter()

    loaded = []

    def load():
        case = load_case(machine.case_path)
        loaded.append((case, run_scenario(case)))
        return None, ""

    start = _outcome(load)
    if start["status"] != "ok":
        start["seconds"] = round(time.perf_counter() - t0, 1)
        for cap in capabilities:
            cells[cap] = dict(start)
            if on_cell:
                on_cell(name, cap, cells[cap])
        return cells
    (case, run), = loaded
    ctx = Context(machine, case, run, folder)
    for cap in capabilities:
        if cap == "run":
            cells[cap] = {**_outcome(CELLS[cap], ctx), "seconds": round(run.seconds, 1)}
        else:
            (folder / cap.replace(" ", "_")).mkdir(exist_ok=True)
            cells[cap] = guarded(CELLS[cap], dataclasses.replace(ctx, out=folder / cap.replace(" ", "_"))
                                 if cap not in ("sweep", "report", "export ccx") else ctx, timeout_s=timeout_s)
        if on_cell:
            on_cell(name, cap, cells[cap])
    return cells


def run_zoo(out: Path, machines=None, capabilities=CAPABILITIES, timeout_s: float = TIMEOUT_S,
            on_cell=None) -> dict:
    """Every capability on every machine: ``{machine: {capability: cell}}``, each cell
    ``{"status": "ok" | "refused" | "failed", "value": float | None, "text": one line, "seconds"}``."""
    from gatetherm.validation.zoo.cells import CELLS

    names = list(MACHINES) if machines is None else list(machines)
    unknown = [n for n in names if n not in MACHINES]
    if unknown:
        raise InputError("--machines", f"unknown machine {unknown[0]!r}", f"choose from {', '.join(MACHINES)}")
    bad = [c for c in capabilities if c not in CELLS]
    if bad:
        raise InputError("--capabilities", f"unknown capability {bad[0]!r}", f"choose from {', '.join(CELLS)}")
    out.mkdir(parents=True, exist_ok=True)
    return {n: _machine_cells(n, MACHINES[n], out, capabilities, timeout_s, on_cell) for n in names}


def short(cell: dict) -> str:
    """A cell in the matrix: its number (3 digits), ``refused`` or ``FAILED``."""
    if cell["status"] == "ok":
        v = cell["value"]
        return "—" if v is None else f"{v:.3g}"
    return "refused" if cell["status"] == "refused" else "FAILED"


def markdown(matrix: dict) -> str:
    """The matrix as markdown: a table of numbers (and ``refused``/``FAILED``), then every cell's line."""
    caps = list(next(iter(matrix.values())).keys()) if matrix else []
    units = {"run": "µm", "reduce": "µm", "paper": "µm", "mlr": "µm", "rom": "µm", "errormodel comp": "µm",
             "sweep": "µm", "sensors": "µm", "diagnose": "factor", "errormodel": "µm", "report": "µm",
             "export ccx": "%"}
    head = "| machine | " + " | ".join(f"{c} ({units.get(c, '')})" for c in caps) + " |\n"
    head += "|---|" + "---:|" * len(caps) + "\n"
    rows = "".join(f"| {m} | " + " | ".join(short(cells[c]) for c in caps) + " |\n" for m, cells in matrix.items())
    counts = {s: sum(c["status"] == s for cells in matrix.values() for c in cells.values())
              for s in ("ok", "refused", "failed")}
    lines = "".join(f"- **{m}**, {c}: {cells[c]['text']} ({cells[c]['seconds']:g} s)\n"
                    for m, cells in matrix.items() for c in caps)
    return (f"{len(matrix)} machines × {len(caps)} capabilities: {counts['ok']} numbers, {counts['refused']} "
            f"refusals, {counts['failed']} failed.\n\n{head}{rows}\nEvery cell:\n\n{lines}")


def write_zoo(out: Path, machines=None, capabilities=CAPABILITIES, timeout_s: float = TIMEOUT_S,
              on_cell=None) -> dict:
    """Run the zoo into ``out``; writes ``out/zoo.md`` and ``out/zoo.json``; returns the matrix."""
    t0 = time.perf_counter()
    matrix = run_zoo(out, machines, capabilities, timeout_s, on_cell)
    seconds = round(time.perf_counter() - t0, 1)
    write_text_atomic(out / "zoo.md", f"# The machine zoo\n\n`gatetherm validate zoo --out {out}` "
                                      f"({seconds:g} s)\n\n{markdown(matrix)}")
    write_text_atomic(out / "zoo.json", json.dumps(
        {"machines": {n: {"case": f"validation/examples/{MACHINES[n].folder}/case.toml",
                          "kind": MACHINES[n].kind} for n in matrix},
         "capabilities": list(capabilities), "timeout_s": timeout_s, "seconds": seconds, "cells": matrix},
        indent=2, allow_nan=False) + "\n")
    return matrix
