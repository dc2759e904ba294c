"""Heat from machine elements: the losses of bearings, ball screws, linear guides and motors.

A machine element is a heat-source kind of a case file (``[sources.REGION] kind``), one module of
this package each (found here, no list to edit: a new kind is a new module). A module holds its
loss law, a small pure function of the operating point (numbers or numpy arrays); the same formula
as the text of an expression (:class:`~gatetherm.solvers.expr.Value`) of the run's inputs; and
``KINDS``, its :class:`ElementKind` entries: the case-file keys and the reader that makes the
expression of a ``[sources.REGION]`` table (:mod:`gatetherm.studies.run.case_sources` reads them
here). The heat problem, the reduced model and the checks of a schedule then see an ordinary power
in W. The formulas and their sources are in ``docs/model.md`` (Machine elements);
``tests/test_elements.py`` checks every expression against its function, ``tests/test_docs.py``
every key against ``docs/case-file.md``.

Units as the handbooks give them: speeds in 1/min, viscosity in mm²/s, lengths in m (the
bearing formula converts to mm), forces in N, torques in N·m, losses in W.
"""
from __future__ import annotations

import importlib
import pkgutil
from dataclasses import dataclass
from typing import Callable

from gatetherm.checks import Range

POSITIVE_M = Range(0.0, lo_open=True, unit="m")
"""A length of an element."""
FACTOR = Range(0.0, unit="1")
"""A factor (Palmgren's f0, f1; a source's ``factor``)."""


@dataclass(frozen=True)
class ElementKind:
    """A heat-source kind: a machine element whose loss a ``[sources.REGION]`` table gives.

    ``read(t, text)`` makes the loss, W, as the text of an expression of the run's inputs from the
    table ``t`` (:class:`gatetherm.studies.run.tables.Table`: ``t.number(key, range, default)``,
    ``t.string(key, default, choices)``, ``t.data``, ``t.fail(key, problem, fix)``) and
    ``text(key, unit, default=None, rng=None)``, the text of a key that may be an expression of
    the schedule's columns (a number, a column, a formula)."""

    name: str
    """The ``kind`` (``kind = "bearing"``)."""
    keys: tuple[str, ...]
    """Its keys of ``[sources.REGION]`` (besides ``kind``, ``factor`` and a moving source's)."""
    read: Callable
    """``read(t, text) -> str``: the loss's expression text."""
    order: int = 100
    """Its place among the kinds (messages, the reference)."""
    lengths: tuple[str, ...] = ()
    """Its keys that are lengths, m: one larger than the body is warned of (a value meant in mm)."""
    parts: tuple = ()
    """(key, unit, range) of the keys whose expression is also checked over the run (the viscosity)."""


def paren(text: str) -> str:
    """``text`` in parentheses (a term of a larger expression)."""
    return f"({text})"


def _discover() -> dict[str, ElementKind]:
    """The kinds of every module of this package, in order; each module's public names offered here too."""
    found = []
    for info in pkgutil.iter_modules(__path__):
        module = importlib.import_module(f"{__name__}.{info.name}")
        found += getattr(module, "KINDS", ())
        globals().update({n: getattr(module, n) for n in getattr(module, "__all__", ())})
    return {k.name: k for k in sorted(found, key=lambda k: (k.order, k.name))}


KINDS: dict[str, ElementKind] = _discover()
"""Every heat-source kind by name (a plug-in may add one: ``KINDS[kind.name] = kind``)."""
