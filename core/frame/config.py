"""TOML model files, read and written from one schema.

Each section of a model file mirrors one parameter dataclass (:data:`SCHEMA`); unknown
keys, wrong types and values outside a parameter's admissible range (declared on its
dataclass, :mod:`gatetherm.checks`) are errors naming the file and the key. ``[effects]``
switches on catalogue effects as ``NAME = {PARAM = VALUE}``, ``[sensors]`` sets sensor
faults as ``CHANNEL = {FAULT = VALUE}``. :func:`config_toml` writes a file that
:func:`load_config` reads back to the same :class:`Config`.
"""
from __future__ import annotations

import dataclasses
import functools
import logging
import math
import os
import types
import typing
from dataclasses import dataclass, field
from importlib import resources

from gatetherm import InputError
from gatetherm.checks import check_fields
from gatetherm.files import parse_toml, read_text
from gatetherm.frame.geometry import FrameParams, MeshParams, check_tie_depth, validate
from gatetherm.frame.problem import TARGETS, ModelConfig, ThermalParams
from gatetherm.solvers.effects import effects_from_table, effects_table
from gatetherm.solvers.heat import TimeScheme
from gatetherm.solvers.material import Material
from gatetherm.solvers.sensors import faults_from_table, faults_table_lines
from gatetherm.studies.run.conditions import SupplyParams

log = logging.getLogger(__name__)

PAPER_TOML = "paper.toml"


@dataclass(frozen=True)
class Config:
    """A model plus the oil-supply unit that drives it."""

    model: ModelConfig = ModelConfig()
    supply: SupplyParams = SupplyParams()
    source: str = "defaults"
    """Where the configuration came from (a file path, or ``gatetherm:paper.toml``)."""
    effects: dict = field(default_factory=dict)
    """Catalogue effects switched on, {name: value} (``[effects]``: ``NAME = {PARAM = VALUE}``)."""
    sensors: dict = field(default_factory=dict)
    """Sensor faults, {channel: {fault: value}} (``[sensors]``: ``CHANNEL = {FAULT = VALUE}``)."""


@dataclass(frozen=True)
class Section:
    """One table of the model file and the dataclass it mirrors."""

    name: str
    """TOML table name, e.g. ``"material.tie_bar"``."""
    path: tuple[str, ...]
    """Attribute path of the dataclass in :class:`Config`."""
    cls: type
    keys: tuple[str, ...] | None = None
    """Fields the file may set (None: all)."""


SCHEMA = (
    Section("geometry", ("model", "frame"), FrameParams),
    Section("mesh", ("model", "mesh"), MeshParams),
    Section("material", ("model", "material"), Material),
    Section("material.tie_bar", ("model", "tie_material"), Material),
    Section("thermal", ("model", "thermal"), ThermalParams),
    Section("supply", ("supply",), SupplyParams),
    Section("model", ("model",), ModelConfig, ("order", "k_base", "joint_conductance", "joint_stiffness")),
    Section("model.scheme", ("model", "scheme"), TimeScheme),
)
"""The model file, section by section, in the order :func:`config_toml` writes it."""
SECTION_NAMES = tuple(s.name for s in SCHEMA) + ("effects", "sensors")


def _get(obj, path):
    for name in path:
        obj = getattr(obj, name)
    return obj


def _set(obj, path, value):
    if not path:
        return value
    return dataclasses.replace(obj, **{path[0]: _set(getattr(obj, path[0]), path[1:], value)})


def _coerce(where: str, value, typ):
    if isinstance(typ, types.UnionType):  # "float | None": a number (None is "not set")
        typ = next(a for a in typing.get_args(typ) if a is not type(None))
    if typ is bool:
        if not isinstance(value, bool):
            raise InputError(where, f"expected true/false, got {value!r}")
        return value
    if typ in (float, int):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise InputError(where, f"expected a number, got {value!r}")
        if typ is int and not (isinstance(value, int) or (math.isfinite(value) and value.is_integer())):
            raise InputError(where, f"expected a whole number, got {value!r}")
        if typ is int:
            return int(value)
        try:
            return float(value)
        except OverflowError:  # an integer beyond any float: its range refuses it
            return value
    raise InputError(where, "cannot be set in a model file")


def _section_table(data: dict, name: str) -> dict:
    node = data
    for part in name.split("."):
        node = node.get(part, {}) if isinstance(node, dict) else {}
    if not isinstance(node, dict):
        raise InputError(name, "expected a table", f"write [{name}] with key = value lines")
    return {k: v for k, v in node.items() if not any(s.name == f"{name}.{k}" for s in SCHEMA)}


@functools.cache
def _hints(cls) -> dict:
    """The type hints of a section's dataclass (resolved once: a sweep plans thousands of points)."""
    return typing.get_type_hints(cls)


def _apply(sec: Section, table: dict, current):
    """``current`` (an instance of ``sec.cls``) with the keys of ``table`` applied."""
    hints = _hints(sec.cls)
    known = sec.keys or tuple(f.name for f in dataclasses.fields(sec.cls))
    changes = {}
    for key, value in table.items():
        if key not in known:
            raise InputError(f"{sec.name}.{key}", "unknown key", f"known keys: {', '.join(sorted(known))}")
        changes[key] = _coerce(f"{sec.name}.{key}", value, hints[key])
    return dataclasses.replace(current, **changes) if changes else current


def parse_config(data: dict, source: str = "<dict>", base: Config | None = None) -> Config:
    """Build a :class:`Config` from a parsed TOML document (overlaying ``base``)."""
    cfg = base or Config()
    for key in data:
        if key not in SECTION_NAMES and not any(s.name.startswith(f"{key}.") for s in SCHEMA):
            raise InputError(key, "unknown section", f"known sections: {', '.join(SECTION_NAMES)}")
    for sec in SCHEMA:
        table = _section_table(data, sec.name)
        current = _get(cfg, sec.path)
        if current is None:  # the tie bar's own material starts from the column material
            if not table:
                continue
            current = _get(cfg, ("model", "material"))
        cfg = _set(cfg, sec.path, _apply(sec, table, current))
    check_config(cfg)
    effects = {**cfg.effects, **effects_from_table(data.get("effects", {}), TARGETS)}
    sensors = {**cfg.sensors, **faults_from_table(data.get("sensors", {}))}
    return dataclasses.replace(cfg, source=source, effects=effects, sensors=sensors)


def check_config(cfg: Config) -> Config:
    """``cfg`` if every parameter of the model file's sections is admissible and the frame
    can be built with its tie bars inside the columns; else InputError naming ``section.key``."""
    for sec in SCHEMA:
        obj = _get(cfg, sec.path)
        if obj is not None:
            check_fields(obj, f"{sec.name}.", sec.keys)
    try:
        check_tie_depth(validate(cfg.model.frame))
    except InputError as err:
        raise err.at("geometry", ".") from None
    return cfg


def load_config(path: str | os.PathLike | None = None, option: str = "--config") -> Config:
    """Read a model file; ``None`` gives the shipped paper model. Errors name the file
    (``option``: where its name came from)."""
    if path is None:
        text = resources.files("gatetherm.studies").joinpath("data", PAPER_TOML).read_text(encoding="utf-8")
        source = f"gatetherm:{PAPER_TOML}"
    else:
        text, source = read_text(path, option, "give a TOML model file"), str(path)
    data = parse_toml(text, source, "fix the model file's syntax")
    try:
        return parse_config(data, source)
    except InputError as err:
        raise err.at(source) from None


def _value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if not math.isfinite(v):
            raise ValueError(f"cannot write {v} to TOML")
        return repr(v)
    raise TypeError(f"cannot write {type(v).__name__} to a model file")


def config_toml(cfg: Config, header: str = "") -> str:
    """The model file of ``cfg``; ``header`` lines become TOML comments. Volumetric
    sources (``ModelConfig.source``) have no key: they come from effects."""
    if cfg.model.source != ModelConfig().source:
        log.warning("model file: volumetric sources not written (they are set by [effects])")
    lines = [f"# {h}" for h in header.splitlines()] + ([""] if header else [])
    for sec in SCHEMA:
        obj = _get(cfg, sec.path)
        if obj is None:
            continue
        keys = sec.keys or tuple(f.name for f in dataclasses.fields(sec.cls))
        rows = [f"{k} = {_value(getattr(obj, k))}" for k in keys if getattr(obj, k) is not None]
        lines += [f"[{sec.name}]", *rows, ""]
    if cfg.effects:
        lines += ["[effects]"] + [f"{name} = {{ {p} = {_value(v)} }}"
                                  for name, table in effects_table(cfg.effects, TARGETS).items() for p, v in table.items()]
        lines += [""]
    lines += faults_table_lines(cfg.sensors)
    return "\n".join(lines).rstrip("\n") + "\n"
