"""Admissible values of parameters: declared once per dataclass field, checked where input is read.

A :class:`Range` says what a number may be (always finite; bounds, open or closed; whole
numbers only). ``@admissible(name=Range, ...)`` attaches ranges to the fields of a parameter
dataclass, next to its definition; :func:`check_fields` checks an instance against them.
Every reader of user input (model files, case files, schedules, data files, command-line
options) calls these, so a parameter has one range everywhere and every refusal states it.
"""
from __future__ import annotations

import dataclasses
import math
import numbers
from dataclasses import dataclass

import numpy as np

from gatetherm import InputError

ABSOLUTE_ZERO_C = -273.15
"""Absolute zero, °C."""
MAX_CELSIUS = 1000.0
"""Highest temperature gatetherm accepts, °C: far above where grey iron and mineral oil
stay the linear solids and liquids the models assume."""


@dataclass(frozen=True)
class Range:
    """Finite numbers from ``lo`` to ``hi``."""

    lo: float = -np.inf
    """Lower bound (-inf: none)."""
    hi: float = np.inf
    """Upper bound (inf: none)."""
    lo_open: bool = False
    """``lo`` itself is excluded."""
    hi_open: bool = False
    """``hi`` itself is excluded."""
    whole: bool = False
    """Whole numbers only."""
    unit: str = ""
    """Unit named in messages, e.g. ``"°C"``."""

    def mask(self, values) -> np.ndarray:
        """Element-wise: is each of ``values`` admissible?"""
        v = np.asarray(values, dtype=float)
        with np.errstate(invalid="ignore"):
            ok = np.isfinite(v) & ((v > self.lo) if self.lo_open else (v >= self.lo))
            ok &= (v < self.hi) if self.hi_open else (v <= self.hi)
            if self.whole:
                ok &= v == np.round(v)
        return ok

    def admits(self, value) -> bool:
        """Is ``value`` (a number, not a bool) admissible?"""
        try:
            return _number(value) and self.holds(float(value))
        except OverflowError:  # an integer beyond any float
            return False

    def holds(self, x: float) -> bool:
        """Is the float ``x`` admissible? (:meth:`mask` for one number, without numpy: fast)"""
        return math.isfinite(x) and (x > self.lo if self.lo_open else x >= self.lo) and \
            (x < self.hi if self.hi_open else x <= self.hi) and (not self.whole or x == round(x))

    def __str__(self) -> str:
        if self.whole and np.isfinite(self.hi) and self.hi - self.lo <= 1:
            return " or ".join(str(int(x)) for x in np.arange(self.lo, self.hi + 1))
        unit = f" {self.unit}" if self.unit else ""
        lo, hi = f"{self.lo:g}", f"{self.hi:g}"
        if np.isfinite(self.lo) and np.isfinite(self.hi):
            bounds = f"{'(' if self.lo_open else '['}{lo}, {hi}{')' if self.hi_open else ']'}"
            return f"{'a whole number' if self.whole else 'a number'} in {bounds}{unit}"
        kind = "a whole number" if self.whole else "a finite number"
        if np.isfinite(self.lo):
            return f"{kind} {'>' if self.lo_open else '>='} {lo}{unit}"
        if np.isfinite(self.hi):
            return f"{kind} {'<' if self.hi_open else '<='} {hi}{unit}"
        return kind

    def check(self, where: str, value, fix: str = ""):
        """``value`` if admissible, else :class:`~gatetherm.InputError` naming ``where`` and the range."""
        if not self.admits(value):
            raise InputError(where, f"got {show(value)}, must be {self}", fix)
        return value


def _number(value) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))


def show(value) -> str:
    """A value as a message quotes it: numbers in ``%g``, anything else in ``repr``."""
    try:
        return f"{float(value):g}" if _number(value) else repr(value)
    except OverflowError:
        return str(value)


POSITIVE = Range(0.0, lo_open=True)
NONNEGATIVE = Range(0.0)
FINITE = Range()
CELSIUS = Range(ABSOLUTE_ZERO_C, MAX_CELSIUS, lo_open=True, unit="°C")
"""A temperature: above absolute zero and at most :data:`MAX_CELSIUS`."""
KELVIN_LIKE = (253.15, 373.15)
"""°C values that are surroundings written in kelvins by mistake (−20 … 100 °C in K): read from
a case file with a warning, refused as a model file's reference."""
ACCELERATION = Range(-1e4, 1e4, unit="m/s²")
"""A component of ``[gravity]``: up to about 1 000 g (a machine on a shaker table, not a
number that makes every displacement overflow)."""
BY_UNIT = {"°C": CELSIUS, "N": Range(-1e12, 1e12, unit="N"), "Pa": Range(-1e12, 1e12, unit="Pa"),
           "m": Range(-1e3, 1e3, unit="m")}
"""The range of a case file's value of a unit where its key names none: a temperature; a force or
pressure (1e12 N, 1 TPa: beyond any machine, short of overflow); a length (1 km). Else: finite."""


def admissible(default: Range | None = None, **ranges: Range):
    """Class decorator (above ``@dataclass``): the :class:`Range` of each named field, and
    ``default`` that of every other field."""
    def attach(cls):
        names = [f.name for f in dataclasses.fields(cls)]
        unknown = set(ranges) - set(names)
        if unknown:
            raise TypeError(f"{cls.__name__} has no fields {sorted(unknown)}")
        cls.__admissible__ = {**({n: default for n in names} if default else {}), **ranges}
        return cls
    return attach


def ranges(cls) -> dict[str, Range]:
    """The field ranges declared by :func:`admissible` on ``cls`` (empty if none)."""
    return dict(getattr(cls, "__admissible__", {}))


def check_fields(obj, prefix: str = "", names=None):
    """``obj`` if each field with a declared range (those in ``names``, default all) is
    admissible or None (not set); else :class:`~gatetherm.InputError` naming ``prefix + field``."""
    for name, rng in ranges(type(obj)).items():
        value = getattr(obj, name)
        if value is not None and (names is None or name in names):
            rng.check(f"{prefix}{name}", value)
    return obj


def check_linear_system(where: str, modes, C, D=None, inputs=None, outputs=None) -> None:
    """InputError naming ``where`` unless ``ẋ = A x + B u, y = C x (+ D u)`` is a sound
    linear system in every mode of ``modes`` ({mode: (A, B)}, any number of modes): consistent
    shapes (and as many ``inputs``/``outputs`` names as B has columns and C rows, where given),
    finite entries, and every A stable (its eigenvalues' real parts negative)."""
    fix = "write it again with 'gatetherm reduce'"

    def fail(what: str):
        raise InputError(where, what, fix)

    if not modes:
        fail("no mode (no A, B matrices)")
    arrays = {"C": C, **({"D": D} if D is not None else {})}
    for mode, (A, B) in modes.items():
        arrays.update({f"A_{mode}": A, f"B_{mode}": B})
    for name, M in arrays.items():
        M = np.asarray(M)
        if M.ndim != 2 or 0 in M.shape:
            fail(f"{name} is not a matrix (shape {M.shape})")
        if not np.issubdtype(M.dtype, np.number) or not np.isfinite(M).all():
            fail(f"{name} has entries that are not finite numbers")
    def usual(sizes):  # the size most matrices agree on: the others are wrong
        return max(sizes, key=sizes.count)
    n = usual([np.shape(A)[0] for A, _ in modes.values()] + [np.shape(C)[1]])
    m, p = usual([np.shape(B)[1] for _, B in modes.values()]), np.shape(C)[0]
    want = {**{f"A_{k}": (n, n) for k in modes}, **{f"B_{k}": (n, m) for k in modes}, "C": (p, n), "D": (p, m)}
    for name, M in arrays.items():
        if np.shape(M) != want[name]:
            fail(f"{name} has shape {np.shape(M)}, expected {want[name]} ({n} states, {m} inputs, {p} outputs)")
    for names, count, what in ((inputs, m, "inputs"), (outputs, p, "outputs")):
        if names is not None and len(names) != count:
            fail(f"{len(names)} {what} named for {count} {what} of the matrices")
    for mode, (A, _) in modes.items():
        eig = np.linalg.eigvals(np.asarray(A, float))
        if not eig.real.max() < -1e-9 * np.abs(eig).max():  # a zero eigenvalue is zero only to round-off
            fail(f"A_{mode} is not stable (an eigenvalue with real part {eig.real.max():.3g} >= 0)")


class NonFiniteError(InputError):
    """A number that would be written to a file, or was read from one, is NaN or infinite:
    ``str(err)`` names the file and the quantity (its path in the data) on one line."""


def first_nonfinite(data, path: str = "") -> tuple[str, float, str] | None:
    """``(path, value, text)`` of the first NaN or infinite float in nested dicts, lists and
    tuples (``path`` as ``a.b[2].c``; ``text`` as a JSON file had it), or None."""
    stack = [(path, data)]
    while stack:
        where, value = stack.pop()
        if isinstance(value, (float, np.floating)) and not math.isfinite(value):
            return where or "the value", float(value), getattr(value, "text", str(float(value)))
        if isinstance(value, dict):
            stack.extend((f"{where}.{k}" if where else str(k), v) for k, v in reversed(list(value.items())))
        elif isinstance(value, (list, tuple)):
            stack.extend((f"{where}[{i}]", v) for i, v in reversed(list(enumerate(value))))
    return None


def json_text(data, what: str, **dumps) -> str:
    """``data`` as JSON text (and a final newline) for the file ``what``; :class:`NonFiniteError`
    naming the quantity if a number in it is NaN or infinite (JSON has no such numbers, and a
    reader would take a default for them)."""
    import json

    bad = first_nonfinite(data)
    if bad is not None:
        raise NonFiniteError(f"{what}: {bad[0]}", f"is {bad[1]}, not a finite number; nothing was written",
                             "report it with the command and its input files")
    return json.dumps(data, allow_nan=False, **dumps) + "\n"


MAX_JSON_DEPTH = 32
"""Deepest nesting of lists and objects a JSON input file may have."""


def parse_json(text: str, where: str, fix: str):
    """The data of the JSON text of the file ``where``: InputError (one line) for text that is
    not JSON, for NaN, Infinity or a number too large for a float, and for nesting deeper than
    :data:`MAX_JSON_DEPTH`."""
    import json

    def constant(name):  # NaN, Infinity: kept until the entry holding it can be named
        return _NonFinite(name)

    def number(text):
        value = float(text)
        return value if math.isfinite(value) else _NonFinite(text)

    def integer(text):
        if len(text.lstrip("-")) > 18:
            raise InputError(where, f"holds the integer {text[:12]}... of {len(text)} digits", fix)
        return int(text)

    try:
        data = json.loads(text, parse_constant=constant, parse_float=number, parse_int=integer)
    except RecursionError:
        data = None
        too_deep = True
    except ValueError as err:
        if isinstance(err, InputError):
            raise
        raise InputError(where, f"not JSON ({err})", fix) from None
    else:
        too_deep = False
        stack = [(data, 1)]
        while stack and not too_deep:
            value, depth = stack.pop()
            if isinstance(value, (dict, list)):
                too_deep = depth > MAX_JSON_DEPTH
                stack.extend((v, depth + 1) for v in (value.values() if isinstance(value, dict) else value))
    if too_deep:
        raise InputError(where, f"nested deeper than {MAX_JSON_DEPTH} levels", fix)
    bad = first_nonfinite(data)
    if bad is not None:
        raise InputError(f"{where}: {bad[0]}", f"holds {bad[2]}, not a finite number", fix)
    return data


class _NonFinite(float):
    """A NaN, an infinity or a number too large for a float as read from a JSON file, its text kept."""
    def __new__(cls, text: str):
        value = super().__new__(cls, "nan")
        value.text = text
        return value


def argument(name: str, value, kinds, expected: str, fix: str = ""):
    """``value`` if it is an instance of ``kinds`` (a bool only where ``bool`` is among them),
    else a one-line :class:`TypeError` naming the argument ``name``, what it ``expected`` and the
    ``fix``: a public function's type check, before any numerics."""
    kinds = kinds if isinstance(kinds, tuple) else (kinds,)
    if isinstance(value, kinds) and not (isinstance(value, (bool, np.bool_)) and bool not in kinds):
        return value
    raise TypeError(f"{name}: got {type(value).__name__} {_short(value)}, expected {expected}" + (f"; {fix}" if fix
                                                                                                  else ""))


def number_argument(name: str, value, rng: Range = FINITE, fix: str = "") -> float:
    """``value`` as a float if it is a number (not a bool: :class:`TypeError`) in ``rng``, else
    :class:`~gatetherm.InputError` naming the argument ``name``, the range and the ``fix``."""
    argument(name, value, numbers.Real, "a number", fix)
    rng.check(name, value, fix)
    return float(value)


def whole_argument(name: str, value, rng: Range, fix: str = "") -> int:
    """``value`` as an int if it is a whole number (an int, or a float with no fraction: not a
    bool, :class:`TypeError`) in ``rng``; else InputError naming ``name``, the range, the fix."""
    argument(name, value, numbers.Real, "a whole number", fix)
    dataclasses.replace(rng, whole=True).check(name, value, fix)
    return int(value)


def _short(value) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."
