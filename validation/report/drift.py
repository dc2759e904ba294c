"""Thermal drift report of one time series, measured or simulated (``gatetherm report --data``).

In the manner of an ISO 230-3 thermal drift test report, and only in these respects: the
drift of a channel is its deviation from its value at the start of the test; each channel's
maximum drift and range (max − min) and the largest over the whole test are reported; the
test duration and the sampling are stated. Set-up, sensor placement, test cycles and
acceptance are not covered. Displacements are the ``*_um`` columns (δ first), temperatures
the ``*_degC`` columns except the inputs; inputs are ``oil_degC``, ``pump``, ``ambient_degC``,
``u_piezo_um`` and every column in another unit (e.g. a power); input phases are where the
pump (or else the first on/off-like input) is on.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gatetherm import InputError
from gatetherm.studies.run.timeseries import TimeSeries

INPUTS = ("oil_degC", "pump", "ambient_degC", "u_piezo_um")
ISO_NOTE = ("Drift in the manner of ISO 230-3 (thermal effects on machine tools), in these respects only: drift is a "
            "channel's deviation from its value at the start of the test; the maximum drift and the range "
            "(max − min) per channel and over the whole test are given, with the test duration and sampling. "
            "Set-up, sensor placement, test cycles and acceptance are not covered.")


@dataclass(frozen=True)
class Channels:
    """The columns of a series by role."""

    displacement: tuple[str, ...]
    """``*_um`` columns (δ first), µm."""
    temperature: tuple[str, ...]
    """``*_degC`` columns that are not inputs, °C."""
    inputs: tuple[str, ...]
    """Oil, pump, room, piezo stroke and columns in any other unit (powers, switches)."""


def channels(ts: TimeSeries) -> Channels:
    names = [n for n in ts.names if n != "time_s"]
    disp = [n for n in names if n.endswith("_um") and n not in INPUTS]
    disp.sort(key=lambda n: n != "delta_um")
    temp = [n for n in names if n.endswith("_degC") and n not in INPUTS]
    other = [n for n in names if n not in disp and n not in temp and not n.endswith("_MPa")]
    return Channels(tuple(disp), tuple(temp), tuple(other))


def check_record(ts: TimeSeries, where: str) -> None:
    """InputError naming ``where`` unless ``ts`` is a record a drift can be read from: two
    samples or more, a displacement or temperature channel, and a value in each of those."""
    if len(ts) < 2:
        raise InputError(str(where), f"{len(ts)} data row: a drift needs two samples or more", "give the whole record")
    ch = channels(ts)
    if not ch.displacement + ch.temperature:
        raise InputError(str(where), "no displacement (*_um) or temperature (*_degC) column besides the inputs",
                         "give the channels whose drift is reported")
    empty = next((n for n in ch.displacement + ch.temperature if not np.isfinite(ts[n]).any()), None)
    if empty:
        raise InputError(f"{where}, column {empty}", "has no values", "fill it or leave the column out")


def phase_signal(ts: TimeSeries, ch: Channels) -> tuple[str, np.ndarray] | None:
    """(label, on at each sample) of the input whose phases are shaded: the pump, else the first
    input that is not a temperature (on where > 0)."""
    if "pump" in ts:
        return "pump on", np.nan_to_num(ts["pump"]) > 0.5
    name = next((n for n in ch.inputs if not n.endswith("_degC")), None)
    return (f"{name} > 0", np.nan_to_num(ts[name]) > 0) if name else None


def drift(x: np.ndarray) -> np.ndarray:
    """Deviation from the first recorded (finite) value."""
    finite = np.flatnonzero(np.isfinite(x))
    return x - x[finite[0]] if len(finite) else x * np.nan


def channel_row(ts: TimeSeries, name: str) -> dict:
    x, t = ts[name], ts.time_s
    d = drift(x)
    ok = np.isfinite(d)
    k = int(np.nanargmax(np.abs(d))) if ok.any() else 0
    return {"channel": name, "start": x[ok][0] if ok.any() else np.nan, "end": x[ok][-1] if ok.any() else np.nan,
            "drift at end": d[ok][-1] if ok.any() else np.nan, "max |drift|": abs(d[k]),
            "at [min]": (t[k] - t[0]) / 60.0, "range": np.nanmax(x) - np.nanmin(x) if ok.any() else np.nan,
            "missing": int((~ok).sum())}


def phases(t: np.ndarray, on: np.ndarray) -> list[tuple[int, int, bool]]:
    """(first, last sample index, on) of each phase; a phase ends at the sample where the next begins."""
    starts = np.r_[0, np.flatnonzero(np.diff(on.astype(int))) + 1]
    ends = np.r_[starts[1:], len(t) - 1]
    return [(int(a), int(b), bool(on[a])) for a, b in zip(starts, ends)]


def phase_rows(ts: TimeSeries, ch: Channels, label: str, on: np.ndarray) -> list[dict]:
    """Per phase: its span, and per displacement channel the drift over the phase and its range."""
    t = ts.time_s
    out = []
    for a, b, state in phases(t, on):
        row = {"phase": label if state else f"not {label}", "from [min]": (t[a] - t[0]) / 60.0,
               "to [min]": (t[b] - t[0]) / 60.0}
        for n in ch.displacement:
            x = ts[n][a:b + 1]
            row[f"{n}: change"] = x[np.isfinite(x)][-1] - x[np.isfinite(x)][0] if np.isfinite(x).any() else np.nan
            row[f"{n}: range"] = np.nanmax(x) - np.nanmin(x) if np.isfinite(x).any() else np.nan
        out.append(row)
    return out


def sampling(ts: TimeSeries) -> dict:
    dt = np.diff(ts.time_s)
    return {"samples": len(ts), "duration_min": float((ts.time_s[-1] - ts.time_s[0]) / 60.0),
            "interval_s": float(np.median(dt)) if len(dt) else np.nan,
            "interval_min_s": float(dt.min()) if len(dt) else np.nan, "interval_max_s": float(dt.max()) if len(dt) else np.nan}


def compute(ts: TimeSeries, work, name: str):
    """The drift report of ``ts`` as a report Result: the figure (``drift.png`` in ``work``), the
    per-channel and per-phase tables and the test's duration and sampling."""
    from gatetherm.validation.plots import save
    from gatetherm.validation.plots.drift import plot_drift
    from gatetherm.validation.report.result import Figure, Result, from_dicts

    check_record(ts, name)
    ch = channels(ts)
    shade = phase_signal(ts, ch)
    save(plot_drift(ts.time_s - ts.time_s[0], {n: drift(ts[n]) for n in ch.displacement},
                    {n: drift(ts[n]) for n in ch.temperature}, {n: ts[n] for n in ch.inputs}, shade, name),
         work / "drift.png")
    s = sampling(ts)
    rows = {kind: [channel_row(ts, n) for n in names] for kind, names in
            (("µm", ch.displacement), ("°C", ch.temperature), ("input", ch.inputs))}
    tables = [from_dicts(f"{title}: drift from the start value ({unit})", rows[key],
                         note="max |drift|: the largest deviation from the start value, at the time given; range: "
                              "max − min over the test; missing: samples without a value.")
              for key, title, unit in (("µm", "Displacements", "µm"), ("°C", "Temperatures", "K; start and end in °C"),
                                       ("input", "Inputs", "in their units")) if rows[key]]
    if shade:
        tables.insert(1, from_dicts(f"Displacements per input phase ({shade[0]} or not), µm",
                                    phase_rows(ts, ch, *shade)))
    worst = {unit: max(rows[unit], key=lambda r: r["max |drift|"]) for unit in ("µm", "°C") if rows[unit]}
    notes = [f"Test duration {s['duration_min']:.1f} min, {s['samples']} samples, sampling interval "
             f"{s['interval_s']:g} s (from {s['interval_min_s']:g} to {s['interval_max_s']:g} s)."]
    d = next((r for r in rows["µm"] if r["channel"] == "delta_um"), None)  # δ first: what a compensation acts on
    notes += [f"δ (delta_um, the tool against the workpiece): largest drift {d['max |drift|']:.4g} µm at "
              f"{d['at [min]']:.4g} min, drift at the end {d['drift at end']:.4g} µm, range {d['range']:.4g} µm."
              ] if d else []
    notes += [f"Largest drift over the whole test, {'displacement' if u == 'µm' else 'temperature'}: "
              f"{r['max |drift|']:.4g} {'µm' if u == 'µm' else 'K'} ({r['channel']}, at {r['at [min]']:.4g} min); "
              f"largest range {max(x['range'] for x in rows[u]):.4g} {'µm' if u == 'µm' else 'K'}."
              for u, r in worst.items()]
    notes.append(ISO_NOTE)
    fig = Figure("drift.png", "Drift of every displacement and temperature from its start value against time, and "
                 "the inputs" + (f"; grey: {shade[0]}" if shade else ""))
    return Result(tables=tuple(tables), figures=(fig,), notes=tuple(notes))
