"""Axis labels and legend entries from a case's own names: the unit of a table column or of a
case-file key, and what the data format's θ_A, θ_B, θ_C and δ are on this machine."""
from __future__ import annotations

import re

SUFFIX_UNITS = {"_um": "µm", "_degC": "°C", "_MPa": "MPa", "_K": "K", "_min": "min", "_s": "s", "_h": "h",
                "_W": "W", "_V": "V", "_m": "m", "_Pa": "Pa", "_rpm": "rpm"}
"""The unit of a column by its name's suffix (the data format's, docs/data-format.md)."""
KEY_UNITS = {
    "film": "W/(m² K)", "film_on": "W/(m² K)", "film_off": "W/(m² K)", "h_air": "W/(m² K)",
    "ambient": "°C", "temperature": "°C", "supply": "°C", "reference": "°C", "flux": "W/m²",
    "power": "W", "density": "W/m³", "k": "W/(m K)", "E": "Pa", "nu": "1", "alpha": "1/K",
    "rho": "kg/m³", "c": "J/(kg K)", "thickness": "m", "size": "m", "distance": "m", "end": "s",
    "step": "s", "output": "s", "fields": "s", "volume": "m³", "rho_c": "J/(m³ K)", "flow_rate": "m³/s",
    "capacity": "J/K", "conductance": "W/K", "hose_capacity": "J/K", "hose_loss": "W/K", "stiffness": "N/m³",
    "A_C": "m²", "order": "1"}
"""The unit of a case-file (or model-file) key by its last part (docs/case-file.md)."""
RESULT_UNITS = ((re.compile(r"^K[ic]_(norm_.*)$"), "1"), (re.compile(r"^K[ic]_"), "µm/K"),
                (re.compile(r"^(l_over_|l1_over_|beta$)"), "1"), (re.compile(r"^nodes$"), "count"))
"""Units of the sweep's result columns that carry no unit suffix."""


PAPER_TIPS = ("F_L", "F_R")
"""The probes of the paper frame's δ (its tips F): its pictures keep the paper's labels."""


def unit(name: str) -> str | None:
    """The unit of a table column, a case-file key (dotted) or a sweep parameter; None: unknown
    (a number a geometry script reads, whose unit is the script's)."""
    for pattern, u in RESULT_UNITS:
        if pattern.search(name):
            return u
    if name.startswith("effect."):
        from gatetherm.solvers.effects import KINDS

        kind = KINDS.get(name.removeprefix("effect.").partition("@")[0])
        return kind.unit if kind is not None else None
    if name.startswith("derived."):
        return None if name.endswith("tank_cavity") else "1"
    if name.startswith("geometry."):
        return KEY_UNITS.get(name.rsplit(".", 1)[1], "m")
    if name.startswith("mesh.parameters."):
        return None
    last = name.rsplit(".", 1)[-1]
    if "." in name and last in KEY_UNITS:
        return KEY_UNITS[last]
    return next((u for s, u in SUFFIX_UNITS.items() if name.endswith(s)), None)


def axis_label(name: str) -> str:
    """``name [unit]``, or ``name`` where the unit is not known."""
    u = unit(name)
    return name if u is None else f"{name} [{u}]"


def _axis(axis: int) -> str:
    return "xyz"[axis]


def signal_labels(problem) -> dict[str, str]:
    """Legend entries of the data format's signals on this case (a
    :class:`~gatetherm.solvers.problem.Problem`): ``θ_A (probe …)``, ``θ_C (mean of …)``, ``δ =
    u_y(a) − u_y(b)``; an empty dict where the case names none. The paper's frame (δ between
    :data:`PAPER_TIPS`) keeps the paper's words: θ_A, θ_B, θ_C and "δ at the tips F"."""
    s, out = problem.signals, {}
    rel = {r.name: r for r in problem.relative}
    if s.delta in rel and (rel[s.delta].a, rel[s.delta].b) == PAPER_TIPS:  # the paper's frame: its own words
        return {"delta_um": "δ at the tips F"}
    for key, probe in (("theta_A_degC", s.theta_A), ("theta_B_degC", s.theta_B)):
        if probe:
            out[key] = f"θ_{key[6]} (probe {probe})"
    if s.theta_C:
        which = f"probe {s.theta_C[0]}" if len(s.theta_C) == 1 else "mean of " + ", ".join(s.theta_C)
        out["theta_C_degC"] = f"θ_C ({which})"
    if s.delta in rel:
        r = rel[s.delta]
        out["delta_um"] = f"δ = u_{_axis(r.axis)}({r.a}) − u_{_axis(r.axis)}({r.b})"
    return out
