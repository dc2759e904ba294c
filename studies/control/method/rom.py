"""The ``rom`` method: a Kalman filter on the case's reduced model and predictive control
(:mod:`..predictive`); step-wise :class:`~gatetherm.studies.control.stepwise_rom.RomStepper`."""
from __future__ import annotations

import dataclasses
import logging
from pathlib import Path

from gatetherm import InputError
from gatetherm.studies.control.method import Batch, Job, Method, Setup

log = logging.getLogger(__name__)


def batch(job: Job) -> Batch:
    """The filter and the predictive control over the record (nothing fitted on it: the benefit as applied)."""
    from gatetherm.studies.control.compensator import NEEDED
    from gatetherm.studies.run.timeseries import validate_complete

    validate_complete(job.ts, NEEDED)
    loop, extra, label = _rom_loop(job)
    notes = (*extra.pop("rom_notes"), *((extra.pop("budget_warning"),) if extra.get("budget_warning") else ()))
    return Batch(loop, extra, label, f"rom ({label})",
                 (loop, "as applied (the reduced model and its causal Kalman filter fit nothing on the record)"),
                 notes=notes, model="the reduced model")


def _reduced_model(job: Job):
    """The reduced model given, or built from the case (kept in ``rom_dir``), and where it is from."""
    from gatetherm.studies.run.reduce import build_rom, cached_rom

    rom, where = job.rom, job.rom_source
    if rom is None:
        if job.case is None:
            raise InputError("--method rom", "needs a reduced model", "give --rom FILE or a model (--case)")
        if job.rom_dir is not None:
            rom, where = cached_rom(job.case, job.settings.states, job.rom_dir, job.cache), \
                str(Path(job.rom_dir) / "rom.npz")
        else:
            rom = build_rom(job.case, job.settings.states, job.cache).rom
    return rom, where


def _rom_loop(job: Job):
    """The rom method's closed loop, its summary entries and a label."""
    from gatetherm.solvers.expr import Value
    from gatetherm.studies.control.compensator import close_loop
    from gatetherm.studies.control.predictive import budget_warning, rom_prediction

    ts, s, actuator = job.ts, job.settings, job.actuator
    if not 2 <= s.states <= 200:
        raise InputError("--states", f"{s.states} is outside 2..200", "e.g. --states 30")
    if not s.sensors:
        raise InputError("--sensors", "no column named", "e.g. --sensors theta_A_degC,theta_B_degC")
    control = dataclasses.replace(s.control, interval_s=s.params.update_interval_s)
    rom, where = _reduced_model(job)
    missing = [n for n in ("delta_um", *s.sensors) if n not in rom.outputs]
    if missing:
        raise InputError(f"{where or 'reduced model'}: outputs", f"no {missing[0]!r}",
                         f"its outputs: {', '.join(rom.outputs[:12])}{' …' if len(rom.outputs) > 12 else ''}")
    read = set().union(*(Value.of(u.text).names() for u in rom.inputs), *(Value.of(p).names() for p in rom.pumps))
    lacking = sorted(read - {"t"} - set(ts.names) - set(rom.defaults))
    if lacking:
        raise InputError(f"{job.source}, column {lacking[0]}", f"missing: the reduced model {where or ''} reads it",
                         "record it, or give a reduced model of the inputs recorded")
    pr, cmds = rom_prediction(ts, rom, s.params, control, s.observer, s.sensors)
    loop = close_loop(ts, pr, s.params, actuator)
    extra = {"rom": where, "rom_states": rom.states, "sensors": list(s.sensors), "threshold_um": cmds.threshold_um,
             "predictive": dataclasses.asdict(control), "observer": dataclasses.asdict(s.observer),
             "budget_exhausted_s": None, "rom_notes": rom.notes}
    if cmds.exhausted_at is not None:
        extra["budget_exhausted_s"] = float(pr.t_s[cmds.exhausted_at])
        extra["budget_warning"] = budget_warning(loop.t_s, loop.delta_comp_um, extra["budget_exhausted_s"],
                                                 control.max_updates)
    how = f"threshold {cmds.threshold_um:.2f} um" if cmds.threshold_um is not None else \
        f"every {s.params.update_interval_s / 60:g} min"
    return loop, extra, f"reduced model ({rom.states} states), Kalman filter on {', '.join(s.sensors)}, {how}"


def stepper(setup: Setup):
    """The case's reduced model (kept in the service's folder) on the schedule's inputs, known in advance."""
    import numpy as np

    from gatetherm.studies.control.predictive import PredictiveParams
    from gatetherm.studies.control.stepwise_rom import RomStepper
    from gatetherm.studies.run.reduce import cached_rom
    from gatetherm.studies.run.timeseries import TimeSeries

    params, sched = setup.params, setup.schedule
    rom = cached_rom(setup.case, setup.states, setup.out)
    for note in rom.notes:  # a service: its log is what it says
        log.warning("%s", note)
    end = float(sched.times[-1])
    t = params.sample_interval_s * np.arange(int(np.floor(end / params.sample_interval_s + 1e-9)) + 1)
    rows = [dict(sched.drive(float(x))) for x in t]
    plan = TimeSeries({"time_s": t, **{k: np.array([r[k] for r in rows], float) for k in rows[0]}})
    control = PredictiveParams(interval_s=params.update_interval_s)
    return RomStepper(rom, plan, params, control), f"rom ({rom.states} states)"


METHOD = Method("rom", batch, stepper, order=30, summary="Kalman filter and predictive control on the reduced model",
                doc=__doc__)
