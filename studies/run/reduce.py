"""Reduced models of a model file, and their check against full FE runs.

The frame model is assembled through the scenario path (:func:`~gatetherm.studies.run.scenario.prepare`,
so a model file's effects act as everywhere), read off as a switched linear system
(:func:`gatetherm.solvers.rom.linear_heat_model`) and reduced; the full FE runs of the
check go through :func:`~gatetherm.studies.run.scenario.run_scenario`.
"""
from __future__ import annotations

import hashlib
import logging
import time
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gatetherm import InputError, __version__, atomic_path, write_text_atomic
from gatetherm.checks import CELSIUS, check_linear_system
from gatetherm.solvers.rom import Reduction, ReducedModel, linear_heat_model, reduce
from gatetherm.solvers.rom_time import discretise, march_rom
from gatetherm.studies.run.config import Config
from gatetherm.studies.run.scenario import ScenarioCache, condition_schedule, prepare, run_scenario

log = logging.getLogger(__name__)

def column_of(output: str) -> str:
    """The time-series column of a reduced-model output (``theta_A_K`` -> ``theta_A_degC``)."""
    return output[: -len("_K")] + "_degC" if output.endswith("_K") else output


def output_of(column: str) -> str:
    """The reduced-model output of a time-series column (``theta_A_degC`` -> ``theta_A_K``)."""
    return column[: -len("_degC")] + "_K" if column.endswith("_degC") else column


def series_inputs(rom: ReducedModel, columns, T_room: float = 20.0) -> tuple[np.ndarray, np.ndarray]:
    """Inputs (samples × 2, deviations from the model's T0) and the pump state of each interval
    (the state recorded at its start, as a schedule file holds it) from time-series columns;
    without ``ambient_degC`` the room stays at ``T_room``."""
    oil = np.asarray(columns["oil_degC"], float)
    amb = np.asarray(columns["ambient_degC"], float) if "ambient_degC" in columns else np.full_like(oil, T_room)
    u = np.column_stack([oil, amb]) - rom.T0
    return u, np.asarray(columns["pump"], float)[:-1] > 0.5


def build_rom(config: Config, dim: int, states: int = 30, cache: ScenarioCache | None = None) -> Reduction:
    """Assemble ``config``'s model in ``dim`` dimensions and reduce it to ``states`` states."""
    t0 = time.perf_counter()
    model = prepare(config, dim, condition_schedule(1, config).drive, cache=cache).model
    build = time.perf_counter() - t0
    red = reduce(linear_heat_model(model), states)
    red.seconds["model_build"] = build
    return red


def rom_key(config: Config, dim: int, states: int) -> str:
    """What a reduced model depends on, as a digest: model, effects, dimension, states, version."""
    return hashlib.sha256(repr((config.model, config.effects, dim, states, __version__)).encode()).hexdigest()


def write_rom(rom: ReducedModel, path) -> None:
    """Write ``rom.npz`` (the arrays of the fields; string arrays for the names)."""
    arrays = {k: getattr(rom, k) for k in ("A_on", "B_on", "A_off", "B_off", "C")}
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        np.savez(fh, **arrays, T0=np.float64(rom.T0), inputs=np.array(rom.inputs), outputs=np.array(rom.outputs))


def load_rom(path) -> ReducedModel:
    """Read a ``rom.npz`` written by :func:`write_rom`, checked
    (:func:`~gatetherm.checks.check_linear_system`, T0 a temperature)."""
    fix = "write one with 'gatetherm reduce'"
    if not Path(path).is_file():
        raise InputError(str(path), "no such file", fix)
    if not zipfile.is_zipfile(path):
        raise InputError(str(path), "not an .npz archive (truncated, or another kind of file)", fix)
    try:
        with np.load(path, allow_pickle=False) as d:
            rom = ReducedModel(*(np.array(d[k], float) for k in ("A_on", "B_on", "A_off", "B_off", "C")),
                               float(d["T0"]), tuple(map(str, d["inputs"])), tuple(map(str, d["outputs"])))
    except (KeyError, ValueError, TypeError, OSError, EOFError, zipfile.BadZipFile) as err:
        raise InputError(str(path), f"not a reduced model ({type(err).__name__}: {err})", fix) from None
    CELSIUS.check(f"{path}: T0", rom.T0, fix)
    check_linear_system(str(path), {"on": (rom.A_on, rom.B_on), "off": (rom.A_off, rom.B_off)}, rom.C,
                        inputs=rom.inputs, outputs=rom.outputs)
    return rom


def save_rom(rom: ReducedModel, key: str, directory: Path, name: str = "rom") -> None:
    """``directory/<name>.npz`` and its key ``<name>.key`` (written last)."""
    write_rom(rom, Path(directory) / f"{name}.npz")
    write_text_atomic(Path(directory) / f"{name}.key", key + "\n")


def cached_rom(config: Config, dim: int, states: int, directory: Path, cache: ScenarioCache | None = None,
               name: str = "rom") -> ReducedModel:
    """The reduced model of ``config`` in ``dim`` dimensions kept as ``directory/<name>.npz``,
    reused while its key (:func:`rom_key`, in ``<name>.key``) matches, else built and kept."""
    path, keyfile = Path(directory) / f"{name}.npz", Path(directory) / f"{name}.key"
    key = rom_key(config, dim, states)
    if path.exists() and keyfile.exists() and keyfile.read_text(errors="replace").strip() == key:
        log.info("reusing %s", path)
        try:
            return load_rom(path)
        except InputError as err:
            log.warning("%s; building the reduced model again", err)
    rom = build_rom(config, dim, states, cache).rom
    save_rom(rom, key, directory, name)
    return rom


@dataclass(frozen=True)
class Check:
    """The reduced model against a full FE run of one condition."""

    condition: int
    max_delta_error_um: float
    max_theta_error_K: float
    """Largest error of θ_A, θ_B, θ_C, K."""
    fe_seconds: float
    """Wall time of the full run (build excluded when the model was cached), s."""
    rom_ms: float
    """Wall time of the reduced run (5 h of 1-min steps, discretisation excluded), ms."""


def rom_run(rom: ReducedModel, cols, T_room: float = 20.0) -> tuple[np.ndarray, float]:
    """(outputs of ``rom`` over the inputs of a full run's columns, one row per sample and a
    column per :attr:`ReducedModel.outputs`, temperatures as rises; wall time of the march, ms)."""
    u, modes = series_inputs(rom, cols, T_room)
    disc = discretise(rom, float(cols["time_s"][1] - cols["time_s"][0]))
    t0 = time.perf_counter()
    y = march_rom(disc, u, modes) @ rom.C.T
    return y, 1e3 * (time.perf_counter() - t0)


def check_run(rom: ReducedModel, number: int, cols, fe_seconds: float = float("nan"), T_room: float = 20.0) -> Check:
    """The reduced model over the inputs of a full run's columns (sample spacing as the run's),
    against the run's δ and θ_A, θ_B, θ_C."""
    y, ms = rom_run(rom, cols, T_room)
    err = {o: float(np.max(np.abs(y[:, rom.output(o)] + (0 if o.endswith("_um") else rom.T0) - cols[column_of(o)])))
           for o in ("delta_um", "theta_A_K", "theta_B_K", "theta_C_K")}
    log.info("condition %d: max |δ_rom − δ_FE| = %.3f µm", number, err["delta_um"])
    return Check(number, err["delta_um"], max(err[k] for k in err if k != "delta_um"), fe_seconds, ms)


def check(config: Config, dim: int, rom: ReducedModel, conditions=(1, 2, 3),
          cache: ScenarioCache | None = None) -> list[Check]:
    """Run each condition on the full model (1-min samples) and check ``rom`` against it."""
    out = []
    for n in conditions:
        fe = run_scenario(config, dim, condition_schedule(n, config), cache=cache)
        out.append(check_run(rom, n, fe.result.columns, fe.result.seconds, config.supply.T_room))
    return out
