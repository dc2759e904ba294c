"""``film`` of ``[thermal.BOUNDARY]`` as a number, or as a table naming a correlation
(:mod:`gatetherm.solvers.convection`), with ``emissivity`` for radiation: a film whose coefficient
follows the surface temperature and the inputs, solved by Picard iterations in each step."""
from __future__ import annotations

from gatetherm.checks import Range
from gatetherm.solvers import convection
from gatetherm.solvers.convection import FilmLaw
from gatetherm.solvers.expr import Value
from gatetherm.solvers.problem import Film
from gatetherm.studies.run.tables import Table

KEYS = {"thermal.BOUNDARY.film": ("correlation", "length", "speed", "reference", "minimum", "factor")}
"""The keys of a film table (as :data:`gatetherm.studies.run.case.KEYS`)."""
FILM = Range(0.0, unit="W/(m² K)")
REFERENCE_POINT = (40.0, 20.0)
"""(surface, ambient) temperature, °C, at which a law's coefficient is the default reference."""


def film(t: Table, boundary: str, names) -> Film:
    """The film of the ``[thermal.BOUNDARY]`` table ``t`` (it has ``film``)."""
    ambient = t.value("ambient", names, unit="°C")
    eps = t.number("emissivity", Range(0.0, 1.0, unit="1"), 0.0)
    if not isinstance(t.data["film"], dict):
        h = t.number("film", FILM)
        if not eps:
            return Film(boundary, h, ambient)
        law = FilmLaw(h=h, emissivity=eps)
        return Film(boundary, law(*REFERENCE_POINT, {}), ambient, law)
    f = t.sub("film", KEYS["thermal.BOUNDARY.film"])
    name = f.string("correlation", choices=convection.CORRELATIONS)
    unit = convection.SPEED.get(name)
    if unit is None and "speed" in f.data:
        f.fail("speed", f"goes with a rotating part or a flow, not {name}", "remove it")
    speed = f.value("speed", names, unit=unit) if unit else Value(0.0)
    law = FilmLaw(name, 0.0, f.number("length", Range(0.0, lo_open=True, unit="m")), speed, eps,
                  f.number("minimum", FILM, 0.0), f.number("factor", Range(0.1, 10.0, unit="1"), 1.0))
    if "reference" not in f.data and not speed.is_constant:
        f.fail("reference", "missing: the coefficient follows the schedule's speed",
               "give the coefficient (W/(m² K)) near the largest the run reaches")
    reference = f.number("reference", Range(0.0, lo_open=True, unit="W/(m² K)")) if "reference" in f.data else law(*REFERENCE_POINT, {})
    return Film(boundary, reference, ambient, law)
