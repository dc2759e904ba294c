"""Reduced models of any case: build, keep as ``rom.npz``, run on a series, check against FE.

The case is assembled through the scenario path (:func:`~gatetherm.studies.run.scenario.prepare`,
so its effects act as everywhere), read off as a switched linear system
(:func:`gatetherm.solvers.rom.linear_heat_model`) and reduced; the full FE runs of the check
go through :func:`~gatetherm.studies.run.scenario.run_scenario`.

``rom.npz`` holds everything needed to integrate the model without gatetherm: per mode
``A_<mode>``, ``B_<mode>`` (``A``, ``B`` without fluids), ``C``, ``D``, ``y0``; ``inputs`` (the
schedule column or expression each input is) and ``offsets`` (subtracted from each input's
value); ``outputs``; ``modes`` and ``pumps`` (the pump expression of every fluid: a mode is
``on``/``off`` per fluid, joined by ``_``); ``T0``; ``default_inputs``/``default_values``
(inputs a series may leave out); ``room`` (the index of the room input, −1: none); ``notes`` (what
a user of the model should know: films held at constants). ``ẋ = A x + B (u − offsets)``,
``y = C x + D (u − offsets) + y0``, x = 0 at the start (every unknown at T0).
"""
from __future__ import annotations

import dataclasses
import hashlib
import logging
import time
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gatetherm import InputError, __version__, atomic_path, write_text_atomic
from gatetherm.checks import CELSIUS, check_linear_system
from gatetherm.solvers.convection import held_coefficient
from gatetherm.solvers.effects import room
from gatetherm.solvers.expr import Value
from gatetherm.solvers.rom import Input, Reduction, ReducedModel, linear_heat_model, mode_name, reduce
from gatetherm.solvers.rom_time import discretise, march_rom, outputs
from gatetherm.studies.run.case import Case
from gatetherm.studies.run.scenario import ScenarioCache, assembled, effective, prepare, run_scenario
from gatetherm.studies.run.simulate import column

log = logging.getLogger(__name__)
FORMAT = "gatetherm-rom/2"


def build_rom(case: Case, states: int = 30, cache: ScenarioCache | None = None) -> Reduction:
    """Assemble ``case`` (its effects on) and reduce it to ``states`` states."""
    if not case.problem.heat or case.time is None:
        raise InputError("case", f"{case.name} has no transient heat solve (steady or prescribed temperatures): "
                         "nothing to reduce", "give a case with [time] settings")
    t0 = time.perf_counter()
    prepared = prepare(case, cache=cache)
    model, fe, held = prepared.model, None, {}
    if model.heat.varying:  # linear: each film that follows the temperature held at its run's mean
        model, fe, held = _held_films(case, prepared, cache)
    build = time.perf_counter() - t0
    red = reduce(linear_heat_model(model, column), states)
    red.seconds["model_build"] = build
    ambient = room(case.problem)
    text = ambient.text or repr(ambient.constant)
    at = next((j for j, u in enumerate(red.rom.inputs) if u.text == text), None)
    red = dataclasses.replace(red, rom=dataclasses.replace(red.rom, defaults=dict(case.defaults), room=at))
    if fe is None:
        return red
    notes = (_held_note(case, red.rom, fe, held),)  # said by what uses the model (rom.notes)
    return dataclasses.replace(red, rom=dataclasses.replace(red.rom, notes=notes),
                               held={b: h[0] for b, h in held.items()})


def _held_films(case: Case, prepared, cache):
    """The case's own run on the full model, the model with each film whose coefficient follows the
    temperature held at :func:`~gatetherm.solvers.convection.held_coefficient` of that run, and per
    film (held, least, largest) coefficient, W/(m² K)."""
    varying, samples = prepared.model.heat.varying, []

    def seen(t, U, env):
        samples.append([(t, v.h(U, env), v.surface(U) - v.ambient(env)) for v in varying])
    fe = run_scenario(case, cache=cache, on_state=seen)
    s = np.array(samples)  # samples × films × (t, h, excess)
    held = {v.boundary: (held_coefficient(s[:, j, 0], s[:, j, 1], s[:, j, 2]), s[:, j, 1].min(), s[:, j, 1].max())
            for j, v in enumerate(varying)}
    target = effective(case, prepared.effects)
    films = tuple(dataclasses.replace(f, h=held[f.boundary][0], law=None) if f.law is not None else f
                  for f in target.problem.films)
    model, _ = assembled(dataclasses.replace(target, problem=dataclasses.replace(target.problem, films=films)), cache)
    return model, fe, held


def _held_note(case: Case, rom: ReducedModel, fe, held: dict) -> str:
    """What holding the films costs, on the case's own run: the largest error of δ (else of the
    displacement output, else the temperature, it is largest for) against the full model, beside
    that output's largest size (a temperature's rise)."""
    err = check_run(rom, case.schedule.label, fe.result.columns).errors
    unit = "um" if any(k.endswith("_um") for k in err) else "degC"
    worst = "delta_um" if "delta_um" in err else max((k for k in err if k.endswith(f"_{unit}")), key=err.get)
    size = float(np.max(np.abs(fe.result.columns[worst] - (0.0 if unit == "um" else case.problem.T0))))  # a rise
    radiating = {f.boundary for f in case.problem.films if getattr(f.law, "emissivity", 0.0)}
    films = "; ".join(f"{b} {h:.3g} W/(m² K) (the law{' with its radiation' * (b in radiating)} {lo:.3g} … {hi:.3g} "
                      "over the run)" for b, (h, lo, hi) in held.items())
    unit = "µm" if unit == "um" else "K"
    return (f"{case.source or case.name}: the reduced model is linear: it holds each film that follows the "
            f"temperature at its mean over the case's own run, weighted by the wall's excess over the ambient: {films}; "
            "on that run "
            f"{worst} is off the full model's by up to {err[worst]:.3g} {unit} (of {size:.3g} {unit}); another run "
            "can be further off: check it against the full model (gatetherm reduce --check)")


def rom_key(case: Case, states: int) -> str:
    """What a reduced model depends on, as a digest: problem, effects, mesh, states, version."""
    mesh = hashlib.sha256(case.mesh.points.tobytes() + case.mesh.cells.tobytes()).hexdigest()
    return hashlib.sha256(repr((case.problem, case.effects, mesh, states, __version__)).encode()).hexdigest()


def _suffix(mode: str) -> str:
    return f"_{mode}" if mode else ""


def write_rom(rom: ReducedModel, path) -> None:
    """Write ``rom.npz`` (see the module docstring)."""
    arrays = {f"{k}{_suffix(m)}": getattr(rom, k)[m] for m in rom.modes for k in ("A", "B")}
    names = lambda xs: np.array(list(xs), dtype=str)  # noqa: E731
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        np.savez(fh, **arrays, C=rom.C, D=rom.D, y0=rom.y0, T0=np.float64(rom.T0), format=np.array(FORMAT),
                 inputs=names(u.text for u in rom.inputs), offsets=np.array([u.offset for u in rom.inputs], float),
                 outputs=names(rom.outputs), modes=names(rom.modes), pumps=names(rom.pumps),
                 default_inputs=names(rom.defaults), default_values=np.array(list(rom.defaults.values()), float),
                 room=np.int64(-1 if rom.room is None else rom.room), notes=names(rom.notes))


def load_rom(path) -> ReducedModel:
    """Read a ``rom.npz`` written by :func:`write_rom`, checked (:func:`~gatetherm.checks.check_linear_system`,
    T0 a temperature); InputError naming the file if it is not one."""
    fix = "write one with 'gatetherm reduce'"
    if not Path(path).is_file():
        raise InputError(str(path), "no such file", fix)
    if not zipfile.is_zipfile(path):
        raise InputError(str(path), "not an .npz archive (truncated, or another kind of file)", fix)
    try:
        with np.load(path, allow_pickle=False) as d:
            modes = tuple(map(str, d["modes"]))
            A = {m: np.array(d[f"A{_suffix(m)}"], float) for m in modes}
            B = {m: np.array(d[f"B{_suffix(m)}"], float) for m in modes}
            inputs = tuple(Input(str(t), float(o)) for t, o in zip(d["inputs"], d["offsets"], strict=True))
            defaults = dict(zip(map(str, d["default_inputs"]), map(float, d["default_values"]), strict=True))
            room = int(d["room"])
            notes = tuple(map(str, d["notes"])) if "notes" in d.files else ()
            rom = ReducedModel(A, B, np.array(d["C"], float), np.array(d["D"], float), np.array(d["y0"], float),
                               inputs, tuple(map(str, d["outputs"])), tuple(map(str, d["pumps"])), float(d["T0"]),
                               defaults, None if room < 0 else room, notes)
    except (KeyError, ValueError, TypeError, OSError, EOFError, zipfile.BadZipFile) as err:
        raise InputError(str(path), f"not a reduced model ({type(err).__name__}: {err})", fix) from None
    CELSIUS.check(f"{path}: T0", rom.T0, fix)
    check_linear_system(str(path), {m: (rom.A[m], rom.B[m]) for m in rom.modes}, rom.C, rom.D,
                        inputs=rom.inputs, outputs=rom.outputs)
    if len(rom.y0) != len(rom.outputs) or not np.isfinite(rom.y0).all():
        raise InputError(str(path), "y0 is not one finite number per output", fix)
    if rom.room is not None and not 0 <= rom.room < len(rom.inputs):
        raise InputError(str(path), f"room {rom.room} is not an input", fix)
    return rom


def save_rom(rom: ReducedModel, key: str, directory: Path, name: str = "rom") -> None:
    """``directory/<name>.npz`` and its key ``<name>.key`` (written last)."""
    write_rom(rom, Path(directory) / f"{name}.npz")
    write_text_atomic(Path(directory) / f"{name}.key", key + "\n")


def cached_rom(case: Case, states: int, directory: Path, cache: ScenarioCache | None = None,
               name: str = "rom") -> ReducedModel:
    """The reduced model of ``case`` kept as ``directory/<name>.npz``, reused while its key
    (:func:`rom_key`, in ``<name>.key``) matches, else built and kept."""
    path, keyfile = Path(directory) / f"{name}.npz", Path(directory) / f"{name}.key"
    key = rom_key(case, states)
    if path.exists() and keyfile.exists() and keyfile.read_text(errors="replace").strip() == key:
        try:
            rom = load_rom(path)
            log.info("reusing %s", path)
            return rom
        except InputError as err:
            log.warning("%s; building the reduced model again", err)
    rom = build_rom(case, states, cache).rom
    save_rom(rom, key, directory, name)
    return rom


def series_inputs(rom: ReducedModel, columns) -> tuple[np.ndarray, np.ndarray]:
    """Inputs (samples × inputs, less their offsets) and the mode index of each interval (the pump
    states at its start, as a schedule file holds them) from time-series columns; a column the
    model reads but the series lacks takes its default value, else is one line naming it."""
    t = np.asarray(columns["time_s"], float)
    env = {"t": t - t[0], **{k: np.asarray(v, float) for k, v in columns.items() if k != "time_s"}}
    need = set().union(*(Value.of(u.text).names() for u in (*rom.inputs, *map(Input, rom.pumps, rom.pumps))))
    for k in need - set(env):
        if k not in rom.defaults:
            raise InputError(f"column {k}", "missing: the reduced model reads it", "record it in the series")
        env[k] = np.full_like(t, rom.defaults[k])

    def value(text):
        return np.broadcast_to(np.asarray(Value.of(text)(env), float), t.shape)

    u = np.column_stack([value(x.text) - x.offset for x in rom.inputs]) if rom.inputs else np.zeros((len(t), 0))
    pumps = [value(p)[:-1] > 0.5 for p in rom.pumps]
    names = [mode_name(s) for s in zip(*pumps)] if pumps else [""] * (len(t) - 1)
    return u, np.array([rom.modes.index(n) for n in names], int)


def rom_outputs(rom: ReducedModel, cols) -> tuple[np.ndarray, float]:
    """(every output of ``rom`` over the inputs of a run's columns, a row per sample; wall time of
    the march, ms)."""
    u, modes = series_inputs(rom, cols)
    disc = discretise(rom, float(cols["time_s"][1] - cols["time_s"][0]))
    t0 = time.perf_counter()
    y = outputs(rom, march_rom(disc, u, modes), u)
    return y, 1e3 * (time.perf_counter() - t0)


@dataclass(frozen=True)
class Check:
    """The reduced model against a full FE run of one schedule."""

    schedule: str
    errors: dict[str, float]
    """Largest |reduced − FE| per output the run has, in its unit."""
    fe_seconds: float
    """Wall time of the full run (build excluded when the model was cached), s."""
    rom_ms: float
    """Wall time of the reduced run (discretisation excluded), ms."""

    @property
    def max_delta_error_um(self) -> float:
        return self.errors.get("delta_um", float("nan"))

    @property
    def max_theta_error_K(self) -> float:
        """Largest error of θ_A, θ_B, θ_C, K."""
        return max((v for k, v in self.errors.items() if k.startswith("theta_")), default=float("nan"))


def check_run(rom: ReducedModel, label: str, cols, fe_seconds: float = float("nan")) -> Check:
    """The reduced model over the inputs of a full run's columns (sample spacing as the run's),
    against the run's every output."""
    y, ms = rom_outputs(rom, cols)
    err = {o: float(np.max(np.abs(y[:, i] - cols[o]))) for i, o in enumerate(rom.outputs) if o in cols}
    log.info("%s: max |δ_rom − δ_FE| = %.3g µm", label, err.get("delta_um", float("nan")))
    return Check(label, err, fe_seconds, ms)


def check(case: Case, rom: ReducedModel, schedules=None, cache: ScenarioCache | None = None) -> list[Check]:
    """Run each schedule (default: the case's own) on the full model and check ``rom`` against it."""
    out = []
    for s in schedules or (case.schedule,):
        fe = run_scenario(case, s, cache=cache)
        out.append(check_run(rom, s.label, fe.result.columns, fe.result.seconds))
    return out
