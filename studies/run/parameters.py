"""The numbers of a case that may be off: each a named change of its file's keys.

A :class:`Parameter` knows the case's value, a plausible range and the keys of the file a
new value writes (:attr:`Parameter.overrides`), so a diagnosis or a study moves it by making
the case again (:meth:`~gatetherm.studies.run.case.Case.with_overrides`). A case file's are
found from its document (:func:`case_parameters`); the paper frame's generator declares its
own (:func:`gatetherm.frame.case.frame_parameters`).

*Geometry* parameters (:func:`geometry`) are dimensions the user marks as uncertain: a new value
makes the mesh again (``remesh``), so every model run of one costs a remeshing too.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

FILM, FLUID_FILM, SOURCE, SHIFT = (0.4, 2.5), (0.2, 5.0), (0.5, 2.0), 3.0
"""Plausible ranges of films, fluid films and sources (factors) and of the initial temperature (shift, K)."""
GEOMETRY = (0.8, 1.25)
"""Plausible range of a dimension marked as uncertain (a factor on the model's value): a drawing
and a machine differ by less than a fifth."""
#: One factor on every region's material property: name -> (key, range, doc).
MATERIAL = {
    "conductivity": ("k", 0.6, 1.6, "thermal conductivity k of every region (one factor)"),
    "expansion": ("alpha", 0.8, 1.25, "thermal expansion coefficient α of every region (one factor; δ is "
                  "proportional to it where all regions share it: the data cannot tell it from a gain of the "
                  "δ sensor)"),
    "heat_capacity": ("c", 0.8, 1.25, "specific heat c, so ρc, of every region (one factor)"),
}


@dataclass(frozen=True)
class Parameter:
    """A number of a case that may be off, and how a value of it changes the case's file."""

    name: str
    param: str
    """Short name of the quantity (``h``, ``factor``, ``T0``, ``k`` …)."""
    unit: str
    value: float
    """The case's own value (the neutral one)."""
    lo: float
    hi: float
    """Plausible range, in the parameter's unit."""
    log_scale: bool
    doc: str
    write: Callable[[float], dict] = field(compare=False, repr=False)
    """``value -> {dotted key: value}`` of the case's file."""
    target: str | None = None
    """The boundary, fluid or region it acts on."""
    remesh: bool = False
    """A new value changes the geometry: the case is meshed again."""

    def overrides(self, value: float) -> dict:
        return self.write(float(value))


def factor(name, param, unit, value, rng, doc, write, target=None) -> Parameter:
    return Parameter(name, param, unit, value, value * rng[0], value * rng[1], True, doc, write, target)


def geometry(key: str, value: float, unit: str, doc: str, rng=GEOMETRY) -> Parameter:
    """The dimension at ``key`` (``geometry.l_C``, ``mesh.parameters.table_height``) as a parameter named
    by its key: ``rng`` times its value (log scale), a new value meshes the case again."""
    return Parameter(key, key.rsplit(".", 1)[-1], unit, value, value * rng[0], value * rng[1], True, doc,
                     lambda v: {key: v}, remesh=True)


def mesh_parameter(document: dict, key) -> float | None:
    """The value of ``key`` (``mesh.parameters.NAME``) in a case file's ``document``; None unless it is a
    non-zero number there."""
    value = document.get("mesh", {}).get("parameters", {}).get(key.removeprefix("mesh.parameters."), None) \
        if isinstance(key, str) and key.startswith("mesh.parameters.") else None
    return None if isinstance(value, bool) or not isinstance(value, (int, float)) or value == 0 else float(value)


UNCERTAIN_FIX = ("name a number of [mesh.parameters] (a parameter of the geometry script), e.g. "
                 "uncertain = [\"mesh.parameters.table_height\"] with table_height = 0.1 in [mesh.parameters]")


def marked(case, keys=()) -> tuple[Parameter, ...]:
    """The ``mesh.parameters`` of a case file marked as uncertain (``[case] uncertain``, and ``keys``,
    e.g. from ``--uncertain``) as geometry parameters."""
    from gatetherm import InputError

    doc = case.origin.document
    out = []
    for key in dict.fromkeys([*doc.get("case", {}).get("uncertain", []), *keys]):
        value = mesh_parameter(doc, key)
        if value is None:
            raise InputError("--uncertain", f"'{key}' is not a non-zero number of [mesh.parameters] of {case.path}",
                             UNCERTAIN_FIX)
        out.append(geometry(key, value, "", f"geometry parameter '{key.rsplit('.', 1)[-1]}' of {doc['mesh']['file']}"))
    return tuple(out)


def _scaled(v, f: float):
    """A file value (a number or an expression) times ``f``."""
    return float(v) * f if isinstance(v, (int, float)) else f"{f!r} * ({v})"


def case_parameters(case) -> tuple[Parameter, ...]:
    """A case file's own numbers as parameters: every film coefficient (per boundary, and the
    2-D faces'), every fluid's films, every source (a factor), the initial temperature of a
    transient case, one factor on every region's k, α, c, and the geometry parameters the case marks
    as uncertain (:func:`marked`)."""
    doc, pr, out = case.origin.document, case.problem, []
    for f in pr.films:
        law = f.law
        if law is not None and law.correlation:  # a correlation: a factor on its convective part
            out.append(factor(f"film_{f.boundary}", "factor", "1", law.factor, FILM, f"factor on the {law.correlation} "
                              f"film of boundary '{f.boundary}' (its convective part)",
                              lambda v, b=f.boundary, r=f.h / law.factor: {f"thermal.{b}.film.factor": v,
                                                                           f"thermal.{b}.film.reference": r * v},
                              f.boundary))  # the reference scaled with it: the iterations settle below 2 × it
        elif (law.h if law is not None else f.h) > 0:  # a number (with radiation: its convective part)
            out.append(factor(f"film_{f.boundary}", "h", "W/(m2 K)", law.h if law is not None else f.h, FILM,
                              f"film coefficient of boundary '{f.boundary}'",
                              lambda v, b=f.boundary: {f"thermal.{b}.film": v}, f.boundary))
    if pr.faces is not None and pr.faces.h > 0:
        out.append(factor("faces_film", "h", "W/(m2 K)", pr.faces.h, FILM, "film coefficient of the section's "
                          "front and back faces", lambda v: {"faces.film": v}))
    for fl in pr.fluids:
        for p in ("film_on", "film_off"):
            if getattr(fl, p) > 0:
                out.append(factor(f"{fl.name}_{p}", p, "W/(m2 K)", getattr(fl, p), FLUID_FILM,
                                  f"wall film coefficient of fluid '{fl.name}', pump {p[5:]}",
                                  lambda v, n=fl.name, p=p: {f"fluids.{n}.{p}": v}, fl.name))
    for src in pr.sources:
        table = doc.get("sources", {}).get(src.region, {})
        if "kind" in table:  # a machine element's loss: a factor on it (its operating point unchanged)
            out.append(factor(f"source_{src.region}", "factor", "1", 1.0, SOURCE, f"factor on the {table['kind']} "
                              f"loss of '{src.region}'", lambda v, r=src.region, f=table.get("factor", 1.0):
                              {f"sources.{r}.factor": v * f}, src.region))
            continue
        key = "density" if "density" in table else "power"
        out.append(factor(f"source_{src.region}", "factor", "1", 1.0, SOURCE, f"factor on the heat source of "
                          f"region '{src.region}'", lambda v, r=src.region, k=key, x=table.get(key):
                          {f"sources.{r}.{k}": _scaled(x, v)}, src.region))
    if case.time is not None:
        out.append(Parameter("initial_offset", "T0", "degC", pr.T0, pr.T0 - SHIFT, pr.T0 + SHIFT, False,
                             "initial temperature of solid and fluids (stress-free temperature unchanged)",
                             lambda v, ref=pr.T_ref: {"initial.temperature": v, "initial.reference": ref}))
    for name, (key, lo, hi, text) in MATERIAL.items():
        out.append(factor(name, "factor", "1", 1.0, (lo, hi), text, lambda v, k=key: {
            f"materials.{r}.{k}": getattr(m, k) * v for r, m in pr.materials.items()}))
    return tuple(out) + marked(case)
