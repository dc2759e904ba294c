"""Write a :class:`~studies.config.Config` as a TOML model file that
:func:`studies.config.load_config` reads back to the same configuration."""
from __future__ import annotations

import dataclasses
import logging
import math

from gatetherm.solvers.effects import effects_table
from gatetherm.solvers.model import ModelConfig
from gatetherm.studies.run.config import Config

log = logging.getLogger(__name__)

#: ModelConfig fields that a model file cannot carry (catalogue effects go to [effects]).
_NOT_IN_FILE = ("source", "joint_stiffness", "alpha_slope")


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


def _section(name: str, table: dict) -> list[str]:
    return [f"[{name}]"] + [f"{k} = {_value(v)}" for k, v in table.items()] + [""]


def config_toml(cfg: Config, header: str = "") -> str:
    """The model file of ``cfg``; ``header`` lines become TOML comments."""
    m = cfg.model
    default = ModelConfig()
    lost = [f for f in _NOT_IN_FILE if getattr(m, f) != getattr(default, f)]
    if lost:
        log.warning("model file: %s not written (not model-file keys)", ", ".join(lost))
    lines = [f"# {h}" for h in header.splitlines()] + ([""] if header else [])
    lines += _section("geometry", dataclasses.asdict(m.frame))
    lines += _section("mesh", dataclasses.asdict(m.mesh))
    lines += _section("material", dataclasses.asdict(m.material))
    if m.tie_material is not None:
        lines += _section("material.tie_bar", dataclasses.asdict(m.tie_material))
    lines += _section("thermal", dataclasses.asdict(m.thermal))
    lines += _section("supply", dataclasses.asdict(cfg.supply))
    lines += _section("model", {"order": m.order, **{k: getattr(m, k) for k in ("k_base", "joint_conductance")
                                                      if getattr(m, k) is not None}})
    if cfg.effects:
        lines += ["[effects]"] + [f"{name} = {{ {p} = {_value(v)} }}"
                                  for name, table in effects_table(cfg.effects).items() for p, v in table.items()]
    return "\n".join(lines).rstrip("\n") + "\n"
