"""``gatetherm validate beam``: beam theory against FE for K_i and K_C over l/l4 and beta
(the paper's Figs. 7 and 8), the error table, the controlled series that explain the
gaps, the effective coefficients of the transient runs, and ``report.md``.

The studies are sweep studies (validation/beam_vs_fe.py) run through the sweep engine
into ``DIR/points``, so a stopped validation resumes where it stopped.
"""
from __future__ import annotations

import json
import resource
import time
from pathlib import Path

import numpy as np

from gatetherm import write_text_atomic
from gatetherm.frame.config import Config
from gatetherm.studies.sweeps.runner import run_points, write_table


def cpu_seconds() -> float:
    """CPU time of this process and its finished children, s."""
    own, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def columns_of(rows: list[dict], columns: list[str] | None = None):
    """(columns, rows) for write_table; columns in first-seen order unless given."""
    return columns or list(dict.fromkeys(k for r in rows for k in r)), rows


def _fe_curves(rows):
    fe = {}
    for r in rows:
        fe.setdefault(r["beta"], []).append((r["l_over_l4"], r["Ki_norm_fe"], r["Kc_norm_fe"]))
    return {b: tuple(np.array(v) for v in zip(*sorted(pts))) for b, pts in fe.items()}


def write_beam_study(out: Path, base: Config, dim: int, workers: int = 1, scheduler: str | None = None,
                     progress=None, a_every: int = 1, series: bool = True) -> dict:
    """Run the beam-vs-FE studies (resumable, points under ``out/points``; ``a_every``,
    ``series``: a subset, see :func:`beam_vs_fe.studies`), write the tables, figures and
    ``report.md``; returns the summary (also ``summary.json``) with ``lines``, the key figures
    as sentences, ``by_beta`` (the error summary per coefficient and beta) and ``effective``."""
    from gatetherm.frame.beam import normalised
    from gatetherm.validation import beam_vs_fe as bv
    from gatetherm.validation import beam_vs_fe_report as bv_report
    from gatetherm.validation.plots import save
    from gatetherm.validation.plots.beam import plot_ki_kc
    from gatetherm.validation.effective import effective_coefficients, table_rows
    from gatetherm.validation.plots.sweep import plot_xy

    t0, c0 = time.perf_counter(), cpu_seconds()
    out = Path(out)
    plans, records = run_points(bv.studies(base, dim, a_every, series), out, workers, scheduler, progress)
    rows = {name: [bv.collect(tasks, records) for tasks in lst] for name, lst in plans.items()}
    main, no_tank = rows["sweep"][0], rows["no_tank"][0]

    a = np.linspace(bv.A_VALUES[dim][0], bv.A_VALUES[dim][-1], 400)
    theory = {b: normalised(a, b) for b in bv.BETAS}
    for rs, sfx in ((main, ""), (no_tank, "_no_tank")):
        write_table(out / f"beam_vs_fe{sfx}.csv", *columns_of(bv.csv_rows(rs)))
        ki, kc = plot_ki_kc(a, theory, _fe_curves(bv.csv_rows(rs)))
        save(ki, out / f"fig7_Ki{sfx}.png")
        save(kc, out / f"fig8_Kc{sfx}.png")
    errors, errors_nt = bv.error_rows(main, no_tank), bv.error_rows(no_tank, no_tank)
    write_table(out / "errors.csv", *columns_of(errors))
    gaps = [e for e in errors if e["gap"] or not e["within_tolerance"]]
    write_text_atomic(out / "errors.md", "# K_i, K_C: FE against the beam theory\n\n"
                      + bv_report.md_table(bv_report.summary_by_beta(errors)) + "\n\n## Gaps\n\n"
                      + (bv_report.md_table(gaps) if gaps else "none") + "\n")
    slender = bv.series_rows([r for rs in rows["slenderness"] for r in rs], "l_over_h")
    tie = bv.series_rows([r for rs in rows["tie_height"] for r in rs], "geometry.t_C")
    for srows, x, name in ((slender, "l_over_h", "slenderness"), (tie, "geometry.t_C", "tie_height")):
        if not srows:
            continue
        write_table(out / f"{name}.csv", *columns_of(srows))
        for k in ("Ki", "Kc"):
            save(plot_xy(srows, x, f"{k}_fe_rel_error", "point", f"{k}: (FE - theory)/theory, no tank cavity",
                         logx=(name == "slenderness"), hline=0.0), out / f"{name}_{k}.png")
    conv = bv.convergence(rows["mesh"], dim)
    write_table(out / "mesh.csv", *columns_of(conv))
    effective = table_rows(effective_coefficients(base, dim))
    write_table(out / "effective.csv", *columns_of(effective))

    skipped = sorted({r["derived.l_over_l4"] for r in main if r["status"] == "skipped"})
    zc_fe, zc_th = bv.zero_crossings(main), bv.zero_crossings(main, which="Ki_norm_theory")
    points = sum(len(t) for lst in plans.values() for t in lst)
    timing = {"points": points, "wall s": round(time.perf_counter() - t0, 1),
              "CPU s": round(cpu_seconds() - c0, 1), "workers": scheduler or workers}
    cfg = next(t.config for t in plans["sweep"][0] if not t.skip)
    text = bv_report.report(dim, cfg, base.source, errors, errors_nt, skipped, zc_fe, zc_th, slender, tie,
                            conv, effective, timing)
    write_text_atomic(out / "report.md", text)
    lines = [f"wrote {out}/report.md, beam_vs_fe.csv, errors.csv, fig7_Ki.png, fig8_Kc.png and series",
             f"{points} points ({len(records)} stored), wall {timing['wall s']} s, CPU {timing['CPU s']} s",
             f"within tolerance: {sum(e['within_tolerance'] for e in errors)} of {len(errors)} "
             f"(no tank cavity: {sum(e['within_tolerance'] for e in errors_nt)} of {len(errors_nt)}); "
             f"gaps > {bv.GAP_REL:.0%} or misses (explained in report.md): {len(gaps)}"]
    lines += [f"beta {b:g}: FE K_i/(3 alpha l^2/8h) min {z['min']:.4f} at l/l4 = {z['at_min']:g}, "
              f"sign changes at {[round(c, 3) for c in z['crossings']]}" for b, z in zc_fe.items()]
    summary = {
        **timing, "within_tolerance": sum(e["within_tolerance"] for e in errors), "values": len(errors),
        "gaps": len(gaps), "within_tolerance_no_tank": sum(e["within_tolerance"] for e in errors_nt),
        "zero_crossings_fe": {str(b): z for b, z in zc_fe.items()}}
    write_text_atomic(out / "summary.json", json.dumps(summary, indent=2) + "\n")
    return {**summary, "lines": lines, "by_beta": bv_report.summary_by_beta(errors), "effective": effective}
