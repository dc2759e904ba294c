"""``gatetherm simulate``: run a paper condition or a schedule file through the FE model."""
from __future__ import annotations

import logging
import sys
import time
from pathlib import Path

import numpy as np

from gatetherm.studies.cli.mesh import add_model_options

log = logging.getLogger(__name__)


def register(sub) -> None:
    p = sub.add_parser("simulate", help="simulate a heating condition; write time series, fields, plots")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--condition", type=int, metavar="N", help="the paper's condition 1, 2 or 3")
    src.add_argument("--schedule", metavar="FILE.csv",
                     help="inputs (time_s, oil_degC, pump[, ambient_degC]) in the gatetherm time-series format")
    add_model_options(p)
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.add_argument("--fields-every", type=float, default=60.0, metavar="MIN",
                   help="write temperature/displacement fields every MIN minutes (default 60)")
    p.add_argument("--effect", action="append", default=[], metavar="NAME:PARAM=VALUE",
                   help="switch on a catalogue effect (see 'gatetherm diagnose --list-effects')")
    p.add_argument("--no-pictures", action="store_true", help="skip the PNG plots and the 3-D picture")
    p.set_defaults(func=run)


class Progress:
    """A one-line bar on a terminal; silent otherwise (logs stay clean)."""

    def __init__(self, label: str, stream=None):
        self.label, self.stream = label, stream or sys.stderr
        self.on = self.stream.isatty()

    def __call__(self, i: int, n: int) -> None:
        if not self.on:
            return
        k = int(30 * i / n)
        self.stream.write(f"\r{self.label} [{'#' * k}{'.' * (30 - k)}] {i}/{n}")
        if i == n:
            self.stream.write("\n")
        self.stream.flush()


def resolve_drive(args, cfg):
    """The schedule (drive), its name and its length in seconds, validated before any work."""
    from gatetherm.studies.run.conditions import condition, condition_drive, table_drive

    if args.schedule:
        from gatetherm.studies.run.timeseries import INPUT_COLUMNS, read_timeseries

        ts = read_timeseries(args.schedule, required=INPUT_COLUMNS)
        amb = ts["ambient_degC"] if "ambient_degC" in ts else None
        t = ts.time_s - ts.time_s[0]
        return (table_drive(t, ts["oil_degC"], ts["pump"], amb, cfg.supply.T_room),
                f"schedule {args.schedule}", float(t[-1]))
    cond = condition(args.condition)
    return condition_drive(cond, cfg.supply), f"condition {args.condition}: {cond.name}", cond.duration


def run(args) -> int:
    from gatetherm.studies.run.config import load_config
    from gatetherm.solvers.effects import ActiveEffects, apply_effects, parse_effect_options

    cfg = load_config(args.config)
    effects = ActiveEffects({**cfg.effects, **parse_effect_options(args.effect).values})  # file, then CLI
    drive, label, duration = resolve_drive(args, cfg)
    out = Path(args.out)
    t_start = time.perf_counter()
    model_cfg, drive = apply_effects(cfg.model, drive, effects, args.dim)
    from gatetherm.solvers.model import build_model
    from gatetherm.studies.run.simulate import delta_figures, run_model, sample_times

    model = build_model(model_cfg, args.dim)
    t_built = time.perf_counter()
    times = sample_times(duration)
    every = max(args.fields_every, 1.0) * 60.0
    field_times = {float(t) for t in times if t % every < 1e-6}
    keep = sorted(field_times | {float(t) for t in times if t % 300.0 < 1e-6})  # + picture candidates
    res = run_model(model, drive, times, keep, Progress(f"condition {args.condition or 'file'}"))
    cols = effects.observe(res.columns)
    figs = delta_figures(cols["time_s"], cols["delta_um"])
    _write_outputs(args, cfg, model, res, cols, figs, label, out, field_times)
    summary = {**figs, "wall_time_s": round(time.perf_counter() - t_start, 2),
               "build_s": round(t_built - t_start, 2), "march_s": round(res.seconds, 2),
               "dim": args.dim, "nodes": len(model.fmesh.points), "elements": len(model.fmesh.cells),
               "schedule": label, "config": cfg.source, "effects": effects.describe()}
    from gatetherm.studies.run.output import write_json

    write_json(out / "summary.json", summary)
    print(f"wrote {out}/timeseries.csv, summary.json, fields/ and plots")
    print("first peak {first_peak_um} µm at {first_peak_min} min, swing {swing_um} µm, wall time {w} s"
          .format(**{k: (round(v, 2) if isinstance(v, float) else v) for k, v in figs.items()},
                  w=summary["wall_time_s"]))
    return 0


def _write_outputs(args, cfg, model, res, cols, figs, label, out: Path, field_times) -> None:
    from gatetherm.studies.run.output import pyvista_grid, write_fields
    from gatetherm.studies.run.timeseries import FORMAT, TimeSeries, write_timeseries

    meta = {"format": FORMAT, "source": "gatetherm simulate", "schedule": label,
            "dim": str(args.dim), "config": cfg.source}
    if args.condition:
        meta["condition"] = str(args.condition)
    write_timeseries(out / "timeseries.csv", TimeSeries(cols, meta))
    states = [(t, U) for t, U in res.states if t in field_times]
    write_fields(model, states, out / "fields")
    if args.no_pictures:
        return
    from gatetherm.validation.plots.run import plot_oil, plot_response, render_deformed

    title = f"gatetherm {args.dim}-D, " + (f"condition {args.condition}" if args.condition else Path(args.schedule).name)
    plot_oil(cols, out / "oil_temperatures.png", title)
    plot_response(cols, out / "response.png", title)
    t_pic = (figs["first_peak_min"] or 60.0) * 60.0
    t, U = min(res.states, key=lambda s: abs(s[0] - t_pic))
    grid = pyvista_grid(model, U)
    umax = float(np.abs(grid["u"]).max()) or 1.0
    scale = float(10 ** np.floor(np.log10(0.08 * max(grid.bounds[1] - grid.bounds[0], 1e-9) / umax)))
    render_deformed(grid, out / "deformed.png", f"{title}, t = {t / 60:.0f} min", scale)
