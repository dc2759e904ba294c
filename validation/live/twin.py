"""A virtual machine over OPC UA: a case's reduced model run K times faster than real time, its
signals served in the layout of :mod:`.nodes`, the correction written to it applied to δ.

Every ``step_s`` of machine time the twin advances the reduced model (the exact step for inputs
linear between samples, :mod:`gatetherm.solvers.rom_time`) on the schedule's inputs and publishes
``time_s``, the inputs, the thermocouples with the sensors' noise (Gaussian, ``noise_K``) rounded
to their resolution (``resolution_K``), the measured δ (``noise_um``, ``resolution_um``) and the
compensated δ ``delta_residual_um`` = δ + the ``offset_um`` read from its own node at that instant (an
ideal axis offset; the twin's truth, without noise). A sample is published with ``time_s`` set to
NaN first and to its time last, so a reader that sees the same finite ``time_s`` before and after
the other values in one read has a consistent sample. ``published_unix_s`` is the wall clock (Unix
time, s) of the publication, for timing a service (not a data-format channel).

One process serves ``machines`` machines (``TwinParams.machines``), each in its own namespace
(:func:`~.nodes.machine_namespace`) with its own sensor noise, correction and clock phase: machine
*i* publishes *i*/N of a step after machine 0, as machines that were not switched on together.
Their thermal model (one case, one schedule) is the same, marched once per machine.
"""
from __future__ import annotations

import asyncio
import copy
import logging
import math
import time
from dataclasses import dataclass

import numpy as np

from gatetherm import InputError
from gatetherm.process import frozen_heap
from gatetherm.validation.live.nodes import OBJECT, WRITTEN, machine_namespace

log = logging.getLogger(__name__)

LAST_WAIT_S = 10.0
"""With ``wait``: how long (wall s) the first and the last sample stay readable for the service's correction
for them, at most (a loaded machine answers late: the first sample was overwritten before the service read it)."""


@dataclass(frozen=True)
class TwinParams:
    """How the twin runs and what its sensors add."""

    speed: float = 1.0
    """Machine seconds per wall second (K)."""
    step_s: float = 60.0
    """Machine time between published samples, s."""
    start_s: float = 0.0
    """Machine time it starts serving at, s (marched silently up to it: a twin restarted mid-run)."""
    until_s: float | None = None
    """Machine time it stops at, s (default: the schedule's end)."""
    noise_K: float = 0.02
    """Standard deviation of a temperature reading, K."""
    resolution_K: float = 0.01
    """Resolution of a temperature reading, K."""
    noise_um: float = 0.05
    """Standard deviation of a δ reading, µm."""
    resolution_um: float = 0.1
    """Resolution of a δ reading, µm."""
    seed: int = 0
    """Random seed of the sensor noise."""
    wait: bool = False
    """Start the clock only once a client has written ``offset_um`` (a service that is still starting), and
    keep the last sample until it has answered it (at most :data:`LAST_WAIT_S`)."""
    faults: tuple[tuple[str, float, float], ...] = ()
    """(column, from_s, to_s): the column reads NaN over that machine time (a sensor fault), s."""
    machines: int = 1
    """Machines served by this process, each in its own namespace (docs/live.md)."""

    def __post_init__(self):
        if isinstance(self.machines, bool) or not isinstance(self.machines, int) or not 1 <= self.machines <= 10000:
            raise InputError("--machines", f"must be a whole number 1..10000, got {self.machines!r}", "e.g. --machines 100")
        if not (math.isfinite(self.speed) and self.speed > 0):
            raise InputError("--speed", f"must be > 0, got {self.speed}", "e.g. --speed 120")
        if not (math.isfinite(self.step_s) and self.step_s > 0):
            raise InputError("twin step", f"must be > 0, got {self.step_s}", "e.g. 60 s")
        for name in ("noise_K", "resolution_K", "noise_um", "resolution_um", "start_s"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
                raise InputError("--start" if name == "start_s" else name, f"must be a finite number >= 0, got {value!r}",
                                 "use values >= 0")
        for fault in self.faults:
            if not (len(fault) == 3 and isinstance(fault[0], str) and all(
                    isinstance(v, (int, float)) and math.isfinite(v) for v in fault[1:]) and fault[1] <= fault[2]):
                raise InputError("--fault", f"{fault!r} is not (column, from_s, to_s) with from_s <= to_s",
                                 "e.g. --fault theta_A_degC:3600:7200")

    def check_against(self, columns, end_s: float) -> None:
        """InputError for a fault of a column the twin does not publish, or a start past ``end_s``."""
        unknown = [f[0] for f in self.faults if f[0] not in columns]
        if unknown:
            raise InputError(f"--fault {unknown[0]}", "is not a column the twin publishes",
                             f"choose one of {', '.join(sorted(columns))}")
        if self.start_s > end_s:
            raise InputError("--start", f"{self.start_s:g} s is past the schedule's end ({end_s:g} s)",
                             f"give a machine time in 0 .. {end_s:g} s")


def endpoint_url(endpoint: str) -> str:
    """``endpoint`` checked: ``opc.tcp://HOST:PORT``, a host name without spaces or slashes and
    a port 1..65535."""
    host, _, port = endpoint[10:].rpartition(":") if isinstance(endpoint, str) else ("", "", "")
    if not (isinstance(endpoint, str) and endpoint.startswith("opc.tcp://") and host and port.isdigit()
            and 1 <= int(port) <= 65535 and endpoint.isprintable() and not any(c in host for c in " /?#@")):
        raise InputError("--endpoint", f"{str(endpoint)[:80]!r} is not opc.tcp://HOST:PORT (a port 1..65535)",
                         "e.g. opc.tcp://127.0.0.1:4840")
    return endpoint


def _quantise(x: np.ndarray, rng, noise: float, resolution: float) -> np.ndarray:
    x = x + (rng.normal(0.0, noise, np.shape(x)) if noise > 0 else 0.0)
    return np.round(x / resolution) * resolution if resolution > 0 else x


class Machine:
    """The reduced model of a case marched on its schedule's inputs, one step at a time."""

    def __init__(self, rom, schedule, step_s: float, published):
        from gatetherm.solvers.rom_time import discretise
        from gatetherm.studies.run.reduce import series_inputs

        self.rom, self.step_s = rom, step_s
        end = float(schedule.times[-1])
        self.times = step_s * np.arange(int(np.floor(end / step_s + 1e-9)) + 1)
        rows = [dict(schedule.drive(float(t))) for t in self.times]
        self.inputs = {k: np.array([r[k] for r in rows], float) for k in rows[0]}
        self.u, self.modes = series_inputs(rom, {"time_s": self.times, **self.inputs})
        self.disc = discretise(rom, step_s)
        self.rows = [rom.output(n) for n in published]
        self.k, self.x = 0, np.zeros(rom.states)

    def advance(self) -> None:
        """One step of machine time."""
        p, k = int(self.modes[self.k]), self.k
        self.x = self.disc.Phi[p] @ self.x + self.disc.G0[p] @ self.u[k] + self.disc.G1[p] @ self.u[k + 1]
        self.k += 1

    def outputs(self) -> np.ndarray:
        """The published outputs now (their units)."""
        r = self.rows
        return self.rom.C[r] @ self.x + self.rom.D[r] @ self.u[self.k] + self.rom.y0[r]


class _Stopping:
    """``async with``: stop a started server on the way out."""
    def __init__(self, server):
        self.server = server

    async def __aenter__(self):
        return self.server

    async def __aexit__(self, *exc):
        await self.server.stop()


class Drive:
    """The correction through an actuator model (:mod:`gatetherm.studies.control.actuator`): each new
    offset is one more command of the sequence, driven with the actuator's strategy and hysteresis."""

    def __init__(self, actuator):
        self.actuator, self.commands, self.stroke = actuator, [], 0.0

    def __call__(self, offset: float) -> float:
        """The displacement achieved at the tool for the offset now written, µm."""
        from gatetherm.studies.control.actuator import apply_commands

        if self.actuator is None:
            return offset
        if not self.commands or offset != self.commands[-1]:
            self.commands.append(offset)
            self.stroke = float(apply_commands(self.actuator, self.commands)[1][-1])
        return self.stroke


async def serve(rom, schedule, endpoint: str, params: TwinParams, published, stopped=None, actuator=None) -> dict:
    """Serve the machines until ``params.until_s`` (or the schedule's end); the summary dict. With
    ``actuator`` (:class:`~gatetherm.studies.control.actuator.ActuatorParams`) the offset drives it;
    without, it is applied exactly."""
    from asyncua import Server, ua

    logging.getLogger("asyncua").setLevel(logging.CRITICAL)  # its warnings about an unencrypted loopback endpoint;
    # a failure to serve is raised (below), not logged with its traceback
    first = Machine(rom, schedule, params.step_s, published)
    params.check_against({*first.inputs, *published}, float(first.times[-1]))
    until = min(params.until_s if params.until_s is not None else math.inf, first.times[-1])
    while first.times[first.k] < params.start_s - 1e-9 and first.k < len(first.times) - 1:
        first.advance()
    server = Server()
    await server.init()
    server.set_endpoint(endpoint_url(endpoint))
    server.set_server_name("gatetherm twin")
    names = ("time_s", *first.inputs, *published, "delta_residual_um", "published_unix_s", *WRITTEN)
    plants = []
    for i in range(params.machines):
        idx = await server.register_namespace(machine_namespace(i, params.machines))
        obj = await server.nodes.objects.add_object(ua.NodeId(OBJECT, idx), ua.QualifiedName(OBJECT, idx))
        nodes = {}
        for name in names:
            nodes[name] = await obj.add_variable(ua.NodeId(name, idx), ua.QualifiedName(name, idx),
                                                 math.nan, ua.VariantType.Double)
            if name in WRITTEN:
                await nodes[name].set_writable()
        plants.append(_Plant(copy.copy(first), nodes, np.random.default_rng(params.seed + i), Drive(actuator)))
    try:
        await server.start()
    except OSError as err:  # an address not of this machine, a port in use
        raise InputError("--endpoint", f"cannot serve on {endpoint} ({err.strerror or err})",
                         "give an address of this machine and a free port, e.g. opc.tcp://127.0.0.1:4840") from None
    with frozen_heap():  # the address space out of the full collections (~220 CPU-ms each at 100 machines)
        return await _serve(server, endpoint, plants, first, until, params, published, stopped)


async def _serve(server, endpoint, plants, first, until, params, published, stopped) -> dict:
    """Serve the plants until ``until`` (machine s): the clock started (once every ``offset_um`` is written
    with ``params.wait``), each plant publishing its samples; the summary dict. The server is stopped
    on the way out."""
    async with _Stopping(server):
        log.info("twin serving %d machine(s) on %s from t = %g s at %gx", len(plants), endpoint,
                 first.times[first.k], params.speed)
        while params.wait:
            if stopped is not None and stopped():
                return {"served": 0, "machines": len(plants)}
            if all([math.isfinite(await p.nodes["offset_um"].read_value()) for p in plants]):
                break
            await asyncio.sleep(0.05)
        t_wall0, t_mach0, unix0 = time.monotonic(), float(first.times[first.k]), time.time()
        lags = []
        await asyncio.gather(*(p.run(t_wall0 + i * params.step_s / params.speed / len(plants), t_mach0, until,
                                     params, published, stopped, lags) for i, p in enumerate(plants)))
    lag = np.array(lags or [math.nan]) * 1e3
    return {"served": sum(p.served for p in plants), "machines": len(plants), "start_s": t_mach0,
            "end_s": max(p.t for p in plants), "clock_start_unix_s": unix0,
            "compensated_band_after_10_min_um": max(p.worst for p in plants),
            "publish_lag_ms": {"median": float(np.median(lag)), "p95": float(np.percentile(lag, 95)),
                               "max": float(lag.max())}}


class _Plant:
    """One machine served: its model, nodes, noise and actuator."""

    def __init__(self, machine: Machine, nodes: dict, rng, drive: Drive):
        self.machine, self.nodes, self.rng, self.drive = machine, nodes, rng, drive
        self.served, self.worst, self.t = 0, 0.0, math.nan

    async def run(self, t_wall0: float, t_mach0: float, until: float, params: TwinParams, published, stopped,
                  lags: list) -> None:
        """Publish a sample every step (machine time ``t_mach0`` at wall ``t_wall0``) until ``until``;
        each publication's lag behind its wall time (s) goes to ``lags``."""
        machine, nodes = self.machine, self.nodes
        delta = published.index("delta_um")
        temps = [i for i, n in enumerate(published) if n.endswith("_degC")]
        late, first, shift = 600.0 + params.start_s, True, 0.0
        while True:
            t = self.t = float(machine.times[machine.k])
            due = t_wall0 + shift + (t - t_mach0) / params.speed
            await asyncio.sleep(max(0.0, due - time.monotonic()))
            offset = float(await nodes["offset_um"].read_value())
            y = machine.outputs()
            shown = y.copy()
            shown[temps] = _quantise(y[temps], self.rng, params.noise_K, params.resolution_K)
            shown[delta] = _quantise(y[delta], self.rng, params.noise_um, params.resolution_um)
            comp = float(y[delta]) + self.drive(offset if math.isfinite(offset) else 0.0)
            values = {**{k: float(v[machine.k]) for k, v in machine.inputs.items()},
                      **dict(zip(published, map(float, shown))), "delta_residual_um": comp}
            for name, lo, hi in params.faults:
                if lo <= t <= hi:
                    values[name] = math.nan
            last = t >= until - 1e-9 or machine.k >= len(machine.times) - 1
            if (first or last) and params.wait:  # the service's correction for it is awaited below
                await nodes["offset_um"].write_value(math.nan)
            await nodes["time_s"].write_value(math.nan)
            for name, value in values.items():
                await nodes[name].write_value(value)
            await nodes["published_unix_s"].write_value(time.time())
            await nodes["time_s"].write_value(t)
            lags.append(time.monotonic() - due)
            self.served += 1
            if t >= late:
                self.worst = max(self.worst, abs(comp))
            if stopped is not None and stopped():
                break
            if first and params.wait and not last:  # the clock runs on once the first sample is answered
                t0 = time.monotonic()
                await self._answered(t0 + LAST_WAIT_S, stopped)
                shift += time.monotonic() - t0
            first = False
            if last:  # the last sample stays readable for a step, and with a service waited for until it answers
                end = time.monotonic() + max(params.step_s / params.speed, LAST_WAIT_S if params.wait else 0.0)
                await asyncio.sleep(params.step_s / params.speed)
                if params.wait:
                    await self._answered(end, stopped)
                break
            machine.advance()

    async def _answered(self, end: float, stopped) -> None:
        """Until the service has written its correction (``offset_um`` finite again), at most to wall ``end``."""
        while time.monotonic() < end and not math.isfinite(await self.nodes["offset_um"].read_value()) \
                and not (stopped is not None and stopped()):
            await asyncio.sleep(0.05)
