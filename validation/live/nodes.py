"""The OPC UA node layout of a machine as ``gatetherm twin`` serves it and ``gatetherm live`` reads it,
and the map file that points ``live`` at a real control's own nodes (docs/live.md).

Default layout: namespace :data:`NAMESPACE`, an object ``Machine`` under ``Objects``, one Double
variable per column of the data format, its string node id the column's name
(``nsu=urn:gatetherm:machine;s=delta_um``):

* read: ``time_s`` (the machine's clock, s), the inputs of the case's schedule (e.g. ``spindle_W``,
  ``ambient_degC``), the thermocouples (``theta_A_degC`` …), ``delta_um`` (the measured,
  uncompensated δ) and, where the machine reports it, ``delta_residual_um`` (what stays after the
  correction);
* written by ``live``: ``offset_um`` (the axis offset), ``gradient_um_per_m`` and ``reference_m``
  (an offset that grows along the axis from a reference position, where the model gives it).

A map file (TOML) replaces any of them: ``[read]`` and ``[write]`` tables of column name -> node id
(``ns=3;s=...``, ``ns=2;i=17`` or ``nsu=URI;s=...``) and an optional ``[scale]`` table of column
name -> factor, the control's unit per gatetherm's (``offset_um = 0.001`` for a control in mm).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from gatetherm import InputError
from gatetherm.files import parse_toml, read_text

NAMESPACE = "urn:gatetherm:machine"
OBJECT = "Machine"
WRITTEN = ("offset_um", "gradient_um_per_m", "reference_m")
"""The correction variables; the twin applies ``offset_um`` (an ideal axis offset)."""
KEYS = ("read", "write", "scale")


def machine_namespace(i: int, machines: int = 1) -> str:
    """The namespace of machine ``i`` (0-based) of a twin serving ``machines``: :data:`NAMESPACE`
    for one, ``urn:gatetherm:machine:1`` … ``:N`` for several (a map file's ``nsu=`` then names it)."""
    return NAMESPACE if machines == 1 else f"{NAMESPACE}:{i + 1}"


def default_node(name: str) -> str:
    """The default node id of a column: ``nsu=urn:gatetherm:machine;s=<name>``."""
    return f"nsu={NAMESPACE};s={name}"


@dataclass(frozen=True)
class NodeMap:
    """Where ``live`` reads each column and writes each correction variable."""

    read: dict[str, str] = field(default_factory=dict)
    """Column name -> node id of a value read every period."""
    write: dict[str, str] = field(default_factory=dict)
    """Correction variable -> node id it is written to."""
    scale: dict[str, float] = field(default_factory=dict)
    """Column or variable -> the control's unit per gatetherm's (default 1)."""

    def factor(self, name: str) -> float:
        """The scale of ``name`` (1 if not given)."""
        return self.scale.get(name, 1.0)


def default_map(columns, gradient: bool = False) -> NodeMap:
    """The default layout for the read ``columns`` (``time_s`` first) and ``offset_um`` written (with
    ``gradient``, also ``gradient_um_per_m`` and ``reference_m``)."""
    names = ("time_s", *(c for c in columns if c != "time_s"))
    return NodeMap({n: default_node(n) for n in names}, {n: default_node(n) for n in WRITTEN[:3 if gradient else 1]})


def read_map(path, columns) -> NodeMap:
    """The map file at ``path`` over the default layout of ``columns``; InputError naming the key."""
    where = str(path)
    text = read_text(Path(path), "--map", "give a TOML map file (docs/live.md)")
    data = parse_toml(text, where, "see the examples in docs/live.md", what="TOML")
    for key in data:
        if key not in KEYS:
            raise InputError(f"{where}: [{key}]", "unknown table", f"use {', '.join(KEYS)}")
    base = default_map(columns)
    read, write = dict(base.read), dict(base.write)
    for table, target in (("read", read), ("write", write)):
        for name, node in data.get(table, {}).items():
            if not isinstance(node, str) or not node.strip():
                raise InputError(f"{where}: [{table}] {name}", "is not a node id string", 'e.g. "ns=3;s=T1"')
            if table == "write" and name not in WRITTEN:
                raise InputError(f"{where}: [write] {name}", "is not a correction variable",
                                 f"use {', '.join(WRITTEN)}")
            target[name] = node.strip()
    scale = {}
    for name, value in data.get("scale", {}).items():
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value == 0:
            raise InputError(f"{where}: [scale] {name}", f"{value!r} is not a non-zero number", "e.g. 0.001")
        scale[name] = float(value)
    return NodeMap(read, write, scale)
