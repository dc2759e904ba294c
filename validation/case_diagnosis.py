"""Diagnosis on a case file's frame: the C-frame example with hidden pieces.

    gatetherm validate case-diagnosis --out DIR [--case CASE.toml] [--seed N]

Each scenario hides up to two pieces in the case (its own parameters off, an
observation-side catalogue effect, sensor faults), runs it with P2 elements (the
diagnosis replays P1, so the discretisation differs: no inverse crime), keeps what a rig
would record (the case's inputs, θ_A, θ_B, θ_C and δ of its ``[signals]``) with Gaussian
noise at the resolution rounded to it, writes it as ``DIR/measured_<scenario>.csv`` and
diagnoses it blind with the case (``gatetherm diagnose --case CASE.toml --data
DIR/measured_<scenario>.csv --mesh-factor F`` gives the same). The truth is meshed with the
case's element sizes times :data:`MESH_FACTOR`, and so is the diagnosis' model, except in
"noise-only, case mesh": there the diagnosis has the example's own mesh, on which the P1
error of δ exceeds the 0.1-µm resolution, and replays with P2 elements instead
(:attr:`~gatetherm.studies.diagnosis.discrepancy.Settings.refine`). Two scenarios make the
spindle housing 3 cm (8.6 %) longer than the case's geometry script has it (δ moves by up to
3.2 µm): once with ``mesh.parameters.spindle_length`` marked as uncertain (the diagnosis tries
it, remeshing for every trial value), once unmarked (the cause then lies
outside every hypothesis). A scenario is *found* when every hidden piece that is a hypothesis
is named or in the group of a named piece, nothing else is named, and a cause outside the
hypotheses leaves the verdict short of ``explained`` (:mod:`validation.scoring`). Writes
``DIR/case_diagnosis.md`` and ``DIR/case_diagnosis.json``.
"""
from __future__ import annotations

import logging
from pathlib import Path

from gatetherm import InputError, write_text_atomic
from gatetherm.studies.diagnosis.discrepancy import Settings, diagnose
from gatetherm.studies.diagnosis.hypotheses import catalogue, configure, parameter_pieces
from gatetherm.studies.run.case import Case, load_case
from gatetherm.studies.run.output import write_json
from gatetherm.studies.run.scenario import run_scenario
from gatetherm.studies.run.simulate import signal_columns
from gatetherm.studies.run.timeseries import write_timeseries
from gatetherm.validation.hidden_effects import diagnosis_row, fmt
from gatetherm.validation.scoring import row_groups, score
from gatetherm.validation.truth import recorded

log = logging.getLogger(__name__)

C_FRAME = Path(__file__).resolve().parent / "examples" / "c_frame" / "case.toml"
MESH_FACTOR = 0.5
"""Element sizes of the study's meshes relative to the case's."""
SPINDLE = "mesh.parameters.spindle_length"
#: Scenario name -> (hidden pieces {label: value} (labels of ``gatetherm diagnose --case C_FRAME
#: --uncertain mesh.parameters.spindle_length --list-effects``), mesh factor, dimensions the diagnosis
#: marks as uncertain).
SCENARIOS = {
    "noise-only": ({}, MESH_FACTOR, ()),
    "film+offset": ({"film_free": 14.0, "sensor_offset(theta_A_degC)": 0.5}, MESH_FACTOR, ()),
    "source+expansion": ({"source_spindle": 1.3, "expansion": 1.1}, MESH_FACTOR, ()),
    "conductivity+lag": ({"conductivity": 0.75, "thermocouple_lag": 90.0}, MESH_FACTOR, ()),
    "capacity+drift": ({"heat_capacity": 1.2, "sensor_drift(delta_um)": 0.4}, MESH_FACTOR, ()),
    "initial": ({"initial_offset": 21.5}, MESH_FACTOR, ()),
    "noise-only, case mesh": ({}, 1.0, ()),
    "spindle length, marked": ({SPINDLE: 0.38}, MESH_FACTOR, (SPINDLE,)),
    "spindle length, not marked": ({SPINDLE: 0.38}, MESH_FACTOR, ()),
}
COLUMNS = ("scenario", "mesh_factor", "order", "hidden", "verdict", "pieces", "alternatives", "found", "wrong_names",
           "missed", "fitted", "p2_minus_p1_delta", "rms_before_um", "rms_after_um", "runs", "seconds")
"""Study columns; ``order``: the elements the diagnosis replayed; ``p2_minus_p1_delta``: its discretisation
check on δ, in resolutions."""


def _hypotheses(case: Case, labels: dict) -> tuple[dict, str]:
    """The hypotheses of ``case`` by label, with the dimensions ``labels`` name, and the first of ``labels``
    that is none of them ('' if every one is)."""
    pieces = {p.label: p for p in catalogue(case, signal_columns(case.problem))}
    for k in labels:
        if k.startswith("mesh."):
            try:
                pieces.update({p.label: p for p in parameter_pieces(case, [k], [k])})
            except InputError:  # a dimension the case's geometry does not have
                return pieces, k
    return pieces, next((k for k in labels if k not in pieces), "")


def lacking(case: Case, labels: dict) -> str:
    """The first of ``labels`` that is not a hypothesis of ``case`` ('' if every one is)."""
    return _hypotheses(case, labels)[1]


def hidden(case: Case, labels: dict) -> dict:
    """{Piece: value} of the labels (effects, the case's parameters, faults of the signal channels)."""
    pieces, missing = _hypotheses(case, labels)
    if missing:
        raise InputError(f"--case {case.path}", f"{missing} is not a hypothesis of this case",
                         "hide pieces it has (gatetherm diagnose --case CASE --list-effects)")
    return {pieces[k]: v for k, v in labels.items()}


def measured_run(case: Case, values: dict, seed: int, name: str):
    """The rig's record of ``case`` with the hidden pieces ``values``, run with P2 elements."""
    truth = configure(case.with_order(2), values)
    schedule = case.schedule
    cols, channels = run_scenario(truth, schedule).columns, signal_columns(case.problem)
    return recorded(cols, ("time_s", *schedule.drive.columns, *channels), channels, seed,
                    {"source": f"case-diagnosis study, scenario {name} (P2 truth of {case.path.name})"})


def found(verdict: str, scored: dict, outside: bool) -> bool:
    """Nothing missed and no wrong name (:func:`~gatetherm.validation.scoring.score`); a cause outside the
    hypotheses not ``explained``."""
    return not scored["missed"] and not scored["wrong_names"] and not (outside and verdict == "explained")


def run_study(out: Path, case_path: Path = C_FRAME, seed: int = 10, scenarios=tuple(SCENARIOS),
              on_row=None) -> list[dict]:
    """The ``scenarios``: measured file, blind diagnosis, study row. Scenarios whose hidden pieces are
    not hypotheses of the case (the C-frame's spindle source and length) are left out, each with a
    warning, before any work; none left is refused."""
    rows = []
    first = load_case(case_path, MESH_FACTOR)
    if first.time is None or not first.problem.signals.complete or not hasattr(first.schedule.drive, "columns"):
        raise InputError(f"--case {case_path}", "the study replays a transient case from its schedule file and "
                         "compares theta_A, theta_B, theta_C and delta: it needs [time] with a schedule and "
                         "[signals] mapping them", "give a case like validation/examples/c_frame/case.toml")
    skipped = {name: lacking(first, SCENARIOS[name][0]) for name in scenarios}
    for name, why in skipped.items():
        if why:
            log.warning("case-diagnosis: scenario %r left out: %s is not a hypothesis of %s", name, why, case_path)
    if all(skipped.values()):
        raise InputError(f"--case {case_path}", "no scenario of the study hides pieces this case has",
                         "give a case like validation/examples/c_frame/case.toml")
    for i, (name, (labels, factor, uncertain)) in enumerate(SCENARIOS.items()):
        if name not in scenarios or skipped[name]:
            continue
        case = first if factor == MESH_FACTOR else load_case(case_path, factor)
        truth = first
        values = hidden(truth, labels)
        ts = measured_run(truth, values, seed + i, name)
        write_timeseries(out / f"measured_{name.replace(', ', '_').replace(' ', '_')}.csv", ts)
        d = diagnose(case, ts, Settings(uncertain=uncertain))
        named, alternatives = [r.piece.label for r in d.pieces], [q.label for r in d.pieces for q in r.alternatives]
        tried = [p.key for p in values if p.kind != "geometry" or p.name in uncertain]
        scored = score([r.piece.key for r in d.pieces], row_groups(d), tried)
        row = {**diagnosis_row(d), "scenario": name, "pieces": named, "alternatives": alternatives, **scored,
               "hidden": ", ".join(f"{k} = {v:g}" for k, v in labels.items()) or "—", "mesh_factor": factor,
               "order": d.order,
               "found": found(d.verdict, scored, len(tried) < len(values)),
               "p2_minus_p1_delta": d.discretisation["delta_um"]}
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
