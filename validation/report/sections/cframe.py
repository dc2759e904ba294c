"""C-frame section: the second machine of validation/examples/c_frame run as a case file, its
channels, the deformed frame at the end and its thermal drift (``gatetherm run``)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from gatetherm.validation.report.result import Figure, Result, from_dicts


def compute(ctx) -> Result:
    import gatetherm.validation
    from gatetherm.studies.run.case import load_case
    from gatetherm.studies.run.output import probe_summary
    from gatetherm.studies.run.scenario import run_scenario
    from gatetherm.studies.run.simulate import column
    from gatetherm.studies.run.timeseries import TimeSeries
    from gatetherm.validation.plots import save
    from gatetherm.validation.plots.field import draw_deformed
    from gatetherm.validation.plots.run import plot_channels
    from gatetherm.validation.report import drift

    case = load_case(Path(gatetherm.validation.__path__[0]) / ctx.scope["case"])
    schedule = case.schedule
    run = run_scenario(case, schedule, keep_times=[float(schedule.times[-1])])
    save(plot_channels(run.columns, case.name), ctx.work / "channels.png", tight=False)
    save(draw_deformed(run, float(run.columns["time_s"][-1]), lambda t: f"{case.name}, t = {t / 3600:.3g} h"),
         ctx.work / "deformed.png")
    summary = probe_summary(case.problem, run.columns)
    probes = [{"probe": k, **v} for k, v in summary["probes"].items()]
    cols, t = run.columns, run.columns["time_s"]
    rel = [{"output": f"{k} [µm]", "at the end": v,
            "largest |value|": float(np.max(np.abs(cols[column(case.problem, ("relative", k))[0]])))}
           for k, v in summary["relative"].items()]
    dr = drift.compute(TimeSeries(cols), ctx.work, f"{case.name}: thermal drift")
    notes = (f"{case.name}: {len(case.mesh.points)} nodes, {len(t) - 1} steps of {t[1] - t[0]:g} s over "
             f"{t[-1] / 3600:g} h.",) + dr.notes[1:-1]
    return Result(tables=(from_dicts("Relative displacements (tool against table)", rel),
                          from_dicts("Probes at the end of the run", probes), *dr.tables[:1]),
                  figures=(Figure("channels.png", "Every temperature and displacement of the run against time"),
                           Figure("deformed.png", "Temperature on the deformed C-frame at the end of the run"),
                           *dr.figures), notes=notes)
