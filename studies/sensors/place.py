"""Where to put the thermocouples: :func:`place_sensors`, from the case's reduced model.

1. Candidates (:mod:`.candidates`): outer-surface (or named-boundary) nodes, thinned, minus boxes
   and the parts the case says cannot carry a sensor (``[sensors] exclude``).
2. Loads (:mod:`.loads`): training = the case's schedule (unless it is held out) and a generated
   family of duty cycles (or given schedules); held out = given schedules (the API gives the
   paper's conditions 1-3 for a case driven by the paper frame's inputs: oil supply, pump, room:
   :func:`gatetherm.frame.conditions.paper_conditions`), else a generated family of its own seed.
3. The reduced model (:func:`gatetherm.studies.run.reduce.build_rom`) marches every load once;
   each candidate's temperature is its basis row times the states (:mod:`.reduced`); the targets
   are every relative displacement of the case; every sensor reading gets its noise
   (:func:`.screen.noise`).
4. Screening (:mod:`.screen`), then the error-model family chooses 1 ... ``count`` sensors by
   leave-one-load-out error (:mod:`.greedy`); each size's model (:mod:`.models`) is scored on the
   held-out loads. The curve stops early when one more sensor lowers the leave-one-load-out
   error by less than ``min_gain``; the placement says so.
5. With the chosen set: the error with each sensor failed (the model refitted without it), and the
   same family given the case's own thermocouples ([signals] θ_A, θ_B, θ_C mean), if any.
"""
from __future__ import annotations

import dataclasses
import logging
import time
from dataclasses import dataclass

import numpy as np

from gatetherm import InputError
from gatetherm.studies.errormodel.fit import FitParams
from gatetherm.studies.run.reduce import build_rom
from gatetherm.studies.run.scenario import ScenarioCache, prepare
from gatetherm.studies.run.simulate import column
from gatetherm.studies.sensors import greedy
from gatetherm.studies.sensors.candidates import Box, boundary_names, candidates as find_candidates, on_rotating, \
    seated_nodes
from gatetherm.studies.sensors.loads import duty_cycles, input_ranges
from gatetherm.studies.sensors.models import error_model, held_out_mae, lag_columns, lag_terms, settings_of
from gatetherm.studies.sensors.reduced import candidate_rows, simulate
from gatetherm.studies.sensors.result import CurvePoint, Placement, Sensor
from gatetherm.studies.sensors.screen import load_key, noise, shortlist as screen

log = logging.getLogger(__name__)

DEFAULT_DURATION_S, DEFAULT_STEP_S = 6 * 3600.0, 60.0
"""Generated loads of a case without a transient schedule: 6 h in steps of 60 s."""


@dataclass(frozen=True)
class PlacementSettings:
    """Settings of :func:`place_sensors`."""

    count: int = 3
    """Sensors to place; the curve runs from 1 to this."""
    boundaries: tuple[str, ...] = ()
    """Named boundaries whose nodes are candidates; empty: the outer surface."""
    spacing_m: float = 0.0
    """Thin the candidates to this spacing, m (0: every node)."""
    exclude: tuple[Box, ...] = ()
    """Boxes no sensor may lie in."""
    min_distance_m: float = 0.0
    """Least distance between two chosen sensors, m."""
    noise_K: float = 0.05
    """Standard deviation of every sensor's noise, K (0: none)."""
    loads: int = 20
    """Generated training loads (none when ``schedules`` are given)."""
    held_out_loads: int = 4
    """Generated held-out loads, where none are given and the case has no paper conditions."""
    ranges: tuple[tuple[str, float, float], ...] = ()
    """(input, lo, hi) of the generated loads; default: the span over the schedules the case knows."""
    duration_s: float | None = None
    """Length of a generated load, s; default: the case's schedule's (6 h if it has none)."""
    step_s: float | None = None
    """Sample step of a generated load, s; default: the case's schedule's (60 s if it has none)."""
    seed: int = 0
    """Seed of the generated loads and of the noise."""
    states: int = 30
    """States of the reduced model."""
    neighbours: int | None = 4
    """Nearest candidates added to each screening pivot; None: no screening (every candidate)."""
    fit: FitParams = FitParams()
    """The error-model family: ``form`` (auto, static, dynamic), ``max_inputs``, lag grid, ``min_gain``."""

    def __post_init__(self):
        checks = (("count", self.count >= 1, "e.g. 3"), ("noise_K", self.noise_K >= 0, "e.g. 0.05"),
                  ("spacing_m", self.spacing_m >= 0, "e.g. 0.02"), ("min_distance_m", self.min_distance_m >= 0, "0.05"),
                  ("loads", self.loads >= 0, "e.g. 20"), ("held_out_loads", self.held_out_loads >= 1, "e.g. 4"),
                  ("states", 2 <= self.states <= 200, "e.g. 30"),
                  ("neighbours", self.neighbours is None or self.neighbours >= 0, "e.g. 4"),
                  ("form", self.fit.form in ("auto", "static", "dynamic"), "auto, static or dynamic"))
        for name, ok, fix in checks:
            if not ok:
                raise InputError(name, f"{getattr(self, name, self.fit.form)!r} is not admissible", fix)


def _loads(case, s: PlacementSettings, schedules, held_out):
    known = list(held_out) if held_out else []
    own = [case.schedule] if len(case.schedule.times) > 1 else []
    ranges = input_ranges(case, own + known, dict((n, (lo, hi)) for n, lo, hi in s.ranges))
    ref = own[0].times if own else None
    duration = s.duration_s or (float(ref[-1]) if ref is not None else DEFAULT_DURATION_S)
    step = s.step_s or (float(ref[1] - ref[0]) if ref is not None else DEFAULT_STEP_S)
    held = known or duty_cycles(ranges, s.held_out_loads, duration, step, s.seed, "held-out")
    train = list(schedules) if schedules else duty_cycles(ranges, s.loads, duration, step, s.seed)
    labels = {h.label for h in held}
    train = [x for x in own if x.label not in labels] + train
    if len(train) < 2:
        raise InputError("training loads", f"{len(train)} given", "give at least two (--loads 20)")
    return train, held, ranges


def _names(case, count: int) -> list[str]:
    taken = {p.name for p in case.problem.probes}
    return [n for n in (f"S{k}" for k in range(1, count + len(taken) + 2)) if n not in taken][:count]


def _signal_columns(case):
    """The case's thermocouples as output columns: θ_A, θ_B and the probes whose mean is θ_C."""
    s, p = case.problem.signals, case.problem
    if not (s.theta_A and s.theta_B and s.theta_C):
        return None
    return {"theta_A_degC": [("theta_A_degC", s.theta_A)], "theta_B_degC": [("theta_B_degC", s.theta_B)],
            "theta_C_degC": [(column(p, ("T", c))[0], c) for c in s.theta_C]}


def _ticker(on_progress, n: int):
    """A pass-through ``tick(x) -> x`` that reports the next of ``n`` steps to ``on_progress``."""
    done = [0]

    def tick(x):
        if on_progress is not None:
            done[0] += 1
            on_progress(done[0], n)
        return x
    return tick


def supported_faces(case, named=()) -> tuple[str, ...]:
    """The boundaries a support holds (bolted to a bed, resting on a foundation or a slide, a symmetry
    plane), but those ``named`` as the candidates: no thermocouple goes between a face and what holds it.
    Their nodes shape the screening (the field is there) and are never chosen."""
    return tuple(dict.fromkeys(b.boundary for b in case.problem.supports
                               if b.boundary in case.mesh.boundaries and b.boundary not in named))


def _screened(case, s: PlacementSettings, X, Y, rows, cand):
    """The shortlist (indices into the candidates; all of them with ``neighbours=None``), the candidates'
    rows and the candidates, without the nodes of the :func:`supported_faces`: screened with the field
    there, never chosen; the nodes of their edges stay, named by their free face."""
    sl = np.arange(len(cand)) if s.neighbours is None else screen(X, Y, rows, cand.xyz, s.noise_K, s.neighbours)[0]
    seats = supported_faces(case, s.boundaries)
    keep, cand = cand.without(seated_nodes(case.mesh, seats))
    if not keep[sl].any():
        raise InputError("--candidates", "every candidate lies on a face a support holds", "name other boundaries")
    cand = dataclasses.replace(cand, boundary=boundary_names(case.mesh, cand.nodes, seats)) if seats else cand
    return (np.cumsum(keep) - 1)[sl[keep[sl]]], rows[keep], cand


def place_sensors(case, settings: PlacementSettings = PlacementSettings(), schedules=None, held_out=None,
                  cache: ScenarioCache | None = None, on_progress=None) -> Placement:
    """Choose ``settings.count`` thermocouple locations of ``case`` (module docstring).

    Parameters
    ----------
    case : Case
        Any case with a heat solve and relative displacements (``[relative]``; the frame's δ).
    settings : PlacementSettings
        Candidates, loads, noise, the error-model family.
    schedules : sequence of Schedule, optional
        Training duty cycles instead of the generated family (the case's own schedule is added).
    held_out : sequence of Schedule, optional
        Loads to judge on (default: generated; :func:`gatetherm.api.place_sensors` gives the paper's
        conditions 1-3 for a case driven by the frame's inputs).
    cache : ScenarioCache, optional
        Reuses the assembled model.
    on_progress : callable, optional
        ``on_progress(i, n)`` after the reduction, each load marched and the selection (``i`` up to ``n``).

    Returns
    -------
    Placement
    """
    s, fit, secs = settings, settings.fit, {}
    p = case.problem
    targets = [column(p, ("relative", r.name))[0] for r in p.relative]
    if not targets:
        raise InputError(case.source or case.name, "has no relative displacement to predict",
                         "add a [relative] table (the tool against the workpiece)")
    cand = find_candidates(case.mesh, s.boundaries, s.spacing_m, s.exclude, unmountable=case.unmountable,
                           axisymmetric=p.plane == "axisymmetric")
    train, held, ranges = _loads(case, s, schedules, held_out)
    tick = _ticker(on_progress, len(train) + len(held) + 2)
    t0 = time.perf_counter()
    cache = cache or ScenarioCache()
    red = tick(build_rom(case, s.states, cache))
    rom = red.rom
    rows, ok = candidate_rows(prepare(case, cache=cache).model, red.basis, cand.nodes)
    cand = cand.subset(ok)
    secs["reduced_model"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    names, steps = sorted(case.inputs()), {}
    tr = [tick(simulate(rom, x, names, load_key("training", i), case.defaults, steps)) for i, x in enumerate(train)]
    ho = [tick(simulate(rom, x, names, load_key("held-out", i), case.defaults, steps)) for i, x in enumerate(held)]
    ti = [rom.output(t) for t in targets]
    X, Y = np.vstack([x.states for x in tr]), np.vstack([x.outputs[:, ti] for x in tr])
    edges = np.cumsum([0] + [len(x.states) for x in tr])
    blocks = list(zip(edges[:-1], edges[1:]))
    secs["loads"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    sl, rows, cand = _screened(case, s, X, Y, rows, cand)
    keys = [f"node {n}" for n in cand.nodes[sl]]

    def temps(loads, idx):  # rises of shortlist members idx over loads, with their noise
        return [x.states @ rows[sl[idx]].T + np.column_stack(
            [noise(s.seed, keys[i], x.key, len(x.states), s.noise_K) for i in idx]) for x in loads]

    every = np.arange(len(sl))
    terms = lag_terms([x.columns for x in tr], names, case.held(), fit) if fit.form != "static" else []
    design = greedy.Design(np.vstack(temps(tr, every)), lag_columns(terms, [x.columns for x in tr]), Y, blocks)
    forms = ("static", "dynamic") if fit.form == "auto" else (fit.form,)
    forms = tuple(f for f in forms if f == "static" or terms) or ("static",)
    paths = {f: greedy.path(design, s.count, f, fit, cand.xyz[sl], s.min_distance_m) for f in forms}
    secs["selection"] = time.perf_counter() - t0
    tick(None)

    t0 = time.perf_counter()
    sensor_names = _names(case, s.count)
    truth = [{t: x.outputs[:, j] for t, j in zip(targets, ti)} for x in ho]
    span = max(float(x.columns["time_s"][-1]) for x in tr)
    source = f"gatetherm sensors: {case.source or case.name}, reduced model ({rom.states} states), {len(tr)} training loads"
    more = {"candidates": len(cand), "inputs": sorted({t.column for t in terms}),
            "noise_K": s.noise_K, "training_loads": [x.label for x in tr]}

    def sensors(step):
        return tuple(Sensor(n, int(cand.nodes[sl[i]]), tuple(float(v) for v in cand.xyz[sl[i]]),
                            cand.boundary[sl[i]]) for n, i in zip(sensor_names, step.sensors))

    def scored(step, selection=()):
        sens = sensors(step)
        model = error_model(design, step, [x.column for x in sens], terms, targets, p.T0, span, source,
                            settings_of(fit, **more), selection)
        cols = [{**x.columns, **{c.column: p.T0 + th[:, k] for k, c in enumerate(sens)}}
                for x, th in zip(ho, temps(ho, list(step.sensors)))]
        return sens, model, held_out_mae(model, cols, truth)

    def point(k, step):
        sens, _, err = scored(step)
        return CurvePoint(k + 1, step.form, sens, dict(zip(targets, step.cv_mae_um)), err)

    curve, chosen, stopped = greedy.curve(paths, forms, s.count, s.min_distance_m, fit, point)
    selection = [{"form": c.form, "terms": [x.column for x in c.sensors], "sensors": c.count,
                  "cv_mae_um": c.cv_mean_um} for c in curve]
    final = chosen[-1]
    sens, model, _ = scored(final, selection)
    failed = {}
    for i, sensor in enumerate(sens):
        if len(final.sensors) > 1:
            rest = greedy.fixed_set(design, final.sensors[:i] + final.sensors[i + 1:], final.form, fit)
            failed[sensor.name] = scored(rest)[2]
    notes = (*rom.notes, *greedy.rising(curve), *on_rotating(case, sens))
    signals = _signals(case, rom, design, tr, ho, terms, targets, truth, fit, s, span, source)
    idx = [sl[i] for i in final.sensors]
    held_T = {x.label: p.T0 + x.states @ rows[idx].T for x in ho}
    secs["models"] = time.perf_counter() - t0
    log.info("placed %d sensors of %d candidates (%d screened) in %s", len(sens), len(cand), len(sl),
             {k: round(v, 1) for k, v in secs.items()})
    return Placement(f"{case.name} ({case.source})" if case.source else case.name, case.dim, sens, model,
                     tuple(curve), failed, cand, sl, stopped, tuple(train), tuple(held), s, signals, ranges,
                     held_T, secs, tuple(notes))


def _signals(case, rom, design, tr, ho, terms, targets, truth, fit, s, span, source):
    """The family given the case's θ_A, θ_B and θ_C mean (each probe with its noise)."""
    chans = _signal_columns(case)
    if chans is None:
        return None

    def theta(x):
        return np.column_stack([np.mean([x.outputs[:, rom.output(col)] - case.problem.T0 +
                                         noise(s.seed, f"probe {probe}", x.key, len(x.states), s.noise_K)
                                         for col, probe in chans[c]], axis=0) for c in chans])

    d = greedy.Design(np.vstack([theta(x) for x in tr]), design.Z[:, 1 + design.s:], design.Y,
                      design.cvs[0].blocks)
    forms = ("static", "dynamic") if fit.form == "auto" and terms else (fit.form if terms else "static",)
    step = greedy.best_form([greedy.fixed_set(d, (0, 1, 2), f, fit) for f in forms], fit)
    model = error_model(d, step, list(chans), terms, targets, case.problem.T0, span, source, {})
    cols = [{**x.columns, **{c: case.problem.T0 + th[:, k] for k, c in enumerate(chans)}}
            for x, th in zip(ho, map(theta, ho))]
    return {"sensors": {c: [probe for _, probe in chans[c]] for c in chans}, "form": step.form,
            "cv_mae_um": dict(zip(targets, step.cv_mae_um)), "held_out_mae_um": held_out_mae(model, cols, truth)}
