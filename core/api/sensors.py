"""Sensor placement: chosen, checked by full FE runs, written (:mod:`gatetherm.api`)."""
from __future__ import annotations

import os
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping, Sequence

from gatetherm import InputError
from gatetherm.api.boundary import settings_argument
from gatetherm.api.run import Case, Schedule, _case
from gatetherm.checks import POSITIVE, Range, argument, number_argument, whole_argument
from gatetherm.studies.sensors.check import FECheck
from gatetherm.studies.sensors.result import NO_SENSOR, Placement

PUBLIC = ("SensorStudy", "check_placement", "place_sensors", "sensor_study", "write_placement")

SPAN = Range(-1e9, 1e9)
"""What a bound of ``ranges`` may be, in the input's unit (°C, W, 1/min …)."""


def place_sensors(case: Case, count: int = 3, *, schedules: Sequence[Schedule] | None = None,
                  held_out: Sequence[Schedule] | None = None, on_progress=None, **settings):
    """Where to put ``count`` thermocouples on ``case``: the surface points whose temperatures
    predict every relative displacement best on held-out duty cycles (docs/sensors.md).

    The case is reduced once (``states`` states); every training and held-out load is marched
    through the reduced model; the candidates are screened by column-pivoted QR of their
    output-weighted temperature snapshots; 1 ... ``count`` sensors and the error-model family
    (static, or with input lags) are chosen greedily, with exchanges, by leave-one-load-out error
    on the training loads, and each size is scored on the held-out loads.

    Parameters
    ----------
    case : Case
        Any case with a heat solve and relative displacements: a case file's, or the paper's frame.
    count : int
        Sensors to place; the held-out error is reported for 1 ... ``count``.
    schedules : sequence of Schedule, optional
        Training duty cycles (:func:`schedule_file`) instead of the generated family; the case's
        own schedule is added unless it is held out.
    held_out : sequence of Schedule, optional
        Loads to judge on (default: the paper's conditions 1-3 for a case driven by the frame's
        inputs, else ``held_out_loads`` generated ones of their own seed).
    **settings
        ``boundaries`` (names whose nodes are the candidates; default the outer surface; the
        regions and boundaries of the case's ``[sensors] exclude`` are never candidates),
        ``spacing_m`` (thin the candidates to this spacing, m), ``exclude`` (boxes no sensor may
        lie in: ``(low corner, high corner)`` pairs, m), ``min_distance_m`` (least distance between
        two sensors, m), ``noise_K`` (standard deviation of each sensor's noise, K; default 0.05),
        ``loads`` (generated training loads, default 20), ``held_out_loads``, ``ranges``
        ({input: (lo, hi)} in the input's unit, e.g. °C, W), ``duration_s``, ``step_s``, ``seed``,
        ``states``, ``neighbours`` (of each screening pivot; None: no screening): the fields of
        :class:`gatetherm.studies.sensors.place.PlacementSettings`; and ``form`` (``auto``,
        ``static``, ``dynamic``), ``max_inputs``, ``min_gain`` of the error-model family.
    on_progress : callable, optional
        ``on_progress(i, n)`` after the reduction, each load marched and the selection (``i`` up to ``n``).

    Returns
    -------
    Placement
        ``.sensors`` (name, node, coordinates in m, boundary), ``.model`` (the errormodel
        ``ErrorModel``), ``.curve`` (per count: form, leave-one-load-out and held-out MAE per target,
        µm), ``.failed`` (held-out MAE with one sensor lost, µm), ``.signals`` (the same family given
        the case's θ_A, θ_B, θ_C mean, if it has them), ``.stopped`` (why the curve stops short),
        ``.candidates.excluded`` (per part that cannot carry a sensor, the candidate nodes it took away).

    Raises
    ------
    InputError
        A setting out of range, an unknown boundary or input, no candidate left, a case without
        relative displacements.
    """
    from gatetherm.frame.conditions import paper_conditions
    from gatetherm.studies.errormodel.fit import FitParams
    from gatetherm.studies.sensors.candidates import Box
    from gatetherm.studies.sensors.place import PlacementSettings, place_sensors as place

    _case(case)
    count = whole_argument("count", count, Range(1, 50), "e.g. 3")
    for name, given in (("schedules", schedules), ("held_out", held_out)):
        if given is not None and not (isinstance(given, (list, tuple)) and all(isinstance(x, Schedule) for x in given)):
            raise TypeError(f"{name}: got {type(given).__name__}, expected a list of Schedule or None; make them with "
                            "gt.schedule_file(path, case)")
    if "seed" in settings:
        settings["seed"] = whole_argument("seed", settings["seed"], Range(0, 2**32 - 1), "e.g. 0")
    fit = {k: settings.pop(k) for k in ("form", "max_inputs", "min_gain") if k in settings}
    settings_argument(PlacementSettings, {k: v for k, v in settings.items() if k != "fit"}, "place_sensors")
    if isinstance(settings.get("ranges"), Mapping):
        settings["ranges"] = tuple((k, *(number_argument(f"ranges[{k!r}]", v, SPAN, "give LO, HI in the input's unit")
                                         for v in (lo, hi))) for k, (lo, hi) in settings["ranges"].items())
    if "exclude" in settings:
        try:
            settings["exclude"] = tuple(b if isinstance(b, Box) else Box(*map(tuple, b)) for b in settings["exclude"])
        except TypeError:
            raise TypeError(f"exclude: got {settings['exclude']!r:.60}, expected (low corner, high corner) pairs; "
                            "e.g. exclude=[((0, 0), (0.1, 0.2))]") from None
        for i, box in enumerate(settings["exclude"]):
            for v in (*box.lo, *box.hi):
                number_argument(f"exclude[{i}]", v, fix="give a box's low and high corners, m")
    if "boundaries" in settings:
        b = settings["boundaries"]
        settings["boundaries"] = (b,) if isinstance(b, str) else tuple(b)
    if on_progress is not None and not callable(on_progress):
        raise TypeError(f"on_progress: got {type(on_progress).__name__}, expected a callable on_progress(i, n) or None")
    held_out = held_out or paper_conditions(case) or None  # the paper's conditions 1-3 for the frame's inputs
    return place(case, PlacementSettings(count=count, fit=FitParams(**fit), **settings), schedules, held_out,
                 on_progress=on_progress)


def check_placement(case: Case, placement: Placement):
    """The independent check of a :func:`place_sensors` result by full FE runs (no reduced model):
    the case made again with the chosen points as ``[probes]``, every training and held-out load
    run in full, the placement model's terms refitted by least squares on the training runs and
    scored on the held-out ones.

    Parameters
    ----------
    case : Case
        The case the placement was made for.
    placement : Placement
        What :func:`place_sensors` returns.

    Returns
    -------
    FECheck
        ``.held_out_mae_um`` against ``.placement_mae_um`` per target (µm) and their ``.ratio``,
        the largest temperature error of the reduced model at the chosen points over the held-out
        loads (``.temperature_error_K``, K), ``.runs``, ``.seconds``.
    """
    from gatetherm.studies.sensors.check import fe_check
    from gatetherm.studies.sensors.result import Placement

    _case(case)
    argument("placement", placement, Placement, "a Placement", "what gt.place_sensors(case) returns")
    return fe_check(case, placement)


def write_placement(out: str | os.PathLike, placement: Placement, case: Case, check: FECheck | None = None,
                    extra: Mapping | None = None) -> dict:
    """Write what ``gatetherm sensors`` writes into ``out``: ``sensors.toml`` (the chosen points as
    ``[probes]``), ``model.json`` (the fitted error model, as ``gatetherm errormodel fit``
    writes it), ``curve.csv``, ``curve.png`` (held-out error against the number of sensors),
    ``machine.png`` (the machine with the chosen points and the case's thermocouples) and, last,
    ``summary.json`` (with the mesh's node count, the FE check's figures if ``check`` is given,
    and ``extra``).

    Parameters
    ----------
    out : path
        The directory (made if missing).
    placement : Placement
        What :func:`place_sensors` returns.
    case : Case
        The case it was made for.
    check : FECheck, optional
        What :func:`check_placement` returns.
    extra : mapping, optional
        More entries of ``summary.json``.

    Returns
    -------
    dict
        The summary.
    """
    from gatetherm.validation.plots import figure, save
    from gatetherm.studies.sensors.result import Placement
    from gatetherm.validation.plots.api import sensor_curve, sensors

    argument("placement", placement, Placement, "a Placement", "what gt.place_sensors(case) returns")
    _case(case)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    save(sensor_curve(placement, ax=figure((6.0, 3.6))), out / "curve.png")
    save(sensors(placement, case, ax=figure((6.0, 5.0))), out / "machine.png")
    more = {"mesh_nodes": len(case.mesh.points), **(extra or {}), **({"fe_check": check.summary()} if check else {})}
    return placement.write(out, extra=more)


def sensor_study(case: Case | str | os.PathLike, count: int = 3, *, schedules: Sequence[Schedule | str | os.PathLike] = (),
                 held_out: Sequence[Schedule | str | os.PathLike] = (), check: bool = False, mesh_factor: float = 1.0,
            on_progress=None, **settings) -> SensorStudy:
    """What ``gatetherm sensors`` does: :func:`place_sensors` on a case (or a case file), and
    optionally :func:`check_placement`; the result writes the command's files and its summary.

    Parameters
    ----------
    case : Case or path
        A case (:func:`load_case`, :func:`gate_frame`) or a case file's path (read with ``mesh_factor``).
    count : int
        Sensors to place.
    schedules, held_out : sequence of Schedule or path
        Training and held-out duty cycles (paths are read with :func:`schedule_file`).
    check : bool
        Also check the placement by full FE runs (:func:`check_placement`).
    mesh_factor : float
        With a case file's path: its element sizes times this.
    on_progress : callable, optional
        ``on_progress(i, n)`` as the placement goes (``i`` up to ``n``).
    **settings
        As :func:`place_sensors`.

    Returns
    -------
    SensorStudy
        ``.placement``, ``.check``, ``.seconds`` (s); ``.write(out)`` writes :data:`OUTPUTS`,
        ``.summary(out)`` the command's lines.
    """
    from gatetherm.api.run import load_case, schedule_file

    path = isinstance(case, (str, os.PathLike))
    number_argument("mesh_factor", mesh_factor, POSITIVE, "e.g. 0.5 for elements half as large")
    if not path and mesh_factor != 1.0:
        raise InputError("mesh_factor", "goes with a case file's path only (a Case is meshed already)",
                         "give the case file's path, or gt.load_case(path, mesh_factor)")
    case = load_case(case, mesh_factor) if path else case
    _case(case)
    names = [str(f) for f in (*schedules, *held_out) if isinstance(f, (str, os.PathLike))]
    schedules = [schedule_file(f, case) if isinstance(f, (str, os.PathLike)) else f for f in schedules or ()]
    held_out = [schedule_file(f, case) if isinstance(f, (str, os.PathLike)) else f for f in held_out or ()]
    t0 = time.perf_counter()
    placement = place_sensors(case, count, schedules=schedules or None, held_out=held_out or None,
                              on_progress=on_progress, **settings)
    seconds = time.perf_counter() - t0
    fe = check_placement(case, placement) if check else None
    config = [] if path or not case.source or case.files else [case.source]
    return SensorStudy(placement, case, fe, seconds, tuple(config + [str(f) for f in case.files] + names))


OUTPUTS = ("sensors.toml", "model.json", "curve.csv", "curve.png", "machine.png", "summary.json")
"""What :meth:`SensorStudy.write` (``gatetherm sensors``) writes into its output directory."""


@dataclass(frozen=True)
class SensorStudy:
    """What :func:`sensor_study` returns: a placement, its optional FE check, and how long it took."""

    placement: object
    """The :func:`place_sensors` result (``.sensors``, ``.curve``, ``.model`` …)."""
    case: Case
    """The case it was made for."""
    check: object = None
    """The :func:`check_placement` result, or None."""
    seconds: float = 0.0
    """Wall time of the placement, s."""
    files: tuple[str, ...] = ()
    """The input files (kept by :meth:`write`: never overwritten)."""

    def write(self, out: str | os.PathLike) -> dict:
        """Write :data:`OUTPUTS` into ``out`` (:func:`write_placement`), replacing the previous
        run's only on success; returns the summary."""
        from gatetherm.outdir import output_dir

        with output_dir(out, OUTPUTS, keep=self.files) as stage:
            summary = write_placement(stage, self.placement, self.case, self.check,
                                      {"seconds_total": round(self.seconds, 2)})
        return summary

    def summary(self, out: str | os.PathLike | None = None) -> str:
        """What ``gatetherm sensors`` prints: the sensors per count with their held-out errors (µm),
        the stop, notes, the loss of each sensor, the case's own thermocouples, the FE check;
        ``out``: the folder written, for the first line."""
        p, check = self.placement, self.check
        excluded = dict(getattr(p.candidates, "excluded", None) or {})
        lines = [f"{len(p.sensors)} sensors of {len(p.candidates)} candidates ({len(p.shortlist)} "
                 f"screened) on a mesh of {len(self.case.mesh.points)} nodes, placed in {self.seconds:.1f} s from "
                 f"{len(p.training)} training loads, judged on {len(p.held_out)} held-out loads; wrote {out}/"
                 "sensors.toml, model.json, curve.csv, curve.png, machine.png, summary.json"]
        if excluded:
            lines.append(f"excluded ({NO_SENSOR}): "
                         + ", ".join(f"{k} ({v} candidate nodes left out)" for k, v in excluded.items()))
        for c in p.curve:
            errs = ", ".join(f"{k} {v:.3g}" for k, v in c.held_out_mae_um.items())
            where = "; ".join(f"{s.name} ({', '.join(f'{v:.3f}' for v in s.xyz)}) on {s.boundary}" for s in c.sensors)
            lines.append(f"K={c.count} {c.form}: held-out MAE {errs} um (leave-one-load-out {c.cv_mean_um:.3g} um); "
                         f"{where}")
        if p.stopped:
            lines.append(f"stopped: {p.stopped}")
        lines += [f"note: {note}" for note in p.notes]
        for name, errs in p.failed.items():
            lines.append(f"{name} failed (model refitted without it): held-out MAE "
                         + ", ".join(f"{k} {v:.3g}" for k, v in errs.items()) + " um")
        if p.signals:
            sig = p.signals
            lines.append(f"the case's thermocouples θ_A, θ_B, θ_C ({sig['form']}): held-out MAE "
                         + ", ".join(f"{k} {v:.3g}" for k, v in sig["held_out_mae_um"].items()) + " um")
        if check:
            lines.append(f"FE check ({check.runs} runs, {check.seconds:.1f} s): held-out MAE "
                         + ", ".join(f"{k} {v:.3g} um ({check.ratio[k]:.3f} of the reduced model's)"
                                     for k, v in check.held_out_mae_um.items())
                         + f"; sensor temperatures within {check.temperature_error_K:.2g} K of FE")
            lines += [f"warning: {check.warning}"] if check.warning else []
        return "\n".join(lines)
