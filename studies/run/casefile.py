"""Write a :class:`~gatetherm.solvers.problem.Problem` as a case file that
:func:`gatetherm.studies.run.case.load_case` reads back to the same problem: how the
paper's frame becomes a case a user can copy (``gatetherm mesh --out DIR`` writes it)."""
from __future__ import annotations

import math

from gatetherm.solvers.expr import Value
from gatetherm.solvers.problem import AXES, Problem
from gatetherm.studies.run.case import TimeSettings


def _v(x) -> str:
    if isinstance(x, Value):
        return f'"{x.text}"' if x.text else _v(x.constant)
    if isinstance(x, str):
        return f'"{x}"'
    if isinstance(x, (list, tuple)):
        return "[" + ", ".join(_v(e) for e in x) + "]"
    if isinstance(x, bool):
        return "true" if x else "false"
    return repr(float(x)) if isinstance(x, float) else str(x)


def _table(name: str, rows: dict) -> list[str]:
    return [f"[{name}]", *(f"{k} = {_v(v)}" for k, v in rows.items() if v is not None), ""]


def case_toml(problem: Problem, name: str, mesh_file: str, points: dict[str, str] | None = None,
              time: TimeSettings | None = None, header: str = "") -> str:
    """The case file of ``problem`` on the mesh ``mesh_file``; ``points`` maps probe names to
    point groups of the mesh (else coordinates are written)."""
    p, points = problem, points or {}
    L = [f"# {h}" for h in header.splitlines()] + ([""] if header else [])
    L += _table("case", {"name": name, "order": p.order, "plane": p.plane if p.dim == 2 else None})
    L += _table("mesh", {"file": mesh_file})
    for r, m in p.materials.items():
        rows = {k: getattr(m, k) for k in ("k", "rho", "c", "E", "nu", "alpha") if not math.isnan(getattr(m, k))}
        L += _table(f"materials.{r}", {**rows, "thickness": p.thickness.get(r) if p.dim == 2 else None})
    L += _table("initial", {"temperature": p.T0, "reference": p.T_ref})
    for f in p.films:
        L += _table(f"thermal.{f.boundary}", {"film": f.h, "ambient": f.ambient})
    for f in p.fixed:
        L += _table(f"thermal.{f.boundary}", {"temperature": f.value})
    for f in p.fluxes:
        L += _table(f"thermal.{f.boundary}", {"flux": f.value})
    if p.faces is not None:
        L += _table("faces", {"film": p.faces.h, "ambient": p.faces.ambient})
    for s in p.sources:
        L += _table(f"sources.{s.region}", {"density": s.density} if s.per == 1.0 else {"power": s.density})
    for f in p.fluids:
        L += _table(f"fluids.{f.name}", {
            "boundary": f.boundary, "capacity": f.capacity, "conductance": f.conductance, "film_on": f.film_on,
            "film_off": f.film_off, "supply": f.supply, "pump": f.pump, "hose_capacity": f.hose_capacity or None,
            "hose_loss": f.hose_loss if f.hose_capacity else None, "hose_name": f.hose_name or None,
            "ambient": f.ambient})
    for s in p.supports:
        if s.values:
            held = dict(zip(s.components, s.values))
            L += _table(f"supports.{s.boundary}", {"type": "displacement",
                                                   "value": [held.get(c, "free") for c in range(p.dim)]})
            continue
        kind = "foundation" if s.stiffness is not None else "fixed"
        L += _table(f"supports.{s.boundary}", {"type": kind, "components": [AXES[c] for c in s.components],
                                               "stiffness": s.stiffness})
    if p.gravity:
        L += _table("gravity", {"acceleration": list(p.gravity)})
    for ld in p.loads:
        L += _table(f"loads.{ld.boundary}", {ld.kind: ld.values[0] if ld.kind == "pressure" else list(ld.values)})
    for pl in p.point_loads:
        L += _table(f"loads.{pl.point}", {"force": list(pl.force)})
    for c in p.contacts:
        L += _table(f"contacts.{c.name}", {"between": list(c.between), "conductance": c.conductance,
                                           "stiffness": list(c.stiffness) if c.stiffness else None})
    for pr in p.probes:
        L += _table(f"probes.{pr.name}", {"point": points.get(pr.name, list(pr.xyz)), "quantities": list(pr.quantities),
                                          "region": pr.region})
    for r in p.relative:
        L += _table(f"relative.{r.name}", {"a": r.a, "b": r.b, "axis": AXES[r.axis]})
    if p.means:
        L += _table("means", dict(p.means))
    s = p.signals
    if s.complete:
        L += _table("signals", {"theta_A": s.theta_A, "theta_B": s.theta_B, "theta_C": list(s.theta_C),
                                "delta": s.delta})
    if time is not None:
        L += _table("time", {"end": time.end, "step": time.step, "output": time.output, "fields": time.fields,
                             "schedule": time.schedule.name if time.schedule else None})
        L += _table("time.scheme", {"theta": p.scheme.theta, "restart": p.scheme.restart,
                                    "restart_intervals": p.scheme.restart_intervals})
    return "\n".join(L).rstrip("\n") + "\n"
