"""TOML model files: ``[geometry]``, ``[mesh]``, ``[material]`` (with an
optional ``[material.tie_bar]``), ``[thermal]``, ``[supply]`` and ``[model]``,
each mirroring a parameter dataclass. Unknown keys and wrong types are errors."""
from __future__ import annotations

import dataclasses
import os
import tomllib
import types
import typing
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

from gatetherm import InputError
from gatetherm.geometry.frame import FrameParams, MeshParams, validate
from gatetherm.solvers.effects import effects_from_table
from gatetherm.solvers.heat import ThermalParams
from gatetherm.solvers.material import Material
from gatetherm.solvers.model import ModelConfig
from gatetherm.studies.run.conditions import SupplyParams

PAPER_TOML = "paper.toml"
_MODEL_KEYS = ("order", "k_base", "joint_conductance")


@dataclass(frozen=True)
class Config:
    """A model plus the oil-supply unit that drives it."""

    model: ModelConfig = ModelConfig()
    supply: SupplyParams = SupplyParams()
    source: str = "defaults"
    effects: dict = field(default_factory=dict)
    """Catalogue effects switched on, {name: value} (``[effects]``: ``NAME = {PARAM = VALUE}``)."""


def _coerce(section: str, key: str, value, typ):
    where = f"{section}.{key}"
    if typ is bool:
        if not isinstance(value, bool):
            raise InputError(where, f"expected true/false, got {value!r}")
        return value
    if typ in (float, int):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise InputError(where, f"expected a number, got {value!r}")
        return int(value) if typ is int else float(value)
    return value


def _build(cls, section: str, table: dict, base=None):
    hints = typing.get_type_hints(cls)
    known = {f.name for f in dataclasses.fields(cls)}
    out = {}
    for key, value in table.items():
        if key not in known:
            raise InputError(f"{section}.{key}", "unknown key",
                             f"known keys: {', '.join(sorted(known))}")
        typ = hints[key]
        if isinstance(typ, types.UnionType):
            typ = float
        out[key] = _coerce(section, key, value, typ)
    return dataclasses.replace(base or cls(), **out)


def parse_config(data: dict, source: str = "<dict>", base: Config | None = None) -> Config:
    """Build a :class:`Config` from a parsed TOML document (overlaying ``base``)."""
    base = base or Config()
    sections = {"geometry", "mesh", "material", "thermal", "supply", "model", "effects"}
    for key in data:
        if key not in sections:
            raise InputError(key, "unknown section", f"known sections: {', '.join(sorted(sections))}")
    m = base.model
    material_table = dict(data.get("material", {}))
    tie_table = material_table.pop("tie_bar", None)
    frame = _build(FrameParams, "geometry", data.get("geometry", {}), m.frame)
    model_table = data.get("model", {})
    for key in model_table:
        if key not in _MODEL_KEYS:
            raise InputError(f"model.{key}", "unknown key", f"known keys: {', '.join(_MODEL_KEYS)}")
    order = _coerce("model", "order", model_table.get("order", m.order), int)
    if order not in (1, 2):
        raise InputError("model.order", f"must be 1 or 2, got {order}")
    material = _build(Material, "material", material_table, m.material)
    model = dataclasses.replace(
        m, frame=validate(frame), mesh=_build(MeshParams, "mesh", data.get("mesh", {}), m.mesh),
        material=material,
        tie_material=_build(Material, "material.tie_bar", tie_table, material) if tie_table else m.tie_material,
        thermal=_build(ThermalParams, "thermal", data.get("thermal", {}), m.thermal), order=order,
        k_base=_coerce("model", "k_base", model_table["k_base"], float) if "k_base" in model_table else m.k_base,
        joint_conductance=(_coerce("model", "joint_conductance", model_table["joint_conductance"], float)
                           if "joint_conductance" in model_table else m.joint_conductance))
    supply = _build(SupplyParams, "supply", data.get("supply", {}), base.supply)
    return Config(model, supply, source, {**base.effects, **effects_from_table(data.get("effects", {}))})


def load_config(path: str | os.PathLike | None = None) -> Config:
    """Read a model file; ``None`` gives the shipped paper model."""
    if path is None:
        text = resources.files("gatetherm.studies").joinpath("data", PAPER_TOML).read_text(encoding="utf-8")
        source = f"gatetherm:{PAPER_TOML}"
    else:
        p = Path(path)
        if not p.is_file():
            raise InputError("--config", f"no such file '{path}'", "give a TOML model file")
        text, source = p.read_text(encoding="utf-8"), str(p)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise InputError(source, f"not valid TOML ({err})") from None
    return parse_config(data, source)
