"""Compound-diagnosis study (issue 14): two missing pieces at once, plus the single-piece
cases of the hidden-effect study.

    gatetherm validate compound --out DIR [--workers 2] [--seed 14] [--pairs 48]
                                [--no-single] [--mesh-size M]

Two-piece cases: ``pairs`` "measured" runs, each with two different hypotheses of the
diagnosis (:func:`studies.diagnosis.hypotheses.catalogue`) in the model. The kinds of the
two cycle through effect+effect, effect+parameter, effect+sensor, parameter+parameter,
parameter+sensor, sensor+sensor; the condition (1–3), then within a kind the hypothesis and
its strength are drawn at random, the strength in the middle half of its range (:func:`draw_value`).
Only hypotheses that show in the data at the weak end of the middle half are drawn
(:func:`visible`: the catalogue's criterion, >0.4 µm RMS in δ over the last two hours or
>0.3 K at a thermocouple's peak, in the case's condition); and the one pair the data cannot
separate even in principle (the material's α with a gain of the δ sensor: δ is
proportional to α) is not drawn. The runs are made on the finer truth
mesh with sensor noise at the resolution (:mod:`validation.hidden_effects`) and diagnosed
blind. Single-piece cases: the hidden-effect study (catalogue effects at two strengths,
noise only, out-of-catalogue effects, parameter mismatches), unless ``--no-single``.

Writes ``DIR/compound.md`` and ``DIR/compound.csv`` and prints the acceptance figures.
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gatetherm import write_text_atomic
from gatetherm.studies.diagnosis.calibrate import coordinate
from gatetherm.studies.diagnosis.discrepancy import diagnose
from gatetherm.studies.diagnosis.hypotheses import PROPORTIONAL, Piece, catalogue, configure
from gatetherm.studies.diagnosis.replay import DELTA
from gatetherm.frame.config import Config
from gatetherm.frame.case import frame_case
from gatetherm.frame.conditions import condition_schedule
from gatetherm.studies.run.scenario import ScenarioCache, run_scenario
from gatetherm.studies.run.timeseries import OUTPUT_COLUMNS
from gatetherm.studies.sweeps.pool import run_pool
from gatetherm.validation import hidden_effects as single, paper_model
from gatetherm.validation.scoring import score
from gatetherm.validation.truth import measured, truth_with

log = logging.getLogger(__name__)

KIND_PAIRS = (("effect", "effect"), ("effect", "parameter"), ("effect", "sensor"),
              ("parameter", "parameter"), ("parameter", "sensor"), ("sensor", "sensor"))
VISIBLE_DELTA_UM, VISIBLE_THETA_K = 0.4, 0.3
"""The catalogue's visibility criterion (``solvers.effects.Effect``)."""
THERMOCOUPLES = ("theta_A_degC", "theta_B_degC", "theta_C_degC")


@dataclass(frozen=True)
class Pair:
    """A two-piece case."""

    pieces: tuple[tuple[str, float], ...]
    """(hypothesis key, value) of each hidden piece."""
    condition: int
    seed: int


def pieces_by_key(config: Config, case=None) -> dict[str, Piece]:
    """Every hypothesis of a diagnosis of the rig's channels on the frame of ``config`` (``case``: that
    frame, made already), by key."""
    return {p.key: p for p in catalogue(case or frame_case(config, 2), OUTPUT_COLUMNS)}


def _middle_half(p: Piece, u: float, side: int) -> float:
    """The value ``u`` (0.25–0.75) of the way along ``p``'s range on ``side`` (±1) of its
    neutral value (for a hypothesis with one inside its range), of zero (a range through
    zero), or across the range (log scale for positive ranges)."""
    if p.neutral is not None and p.lo <= p.neutral <= p.hi:
        end = p.hi if side > 0 else p.lo
        return float(p.neutral * (end / p.neutral) ** u if p.log_scale else p.neutral + u * (end - p.neutral))
    if p.lo < 0 < p.hi:
        return float(side * u * max(-p.lo, p.hi))
    return coordinate(p)[1](u if side > 0 else 1.0 - u)


def draw_value(p: Piece, rng: np.random.Generator) -> float:
    """A strength in the middle half of ``p``'s range (:func:`_middle_half`, random side)."""
    return _middle_half(p, rng.uniform(0.25, 0.75), 1 if rng.random() < 0.5 else -1)


def weakest(p: Piece) -> tuple[float, float]:
    """The two ends of the middle half nearest to "no change"."""
    return _middle_half(p, 0.25, 1), _middle_half(p, 0.25, -1)


def visible(config: Config, conditions=(1, 2, 3), dim: int = 2) -> dict[tuple[int, str], bool]:
    """For every condition and hypothesis: does it show at both :func:`weakest` values, by
    the catalogue's criterion (δ changes by more than 0.4 µm RMS over the last two hours or
    a thermocouple by more than 0.3 K at its peak; ``solvers.effects.Effect``)?"""
    case = frame_case(config, dim)
    drawn = {k for pair in KIND_PAIRS for k in pair}  # a dimension is never drawn: no remeshing for it
    pieces = {k: p for k, p in pieces_by_key(config, case).items() if p.kind in drawn}
    out = {(c, k): True for c in conditions for k in pieces}
    cache = ScenarioCache(2)
    for cond in conditions:
        sched = condition_schedule(cond, config.supply)
        last = sched.times >= sched.times[-1] - 2 * 3600.0
        base = run_scenario(case, sched, cache=cache).columns
        for k, p in pieces.items():
            for v in weakest(p):
                cols = run_scenario(configure(case, {p: v}), sched, cache=cache).columns
                d = float(np.sqrt(np.mean((cols[DELTA] - base[DELTA])[last] ** 2)))
                th = max(float(np.max(np.abs(cols[c] - base[c]))) for c in THERMOCOUPLES)
                out[cond, k] &= d > VISIBLE_DELTA_UM or th > VISIBLE_THETA_K
    return out


def pairs(config: Config, n: int = 48, seed: int = 14, conditions=(1, 2, 3), shows=None) -> list[Pair]:
    """``n`` two-piece cases: a condition, then two hypotheses that ``shows``
    ({(condition, key): bool}, default: all) marks visible in it."""
    rng = np.random.default_rng(seed)
    known = pieces_by_key(config)
    out = []
    for i in range(n):
        cond = int(rng.choice(conditions))
        by_kind: dict[str, list[Piece]] = {}
        for k, p in known.items():
            if shows is None or shows.get((cond, k), False):
                by_kind.setdefault(p.kind, []).append(p)
        ka, kb = KIND_PAIRS[i % len(KIND_PAIRS)]
        while True:
            a, b = (by_kind[k][rng.integers(len(by_kind[k]))] for k in (ka, kb))
            if a != b and frozenset({a.key, b.key}) not in PROPORTIONAL:
                break
        out.append(Pair(((a.key, draw_value(a, rng)), (b.key, draw_value(b, rng))), cond,
                        int(rng.integers(1 << 31))))
    return out


def run_pair(pair: Pair, config: Config) -> dict:
    """Make the measured run of ``pair``, diagnose it blind, return the study row."""
    case = frame_case(config, 2)
    known = pieces_by_key(config, case)
    values = {known[k]: v for k, v in pair.pieces}
    ts = measured(truth_with(config, pair.condition, values), pair.seed, pair.condition)
    row = single.diagnosis_row(diagnose(case, ts, single.SETTINGS))
    hidden = [k for k, _ in pair.pieces]
    named = set(row["pieces"])
    sc = score(row["pieces"], row["groups"], hidden)
    return {"hidden": hidden, "strengths": [v for _, v in pair.pieces], "condition": pair.condition, "seed": pair.seed,
            "kinds": "+".join(k.split(":")[0] for k in hidden), **row, **sc,
            "both_named": set(hidden) <= named, "both_named_or_equivalent": not sc["missed"],
            "wrong_piece": bool(sc["wrong_names"]), "wrong_piece_strict": bool(named - set(hidden)),
            "wrong_effect": any(k.startswith("effect:") for k in sc["wrong_names"])}


def _pair_worker(args):
    pair, mesh_size = args
    logging.basicConfig(level=logging.WARNING)
    return run_pair(pair, paper_model(size=mesh_size))


def acceptance(rows: list[dict]) -> dict:
    n = len(rows)
    out = {"pairs": n, "both_named": sum(r["both_named"] for r in rows),
           "both_named_pct": 100.0 * sum(r["both_named"] for r in rows) / max(n, 1),
           "both_named_or_equivalent": sum(r["both_named_or_equivalent"] for r in rows),
           "wrong_piece": sum(r["wrong_piece"] for r in rows),
           "wrong_piece_pct": 100.0 * sum(r["wrong_piece"] for r in rows) / max(n, 1),
           "wrong_piece_strict": sum(r["wrong_piece_strict"] for r in rows),
           "missed": sum(bool(r["missed"]) for r in rows),
           "wrong_effect": sum(r["wrong_effect"] for r in rows),
           "verdicts": {v: sum(r["verdict"] == v for r in rows) for v in sorted({r["verdict"] for r in rows})}}
    for kinds in sorted({r["kinds"] for r in rows}):
        mine = [r for r in rows if r["kinds"] == kinds]
        out[f"both_named[{kinds}]"] = f"{sum(r['both_named'] for r in mine)}/{len(mine)}"
    if rows:
        out.update(seconds_median=float(np.median([r["seconds"] for r in rows])),
                   seconds_max=max(r["seconds"] for r in rows),
                   runs_median=float(np.median([r["runs"] for r in rows])), runs_max=max(r["runs"] for r in rows))
    return out


COLUMNS = ("hidden", "strengths", "condition", "seed", "verdict", "pieces", "alternatives", "both_named", "wrong_piece",
           "wrong_names", "missed", "stand_ins", "best_rejected", "rms_before_um", "rms_after_um", "runs", "seconds")


def _fmt(v) -> str:
    if isinstance(v, list) and v and isinstance(v[0], float):
        return ", ".join(f"{x:.4g}" for x in v)
    return single.fmt(v)


def kinds_markdown(rows: list[dict]) -> str:
    """The pairs by the kinds of their hidden pieces (docs/diagnosis.md, "Compound diagnosis")."""
    L = ["| hidden kinds | cases | verdict `explained` | both pieces named | both named, or in a named piece's group "
         "| a wrong piece named (groups as right) | a piece missed | a wrong catalogue effect "
         "| a piece other than the hidden (groups as wrong) |", "|---|---|---|---|---|---|---|---|---|"]
    groups = [(" + ".join(k), [r for r in rows if r["kinds"] == "+".join(k)]) for k in KIND_PAIRS]
    for name, mine in groups + [("all", rows)]:
        n = len(mine)
        counts = [sum(r["verdict"] == "explained" for r in mine)] + [
            sum(bool(r[k]) for r in mine) for k in ("both_named", "both_named_or_equivalent", "wrong_piece", "missed",
                                                     "wrong_effect", "wrong_piece_strict")]
        cells = [str(c) for c in counts]
        if name == "all":
            for i in (1, 3, 6):
                cells[i] += f" ({100 * counts[i] / max(n, 1):.1f} %)"
        L.append(f"| {name} | {n} | " + " | ".join(cells) + " |")
    return "\n".join(L)


def table_markdown(rows: list[dict], acc: dict, single_rows: list[dict], single_acc: dict | None) -> str:
    head = ["hidden pieces", "strengths", "cond.", "noise seed", "verdict", "pieces named", "or equally", "both named",
            "wrong piece", "wrong names", "missed", "stand-ins", "best rejected", "δ RMS before (µm)",
            "δ RMS after (µm)", "model runs", "time (s)"]
    L = ["# Compound-diagnosis study", "",
         "Held-out window: last 40 % of each 5-h, 1-min run; sensor noise at the resolution (0.1 µm, 0.05 K). "
         "Strengths in the hypothesis' unit (`gatetherm diagnose --list-effects`).", "",
         "## Two pieces at once", "", "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    L += ["| " + " | ".join(_fmt(r[k]) for k in COLUMNS) + " |" for r in rows]
    L += ["", "### By kinds", "", kinds_markdown(rows)]
    L += ["", "### Figures", ""] + [f"- {k}: {_fmt(v)}" for k, v in acc.items()]
    if single_acc is not None:
        L += ["", "## Single pieces (the hidden-effect study's cases)", "",
              single.table_markdown(single_rows, single_acc).split("\n", 2)[2]]
    return "\n".join(L) + "\n"


def row_line(row: dict) -> str:
    if "hidden" not in row:
        return single.row_line(row)
    return (f"{' + '.join(row['hidden']):<62} c{row['condition']} -> {row['verdict']:<16} "
            f"{_fmt(row['pieces']):<60} {'OK' if row['both_named'] else '--'}"
            f"{' WRONG' if row['wrong_piece'] else ''} ({row['seconds']:.0f} s, {row['runs']} runs)")


def write_compound(out: Path, workers: int = 2, seed: int = 14, n_pairs: int = 48, with_single: bool = True,
                   mesh_size: float | None = None, on_row=None) -> tuple[dict, list[dict]]:
    """Run the study, write ``compound.md`` and ``.csv``; returns the figures and the pairs' rows."""
    t0 = time.perf_counter()
    config = paper_model(size=mesh_size)
    shows = visible(config)
    hidden = sorted(f"{k}(c{c})" for (c, k), v in shows.items() if not v)
    log.info("not drawn (below the visibility criterion at the weak end of the middle half): %s", hidden)
    todo = pairs(config, n_pairs, seed, shows=shows)
    rows = run_pool(_pair_worker, [(p, mesh_size) for p in todo], workers, on_row)
    acc = acceptance(rows)
    single_rows, single_acc = [], None
    if with_single:
        single_rows = run_pool(single.case_worker, [(c, mesh_size) for c in single.cases()], workers, on_row)
        single_acc = single.acceptance(single_rows)
    figures = {"not_drawn_invisible": hidden, **acc, **({f"single.{k}": v for k, v in single_acc.items()} if single_acc else {}),
               "study_wall_time_s": round(time.perf_counter() - t0, 1)}
    out = Path(out)
    write_text_atomic(out / "compound.md", table_markdown(rows, figures, single_rows, single_acc))
    write_text_atomic(out / "compound.csv", single.table_csv(rows, COLUMNS, _fmt))
    if single_rows:
        write_text_atomic(out / "hidden_effects.csv", single.table_csv(single_rows))
    return {k: _fmt(v) for k, v in figures.items()}, rows
