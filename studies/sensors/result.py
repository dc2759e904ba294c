"""What a placement found, and its files: ``sensors.toml``, ``model.json``, ``curve.csv`` and,
last, ``summary.json`` (the pictures are drawn by :mod:`gatetherm.validation.plots.sensors`)."""
from __future__ import annotations

import csv
import dataclasses
import io
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gatetherm import write_text_atomic
from gatetherm.checks import json_text
from gatetherm.studies.errormodel.model import ErrorModel, save_model
from gatetherm.studies.sensors.candidates import Candidates
from gatetherm.studies.sensors.models import settings_of


@dataclass(frozen=True)
class Sensor:
    """A chosen thermocouple location: a mesh node."""

    name: str
    node: int
    xyz: tuple[float, ...]
    """Coordinates, m."""
    boundary: str
    """The boundary it lies on."""

    @property
    def column(self) -> str:
        """Its column in a run of the case with it as a probe."""
        return f"T_{self.name}_degC"


@dataclass(frozen=True)
class CurvePoint:
    """The best set of ``count`` sensors and its errors."""

    count: int
    form: str
    """``static`` or ``dynamic`` (the errormodel's forms)."""
    sensors: tuple[Sensor, ...]
    cv_mae_um: dict[str, float]
    """Per target, leave-one-load-out MAE over the training loads, um."""
    held_out_mae_um: dict[str, float]
    """Per target, MAE over the held-out loads, um."""

    @property
    def cv_mean_um(self) -> float:
        return float(np.mean(list(self.cv_mae_um.values())))

    @property
    def held_out_mean_um(self) -> float:
        return float(np.mean(list(self.held_out_mae_um.values())))


@dataclass(frozen=True)
class Placement:
    """The chosen sensors of a case, their error model, and the error against their number."""

    case: str
    """The case's name and file."""
    dim: int
    sensors: tuple[Sensor, ...]
    model: ErrorModel
    curve: tuple[CurvePoint, ...]
    """K = 1 ... the placed count."""
    failed: dict[str, dict[str, float]]
    """Per chosen sensor: the held-out MAE per target (um) of the model refitted without it."""
    candidates: Candidates
    shortlist: np.ndarray = field(repr=False)
    """Indices into ``candidates`` that screening kept."""
    stopped: str
    """Why the curve ends before the asked count ("" if it reaches it)."""
    training: tuple = field(repr=False)
    """The training loads (Schedules)."""
    held_out: tuple = field(repr=False)
    """The held-out loads (Schedules)."""
    settings: object = None
    """The :class:`~gatetherm.studies.sensors.place.PlacementSettings`."""
    signals: dict | None = None
    """The same family given the case's thermocouples θ_A, θ_B and the θ_C mean ([signals]), if it has them."""
    ranges: tuple = ()
    """The inputs' ranges of the generated loads (InputRange)."""
    held_temperatures: dict = field(default_factory=dict, repr=False)
    """Per held-out load, the chosen sensors' temperatures by the reduced model, noise-free (samples x sensors), degC."""
    seconds: dict = field(default_factory=dict)
    notes: tuple[str, ...] = ()
    """What the command should say (the curve rising on held-out loads, a short candidate list)."""

    def probes(self) -> dict[str, tuple[float, ...]]:
        return {s.name: s.xyz for s in self.sensors}

    def summary(self) -> dict:
        """What ``summary.json`` holds."""
        point = lambda c: {"count": c.count, "form": c.form, "sensors": [dataclasses.asdict(s) for s in c.sensors],  # noqa: E731
                           "cv_mae_um": c.cv_mae_um, "held_out_mae_um": c.held_out_mae_um}
        s = self.settings
        return {"case": self.case, "dim": self.dim, "sensors": [dataclasses.asdict(x) for x in self.sensors],
                "form": self.curve[-1].form, "held_out_mae_um": self.curve[-1].held_out_mae_um,
                "cv_mae_um": self.curve[-1].cv_mae_um, "curve": [point(c) for c in self.curve],
                "stopped": self.stopped, "notes": list(self.notes),
                "one_sensor_failed": self.failed, "signals": self.signals,
                "candidates": len(self.candidates), "shortlist": int(len(self.shortlist)),
                "excluded": dict(self.candidates.excluded),
                "training_loads": [x.label for x in self.training], "held_out_loads": [x.label for x in self.held_out],
                "input_ranges": [dataclasses.asdict(r) for r in self.ranges],
                "settings": _plain({**dataclasses.asdict(s), "fit": settings_of(s.fit)}) if s is not None else {},
                "seconds": {k: round(v, 2) for k, v in self.seconds.items()}}

    def write(self, out, extra: dict | None = None) -> dict:
        """Write ``out/sensors.toml``, ``model.json``, ``curve.csv`` and, last, ``summary.json`` (with
        ``extra`` entries); returns the summary."""
        out = Path(out)
        write_text_atomic(out / "sensors.toml", sensors_toml(self))
        save_model(out / "model.json", self.model)
        write_text_atomic(out / "curve.csv", curve_csv(self))
        summary = {**self.summary(), **(extra or {})}
        write_text_atomic(out / "summary.json", json_text(summary, "summary.json", indent=1))
        return summary


def _plain(v):
    if isinstance(v, dict):
        return {k: _plain(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_plain(x) for x in v]
    return v


def sensors_toml(p: Placement) -> str:
    """The ``[probes]`` tables of the chosen points, to paste into a case file."""
    lines = [f"# Thermocouples chosen by 'gatetherm sensors' for {p.case}: {len(p.sensors)} of {len(p.candidates)} "
             f"candidates, {p.curve[-1].form} error model (model.json), held-out MAE "
             + ", ".join(f"{k} {v:.3g} um" for k, v in p.curve[-1].held_out_mae_um.items())]
    if p.candidates.excluded:
        lines.append(f"# none on {excluded_text(p.candidates.excluded)} ({NO_SENSOR})")
    lines.append("")
    for s in p.sensors:
        lines += [f"[probes.{s.name}]", f"point = [{', '.join(repr(float(v)) for v in s.xyz)}]   # node {s.node}, "
                  f"on boundary \"{s.boundary}\"", 'quantities = ["T"]', ""]
    return "\n".join(lines)


NO_SENSOR = "cannot carry a sensor: [sensors] exclude, or a face a support holds"
"""Why a part's nodes are no candidates (:attr:`~gatetherm.studies.sensors.candidates.Candidates.excluded`)."""


def excluded_text(excluded: dict[str, int]) -> str:
    """``spindle (24 candidate nodes), …``: the parts no sensor may go on."""
    return ", ".join(f"{k} ({v} candidate node{'s' * (v != 1)})" for k, v in excluded.items())


def curve_csv(p: Placement) -> str:
    """One row per sensor count: form, mean and per-target errors (um), the sensors' coordinates (m)."""
    targets = list(p.curve[0].held_out_mae_um)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["count", "form", "cv_mae_um", "held_out_mae_um", *(f"held_out_{t}" for t in targets),
                *(f"cv_{t}" for t in targets), "sensors"])
    for c in p.curve:
        pts = "; ".join(f"{s.name} (" + ", ".join(f"{v:.4f}" for v in s.xyz) + ")" for s in c.sensors)
        w.writerow([c.count, c.form, f"{c.cv_mean_um:.6g}", f"{c.held_out_mean_um:.6g}",
                    *(f"{c.held_out_mae_um[t]:.6g}" for t in targets), *(f"{c.cv_mae_um[t]:.6g}" for t in targets), pts])
    return buf.getvalue()
