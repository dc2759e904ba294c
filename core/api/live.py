"""Compensation beside a machine over OPC UA, and a virtual machine to test it on (:mod:`gatetherm.api`)."""
from __future__ import annotations

import asyncio
import contextlib
import logging
import signal
import threading
from pathlib import Path

import numpy as np

from gatetherm.api.run import PATH, Case, _case
from gatetherm.checks import argument

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


def twin(case: Case, endpoint: str, speed: float = 1.0, *, schedule=None, until: float | None = None,
         start: float = 0.0, states: int = 30, rom=None, seed: int = 0, actuator: bool = False, stopped=None,
         **noise) -> dict:
    """Serve a virtual machine over OPC UA: the case's reduced model in ``speed``× real time.

    Parameters
    ----------
    case : Case
        The machine: its reduced model (built with ``states`` states unless ``rom`` is given), its
        schedule and its [signals] (θ_A, θ_B, θ_C, δ).
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
        ``noise_um``, ``resolution_um``, ``step_s``, ``wait``: start the clock once a client has written,
        ``faults``: (column, from_s, to_s) read as NaN).

    Returns
    -------
    dict
        ``served`` samples, ``start_s``, ``end_s`` and ``compensated_band_after_10_min_um`` (µm,
        the twin's true δ with the correction applied).
    """
    from gatetherm.studies.run.reduce import build_rom
    from gatetherm.validation.live.twin import TwinParams, serve

    _case(case)
    params = TwinParams(speed=speed, start_s=start, until_s=until, seed=seed, **noise)
    if actuator and case.actuator is None:
        from gatetherm import InputError

        raise InputError(f"{case.source}: [actuator]", "the case has none", "add one, or apply the ideal offset")
    sched = _schedule(case, schedule)
    rom = rom or build_rom(case, states).rom
    published = tuple(n for n in SENSORS if n in rom.outputs)
    return asyncio.run(serve(rom, sched, endpoint, params, published, stopped, case.actuator if actuator else None))


def _stepper(case, method, model, target, params, states, out, sched):
    from gatetherm import InputError
    from gatetherm.studies.control.methods import METHODS, Settings, coefficients
    from gatetherm.studies.control.predictive import PredictiveParams
    from gatetherm.studies.control.regression import THETAS, fit_regression
    from gatetherm.studies.control.stepwise import PaperStepper, RegressionStepper, error_model_stepper
    from gatetherm.studies.run.scenario import run_scenario
    from gatetherm.studies.run.timeseries import TimeSeries

    if model is not None:
        from gatetherm.studies.errormodel.model import load_model
        from gatetherm.studies.errormodel.replay import loop_target

        m = load_model(model) if isinstance(model, (str, Path)) else model
        return error_model_stepper(m, loop_target(m, target), params), f"errormodel {model}"
    if method not in METHODS[:3]:
        raise InputError("--method", f"unknown method {method!r}", "choose paper, mlr or rom, or give --model")
    if case is None:
        raise InputError("--case", f"the {method} method needs the machine's case", "give --case CASE.toml")
    if method == "rom":
        from gatetherm.studies.control.stepwise_rom import RomStepper
        from gatetherm.studies.run.reduce import cached_rom

        rom = cached_rom(case, states, out)
        end = float(sched.times[-1])
        t = params.sample_interval_s * np.arange(int(np.floor(end / params.sample_interval_s + 1e-9)) + 1)
        rows = [dict(sched.drive(float(x))) for x in t]
        plan = TimeSeries({"time_s": t, **{k: np.array([r[k] for r in rows], float) for k in rows[0]}})
        control = PredictiveParams(interval_s=params.update_interval_s)
        return RomStepper(rom, plan, params, control), f"rom ({rom.states} states)"
    run = run_scenario(case).series({})
    if method == "paper":
        ki, kc, source = coefficients(case, run, Settings())
        return PaperStepper(ki, kc, params), f"paper (K_i {ki:.4g}, K_C {kc:.4g} um/K, {source})"
    return RegressionStepper(fit_regression(run, THETAS), params), "mlr"


def live(case: Case | None = None, method: str = "rom", *, endpoint: str, out, model=None, target: str | None = None,
         map=None, period: float = 60.0, update: float | None = None, until: float | None = None,
         states: int = 30, schedule=None, guards=None, status_port: int | None = None, on_period=None,
         on_ready=None) -> dict:
    """Compensate a machine over OPC UA: read its sensors every period of its clock, write the correction.

    Parameters
    ----------
    case : Case, optional
        The machine's case (methods ``paper``, ``mlr``, ``rom``; not needed with ``model``).
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
    status_port : int, optional
        Serve the status page on ``http://127.0.0.1:PORT/`` (``/status.json``: the same as data).
    on_period : callable, optional
        Called with each period's logged row (a dict).
    on_ready : callable, optional
        Called once the model is built and the directory locked, before connecting.

    Returns
    -------
    dict
        The counts (``periods``, ``missed``, ``held``, ``limited``, ``reconnects``, ``restarts``), the
        rows logged and ``compensated_band_um`` where the machine reports its compensated δ; also
        written to ``out/summary.json``.
    """
    import os

    from gatetherm.studies.control.compensator import CompensatorParams
    from gatetherm.validation.live import journal as jr, service
    from gatetherm.validation.live.nodes import default_map, read_map
    from gatetherm.validation.live.twin import endpoint_url

    endpoint_url(endpoint)
    guards = guards or service.Guards()
    params = service.LiveParams(period_s=float(period), until_s=until, guards=guards)
    service.check(params)
    every = update if update is not None else (300.0 if abs(300.0 / period - round(300.0 / period)) < 1e-9
                                               and period <= 300.0 else period)
    cp = CompensatorParams(sample_interval_s=float(period), update_interval_s=float(every))
    out = Path(argument("out", out, PATH, "a folder's path"))
    fd = jr.lock(out)
    try:
        sched = _schedule(case, schedule) if case is not None else None
        stepper, label = _stepper(case, method, model, target, cp, states, out, sched)
        required = tuple(stepper.columns)
        if map is None:
            extras = tuple(sorted(case.inputs())) if case is not None else ()
            nodes = default_map((*extras, *required, "delta_residual_um"))
        else:
            nodes = read_map(map, required)
        read = tuple(n for n in nodes.read if n != "time_s")
        columns = ("time_s", *read, "offset_um", "offset_wanted_um", "delta_forecast_um", "held", "limited")
        journal = jr.Journal(out, columns, {"source": "gatetherm live", "method": label, "endpoint": endpoint,
                                            "period_s": f"{period:g}"})
        if on_ready is not None:
            on_ready()
        try:
            counts = asyncio.run(_serve_until_signal(stepper, journal, endpoint, nodes, params, read, on_period,
                                                     status_port))
        finally:
            journal.close()
        return service.summarize(out, counts)
    finally:
        os.close(fd)


async def _serve_until_signal(stepper, journal, endpoint, nodes, params, read, on_period, status_port):
    from gatetherm.validation.live.service import serve
    from gatetherm.validation.live.status import Status, serve_status

    stop = asyncio.Event()
    loop = asyncio.get_running_loop()
    handled = []
    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGINT, signal.SIGTERM):
            old = signal.getsignal(sig)
            with contextlib.suppress(ValueError, RuntimeError):
                loop.add_signal_handler(sig, stop.set)
                handled.append((sig, old))
    status = server = None
    if status_port is not None:
        status = Status(journal.dir, stepper.columns)
        try:
            server = await serve_status(status, status_port)
        except OSError as err:
            from gatetherm import InputError

            raise InputError("--status-port", f"cannot serve on 127.0.0.1:{status_port} ({err.strerror})",
                             "give a free port") from None
    try:
        return await serve(stepper, journal, endpoint, nodes, params, read, on_period, stop, status)
    finally:
        if server is not None:
            server.close()
        for sig, old in handled:
            loop.remove_signal_handler(sig)
            signal.signal(sig, old)
