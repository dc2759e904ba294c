"""``gatetherm live``: a step-wise compensator beside a machine, over OPC UA.

Every ``period_s`` of the machine's clock (``time_s``, so a twin running faster than real time is
followed in its own time) the service reads one sample, checks it (the guards below), steps the
compensator (:mod:`gatetherm.studies.control.stepwise`), limits the correction and writes it to
the control; it logs the row (:mod:`.journal`), then saves the state. Periods that pass without a
sample (the service down, the connection lost, the machine clock jumping) are stepped as missing:
the command holds, the reduced model's filter predicts across them, and they are counted.

Guards (:class:`Guards`, each with its default, docs/live.md):

* the correction is clipped to ±``max_offset_um`` and its change to ±``max_change_um`` per period,
  a gradient's change to ±``max_gradient_change_um_per_m`` per period;
* a sample with a missing (NaN) value or a jump beyond ``max_jump_K`` (temperatures) or
  ``max_jump_um`` (δ) per period since the last good one holds the last correction (logged);
* a lost connection is retried with back-off (``retry_first_s`` doubling to ``retry_max_s``) while
  the correction holds; after ``hold_s`` the correction ramps to zero at ``ramp_um_per_s``, and
  the ramped value is what is written on reconnection (a control keeps the last value written
  while the link is down: its own watchdog is what makes that safe);
* the never-worse monitor (:mod:`.monitor`): where the machine reports its measured δ, a
  compensation that leaves δ worse than none over a window is warned once, flagged and (default)
  ramped to zero, the verdict kept across restarts;
* SIGINT/SIGTERM end the loop between two periods, the state saved.

Where the compensator gives a gradient along an axis (:mod:`.axis`), it is written beside the
offset (``gradient_um_per_m``, ``reference_m``): as decided on a good sample, held on a held one,
and scaled down with the offset when the monitor's fallback ramps it.
"""
from __future__ import annotations

import asyncio
import logging
import math
import time
from dataclasses import dataclass, field

import numpy as np

from gatetherm import InputError
from gatetherm.validation.live.journal import Journal
from gatetherm.validation.live.link import Pace, _close, _connect, _sample, _write
from gatetherm.validation.live.monitor import Monitor, Watch
from gatetherm.validation.live.nodes import NodeMap

log = logging.getLogger(__name__)

NOT_STARTED_S = 0.25
"""Longest wait between reads while the machine's clock reads NaN (not started, or publishing), and
after a period while the wall time between periods is not yet known (:class:`~.link.Pace`), s: a
sample is seen at most this late (at 1 s, the first period of a 1-s clock was late; at every 0.05 s,
100 services starting together asked one twin for 2000 reads a second)."""


@dataclass(frozen=True)
class Guards:
    """What the service refuses to pass on to the control."""

    max_offset_um: float = 100.0
    """Largest correction written, µm (set it to the control's own limit)."""
    max_change_um: float = 5.0
    """Largest change of the correction per period, µm."""
    max_gradient_change_um_per_m: float = 5.0
    """Largest change of the gradient along an axis per period, µm per m (the default: at 1 m from
    the reference position the gradient's change moves the correction no more than ``max_change_um``)."""
    max_jump_K: float = 1.0
    """Largest change of a temperature per period that a sensor can show, K."""
    max_jump_um: float = 10.0
    """Largest change of a measured δ per period, µm."""
    retry_first_s: float = 0.5
    """First wait before reconnecting, wall s (doubled per attempt)."""
    retry_max_s: float = 8.0
    """Longest wait between attempts, wall s."""
    hold_s: float = 60.0
    """Wall time a lost connection holds the correction before it ramps to zero, s."""
    ramp_um_per_s: float = 0.1
    """Rate at which the correction falls to zero while the connection stays lost, µm per wall s."""
    timeout_s: float = 5.0
    """Timeout of one OPC UA request, s (also the interval and timeout of the client's watchdog probe)."""


@dataclass(frozen=True)
class LiveParams:
    """When the service steps and stops."""

    period_s: float = 60.0
    """Compensator period on the machine's clock, s (the sampling of the method)."""
    t0_s: float = 0.0
    """Machine time of period 0 (the schedule's start), s."""
    until_s: float | None = None
    """Machine time to stop after, s (None: until stopped)."""
    poll_s: float = 0.05
    """Wall time between reads while waiting for the next period, s."""
    guards: Guards = field(default_factory=Guards)
    monitor: Monitor = field(default_factory=Monitor)
    """The never-worse monitor (:mod:`.monitor`)."""


def _limits(column: str, g: Guards) -> float:
    return g.max_jump_K if column.endswith("_degC") else g.max_jump_um if column.endswith("_um") else math.inf


class Service:
    """The loop's state between periods (see the module docstring)."""

    def __init__(self, stepper, journal: Journal, params: LiveParams, read: tuple[str, ...]):
        self.stepper, self.journal, self.p, self.read = stepper, journal, params, read
        s = journal.state or {}
        if s:
            stepper.restore(s["stepper"])
        self.next = int(s.get("next", 0))
        self.written = float(s.get("offset_um", 0.0))
        self.good = dict(s.get("good", {}))
        self.good_k = s.get("good_k")
        self.gradient = s.get("gradient_um_per_m")
        self.reference = stepper.axis.s0 if hasattr(stepper, "axis") else None
        self.counts = dict(s.get("counts", {"periods": 0, "missed": 0, "held": 0, "limited": 0, "reconnects": 0,
                                            "restarts": 0}))
        self.counts.setdefault("worse", 0)
        self.watch = Watch(params.monitor, s.get("monitor"))
        if s:
            self.counts["restarts"] += 1
            if self.watch.worse is not None:
                journal.event(None, f"resumed fallen back ({params.monitor.fallback}): compensation made delta "
                              f"worse at t = {self.watch.worse['t_s']:g} s")

    def bad(self, k: int, sample: dict) -> str | None:
        """Why ``sample`` (period k) is not used, or None."""
        for c in self.stepper.columns:
            x = sample.get(c, math.nan)
            if not math.isfinite(x):
                return f"{c} missing"
            if c in self.good and self.good_k is not None:
                limit = _limits(c, self.p.guards) * (k - self.good_k)
                if abs(x - self.good[c]) > limit:
                    return f"{c} jumped {x - self.good[c]:+.3g} in {k - self.good_k} period(s)"
        return None

    def period(self, t: float, k: int, sample: dict) -> dict:
        """Step period k (time t, s) with ``sample``: the row logged."""
        g = self.p.guards
        for j in range(self.next, k):  # periods without a sample
            self.stepper.skip(self.p.t0_s + j * self.p.period_s)
        if k > self.next:
            self.counts["missed"] += k - self.next
            self.journal.event(t, f"{k - self.next} period(s) without a sample (missed)")
        why = self.bad(k, sample)
        held = limited = 0
        applied = self.written  # the correction held over this period
        unc = sample.get("delta_um", math.nan)
        comp = sample.get("delta_residual_um", math.nan)
        comp = comp if math.isfinite(comp) else unc + applied
        if why is None and self.watch.add(t, unc, comp, applied) is not None:
            w = self.watch.worse
            self.journal.event(t, f"compensation makes delta worse: largest |residual| {w['compensated_um']:.2f} um > "
                               f"{w['uncompensated_um']:.2f} um uncompensated over the last "
                               f"{self.p.monitor.window} periods; fallback {self.p.monitor.fallback}")
        if why is not None:
            corr = self.stepper.skip(t)
            wanted, held = self.written, 1
            self.counts["held"] += 1
            self.journal.event(t, f"sample held: {why}; correction held at {self.written:.3f} um")
        else:
            corr = self.stepper.step(t, sample)
            wanted = corr.offset_um
            self.good = {c: sample[c] for c in self.stepper.columns}
            self.good_k = k
        gradient = getattr(corr, "gradient_um_per_m", None)
        gradient = self.gradient if held or gradient is None else gradient
        target = self.watch.command(wanted)
        new = float(np.clip(np.clip(target, self.written - g.max_change_um, self.written + g.max_change_um),
                            -g.max_offset_um, g.max_offset_um))
        if gradient is not None and target != wanted:  # fallen back: the gradient scaled with the offset
            gradient = gradient * new / self.written if self.written else 0.0
        gradient_wanted = gradient
        if gradient is not None:  # its change limited like the offset's, from 0 (what the control holds at first)
            before, most = self.gradient or 0.0, g.max_gradient_change_um_per_m
            gradient = float(np.clip(gradient, before - most, before + most))
        self.gradient = gradient
        worse = int(self.watch.worse is not None)
        self.counts["worse"] += worse
        if abs(new - target) > 1e-12 or (gradient is not None and abs(gradient - gradient_wanted) > 1e-12):
            limited = 1
            self.counts["limited"] += 1
            self.journal.event(t, f"correction limited: {wanted:.3f} -> {new:.3f} um" + (
                f", gradient {gradient_wanted:.3f} -> {gradient:.3f} um/m" if gradient != gradient_wanted else ""))
        self.written = new
        self.next = k + 1
        self.counts["periods"] += 1
        row = {"time_s": t, **sample, "offset_um": new, "offset_wanted_um": wanted,
               "delta_forecast_um": corr.predicted_um, "held": held, "limited": limited, "worse": worse,
               "gradient_um_per_m": gradient, "reference_m": getattr(corr, "reference_m", None)}
        self.journal.row(row)
        self.journal.save({"stepper": self.stepper.state(), "next": self.next, "offset_um": self.written,
                           "gradient_um_per_m": self.gradient, "good": self.good, "good_k": self.good_k,
                           "counts": self.counts, "monitor": self.watch.state(), "t_logged": t})
        return row


async def serve(stepper, journal: Journal, endpoint: str, nodes: NodeMap, params: LiveParams,
                read: tuple[str, ...], on_period=None, stop: asyncio.Event | None = None, status=None) -> dict:
    """Run the loop until ``params.until_s`` or ``stop``; the counts. ``status``: a
    :class:`~.status.Status` fed every period's row."""
    from asyncua import ua

    logging.getLogger("asyncua").setLevel(logging.ERROR)  # its notes on session timeouts and unencrypted loopback
    svc, g = Service(stepper, journal, params, read), params.guards
    stop = stop or asyncio.Event()
    client, resolved, wait, lost_at, ever = None, None, g.retry_first_s, None, False
    pace, nones, said = Pace(params.poll_s, NOT_STARTED_S), 0, -math.inf

    async def pause(seconds):  # ended early by stop
        try:
            await asyncio.wait_for(stop.wait(), seconds)
        except asyncio.TimeoutError:
            pass
    try:
        while not stop.is_set():
            try:
                if client is None:
                    client, resolved = await _connect(endpoint, nodes, g.timeout_s)
                    if lost_at is not None:
                        svc.counts["reconnects"] += ever
                        journal.event(None, f"{'re' if ever else ''}connected after {time.monotonic() - lost_at:.1f} s")
                    lost_at, wait, ever = None, g.retry_first_s, True
                    await _write(resolved, nodes, svc.written, svc.gradient, svc.reference)
                sample = await _sample(client, resolved, read, nodes.factor)
                if sample is None:  # the machine is publishing (or its clock not started: back off to NOT_STARTED_S)
                    nones += 1
                    await pause(min(params.poll_s * 2.0 ** (nones - 1), max(params.poll_s, NOT_STARTED_S)))
                    continue
                nones = 0
                t = sample.pop("time_s")
                k = int(round((t - params.t0_s) / params.period_s))
                if params.until_s is not None and t > params.until_s + 1e-9:
                    break
                if k < svc.next:
                    await pause(pace.wait(time.monotonic()))
                    continue
                pace.handled(k, time.monotonic())
                row = svc.period(t, k, sample)
                if status is not None:
                    status.add(row, svc.counts)
                await _write(resolved, nodes, svc.written, svc.gradient, svc.reference)
                if on_period is not None:
                    on_period(row)
                if params.until_s is not None and t >= params.until_s - 1e-9:
                    break
            except (OSError, asyncio.TimeoutError, ConnectionError, ua.UaError, RuntimeError) as err:
                if client is not None or lost_at is None:
                    journal.event(None, f"connection lost ({type(err).__name__}: {err}); correction held at "
                                  f"{svc.written:.3f} um")
                    lost_at = lost_at or time.monotonic()
                    said = -math.inf
                if time.monotonic() - said >= 60.0:  # on the terminal too, each minute: not a silent hang
                    log.warning("%s: %s for %.0f s (%s: %s); retrying, Ctrl-C stops", endpoint,
                                "no connection" if not ever else "connection lost", time.monotonic() - lost_at,
                                type(err).__name__, str(err)[:200])
                    said = time.monotonic()
                await _close(client)
                client, before = None, time.monotonic()
                pace.reset()
                await pause(wait)
                wait = min(2 * wait, g.retry_max_s)
                now = time.monotonic()
                ramping = min(now - before, now - lost_at - g.hold_s)  # wall s of this wait past the hold
                if ramping > 0 and svc.written != 0.0:
                    down = now - lost_at
                    ramped = math.copysign(max(0.0, abs(svc.written) - g.ramp_um_per_s * ramping), svc.written)
                    journal.event(None, f"connection lost {down:.0f} s: correction ramped to {ramped:.3f} um")
                    if svc.gradient:
                        svc.gradient *= ramped / svc.written
                    svc.written = ramped
    finally:
        await _close(client)
    return svc.counts


def check(params: LiveParams) -> None:
    """InputError on a bad period or guard."""
    if not (math.isfinite(params.period_s) and params.period_s > 0):
        raise InputError("--period", f"must be > 0, got {params.period_s}", "e.g. --period 60")
    g = params.guards
    if min(g.max_offset_um, g.max_change_um, g.max_gradient_change_um_per_m, g.max_jump_K, g.max_jump_um, g.retry_first_s, g.hold_s,
           g.ramp_um_per_s, g.timeout_s) <= 0:
        raise InputError("live guards", "must be > 0", "see the defaults in docs/live.md")
