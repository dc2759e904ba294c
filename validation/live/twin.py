"""A virtual machine over OPC UA: a case's reduced model run K times faster than real time, its
signals served in the layout of :mod:`.nodes`, the correction written to it applied to δ.

Every ``step_s`` of machine time the twin advances the reduced model (the exact step for inputs
linear between samples, :mod:`gatetherm.solvers.rom_time`) on the schedule's inputs and publishes
``time_s``, the inputs, the thermocouples with the sensors' noise (Gaussian, ``noise_K``) rounded
to their resolution (``resolution_K``), the measured δ (``noise_um``, ``resolution_um``) and the
compensated δ ``delta_residual_um`` = δ + the ``offset_um`` read from its own node at that instant (an
ideal axis offset; the twin's truth, without noise). A sample is published with ``time_s`` set to
NaN first and to its time last, so a reader that sees the same finite ``time_s`` before and after
the other values in one read has a consistent sample.
"""
from __future__ import annotations

import asyncio
import logging
import math
import time
from dataclasses import dataclass

import numpy as np

from gatetherm import InputError
from gatetherm.validation.live.nodes import NAMESPACE, OBJECT, WRITTEN

log = logging.getLogger(__name__)


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
    """Start the clock only once a client has written ``offset_um`` (a service that is still starting)."""
    faults: tuple[tuple[str, float, float], ...] = ()
    """(column, from_s, to_s): the column reads NaN over that machine time (a sensor fault), s."""

    def __post_init__(self):
        if not (math.isfinite(self.speed) and self.speed > 0):
            raise InputError("--speed", f"must be > 0, got {self.speed}", "e.g. --speed 120")
        if not (math.isfinite(self.step_s) and self.step_s > 0):
            raise InputError("twin step", f"must be > 0, got {self.step_s}", "e.g. 60 s")
        if min(self.noise_K, self.resolution_K, self.noise_um, self.resolution_um, self.start_s) < 0:
            raise InputError("twin noise", "negative", "use values >= 0")


def endpoint_url(endpoint: str) -> str:
    """``endpoint`` checked: ``opc.tcp://HOST:PORT``."""
    if not isinstance(endpoint, str) or not endpoint.startswith("opc.tcp://") or ":" not in endpoint[10:]:
        raise InputError("--endpoint", f"{endpoint!r} is not opc.tcp://HOST:PORT", "e.g. opc.tcp://127.0.0.1:4840")
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
    """Serve the machine until ``params.until_s`` (or the schedule's end); the summary dict. With
    ``actuator`` (:class:`~gatetherm.studies.control.actuator.ActuatorParams`) the offset drives it;
    without, it is applied exactly."""
    from asyncua import Server, ua

    logging.getLogger("asyncua").setLevel(logging.ERROR)  # its warnings about an unencrypted loopback endpoint
    machine = Machine(rom, schedule, params.step_s, published)
    until = min(params.until_s if params.until_s is not None else math.inf, machine.times[-1])
    while machine.times[machine.k] < params.start_s - 1e-9 and machine.k < len(machine.times) - 1:
        machine.advance()
    rng = np.random.default_rng(params.seed)
    drive = Drive(actuator)
    server = Server()
    await server.init()
    server.set_endpoint(endpoint_url(endpoint))
    server.set_server_name("gatetherm twin")
    idx = await server.register_namespace(NAMESPACE)
    obj = await server.nodes.objects.add_object(ua.NodeId(OBJECT, idx), ua.QualifiedName(OBJECT, idx))
    names = ("time_s", *machine.inputs, *published, "delta_residual_um", *WRITTEN)
    nodes = {}
    for name in names:
        nodes[name] = await obj.add_variable(ua.NodeId(name, idx), ua.QualifiedName(name, idx),
                                             math.nan, ua.VariantType.Double)
        if name in WRITTEN:
            await nodes[name].set_writable()
    delta = published.index("delta_um")
    temps = [i for i, n in enumerate(published) if n.endswith("_degC")]
    worst, late, served = 0.0, 600.0 + params.start_s, 0
    async with server:
        log.info("twin serving %s from t = %g s at %gx", endpoint, machine.times[machine.k], params.speed)
        while params.wait and not math.isfinite(await nodes["offset_um"].read_value()):
            if stopped is not None and stopped():
                return {"served": 0}
            await asyncio.sleep(0.05)
        t_wall0, t_mach0 = time.monotonic(), float(machine.times[machine.k])
        while True:
            t = float(machine.times[machine.k])
            await asyncio.sleep(max(0.0, t_wall0 + (t - t_mach0) / params.speed - time.monotonic()))
            offset = float(await nodes["offset_um"].read_value())
            y = machine.outputs()
            shown = y.copy()
            shown[temps] = _quantise(y[temps], rng, params.noise_K, params.resolution_K)
            shown[delta] = _quantise(y[delta], rng, params.noise_um, params.resolution_um)
            comp = float(y[delta]) + drive(offset if math.isfinite(offset) else 0.0)
            values = {**{k: float(v[machine.k]) for k, v in machine.inputs.items()},
                      **dict(zip(published, map(float, shown))), "delta_residual_um": comp}
            for name, lo, hi in params.faults:
                if lo <= t <= hi:
                    values[name] = math.nan
            await nodes["time_s"].write_value(math.nan)
            for name, value in values.items():
                await nodes[name].write_value(value)
            await nodes["time_s"].write_value(t)
            served += 1
            if t >= late:
                worst = max(worst, abs(comp))
            if stopped is not None and stopped():
                break
            if t >= until - 1e-9 or machine.k >= len(machine.times) - 1:
                await asyncio.sleep(params.step_s / params.speed)  # the last sample stays readable for a step
                break
            machine.advance()
    return {"served": served, "start_s": t_mach0, "end_s": t, "compensated_band_after_10_min_um": worst}
