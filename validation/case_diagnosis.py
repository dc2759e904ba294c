"""Diagnosis on a case file's frame: the C-frame example with hidden pieces.

    gatetherm validate case-diagnosis --out DIR [--case CASE.toml] [--seed N]

Each scenario hides up to two pieces in the case (its own parameters off, an
observation-side catalogue effect, sensor faults), runs it with P2 elements (the
diagnosis replays P1, so the discretisation differs: no inverse crime), keeps what a rig
would record (the case's inputs, θ_A, θ_B, θ_C and δ of its ``[signals]``) with Gaussian
noise at the resolution rounded to it, writes it as ``DIR/measured_<scenario>.csv`` and
diagnoses it blind with the case (``gatetherm diagnose --case CASE.toml --data
DIR/measured_<scenario>.csv --mesh-factor F`` gives the same). Both meshes are the case's
geometry with its element sizes times :data:`MESH_FACTOR`: on the example's own mesh the
P1 error of δ exceeds the 0.1-µm resolution (the diagnosis' discretisation check says
so), which the last scenario shows. A scenario is *found* when every hidden piece is
named, or listed as an equally good alternative of a named piece, and nothing else is
named. Writes ``DIR/case_diagnosis.md`` and ``DIR/case_diagnosis.json``.
"""
from __future__ import annotations

import logging
from pathlib import Path

from gatetherm import write_text_atomic
from gatetherm.studies.diagnosis.discrepancy import diagnose
from gatetherm.studies.diagnosis.hypotheses import catalogue, configure
from gatetherm.studies.run.case import Case, load_case
from gatetherm.studies.run.output import write_json
from gatetherm.studies.run.scenario import run_scenario
from gatetherm.studies.run.timeseries import OUTPUT_COLUMNS, write_timeseries
from gatetherm.validation.hidden_effects import diagnosis_row, fmt, recorded

log = logging.getLogger(__name__)

C_FRAME = Path(__file__).resolve().parent / "examples" / "c_frame" / "case.toml"
MESH_FACTOR = 0.5
"""Element sizes of the study's meshes relative to the case's."""
#: Scenario name -> (hidden pieces {label: value} (labels of ``gatetherm diagnose --case C_FRAME
#: --list-effects``), mesh factor).
SCENARIOS = {
    "noise-only": ({}, MESH_FACTOR),
    "film+offset": ({"film_free": 14.0, "sensor_offset(theta_A_degC)": 0.5}, MESH_FACTOR),
    "source+expansion": ({"source_spindle": 1.3, "expansion": 1.1}, MESH_FACTOR),
    "conductivity+lag": ({"conductivity": 0.75, "thermocouple_lag": 90.0}, MESH_FACTOR),
    "capacity+drift": ({"heat_capacity": 1.2, "sensor_drift(delta_um)": 0.4}, MESH_FACTOR),
    "initial": ({"initial_offset": 21.5}, MESH_FACTOR),
    "noise-only, case mesh": ({}, 1.0),
}
COLUMNS = ("scenario", "mesh_factor", "hidden", "verdict", "pieces", "alternatives", "found", "fitted",
           "p2_minus_p1_delta", "rms_before_um", "rms_after_um", "runs", "seconds")
"""Study columns; ``p2_minus_p1_delta``: the diagnosis' discretisation check on δ, in resolutions."""


def hidden(case: Case, labels: dict) -> dict:
    """{Piece: value} of the labels (effects, the case's parameters, faults of the signal channels)."""
    pieces = {p.label: p for p in catalogue(case, OUTPUT_COLUMNS)}
    unknown = [k for k in labels if k not in pieces]
    if unknown:
        raise ValueError(f"{unknown[0]} is not a hypothesis of {case.path}")
    return {pieces[k]: v for k, v in labels.items()}


def measured_run(case: Case, values: dict, seed: int, name: str):
    """The rig's record of ``case`` with the hidden pieces ``values``, run with P2 elements."""
    truth = configure(case.with_overrides({"case.order": 2}), values)
    schedule = case.schedule
    cols = run_scenario(truth, schedule).columns
    return recorded(cols, ("time_s", *schedule.drive.columns, *OUTPUT_COLUMNS), OUTPUT_COLUMNS, seed,
                    {"source": f"case-diagnosis study, scenario {name} (P2 truth of {case.path.name})"})


def found(named, alternatives, hidden_labels) -> bool:
    """Every hidden piece named or an alternative of a named one, and nothing else named."""
    return all(h in named or h in alternatives for h in hidden_labels) and len(named) == len(hidden_labels)


def run_study(out: Path, case_path: Path = C_FRAME, seed: int = 10, scenarios=tuple(SCENARIOS),
              on_row=None) -> list[dict]:
    """The ``scenarios``: measured file, blind diagnosis, study row."""
    rows = []
    for i, (name, (labels, factor)) in enumerate(SCENARIOS.items()):
        if name not in scenarios:
            continue
        case = load_case(case_path, factor)
        ts = measured_run(case, hidden(case, labels), seed + i, name)
        write_timeseries(out / f"measured_{name.replace(', ', '_').replace(' ', '_')}.csv", ts)
        d = diagnose(case, ts)
        named, alternatives = [r.piece.label for r in d.pieces], [q.label for r in d.pieces for q in r.alternatives]
        row = {**diagnosis_row(d), "scenario": name, "pieces": named, "alternatives": alternatives,
               "hidden": ", ".join(f"{k} = {v:g}" for k, v in labels.items()) or "—", "mesh_factor": factor,
               "found": found(named, alternatives, labels), "p2_minus_p1_delta": d.discretisation["delta_um"]}
        rows.append(row)
        if on_row:
            on_row(row)
    return rows


def cell(v) -> str:
    """A table cell: fitted values as ``name = value`` pairs."""
    return ", ".join(f"{k} = {x:.4g}" for k, x in v.items()) or "—" if isinstance(v, dict) else fmt(v)


def table_markdown(rows: list[dict]) -> str:
    head = "| " + " | ".join(COLUMNS) + " |\n|" + "---|" * len(COLUMNS) + "\n"
    return head + "".join("| " + " | ".join(cell(r[c]) for c in COLUMNS) + " |\n" for r in rows)


def summary(rows: list[dict]) -> str:
    flagged = [r["scenario"] for r in rows if r["p2_minus_p1_delta"] > 1.0]
    return (f"{sum(r['found'] for r in rows)} of {len(rows)} scenarios found; the discretisation check exceeds the "
            f"resolution in {', '.join(flagged) or 'none'}")


def write_case_diagnosis(out: Path, case_path: Path = C_FRAME, seed: int = 10, scenarios=tuple(SCENARIOS),
                         on_row=None) -> tuple[str, list[dict]]:
    """Run the study into ``out``; returns (the one-line summary, the rows)."""
    rows = run_study(out, case_path, seed, scenarios, on_row)
    line = summary(rows)
    write_text_atomic(out / "case_diagnosis.md", f"# Diagnosis on {case_path}\n\n{line}\n\n{table_markdown(rows)}")
    write_json(out / "case_diagnosis.json", {"case": str(case_path), "seed": seed, "summary": line, "rows": rows})
    return line, rows
