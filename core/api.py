"""The public Python API: what a notebook or a script calls (``import gatetherm as gt``).

It composes the layers below for the common tasks and is itself composed by nothing but the
command line (``gatetherm.cli``), whose every command parses its arguments and calls a
function here::

    import gatetherm as gt
    case = gt.load_case("validation/examples/c_frame/case.toml")
    run = gt.run(case)                         # the case's own schedule, or schedule=...
    run.time, run["delta_um"]                  # numpy arrays
    run.field("T", t=run.time[-1])             # nodal fields on demand
    gt.plot.series(run, "delta_um", ax=ax)     # plots take ax= and return it
    run.write("out/")                          # what `gatetherm run` writes

The paper's frame is a case like any other: ``gt.gate_frame(dim=2)``.
"""
from __future__ import annotations

import dataclasses
import logging
import os
import time as _time
from pathlib import Path
from typing import Callable, Mapping

import numpy as np

from gatetherm import InputError
from gatetherm.process import configure
from gatetherm.studies.run.case import Case, load_case
from gatetherm.studies.run.frame_case import gate_frame
from gatetherm.studies.run.scenario import ScenarioRun, run_scenario
from gatetherm.studies.run.schedules import Schedule, condition_schedule, file_schedule

log = logging.getLogger(__name__)

STATE_BUDGET_BYTES = 512e6
"""Heat states a :class:`Run` keeps at every sample up to this size; beyond, only at the field times."""

__all__ = ["Case", "Run", "Schedule", "beam_coefficients", "check_placement", "check_rom", "check_schedules",
           "compensate", "condition", "configure", "diagnose", "gate_frame", "load_case", "place_sensors", "reduce",
           "run", "schedule_file", "write_placement", "write_reduction"]


def condition(number: int, case: Case | None = None, step_s: float = 60.0) -> Schedule:
    """The paper's condition ``number``: the oil supply unit's set points and pump states.

    Parameters
    ----------
    number : int
        1, 2 or 3 (``docs/paper.md``).
    case : Case, optional
        A frame case whose supply unit drives it (default: the shipped paper model's).
    step_s : float
        Sample interval, s.

    Returns
    -------
    Schedule
        5 h of ``oil_degC`` (°C), ``pump`` (0/1) and ``ambient_degC`` (°C) samples.
    """
    supply = getattr(getattr(case, "origin", None), "config", None)
    return condition_schedule(number, *(() if supply is None else (supply.supply,)), step_s=step_s)


def beam_coefficients(case: Case, source: str = "theory") -> tuple[float, float]:
    """The paper's predictor coefficients, δ = K_i (θ_A − θ_B) − K_C θ_C, of the paper's frame.

    Parameters
    ----------
    case : Case
        A frame from :func:`gate_frame` (a case file has no beam model).
    source : str
        ``"theory"``: the beam theory (eqs. 22–29) on the frame's dimensions; ``"fe"``: the FE
        frame under the theory's two load cases (θ_A − θ_B = 1 K over the heated height, +1 K on
        the tie bar), δ at the tips.

    Returns
    -------
    tuple of float
        K_i, K_C in µm/K.
    """
    from gatetherm.studies.control.methods import Settings, coefficients

    if source not in ("theory", "fe"):
        raise InputError("source", f"unknown source {source!r}", "choose 'theory' or 'fe'")
    ki, kc, _ = coefficients(case, None, Settings(k_source=source))
    return float(ki), float(kc)


def schedule_file(path: str | os.PathLike, case: Case, step_s: float = 60.0) -> Schedule:
    """A schedule file of the inputs ``case`` reads.

    Parameters
    ----------
    path : str or path
        A time-series file (``docs/data-format.md``) with a column for every input the case reads.
    case : Case
        The case it drives.
    step_s : float
        Sample interval, s (linear between the file's samples; a pump keeps its last one).

    Returns
    -------
    Schedule
    """
    return file_schedule(path, sorted(case.inputs()), case.held(), case.defaults, step_s)


@dataclasses.dataclass(frozen=True)
class Run:
    """A finished run of a case: its columns in the data format, and heat states for fields.

    ``run["delta_um"]`` is a column (numpy array), ``run.time`` the sample times (s);
    :meth:`field` gives a nodal field at a kept time, :meth:`write` the run directory."""

    case: Case
    scenario: ScenarioRun
    seconds: float
    """Wall time of the run, s (model build included)."""
    order_check: object = None
    """A linear-element case: its final outputs at P1 and P2 on the same mesh
    (:class:`~gatetherm.studies.run.order_check.OrderCheck`), if checked."""

    @property
    def time(self) -> np.ndarray:
        """Sample times, s from the start."""
        return self.scenario.columns["time_s"]

    @property
    def columns(self) -> dict[str, np.ndarray]:
        """Every column of the run in the data format (``docs/data-format.md``), name → array."""
        return self.scenario.columns

    def __getitem__(self, name: str) -> np.ndarray:
        if name not in self.columns:
            raise KeyError(f"{name!r}: columns are {', '.join(self.columns)}")
        return self.columns[name]

    @property
    def kept(self) -> list[float]:
        """Times (s) whose full state is kept: :meth:`field` answers at these."""
        return [t for t, _ in self.scenario.result.states]

    def state(self, t: float) -> tuple[float, np.ndarray | None]:
        """(time, heat state) kept nearest ``t`` (s); a time no state is kept near is an error."""
        from gatetherm.studies.run.output import nearest_state

        kept, U = nearest_state(self.scenario, t)
        step = float(np.median(np.diff(self.time))) if len(self.time) > 1 else 1.0
        if abs(kept - t) > 1e-6 * max(step, 1.0):
            raise InputError("t", f"no state kept at {t:g} s (nearest {kept:g} s)",
                             "run with keep=... listing the times whose fields you want")
        return kept, U

    def field(self, name: str, t: float | None = None) -> np.ndarray:
        """A nodal field at a kept time.

        Parameters
        ----------
        name : str
            ``"T"`` (°C), ``"u"`` (m, nodes × 3), ``"sigma_xx"`` … and ``"von_mises"`` (Pa).
        t : float, optional
            Time, s (default: the last sample); one of :attr:`kept`.

        Returns
        -------
        numpy.ndarray
            One value (a row for ``"u"``) per mesh node.
        """
        from gatetherm.studies.run.output import nodal_fields

        t = float(self.time[-1]) if t is None else float(t)
        _, U = self.state(t)
        fields = nodal_fields(self.scenario.model, U, stress=name not in ("T", "u"))
        if name not in fields:
            raise KeyError(f"{name!r}: fields are {', '.join(fields)}")
        return fields[name]

    def summary(self) -> dict:
        """What ``summary.json`` holds: the case, its size, every probe and relative displacement
        at the last sample, and δ's figures where the case has a δ."""
        from gatetherm.studies.run.output import probe_summary
        from gatetherm.studies.run.simulate import delta_figures

        c, p = self.case, self.case.problem
        out = {"case": c.name, "file": c.source, "dim": p.dim, "order": p.order,
               "analysis": ("prescribed temperature" if p.thermal else "mechanical") if not p.heat else
               ("transient" if c.time else "steady"),
               "nodes": len(c.mesh.points), "elements": len(c.mesh.cells), "schedule": self.scenario.schedule.label,
               "effects": self.scenario.effects.describe(), "wall_time_s": round(self.seconds, 2),
               "march_s": round(self.scenario.result.seconds, 2), **probe_summary(p, self.columns)}
        if "delta_um" in self.columns and len(self.time) > 1:
            out.update(delta_figures(self.time, self["delta_um"]))
        if self.order_check is not None:
            out["order_check"] = self.order_check.summary()
        return out

    def write(self, out: str | os.PathLike, pictures: bool = True, fields_every: float | None = None) -> dict:
        """Write the run directory that ``gatetherm run`` writes.

        Parameters
        ----------
        out : str or path
            The folder: ``timeseries.csv``, ``summary.json``, ``fields/`` (ParaView) and the pictures.
        pictures : bool
            Write ``channels.png`` and ``deformed.png``.
        fields_every : float, optional
            Interval of the fields, s (default: the case's field interval); the last sample always.

        Returns
        -------
        dict
            The summary (:meth:`summary`).
        """
        from gatetherm.studies.run.output import write_json, write_run

        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        every = fields_every or (self.case.time.fields if self.case.time else 1.0)
        times = [float(t) for t in self.time]
        fields = {t for t in times if abs(t / every - round(t / every)) < 1e-9} | {times[-1]}
        fields &= set(self.kept)
        sched = self.scenario.schedule
        meta = {"source": "gatetherm", "case": self.case.source, "name": self.case.name, "dim": str(self.case.dim),
                "schedule": sched.label, **({"condition": str(sched.condition)} if sched.condition else {})}
        picture = self._picture_time()
        solved = write_run(out, self.scenario, meta, fields, (picture,) if pictures and picture is not None else ())
        if pictures:
            from gatetherm.validation.plots.run import write_pictures

            write_pictures(self.scenario, out, self.case.name, picture, solved)
        summary = self.summary()
        write_json(out / "summary.json", summary)
        return summary

    def _picture_time(self) -> float | None:
        """When the deformed picture shows the case: δ's first peak where it has one, else the end."""
        if self.scenario.model.elastic is None:
            return None
        figs = self.summary() if "delta_um" in self.columns and len(self.time) > 1 else {}
        peak = figs.get("first_peak_min")
        return peak * 60.0 if peak is not None else float(self.time[-1])



def run(case: Case, schedule: Schedule | None = None, effects: Mapping[str, float] | None = None, *,
        keep=None, on_step: Callable[[int, int], None] | None = None, check_order: bool = False) -> Run:
    """Run ``case``.

    Parameters
    ----------
    case : Case
        From :func:`load_case` or :func:`gate_frame`.
    schedule : Schedule, optional
        What drives it (default: its own: the case file's ``[time]`` and schedule, or the frame's
        condition); :func:`condition`, :func:`schedule_file`.
    effects : mapping, optional
        Effects switched on, ``{key: value}`` (``gatetherm diagnose --list-effects``).
    keep : sequence of float, optional
        Times (s) whose heat state is kept for :meth:`Run.field` (default: every sample while they
        take less than :data:`STATE_BUDGET_BYTES`, else the case's field times and the end).
    on_step : callable, optional
        ``on_step(i, n)`` after each of the ``n`` samples.
    check_order : bool
        A linear-element case on a small mesh: solve its final state once more with quadratic
        elements and warn (one log line naming the output and the fix) where they differ by more
        than :data:`gatetherm.studies.run.order_check.TOLERANCE`.

    Returns
    -------
    Run
    """
    t0 = _time.perf_counter()
    schedule = case.schedule if schedule is None else schedule
    times = [float(t) for t in schedule.times]
    if keep is None:
        n = len(case.mesh.points) * case.problem.order ** case.dim
        every = case.time.fields if case.time else 1.0
        keep = times if len(times) * n * 8 <= STATE_BUDGET_BYTES else \
            [t for t in times if abs(t / every - round(t / every)) < 1e-9] + [times[-1]]
    scenario = run_scenario(case, schedule, effects, keep_times=sorted(set(map(float, keep)) | {times[-1]}),
                            on_step=on_step)
    check = None
    if check_order:
        from gatetherm.studies.run.order_check import order_check

        check = order_check(case, scenario)
    return Run(case, scenario, _time.perf_counter() - t0, check)


def reduce(case: Case, states: int = 30):
    """The reduced heat model of ``case`` (its effects on): balanced truncation.

    Parameters
    ----------
    case : Case
        Any case with a transient heat solve.
    states : int
        States of the reduced model.

    Returns
    -------
    Reduction
        ``.rom`` the :class:`~gatetherm.solvers.rom.ReducedModel` (``gatetherm.studies.run.reduce.write_rom``
        keeps it as ``rom.npz``), with the error bounds, Hankel singular values and timings of its making.
    """
    from gatetherm.studies.run.reduce import build_rom

    return build_rom(case, states)


def check_schedules(case: Case) -> list[Schedule]:
    """What a reduced model of ``case`` is checked on (:func:`check_rom`'s default).

    Parameters
    ----------
    case : Case

    Returns
    -------
    list of Schedule
        Its own schedule and, where the case reads only the inputs they drive (the oil supply,
        the pump, the room), the paper's conditions 1-3.
    """
    from gatetherm.solvers.frame import AMBIENT, PUMP, SUPPLY

    out = [case.schedule] if len(case.schedule.times) > 1 else []
    if case.inputs() and case.inputs() <= {SUPPLY, PUMP, AMBIENT}:
        out += [condition(n, case) for n in (1, 2, 3) if condition(n, case).label != case.schedule.label]
    return sorted(out, key=lambda s: (s.condition is None, s.condition or 0))


def check_rom(case: Case, rom, schedules=None) -> list:
    """The reduced model ``rom`` of ``case`` against full FE runs.

    Parameters
    ----------
    case : Case
        The case it was reduced from.
    rom : ReducedModel
        ``reduce(case).rom``, or one read with ``gatetherm.studies.run.reduce.load_rom``.
    schedules : list of Schedule, optional
        What to run (default :func:`check_schedules`).

    Returns
    -------
    list
        Per schedule, the largest error of every output (δ in µm, temperatures in K).
    """
    from gatetherm.studies.run.reduce import check
    from gatetherm.studies.run.scenario import ScenarioCache

    return check(case, rom, check_schedules(case) if schedules is None else schedules, ScenarioCache())


def write_reduction(out: str | os.PathLike, red, checks, case: Case, states: int, seconds: float) -> dict:
    """Write a reduction: ``out/rom.npz``, ``out/rom.key`` and, last, ``out/summary.json``.

    Parameters
    ----------
    out : str or path
        The folder.
    red : Reduction
        :func:`reduce`'s result.
    checks : list
        :func:`check_rom`'s result (may be empty).
    case : Case
        The case it was reduced from.
    states : int
        Its states (in the key that later runs reuse it by).
    seconds : float
        Wall time of the reduction, s.

    Returns
    -------
    dict
        The summary: states, bounds (µm), the static-gain error, timings and checks.
    """
    from gatetherm.studies.run.output import write_json
    from gatetherm.studies.run.reduce import rom_key, save_rom

    out = Path(out)
    save_rom(red.rom, rom_key(case, states), out)
    summary = {"states": red.rom.states, "dim": case.dim, "model": case.source, "nodes_full": int(red.basis.shape[0]),
               "inputs": [dataclasses.asdict(u) for u in red.rom.inputs], "outputs": list(red.rom.outputs),
               "modes": list(red.rom.modes), "error_bound_bt": red.error_bound,
               "static_gain_error": red.static_gain_error, "hankel_singular_values": red.hankel,
               "reduction_seconds": round(seconds, 2), "seconds": {k: round(v, 2) for k, v in red.seconds.items()},
               "checks": {c.schedule: dataclasses.asdict(c) for c in checks}}
    if checks:
        summary["max_delta_error_um"] = max(c.max_delta_error_um for c in checks)
    write_json(out / "summary.json", summary)
    return summary


def compensate(series, case: Case | None = None, method: str = "paper", *, actuator="case", **settings):
    """Compensate a run: predict δ and drive the actuator with the command.

    Parameters
    ----------
    series : TimeSeries or Run
        The run (θ_A, θ_B, θ_C and δ, the uncompensated thermal displacement; for ``rom`` the
        inputs the reduced model reads): a :class:`Run`, or a measured file read with
        ``gatetherm.studies.run.timeseries.read_timeseries``.
    case : Case, optional
        The model (default: a Run's own case): the paper method's beam-theory or FE K, the mlr
        training run (its own schedule) and the rom reduced model come from it.
    method : str
        ``"paper"``, ``"mlr"`` or ``"rom"``.
    actuator : ActuatorParams, None or "case"
        The actuator in the loop (``"case"``: the case's ``[actuator]``, the frame's piezo; None:
        ideal, the command sent to the control as an offset).
    **settings
        Fields of :class:`gatetherm.studies.control.methods.Settings` (``Ki``, ``Kc``,
        ``k_source``, ``states``, ``params``, ``control``, ``sensors``); ``rom=`` a reduced model.

    Returns
    -------
    Compensation
        ``.loop`` (the compensated δ, the strokes, the updates), ``.summary`` (bands, updates).
    """
    from gatetherm.studies.control.methods import Settings, compensate as methods_compensate

    if isinstance(series, Run):
        case = case or series.case
        series = series.scenario.series({"source": "gatetherm.api.compensate"})
    rom = settings.pop("rom", None)
    chosen = (case.actuator if case is not None else None) if actuator == "case" else actuator
    return methods_compensate(series, case, Settings(method=method, **settings), chosen, rom=rom)


def diagnose(case: Case, measured, **settings):
    """Where ``case`` and a measured run disagree, and the missing pieces that explain it.

    Parameters
    ----------
    case : Case
        The model: a case file's, or the paper frame's.
    measured : TimeSeries or path
        The measurement: every input the case reads, and the channels to compare.
    **settings
        Fields of :class:`gatetherm.studies.diagnosis.discrepancy.Settings` (``train_fraction``,
        ``effects``, ``parameters``, ``sensors``, ``max_pieces``, ``uncertain``: dimensions to try
        besides those the case marks, e.g. ``("mesh.parameters.table_height",)`` …).

    Returns
    -------
    Diagnosis
        ``.verdict``, ``.pieces`` (each with its fitted value), ``.groups`` (what the data cannot
        tell from a named piece, and what would), ``.stand_ins`` (pieces that make the model fit
        but fail a model-form check), ``.cause`` (what kind of cause would fit what stays
        unexplained), ``.summary()``; docs/diagnosis.md.
    """
    from gatetherm.studies.diagnosis.discrepancy import Settings, diagnose as run_diagnosis
    from gatetherm.studies.run.timeseries import TimeSeries, read_timeseries

    ts = measured if isinstance(measured, TimeSeries) else read_timeseries(measured, required=("time_s",))
    return run_diagnosis(case, ts, Settings(**settings))


def place_sensors(case: Case, count: int = 3, *, schedules=None, held_out=None, **settings):
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
        ``boundaries`` (names whose nodes are the candidates; default the outer surface),
        ``spacing_m`` (thin the candidates to this spacing, m), ``exclude`` (boxes no sensor may
        lie in: ``(low corner, high corner)`` pairs, m), ``min_distance_m`` (least distance between
        two sensors, m), ``noise_K`` (standard deviation of each sensor's noise, K; default 0.05),
        ``loads`` (generated training loads, default 20), ``held_out_loads``, ``ranges``
        ({input: (lo, hi)} in the input's unit, e.g. °C, W), ``duration_s``, ``step_s``, ``seed``,
        ``states``, ``neighbours`` (of each screening pivot; None: no screening): the fields of
        :class:`gatetherm.studies.sensors.place.PlacementSettings`; and ``form`` (``auto``,
        ``static``, ``dynamic``), ``max_inputs``, ``min_gain`` of the error-model family.

    Returns
    -------
    Placement
        ``.sensors`` (name, node, coordinates in m, boundary), ``.model`` (the errormodel
        ``ErrorModel``), ``.curve`` (per count: form, leave-one-load-out and held-out MAE per target,
        µm), ``.failed`` (held-out MAE with one sensor lost, µm), ``.signals`` (the same family given
        the case's θ_A, θ_B, θ_C mean, if it has them), ``.stopped`` (why the curve stops short).

    Raises
    ------
    InputError
        A setting out of range, an unknown boundary or input, no candidate left, a case without
        relative displacements.
    """
    from gatetherm.studies.errormodel.fit import FitParams
    from gatetherm.studies.sensors.candidates import Box
    from gatetherm.studies.sensors.place import PlacementSettings, place_sensors as place

    fit = {k: settings.pop(k) for k in ("form", "max_inputs", "min_gain") if k in settings}
    if isinstance(settings.get("ranges"), Mapping):
        settings["ranges"] = tuple((k, float(lo), float(hi)) for k, (lo, hi) in settings["ranges"].items())
    if "exclude" in settings:
        settings["exclude"] = tuple(b if isinstance(b, Box) else Box(*map(tuple, b)) for b in settings["exclude"])
    if "boundaries" in settings:
        b = settings["boundaries"]
        settings["boundaries"] = (b,) if isinstance(b, str) else tuple(b)
    return place(case, PlacementSettings(count=count, fit=FitParams(**fit), **settings), schedules, held_out)


def check_placement(case: Case, placement):
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

    return fe_check(case, placement)


def write_placement(out: str | os.PathLike, placement, case: Case, check=None, extra: Mapping | None = None) -> dict:
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
    from gatetherm.validation.plots.api import sensor_curve, sensors

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    save(sensor_curve(placement, ax=figure((6.0, 3.6))), out / "curve.png")
    save(sensors(placement, case, ax=figure((6.0, 5.0))), out / "machine.png")
    more = {"mesh_nodes": len(case.mesh.points), **(extra or {}), **({"fe_check": check.summary()} if check else {})}
    return placement.write(out, extra=more)
