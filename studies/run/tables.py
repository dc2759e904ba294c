"""One table of a TOML input file, read key by key: typed access whose every refusal is
one :class:`~gatetherm.InputError` line naming the file, the key and what is admissible
(ranges from :mod:`gatetherm.checks`)."""
from __future__ import annotations

import logging
from pathlib import Path

from gatetherm import InputError
from gatetherm.checks import BY_UNIT, CELSIUS, FINITE, KELVIN_LIKE, Range
from gatetherm.solvers.expr import ExpressionError, Value
from gatetherm.studies.run.timeseries import alike

log = logging.getLogger(__name__)

MAX_TEXT = 200
"""Longest string a case file's value may be (a name, a file's path, a choice)."""
COLUMN_UNSAFE = ',"#'
"""Characters a name that becomes a data-format column may not hold (docs/data-format.md)."""


class Inputs(tuple):
    """The input names of a case's expressions (``t`` and the schedule's columns) and the file the
    columns come from (``source``, e.g. ``"the schedule s.csv"``; empty: no schedule), which the
    message about an unknown input names."""

    def __new__(cls, names, source: str = ""):
        self = super().__new__(cls, names)
        self.source = source
        return self


class Said(set):
    """The warnings one reading of a case file gave; a case made again from its document (with
    overrides: a sweep, a diagnosis, the quadratic-element check) repeats none of them."""

    def warn(self, logger, fmt: str, *args) -> None:
        text = fmt % args
        (logger.debug if text in self else logger.warning)("%s", text)
        self.add(text)


class MeshNames(tuple):
    """The keys a table may have where they name parts of the mesh (``what``: "boundary", …; ``plural``):
    an unknown one is "not a boundary of the mesh", not an unknown key."""

    def __new__(cls, names, what: str, plural: str):
        self = super().__new__(cls, names)
        self.what, self.plural = what, plural
        return self


class Table:
    """One table of the case file; remembers where it is for the error messages, and what was said."""

    def __init__(self, file: Path, where: str, data, known=None, said: Said | None = None):
        self.file, self.where = file, where
        self.said = Said() if said is None else said
        if not isinstance(data, dict):
            raise InputError(f"{file}: {where}", f"expected a table, got {data!r}", f"write [{where}] with key = value")
        self.data = data
        if known is not None:
            for key in data:
                if key not in known and isinstance(known, MeshNames):
                    raise InputError(f"{file}: {where}.{key}", f"'{key}' is not a {known.what} of the mesh",
                                     f"{known.plural}: {', '.join(known) or 'none'}{alike(key, known, 'names')}")
                if key not in known:
                    raise InputError(f"{file}: {where}.{key}", "unknown key", f"known keys: {', '.join(known)}")

    def key(self, k: str) -> str:
        return f"{self.file}: {self.where}.{k}" if self.where else f"{self.file}: {k}"

    def fail(self, k: str, problem: str, fix: str = ""):
        raise InputError(self.key(k), problem, fix)

    def number(self, k: str, rng: Range = FINITE, default=None) -> float:
        """The number at ``k`` if ``rng`` admits it; ``default`` if absent (None: required)."""
        if k not in self.data:
            if default is None:
                self.fail(k, "missing", f"give {rng}")
            return default
        value = float(rng.check(self.key(k), self.data[k]))
        if rng is CELSIUS:
            self._kelvin(k, value)
        return value

    def _kelvin(self, k: str, celsius: float) -> None:
        """Warn of a temperature in °C that reads as one in K (a room at 293.15 °C)."""
        if KELVIN_LIKE[0] <= celsius <= KELVIN_LIKE[1]:
            self.said.warn(log, "%s: %g °C reads like a temperature in kelvins (%g °C); temperatures are in °C",
                           self.key(k), celsius, celsius - 273.15)

    def string(self, k: str, default=None, choices=None) -> str:
        if k not in self.data:
            if default is None:
                self.fail(k, "missing", f"choose one of {', '.join(choices)}" if choices else "give a name")
            return default
        v = self.data[k]
        if not isinstance(v, str) or (choices and v not in choices):
            self.fail(k, f"{v!r} is not admissible", f"choose one of {', '.join(choices)}" if choices else "give a string")
        if not v.isprintable() or len(v) > MAX_TEXT:
            self.fail(k, f"is not one printable line of at most {MAX_TEXT} characters ({len(v)} characters)",
                      "give a plain name or path, without control characters")
        return v

    def column_name(self, name: str, what: str) -> str:
        """``name`` (a key of this table: a probe, a relative displacement) if it can name a
        data-format column; refused at reading, not after a run."""
        if not name.isprintable() or len(name) > 64 or any(c in name for c in COLUMN_UNSAFE) or not name.strip():
            self.fail(name, f"cannot name a {what}'s columns (it holds a comma, a quote, a '#' or a control "
                      "character, or is empty or longer than 64 characters)", "use letters, digits, '_', '-' or '.'")
        return name

    def name(self, k: str, valid, what: str, default=None) -> str:
        v = self.string(k, default=default)
        if v and v not in valid:
            self.fail(k, f"'{v}' is not a {what} of the mesh", f"{what}s: {', '.join(valid) or 'none'}")
        return v

    def value(self, k: str, names, default=None, unit: str = "", rng: Range | None = None) -> Value:
        """The value at ``k``: a number or an expression of ``names``, in ``rng`` (default the range
        of its ``unit``, :data:`gatetherm.checks.BY_UNIT`: °C a temperature, N a force …; else
        finite), checked now if it reads no input, else wherever it is evaluated."""
        rng = rng or BY_UNIT.get(unit, FINITE)
        if k not in self.data and default is not None:
            return Value(default, "", self.key(k), rng)
        if k not in self.data:
            self.fail(k, "missing", f"give a number{' in ' + unit if unit else ''} or an expression")
        try:
            v = Value.of(self.data[k], self.key(k), rng)
        except ExpressionError as err:
            self.fail(k, str(err), "write a number or an expression such as \"100*sin(pi*t/40)\"")
        if rng is CELSIUS and v.is_constant:
            self._kelvin(k, float(v.constant))
        unknown = sorted(v.names() - set(names))
        if unknown and isinstance(names, Inputs):
            u, columns = unknown[0], [n for n in names if n != "t"]
            if names.source:
                self.fail(k, f"'{u}' in '{v}' is not a column of {names.source}",
                          f"add the column {u} to it{alike(u, columns)} (inputs here: {', '.join(sorted(names))})")
            self.fail(k, f"'{u}' in '{v}' is no input: the case has no [time] schedule",
                      f"give [time] schedule = a time-series file with a {u} column, or a number")
        if unknown:
            self.fail(k, f"unknown input '{unknown[0]}' in '{v}'", f"inputs here: {', '.join(sorted(names))}")
        return v

    def sub(self, k: str, known=None) -> "Table":
        return Table(self.file, f"{self.where}.{k}" if self.where else k, self.data.get(k, {}), known, self.said)
