"""Sensor placement section: the paper frame's three chosen points next to its A, B and C mean
(held-out conditions 1-3), where they lie, the independent FE check, and the C-frame example's
held-out error against the number of sensors (``gatetherm sensors``)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from gatetherm.validation.report.result import Figure, Result, table

TIPS = ("F_L", "F_R")
"""The frame's tool and workpiece tips (probes), where a chosen point may lie."""


def _mm(v) -> str:
    return ", ".join(f"{1e3 * x:.0f}" for x in v)


def _relative(placement, probes) -> list[list[str]]:
    """Each chosen point: coordinates, boundary, the nearest of ``probes`` and the offset to it (mm)."""
    rows = []
    for s in placement.sensors:
        name, xyz = min(probes.items(), key=lambda kv: np.linalg.norm(np.subtract(s.xyz, kv[1])))
        d = np.subtract(s.xyz, xyz)
        rows.append([s.name, _mm(s.xyz), s.boundary, name, _mm(d), f"{1e3 * np.linalg.norm(d):.0f}"])
    return rows


def _delta(placement) -> float:
    return placement.curve[-1].held_out_mae_um["delta_um"]


def _errors(label, form, held, cv, targets) -> list[str]:
    return [label, form, *(f"{held[t]:.3g}" for t in targets), *(f"{cv[t]:.3g}" for t in targets)]


def compute(ctx) -> Result:
    import gatetherm.validation
    from gatetherm.studies.run.case import load_case
    from gatetherm.frame.case import gate_frame
    from gatetherm.frame.conditions import paper_conditions
    from gatetherm.studies.sensors.check import fe_check
    from gatetherm.studies.sensors.place import PlacementSettings, place_sensors
    from gatetherm.validation.plots import save
    from gatetherm.validation.plots.sensors import plot_curve, plot_machine

    sc = ctx.scope
    frame = gate_frame(2)
    by_seed = {seed: place_sensors(frame, PlacementSettings(count=sc["frame_count"], loads=sc["loads"], seed=seed),
                                   held_out=paper_conditions(frame)) for seed in sc["seeds"]}
    pf = by_seed[sc["seeds"][0]]
    paper = {p.name: p.xyz for p in frame.problem.probes if p.name in ("A", "B") or p.name.startswith("C")}
    marks = {**paper, **{p.name: p.xyz for p in frame.problem.probes if p.name in TIPS}}
    save(plot_machine(frame.mesh, pf, probes=paper).figure, ctx.work / "frame_sensors.png")
    check = fe_check(frame, pf)
    case = load_case(Path(gatetherm.validation.__path__[0]) / sc["case"])
    pc = place_sensors(case, PlacementSettings(count=sc["case_count"], loads=sc["loads"]), held_out=paper_conditions(case))
    named = {n for names in pc.signals["sensors"].values() for n in names}
    own = {p.name: p.xyz for p in case.problem.probes if p.name in named}
    save(plot_machine(case.mesh, pc, probes=own).figure, ctx.work / "cframe_sensors.png")
    save(plot_curve(pc).figure, ctx.work / "cframe_curve.png")

    targets = list(pf.curve[-1].held_out_mae_um)
    heads = ["sensors", "form", *(f"held-out {t} [µm]" for t in targets), *(f"leave-one-load-out {t} [µm]"
                                                                           for t in targets)]
    rows = [_errors(f"{c.count} chosen: " + ", ".join(s.name for s in c.sensors), c.form, c.held_out_mae_um,
                    c.cv_mae_um, targets) for c in pf.curve]
    sig = pf.signals
    rows.append(_errors("the paper's A, B and C mean (C1-C10)", sig["form"], sig["held_out_mae_um"], sig["cv_mae_um"],
                        targets))
    ours, theirs = pf.curve[-1].held_out_mae_um["delta_um"], sig["held_out_mae_um"]["delta_um"]
    answer = table("Paper frame, 2-D: chosen points against the paper's thermocouples, held out: conditions 1-3",
                   heads, rows,
                   note=f"Fitted on {len(pf.training)} generated duty cycles of the oil supply (20-40 °C) and the "
                        f"pump; sensor noise {pf.settings.noise_K:g} K on every thermocouple.")
    where = table("Where the chosen points lie (mm; the offset is from the nearest of A, B, C1-C10 and the tips "
                  "F_L (tool), F_R (workpiece))",
                  ["sensor", "x, y", "boundary", "nearest", "offset x, y", "distance"], _relative(pf, marks))
    seeds = table("Paper frame: the answer over seeds of the generated duty cycles and the sensor noise",
                  ["seed", "held-out δ, chosen [µm]", "held-out δ, A, B, C mean [µm]", "ratio", "chosen points (mm)"],
                  [[str(k), f"{_delta(q):.3g}", f"{q.signals['held_out_mae_um']['delta_um']:.3g}",
                    f"{_delta(q) / q.signals['held_out_mae_um']['delta_um']:.2f}",
                    "; ".join(f"{x.name} ({_mm(x.xyz)})" for x in q.sensors)] for k, q in by_seed.items()])
    ct = list(pc.curve[-1].held_out_mae_um)
    curve = table(f"C-frame example: held-out error against the number of sensors ({len(pc.held_out)} held-out "
                  "duty cycles)", ["sensors", "form", *(f"held-out {t} [µm]" for t in ct),
                                   *(f"leave-one-load-out {t} [µm]" for t in ct)],
                  [_errors(str(c.count), c.form, c.held_out_mae_um, c.cv_mae_um, ct) for c in pc.curve]
                  + [_errors("its TF, TB, TS", pc.signals["form"], pc.signals["held_out_mae_um"],
                             pc.signals["cv_mae_um"], ct)])
    worst = max(pf.failed, key=lambda k: pf.failed[k]["delta_um"])
    notes = (f"Paper frame: {len(pf.sensors)} points chosen from {len(pf.candidates)} surface nodes "
             f"({len(pf.shortlist)} screened) predict δ over conditions 1-3 to {ours:.3g} µm MAE, the same family "
             f"given A, B and the C mean to {theirs:.3g} µm ({ours / theirs:.2f} of it).",
             "FE check (separate full runs with probes at the chosen points, least squares on the training runs): "
             + ", ".join(f"{k} {v:.3g} µm ({check.ratio[k]:.3f} of the reduced model's)"
                         for k, v in check.held_out_mae_um.items())
             + f"; the chosen points' temperatures within {check.temperature_error_K:.2g} K of FE.",
             f"If {worst} fails, the model refitted on the other two predicts δ to {pf.failed[worst]['delta_um']:.3g} µm.",
             *(f"C-frame: {n}" for n in pc.notes), *([f"C-frame: {pc.stopped}"] if pc.stopped else []))
    return Result(tables=(answer, where, seeds, curve), notes=notes, figures=(
        Figure("frame_sensors.png", "Paper frame, 2-D: candidates (grey), screened (circles), the chosen points (red) "
                                    "and the paper's A, B, C1-C10 (blue)"),
        Figure("cframe_sensors.png", "C-frame example: the chosen points and the example's thermocouples TF, TB, TS"),
        Figure("cframe_curve.png", "C-frame example: held-out and leave-one-load-out MAE against the number of "
                                   "sensors; stars: the example's TF, TB, TS in the same family")))
