"""``gatetherm validate TARGET``: regenerate a validation study in one command.

Each target is an entry of :data:`TARGETS` (help, add_arguments, run); adding a target
is adding an entry. Targets run their points through the sweep engine into
``DIR/points``, so a stopped validation resumes where it stopped.

* ``beam``: beam theory vs FE for K_i and K_C over l/l4 and beta (Figs. 7, 8), the error
  table, the controlled series that explain the gaps, the effective coefficients of
  the transient runs, and ``report.md``.
* ``design``: the tie-bar position that minimises the 5-h swing of delta for
  conditions 1-3, and a second tie bar above the cutting area.
"""
from __future__ import annotations

import json
import resource
import sys
import time
from pathlib import Path

import numpy as np

from gatetherm import write_text_atomic
from gatetherm.studies.cli.mesh import add_model_options
from gatetherm.studies.cli.sweep import PointStore, add_parallel_options, run_studies, write_table


def register(sub) -> None:
    p = sub.add_parser("validate", help="regenerate a validation study (beam, design)",
                       description="Regenerate a validation study: tables, figures and report.md.")
    targets = p.add_subparsers(dest="target", metavar="TARGET", required=True)
    for name, (text, add_arguments, run) in TARGETS.items():
        t = targets.add_parser(name, help=text, description=text)
        add_arguments(t)
        t.add_argument("--out", required=True, metavar="DIR", help="output directory")
        add_parallel_options(t)
        t.set_defaults(func=_guarded(run))


def _cpu_seconds() -> float:
    own, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


class PointsFailed(Exception):
    """Some points raised; the finished ones are stored, a rerun retries the rest."""


def run_points(named_studies: dict, out: Path, args, label: str):
    """Plan and run every study (one shared point store); the task lists per study name and
    the records by key. Raises :class:`PointsFailed` after storing what finished."""
    from gatetherm.studies.cli.simulate import Progress
    from gatetherm.studies.sweeps.sweep import plan

    plans = {name: [plan(s) for s in studies] for name, studies in named_studies.items()}
    jobs = [(tasks, PointStore(out)) for lst in plans.values() for tasks in lst]
    done, failed = run_studies(jobs, args.workers, args.scheduler, Progress(label))
    if failed:
        raise PointsFailed("; ".join(f"{dict(t.params)}: {err}" for t, err in failed[:3])
                           + f" ({len(failed)} points failed; rerun to retry them)")
    return plans, {k: v for d in done for k, v in d.items()}


def _guarded(run):
    """A target's run(args) that reports failed points on stderr with exit code 1."""
    def wrapped(args) -> int:
        try:
            return run(args)
        except PointsFailed as err:
            print(f"gatetherm: {err}", file=sys.stderr)
            return 1
    return wrapped


def _rows(rows: list[dict], columns: list[str] | None = None):
    columns = columns or list(dict.fromkeys(k for r in rows for k in r))
    return columns, rows


# --- beam ---------------------------------------------------------------------------------

def _beam_arguments(p) -> None:
    add_model_options(p)


def _fe_curves(rows):
    fe = {}
    for r in rows:
        fe.setdefault(r["beta"], []).append((r["l_over_l4"], r["Ki_norm_fe"], r["Kc_norm_fe"]))
    return {b: tuple(np.array(v) for v in zip(*sorted(pts))) for b, pts in fe.items()}


def run_beam(args) -> int:
    from gatetherm.solvers.beam import normalised
    from gatetherm.studies.run.config import load_config
    from gatetherm.validation import beam_vs_fe as bv
    from gatetherm.validation import beam_vs_fe_report as bv_report
    from gatetherm.validation.plots.beam import plot_ki_kc
    from gatetherm.validation.effective import effective_coefficients, table_rows
    from gatetherm.validation.plots.sweep import plot_xy

    t0, c0 = time.perf_counter(), _cpu_seconds()
    out, dim = Path(args.out), args.dim
    base = load_config(args.config)
    plans, records = run_points(bv.studies(base, dim), out, args, f"validate beam {dim}-D")
    rows = {name: [bv.collect(tasks, records) for tasks in lst] for name, lst in plans.items()}
    main, no_tank = rows["sweep"][0], rows["no_tank"][0]

    a = np.linspace(bv.A_VALUES[dim][0], bv.A_VALUES[dim][-1], 400)
    theory = {b: normalised(a, b) for b in bv.BETAS}
    for rs, sfx in ((main, ""), (no_tank, "_no_tank")):
        write_table(out / f"beam_vs_fe{sfx}.csv", *_rows(bv.csv_rows(rs)))
        plot_ki_kc(a, theory, _fe_curves(bv.csv_rows(rs)), out / f"fig7_Ki{sfx}.png", out / f"fig8_Kc{sfx}.png")
    errors, errors_nt = bv.error_rows(main, no_tank), bv.error_rows(no_tank, no_tank)
    write_table(out / "errors.csv", *_rows(errors))
    gaps = [e for e in errors if e["gap"] or not e["within_tolerance"]]
    write_text_atomic(out / "errors.md", "# K_i, K_C: FE against the beam theory\n\n"
                      + bv_report.md_table(bv_report.summary_by_beta(errors)) + "\n\n## Gaps\n\n"
                      + (bv_report.md_table(gaps) if gaps else "none") + "\n")
    slender = bv.series_rows([r for rs in rows["slenderness"] for r in rs], "l_over_h")
    tie = bv.series_rows([r for rs in rows["tie_height"] for r in rs], "geometry.t_C")
    for series, x, name in ((slender, "l_over_h", "slenderness"), (tie, "geometry.t_C", "tie_height")):
        if not series:
            continue
        write_table(out / f"{name}.csv", *_rows(series))
        for k in ("Ki", "Kc"):
            plot_xy(series, x, f"{k}_fe_rel_error", "point", out / f"{name}_{k}.png",
                    f"{k}: (FE - theory)/theory, no tank cavity", logx=(name == "slenderness"), hline=0.0)
    conv = bv.convergence(rows["mesh"], dim)
    write_table(out / "mesh.csv", *_rows(conv))
    effective = table_rows(effective_coefficients(base, dim))
    write_table(out / "effective.csv", *_rows(effective))

    skipped = sorted({r["derived.l_over_l4"] for r in main if r["status"] == "skipped"})
    zc_fe, zc_th = bv.zero_crossings(main), bv.zero_crossings(main, which="Ki_norm_theory")
    points = sum(len(t) for lst in plans.values() for t in lst)
    timing = {"points": points, "wall s": round(time.perf_counter() - t0, 1),
              "CPU s": round(_cpu_seconds() - c0, 1), "workers": args.scheduler or args.workers}
    cfg = next(t.config for t in plans["sweep"][0] if not t.skip)
    text = bv_report.report(dim, cfg, base.source, errors, errors_nt, skipped, zc_fe, zc_th, slender, tie,
                            conv, effective, timing)
    write_text_atomic(out / "report.md", text)
    write_text_atomic(out / "summary.json", json.dumps({
        **timing, "within_tolerance": sum(e["within_tolerance"] for e in errors), "values": len(errors),
        "gaps": len(gaps), "within_tolerance_no_tank": sum(e["within_tolerance"] for e in errors_nt),
        "zero_crossings_fe": {str(b): z for b, z in zc_fe.items()}}, indent=2) + "\n")
    print(f"wrote {out}/report.md, beam_vs_fe.csv, errors.csv, fig7_Ki.png, fig8_Kc.png and series")
    print(f"{points} points ({len(records)} stored), wall {timing['wall s']} s, CPU {timing['CPU s']} s")
    print(f"within tolerance: {sum(e['within_tolerance'] for e in errors)} of {len(errors)} "
          f"(no tank cavity: {sum(e['within_tolerance'] for e in errors_nt)} of {len(errors_nt)}); "
          f"gaps > {bv.GAP_REL:.0%} or misses (explained in report.md): {len(gaps)}")
    for b, z in zc_fe.items():
        print(f"beta {b:g}: FE K_i/(3 alpha l^2/8h) min {z['min']:.4f} at l/l4 = {z['at_min']:g}, "
              f"sign changes at {[round(c, 3) for c in z['crossings']]}")
    return 0


# --- design -------------------------------------------------------------------------------

def _design_arguments(p) -> None:
    add_model_options(p)


def run_design(args) -> int:
    from gatetherm.studies.sweeps import design as ds
    from gatetherm.studies.run.config import load_config
    from gatetherm.studies.sweeps.sweep import table
    from gatetherm.validation.plots.sweep import plot_histories, plot_positions, plot_second

    t0, c0 = time.perf_counter(), _cpu_seconds()
    out, dim = Path(args.out), args.dim
    base = load_config(args.config)
    grid = ds.first_grid(base, dim)

    def positions(values):
        plans, records = run_points({"p": [ds.position_study(base, dim, values)]}, out, args, "design: l4")
        return table(plans["p"][0], records)[1]

    rows = positions(grid)
    rows += positions(ds.refined_grid(grid, ds.optimum(rows)["l4"]))
    best = ds.optimum(rows)
    paper_rows = positions([base.model.frame.l4])
    first = (base.model.frame.l4, best["l4"])
    plans, records = run_points({"s": [ds.second_study(base, dim, first)]}, out, args, "design: second bar")
    second = ds.second_summary(table(plans["s"][0], records)[1])
    columns = list(dict.fromkeys(k for r in rows for k in r))
    write_table(out / "positions.csv", columns, sorted(rows, key=lambda r: (r["geometry.l4"], r["condition"])))
    write_table(out / "second_tie_bar.csv", *_rows(second))
    plot_positions(rows, {f"model l4 = {first[0]:.3g}": first[0], f"optimum {best['l4']:.3g}": best["l4"]},
                   out / "design_position.png", f"one tie bar, {dim}-D")
    plot_second(second, out / "design_second.png", f"second tie bar above the cutting area, {dim}-D")
    top = min(second, key=lambda r: r["worst_swing_um"])
    column = plans["s"][0][0].config.model.frame.column_height
    designs = {f"model, l4 = {first[0]:.3g} m": base,
               f"optimal l4 = {best['l4']:.3g} m": ds.with_frame(base, l4=best["l4"]),
               f"l4 = {top['l4']:.3g} m + second bar at {top['l4_2']:.3g} m":
                   ds.with_frame(base, l4=top["l4"], l4_2=top["l4_2"], column_height=column)}
    plot_histories(ds.histories(designs, dim), out / "design_histories.png")
    paper_swing = ds.swings(paper_rows)[round(first[0], 6)]
    timing = {"wall s": round(time.perf_counter() - t0, 1), "CPU s": round(_cpu_seconds() - c0, 1),
              "workers": args.scheduler or args.workers}
    write_text_atomic(out / "report.md", ds.report(dim, base, best, paper_swing, second, timing))
    print(f"wrote {out}/report.md, positions.csv, second_tie_bar.csv and design_*.png")
    print(f"optimal l4 = {best['l4']:.4g} m: worst swing {best['worst_swing_um']:.1f} um "
          f"(model's l4 = {first[0]:.4g} m: {max(paper_swing.values()):.1f} um)")
    print(f"second tie bar at {top['l4_2']:.4g} m with l4 = {top['l4']:.4g} m: worst swing "
          f"{top['worst_swing_um']:.1f} um ({top['reduction_vs_one_bar']:.0%} below one bar)")
    return 0


TARGETS = {
    "beam": ("beam theory vs FE: K_i, K_C over l/l4 and beta, error table, series, report",
             _beam_arguments, run_beam),
    "design": ("tie-bar position minimising the 5-h swing of delta; a second tie bar above the arms",
               _design_arguments, run_design),
}
