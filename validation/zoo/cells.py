"""The zoo's cells: each capability on one machine, through the functions its command calls.

Each ``cell_*`` takes the machine's :class:`~gatetherm.validation.zoo.Context` and returns
``(value, one line)`` or raises (an ``InputError`` is a refusal); what each value is:
:mod:`gatetherm.validation.zoo`.
"""
from __future__ import annotations


import numpy as np

from gatetherm import InputError, write_text_atomic
from gatetherm.validation.zoo.context import CCX_TOLERANCE, TIMEOUT_S, Context, _band, _one_line, _transient

def cell_run(ctx: Context):
    x, name = ctx.columns[ctx.delta], ctx.delta
    temps = [c for c in ctx.columns if c.endswith("_degC") and c != "ambient_degC"]
    tmax = max(float(np.nanmax(ctx.columns[c])) for c in temps) if temps else float("nan")
    if _transient(ctx):
        v = float(np.nanmax(x) - np.nanmin(x))
        return v, (f"{name} swing {v:.3g} µm over {ctx.columns['time_s'][-1] / 3600:g} h, hottest probe "
                   f"{tmax:.2f} °C")
    v = float(x[-1])
    return v, f"steady {name} = {v:.4g}, hottest probe {tmax:.2f} °C"


def cell_reduce(ctx: Context):
    from gatetherm.studies.run.reduce import build_rom, check as check_rom
    from gatetherm.studies.run.scenario import ScenarioCache

    red = build_rom(ctx.case)  # its default states, as `gatetherm reduce`
    (check,) = check_rom(ctx.case, red.rom, [ctx.case.schedule], ScenarioCache())
    err = check.errors.get(ctx.delta)
    if err is None:
        raise RuntimeError(f"the check has no {ctx.delta}")
    worst = max((v for k, v in check.errors.items() if k.endswith("_degC")), default=float("nan"))
    return float(err), (f"{red.rom.states if hasattr(red.rom, 'states') else 'default'} states: {ctx.delta} within "
                        f"{err:.3g} µm of FE, temperatures within {worst:.3g} K")


def _compensated(ctx: Context, comp):
    s = comp.summary
    loop = comp.loop
    unc = _band(loop.t_s, loop.delta_um)
    res = s["residual_band_um"]
    verdict = "better" if res < unc else "WORSE, no refusal" if res > unc else "same"
    return float(res), f"residual band {res:.3g} µm vs {unc:.3g} µm uncompensated ({verdict})"


def _cell_method(method: str):
    def cell(ctx: Context):
        from gatetherm.studies.control.methods import Settings, compensate, compensated_case

        return _compensated(ctx, compensate(ctx.series, compensated_case(ctx.case), Settings(method=method),
                                            ctx.case.actuator))
    cell.__name__ = f"cell_{method}"
    return cell


def _errormodel_fit(ctx: Context, start: float, end: float):
    from gatetherm.studies.errormodel.fit import FitParams, fit_error_model, fraction_span

    ts = ctx.series
    drive = getattr(ctx.case.schedule.drive, "columns", ())  # a steady case's drive has no columns
    candidates = [c for c in ts.names if c.endswith("_degC") and c not in drive]
    inputs = [c for c in drive if c in ts.names]
    span = fraction_span(ts.time_s, start, end)
    return ts, fit_error_model(ts, [ctx.delta], candidates, inputs, FitParams(), span, source="zoo"), span


def cell_errormodel_comp(ctx: Context):
    from gatetherm.studies.control.methods import Settings, compensate

    ts, model, _ = _errormodel_fit(ctx, 0.0, 0.5)
    return _compensated(ctx, compensate(ts, ctx.case, Settings(method="errormodel", model=model), ctx.case.actuator))


def cell_errormodel(ctx: Context):
    from gatetherm.studies.errormodel.model import predict

    ts, model, span = _errormodel_fit(ctx, 0.0, 0.6)
    pred = predict(model, ts)[ctx.delta]
    later = ts.time_s > span[1]
    r = np.asarray(ts[ctx.delta])[later] - pred[later]
    rms = float(np.sqrt(np.nanmean(r ** 2)))
    m = model.targets[0]
    return rms, (f"{m.form} form on {', '.join(m.sensors) or 'no sensor'}: held-out RMS {rms:.3g} µm "
                 f"(fit RMS {m.residual['rms_um']:.3g} µm)")


def cell_sweep(ctx: Context):
    from gatetherm.studies.sweeps.runner import PointStore, run_studies
    from gatetherm.studies.sweeps.studyfile import load_study
    from gatetherm.studies.sweeps.sweep import plan, table

    key, values = ctx.machine.sweep
    folder = ctx.out / "sweep"
    folder.mkdir(parents=True, exist_ok=True)
    study_file = folder / "study.toml"
    write_text_atomic(study_file, f'[study]\nname = "zoo sweep of {ctx.machine.folder}"\n'
                                  f'case = "{ctx.machine.case_path.as_posix()}"\n\n'
                                  f'[grid]\n"{key}" = [{values[0]!r}, {values[1]!r}]\n')
    study = load_study(study_file)
    tasks = plan(study)
    (records,), failed = run_studies([(tasks, PointStore(folder))], 1, None)
    if failed:
        raise RuntimeError(f"{len(failed)} of {len(tasks)} points failed: {_one_line(str(failed[0]))}")
    columns, rows = table(tasks, records, study.columns)
    stem = ctx.delta.removesuffix("_um")
    col = "swing_um" if "swing_um" in columns else f"{stem}_final_um" if f"{stem}_final_um" in columns \
        else next(c for c in columns if c.endswith(("_um", "_degC")) and c not in (key,))
    a, b = float(rows[0][col]), float(rows[1][col])
    return b - a, f"{col} {a:.4g} → {b:.4g} over {key} {values[0]:g} → {values[1]:g}"


def _on_moving(ctx: Context, node: int) -> bool:
    mesh = ctx.case.mesh
    for name in ctx.machine.moving:
        cells = mesh.cells[mesh.regions[name]] if name in mesh.regions else np.empty((0, 0), int)
        if np.isin(node, cells):
            return True
    return False


def cell_sensors(ctx: Context):
    from gatetherm.studies.sensors.place import PlacementSettings, place_sensors

    p = place_sensors(ctx.case, PlacementSettings(count=3, loads=8, held_out_loads=3, states=20))
    target = ctx.delta
    got = p.curve[-1]
    placed = got["held_out_mae_um"][target] if isinstance(got, dict) else got.held_out_mae_um[target]
    designer = None
    if p.signals is not None:
        s = p.signals
        designer = s["held_out_mae_um"][target] if isinstance(s, dict) else s.held_out_mae_um[target]
    moving = sum(_on_moving(ctx, s.node) for s in p.sensors)
    where = ", ".join(f"{s.boundary}" for s in p.sensors)
    return float(placed), (f"{len(p.sensors)} placed (on {where}): held-out MAE {placed:.3g} µm; "
                           + (f"designer's θ_A, θ_B, θ_C: {designer:.3g} µm; " if designer is not None else "")
                           + f"{moving} on a moving part")


def cell_diagnose(ctx: Context):
    from gatetherm.studies.diagnosis.discrepancy import Settings, diagnose
    from gatetherm.validation.case_diagnosis import hidden, measured_run

    m = ctx.machine
    if not m.hidden:
        raise InputError(f"{m.case_path}", "the zoo hides nothing in this case (no source to strengthen)",
                         "give the machine a hidden piece in validation/zoo.py")
    values = hidden(ctx.case, {m.hidden: m.factor})
    if not _transient(ctx):  # no record to make: the library's word on the steady run itself
        diagnose(ctx.case, ctx.series, Settings(max_pieces=2))
    ts = measured_run(ctx.case, values, 51, m.folder)
    d = diagnose(ctx.case, ts, Settings(max_pieces=2))
    named = {r.piece.label: r for r in d.pieces}
    fitted = d.summary()["fitted"]
    value = next((float(v) for k, v in fitted.items() if m.hidden in k), float("nan"))
    others = [k for k in named if k != m.hidden]
    ok = m.hidden in named and not others
    return value, (f"{d.verdict}; named {', '.join(named) or 'nothing'} (hidden {m.hidden} ×{m.factor:g}"
                   f"{', found alone' if ok else ', NOT found alone'}); {d.runs} runs, {d.seconds:.0f} s")


def cell_report(ctx: Context):
    from gatetherm.studies.run.timeseries import TimeSeries
    from gatetherm.validation.report.drift import check_record, compute

    ts = ctx.series
    if not isinstance(ts, TimeSeries):
        raise RuntimeError("no time series")
    check_record(ts, f"{ctx.machine.folder} run")
    folder = ctx.out / "report"
    folder.mkdir(parents=True, exist_ok=True)
    result = compute(ts, folder, "timeseries.csv")
    x = np.asarray(ts[ctx.delta], float)
    drift = float(np.nanmax(np.abs(x - x[np.isfinite(x)][0])))
    return drift, f"drift report: largest drift of {ctx.delta} {drift:.3g} µm, {len(result.notes)} notes"


def cell_ccx(ctx: Context):
    from gatetherm.studies.run.ccx import export_state, run_ccx

    case, schedule = ctx.case, ctx.case.schedule
    t = float(schedule.times[-1])
    inp, info = export_state(case, schedule, t, f"gatetherm zoo {ctx.machine.folder}, t = {t / 60:g} min")
    folder = ctx.out / "ccx"
    folder.mkdir(parents=True, exist_ok=True)
    write_text_atomic(folder / "job.inp", inp)
    ccx = run_ccx(folder, info, timeout=TIMEOUT_S)["relative_m"]
    rel = {k: ccx[k] / g - 1.0 for k, g in info["relative_m"].items() if g}
    worst = max(rel, key=lambda k: abs(rel[k]))
    v = 100.0 * abs(rel[worst])
    return v, (f"{worst}: gatetherm {info['relative_m'][worst] * 1e6:.4g} µm, CalculiX {ccx[worst] * 1e6:.4g} µm "
               f"({'within' if v <= 100 * CCX_TOLERANCE else 'OUTSIDE'} 0.5 %)")


CELLS = {"run": cell_run, "reduce": cell_reduce, "paper": _cell_method("paper"), "mlr": _cell_method("mlr"),
         "rom": _cell_method("rom"), "errormodel comp": cell_errormodel_comp, "sweep": cell_sweep,
         "sensors": cell_sensors, "diagnose": cell_diagnose, "errormodel": cell_errormodel, "report": cell_report,
         "export ccx": cell_ccx}


