"""Compensation beside a machine over OPC UA, and a virtual machine to test it on (:mod:`gatetherm.api`)."""
from __future__ import annotations

import asyncio
import dataclasses
import logging
import os
from pathlib import Path
from typing import Mapping

from gatetherm.api.run import PATH, Case, Schedule
from gatetherm.api.run import _case as _a_case
from gatetherm.checks import argument
from gatetherm.solvers.rom import ReducedModel
from gatetherm.studies.errormodel.fitted import ErrorModel
from gatetherm.validation.live.monitor import Monitor
from gatetherm.validation.live.service import Guards

PUBLIC = ("live", "twin")  # offered as gt.NAME (gatetherm.api finds them here)

log = logging.getLogger(__name__)

SENSORS = ("theta_A_degC", "theta_B_degC", "theta_C_degC", "delta_um")
"""What the twin measures besides the schedule's inputs: the data format's channels."""


def _schedule(case: Case, schedule):
    from gatetherm.api.run import schedule_file

    if schedule is None:
        if case.time is None:
            from gatetherm import InputError

            raise InputError(f"{case.source}: [time]", "the case has no schedule", "give --schedule S.csv")
        return case.schedule
    return schedule if hasattr(schedule, "drive") else schedule_file(schedule, case)


def twin(case: Case | str | Path, endpoint: str, speed: float = 1.0, *,
         schedule: Schedule | str | os.PathLike | None = None, until: float | None = None, start: float = 0.0,
         states: int = 30, rom: ReducedModel | None = None, seed: int = 0, actuator: bool = False, stopped=None,
         **noise) -> dict:
    """Serve a virtual machine over OPC UA: the case's reduced model in ``speed``× real time.

    Parameters
    ----------
    case : Case or path
        The machine: its reduced model (built with ``states`` states unless ``rom`` is given), its
        schedule and its [signals] (θ_A, θ_B, θ_C, δ). A path is read once the other arguments are
        checked.
    endpoint : str
        ``opc.tcp://HOST:PORT`` to serve on.
    speed : float
        Machine seconds per wall second.
    schedule : Schedule or path, optional
        The inputs (default: the case's own schedule).
    until, start : float
        Machine time to stop at (default: the schedule's end) and to start serving at, s.
    seed : int
        Seed of the sensor noise.
    actuator : bool
        Apply the correction through the case's ``[actuator]`` (its piezo model: reach, hysteresis,
        strategy) instead of as an ideal axis offset.
    stopped : callable, optional
        Returns True when the twin should stop (checked every step).
    **noise
        Fields of :class:`gatetherm.validation.live.twin.TwinParams` (``noise_K``, ``resolution_K``,
        ``noise_um``, ``resolution_um``, ``step_s``, ``wait``: start the clock once a client has written
        (every machine's client), ``faults``: (column, from_s, to_s) read as NaN, ``machines``: machines
        served by this process, machine i in namespace ``urn:gatetherm:machine:i``, a sample each
        ``step_s`` spread evenly over the step; docs/live.md).

    Returns
    -------
    dict
        ``served`` samples (all machines), ``machines``, ``start_s``, ``end_s``,
        ``compensated_band_after_10_min_um`` (µm, the twin's true δ with the correction applied; the
        largest over the machines), ``clock_start_unix_s`` and ``publish_lag_ms`` (median, p95, max
        of a sample's publication behind its wall time, ms).
    """
    import math

    from gatetherm import InputError
    from gatetherm.studies.run.reduce import build_rom
    from gatetherm.validation.live.twin import TwinParams, endpoint_url, serve

    endpoint_url(endpoint)
    params = TwinParams(speed=speed, start_s=start, until_s=until, seed=seed, **noise)
    if rom is None and not 2 <= states <= 200:
        raise InputError("--states", f"{states} is outside 2..200", "e.g. --states 30")
    if until is not None and not math.isfinite(until):
        raise InputError("--until", "must be a finite number of seconds", "e.g. --until 21600")
    case = _case(case)
    if actuator and case.actuator is None:
        raise InputError(f"{case.source}: [actuator]", "the case has none", "add one, or apply the ideal offset")
    sched = _schedule(case, schedule)
    rom = rom or build_rom(case, states).rom
    for note in rom.notes:  # the twin's machine is that reduced model
        log.warning("%s", note)
    published = tuple(n for n in SENSORS if n in rom.outputs)
    return asyncio.run(serve(rom, sched, endpoint, params, published, stopped, case.actuator if actuator else None))


def _case(case) -> Case:
    """``case``, read if it is a path; else it must be a Case."""
    if isinstance(case, (str, Path)):
        from gatetherm.api.run import load_case

        return load_case(case)
    return _a_case(case)


def _stepper(case, method, model, target, params, states, out, sched, axis=None):
    """The step-wise compensator of ``method`` (:mod:`gatetherm.studies.control.method`), or of the
    error model ``model``, and its label."""
    from gatetherm import InputError
    from gatetherm.studies.control import method as methods

    setup = methods.Setup(case, params, states, out, sched, target=target)
    if model is not None:
        from gatetherm.studies.errormodel.model import load_model

        m = load_model(model) if isinstance(model, (str, Path)) else model
        if axis is not None:
            from gatetherm.studies.control.stepwise import error_model_stepper
            from gatetherm.validation.live.axis import AxisStepper

            probes = {k: error_model_stepper(m, m.target(k).target, params) for k in axis.positions_m}
            return AxisStepper(probes, axis), f"errormodel {model} along an axis ({len(probes)} probes)"
        return methods.get("errormodel").stepper(dataclasses.replace(setup, model=m))[0], f"errormodel {model}"
    if axis is not None:
        raise InputError("--axis", f"the {method} method gives delta at one point, not along an axis",
                         "give a --model with a target per probe, or leave --axis out (offset only)")
    offered = methods.offered(stepwise=True)
    if method not in offered:
        raise InputError("--method", f"unknown method {method!r}", f"choose {methods.either(offered)}, or give --model")
    if case is None:
        raise InputError("--case", f"the {method} method needs the machine's case", "give --case CASE.toml")
    return methods.get(method).stepper(setup)


def live(case: Case | str | Path | None = None, method: str = "rom", *, endpoint: str, out: str | os.PathLike,
         model: ErrorModel | str | os.PathLike | None = None, target: str | None = None,
         map: str | os.PathLike | None = None, period: float = 60.0, update: float | None = None,
         until: float | None = None, states: int = 30, schedule: Schedule | str | os.PathLike | None = None,
         guards: Guards | None = None, monitor: Monitor | Mapping | None = None,
         axis: dict | None = None, reference: float | None = None, status_port: int | None = None,
         on_period=None, on_ready=None, poll: float = 0.05) -> dict:
    """Compensate a machine over OPC UA: read its sensors every period of its clock, write the correction.

    Parameters
    ----------
    case : Case or path, optional
        The machine's case (methods ``paper``, ``mlr``, ``rom``; not needed with ``model``); a path
        is read once the endpoint is checked.
    method : str
        ``"paper"``, ``"mlr"`` or ``"rom"``.
    endpoint : str
        The control's OPC UA server, ``opc.tcp://HOST:PORT``.
    out : path
        Directory of ``live.csv``, ``state.json``, ``events.log``, ``summary.json`` and the lock; a
        run into the directory of an earlier one resumes it.
    model : path or ErrorModel, optional
        A thermal-error model (``gatetherm errormodel fit``) instead of ``method``; ``target`` its channel.
    map : path, optional
        A map file of the control's node ids (docs/live.md); default the twin's layout.
    period : float
        Compensator period on the machine's clock, s.
    update : float, optional
        Command update interval, s (a multiple of ``period``; default 300 s where it is one, else ``period``).
    until : float, optional
        Machine time to stop after, s.
    states : int
        ``rom``: states of the reduced model (kept in ``out``).
    schedule : Schedule or path, optional
        ``rom``: the inputs known in advance (default the case's schedule).
    guards : Guards, optional
        :class:`gatetherm.validation.live.service.Guards` (defaults in docs/live.md).
    monitor : Monitor or dict, optional
        The never-worse monitor, :class:`gatetherm.validation.live.monitor.Monitor` or a dict of its
        fields (default: a window of 30 periods, a margin of 1 µm, fallback ``"zero"``; docs/live.md).
    axis : dict, optional
        With ``model``: target channel -> its probe's position along the axis, m (two or more). The
        offset is then written at the reference position with a gradient along the axis
        (``gradient_um_per_m``, ``reference_m``); without, the offset only.
    reference : float, optional
        The reference position s0 of the offset, m (default the smallest probe position).
    status_port : int, optional
        Serve the status page on ``http://127.0.0.1:PORT/`` (``/status.json``: the same as data).
    on_period : callable, optional
        Called with each period's logged row (a dict).
    on_ready : callable, optional
        Called once the model is built and the directory locked, before connecting.
    poll : float
        Wall time between two reads while waiting for the next period, s (a sample is seen at most
        this late; each read is a request to the control).

    Returns
    -------
    dict
        The counts (``periods``, ``missed``, ``held``, ``limited``, ``reconnects``, ``restarts``,
        ``worse``: periods after a worse verdict), ``monitor`` (the verdict or None), the rows logged and ``compensated_band_um`` where the machine reports its compensated δ; also
        written to ``out/summary.json``.
    """
    import os

    from gatetherm.studies.control.compensator import CompensatorParams
    from gatetherm.validation.live import journal as jr, service
    from gatetherm.validation.live.nodes import default_map, read_map
    from gatetherm.validation.live.runner import serve_until_signal
    from gatetherm.validation.live.twin import endpoint_url

    from gatetherm import InputError
    from gatetherm.validation.live.axis import Axis

    endpoint_url(endpoint)
    if status_port is not None and not 1 <= status_port <= 65535:
        raise InputError("--status-port", f"{status_port} is not a port 1..65535", "e.g. --status-port 8080")
    if model is None and case is None:
        raise InputError("--case/--model", "give the machine's case (or a fitted model)", "e.g. --case case.toml")
    guards = guards or service.Guards()
    monitor = Monitor(**monitor) if isinstance(monitor, Mapping) else monitor or Monitor()
    params = service.LiveParams(period_s=float(period), until_s=until, guards=guards, poll_s=poll, monitor=monitor)
    service.check(params)
    if not (isinstance(poll, (int, float)) and 0 < poll < 60):
        raise InputError("poll", f"must be a wall time in s in (0, 60), got {poll!r}", "e.g. poll=0.05")
    axis = Axis(dict(axis), reference) if axis else None
    if axis is not None and model is None:
        raise InputError("--axis", "needs a fitted --model with a target per probe",
                         "give --model, or leave --axis out (offset only)")
    case = _case(case) if case is not None else None
    every = update if update is not None else (300.0 if abs(300.0 / period - round(300.0 / period)) < 1e-9
                                               and period <= 300.0 else period)
    cp = CompensatorParams(sample_interval_s=float(period), update_interval_s=float(every))
    out = Path(argument("out", out, PATH, "a folder's path"))
    fd = jr.lock(out)
    try:
        sched = _schedule(case, schedule) if case is not None else None
        stepper, label = _stepper(case, method, model, target, cp, states, out, sched, axis)
        required = tuple(stepper.columns)
        if map is None:
            extras = tuple(sorted(case.inputs())) if case is not None else ()
            nodes = default_map((*extras, *required, "delta_residual_um"), gradient=axis is not None)
        else:
            nodes = read_map(map, required)
        read = tuple(n for n in nodes.read if n != "time_s")
        columns = ("time_s", *read, "offset_um", "offset_wanted_um", "delta_forecast_um", "held", "limited", "worse",
                   *(("gradient_um_per_m", "reference_m") if axis is not None else ()))
        journal = jr.Journal(out, columns, {"source": "gatetherm live", "method": label, "endpoint": endpoint,
                                            "period_s": f"{period:g}"})
        if on_ready is not None:
            on_ready()
        try:
            counts = asyncio.run(serve_until_signal(stepper, journal, endpoint, nodes, params, read, on_period,
                                                    status_port))
        finally:
            journal.close()
        return jr.summarize(out, counts)
    finally:
        os.close(fd)
