"""Values of a case: a constant, or an expression of time, schedule inputs and position.

A case file gives a boundary temperature, an ambient, a source or a prescribed
temperature field as a number or as a string such as ``"ambient_degC"``,
``"100*sin(pi*t/40)"`` or ``"sqrt(x**2 + y**2) + z"``. The string is parsed once into
a restricted expression (numbers, names, + - * / **, comparisons and the functions of
:data:`FUNCTIONS`); nothing else of Python is reachable, so a case file cannot run code.
An expression is at most :data:`MAX_LENGTH` characters and :data:`MAX_DEPTH` operations
deep. Every evaluation is checked: a division by zero, an overflow, a result out of the
function's domain (``sqrt(-1)``, ``log(0)``) or a value that is not finite or not in the
:class:`~gatetherm.checks.Range` of its key is an :class:`~gatetherm.InputError` naming the
key, the expression and the time (or point) where it happened.
"""
from __future__ import annotations

import ast
import functools
import math
import operator
from dataclasses import dataclass, field
from typing import Mapping

import numpy as np

from gatetherm import InputError
from gatetherm.checks import FINITE, Range, show

FUNCTIONS = {"sqrt": np.sqrt, "sin": np.sin, "cos": np.cos, "tan": np.tan, "exp": np.exp, "log": np.log,
             "abs": np.abs, "tanh": np.tanh, "atan2": np.arctan2,
             "min": lambda *a: functools.reduce(np.minimum, a), "max": lambda *a: functools.reduce(np.maximum, a)}
"""Functions an expression may call (on arrays: a field)."""


def _power(a: float, b: float) -> float:
    r = a ** b
    if isinstance(r, complex):
        raise ValueError("a negative number to a fractional power")
    return r


ARITY = {"atan2": (2, 2), "min": (2, None), "max": (2, None)}
"""(fewest, most) arguments of the functions that do not take exactly one (None: no limit)."""
CONSTANTS = {"pi": math.pi}
MAX_LENGTH = 1000
"""Longest expression, characters."""
MAX_DEPTH = 50
"""Deepest nesting of operations and calls in an expression."""
_BINARY = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
           ast.Pow: operator.pow}
_COMPARE = {ast.Lt: operator.lt, ast.LtE: operator.le, ast.Gt: operator.gt, ast.GtE: operator.ge}
_NUMBERS = ({"sqrt": math.sqrt, "sin": math.sin, "cos": math.cos, "tan": math.tan, "exp": math.exp, "log": math.log,
             "abs": abs, "tanh": math.tanh, "atan2": math.atan2, "min": min, "max": max},
            {**_BINARY, ast.Pow: _power}, float)
"""(functions, operators, number type) for a value at one time: Python floats, without numpy
(fast, and every error raises)."""
_ARRAYS = (FUNCTIONS, _BINARY, np.float64)
"""The same for arrays (a field): numpy, whose errors raise under ``np.errstate(all="raise")``."""


class ExpressionError(ValueError):
    """The text is not an admissible expression (the message says why)."""


def _check(node: ast.AST) -> None:
    if isinstance(node, ast.Expression):
        return _check(node.body)
    if isinstance(node, ast.Constant):
        if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
            raise ExpressionError(f"{node.value!r} is not a number")
        digits = len(str(node.value)) if isinstance(node.value, int) else 0
        if digits > 308 or not math.isfinite(node.value):
            what = f"a number of {digits} digits" if digits else "a number"
            raise ExpressionError(f"{what} is beyond the floating-point range (1.8e308)")
        return None
    if isinstance(node, ast.Name):
        return None
    if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
        _check(node.left)
        return _check(node.right)
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.UAdd, ast.USub)):
        return _check(node.operand)
    if isinstance(node, ast.Compare) and len(node.ops) == 1 and type(node.ops[0]) in _COMPARE:
        _check(node.left)
        return _check(node.comparators[0])
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in FUNCTIONS \
            and not node.keywords:
        lo, hi = ARITY.get(node.func.id, (1, 1))
        if len(node.args) < lo or (hi is not None and len(node.args) > hi):
            wanted = f"{lo}" if lo == hi else f"{lo} or more"
            raise ExpressionError(f"{node.func.id}() takes {wanted} argument{'s' if wanted != '1' else ''}, "
                                  f"got {len(node.args)}")
        for a in node.args:
            _check(a)
        return None
    what = node.func.id if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) else type(node).__name__
    raise ExpressionError(f"'{what}' is not allowed (numbers, names, + - * / **, < > <= >=, and "
                          f"{', '.join(FUNCTIONS)})")


@functools.lru_cache(maxsize=1024)
def _parse(text: str) -> ast.Expression:
    """The checked syntax tree of ``text`` (memoised: a pure function of the text)."""
    if len(text) > MAX_LENGTH:
        raise ExpressionError(f"the expression has {len(text)} characters, more than {MAX_LENGTH}")
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as err:
        raise ExpressionError(f"cannot parse '{text}' ({err.msg})") from None
    except (RecursionError, MemoryError):
        raise ExpressionError(f"the expression is nested more than {MAX_DEPTH} deep") from None
    if _depth(tree) > MAX_DEPTH:
        raise ExpressionError(f"the expression is nested more than {MAX_DEPTH} deep")
    _check(tree)
    return tree


def _depth(tree: ast.AST) -> int:
    """Deepest nesting of the operations and calls of ``tree`` (without recursion)."""
    deepest, stack = 0, [(tree, 0)]
    while stack:
        node, d = stack.pop()
        d += isinstance(node, (ast.BinOp, ast.UnaryOp, ast.Compare, ast.Call))
        deepest = max(deepest, d)
        stack.extend((c, d) for c in ast.iter_child_nodes(node))
    return deepest


def _eval(node: ast.AST, env: Mapping[str, object], how):
    """The value of ``node`` for ``env``, computed ``how`` (:data:`_NUMBERS` or :data:`_ARRAYS`)."""
    if isinstance(node, ast.Expression):
        return _eval(node.body, env, how)
    if isinstance(node, ast.Constant):
        return how[2](node.value)
    if isinstance(node, ast.Name):
        v = env[node.id] if node.id in env else CONSTANTS[node.id]
        return v if isinstance(v, np.ndarray) else how[2](v)
    if isinstance(node, ast.BinOp):
        return how[1][type(node.op)](_eval(node.left, env, how), _eval(node.right, env, how))
    if isinstance(node, ast.UnaryOp):
        v = _eval(node.operand, env, how)
        return -v if isinstance(node.op, ast.USub) else v
    if isinstance(node, ast.Compare):
        return 1.0 * _COMPARE[type(node.ops[0])](_eval(node.left, env, how), _eval(node.comparators[0], env, how))
    return how[0][node.func.id](*(_eval(a, env, how) for a in node.args))


_DOMAIN = "an argument outside a function's domain: the root of a negative number, the logarithm of zero or less"


def _first(ok: np.ndarray):
    """Index of the first False of ``ok`` (None: there is none)."""
    return np.unravel_index(int(np.argmin(ok)), np.shape(ok)) if not np.all(ok) else None


@dataclass(frozen=True)
class Value:
    """A constant (``text`` empty) or an expression; :meth:`names` are the inputs it reads.
    ``key`` and ``range`` (set by the reader of the input) say where it was given and what
    its values may be: every evaluation is checked against them (:meth:`__call__`)."""

    constant: float = 0.0
    """The value when there is no expression."""
    text: str = ""
    """The expression, as written."""
    key: str = field(default="", compare=False, repr=False)
    """Where the value was given (file and key), for messages."""
    range: Range = field(default=FINITE, compare=False, repr=False)
    """What its values may be."""

    @classmethod
    def of(cls, v: float | str, key: str = "", range: Range = FINITE) -> "Value":
        """A :class:`Value` from a number or an expression (:class:`ExpressionError` if it is
        not one; :class:`~gatetherm.InputError` if a number, or an expression without inputs,
        is not in ``range``)."""
        if isinstance(v, Value):
            return v
        if isinstance(v, bool):
            raise ExpressionError(f"{v!r} is not a number")
        if isinstance(v, (int, float)):
            return cls(float(range.check(key or "value", v)), "", key, range)
        value = cls(0.0, " ".join(str(v).split()), key, range)
        value.tree  # parse now: errors surface where the case is read
        if not value.names():
            value({})  # a constant expression is checked now
        return value

    @property
    def tree(self) -> ast.Expression:
        return _parse(self.text)

    @property
    def is_constant(self) -> bool:
        return not self.text

    def names(self) -> set[str]:
        """Variables the expression reads (time ``t``, inputs, coordinates)."""
        if self.is_constant:
            return set()
        nodes = list(ast.walk(self.tree))
        called = {id(n.func) for n in nodes if isinstance(n, ast.Call)}
        return {n.id for n in nodes if isinstance(n, ast.Name) and id(n) not in called} - set(CONSTANTS)

    def __call__(self, env: Mapping[str, object] | None = None):
        """The value for the variables ``env`` (numbers or arrays, which broadcast); an
        :class:`~gatetherm.InputError` if it cannot be evaluated or is not in :attr:`range`."""
        if self.is_constant:
            return self.constant
        env = env or {}
        arrays = np.ndarray in map(type, env.values())
        try:
            if not arrays:
                v = _eval(self.tree, env, _NUMBERS)
            else:
                with np.errstate(all="raise", under="ignore"):
                    v = _eval(self.tree, env, _ARRAYS)
        except KeyError as err:
            raise self._error(env, (), f"reads {err}, which is not given") from None
        except (FloatingPointError, ZeroDivisionError, OverflowError, ValueError) as err:
            why = str(err) if arrays or "power" in str(err) else {ZeroDivisionError: "division by zero",
                                                                   OverflowError: "overflow"}.get(type(err), _DOMAIN)
            with np.errstate(all="ignore"):  # where, for arrays (a field)
                ok = np.isfinite(_eval(self.tree, env, _ARRAYS)) if arrays else np.ones(())
            raise self._error(env, _first(ok), f"cannot be evaluated ({why})") from None
        if not arrays and self.range.holds(v):  # the usual case, fast
            return v
        ok = self.range.mask(v)
        if not ok.all():
            at = _first(ok)
            raise self._error(env, at, f"is {show(np.asarray(v, float)[at])}", f", must be {self.range}")
        return v

    def _error(self, env: Mapping[str, object], at, problem: str, must: str = "") -> InputError:
        """The error of an evaluation: the key, the expression, the time or point, the range."""
        names = sorted((self.names() | {"t"}) & set(env), key=lambda n: (n != "t", n))
        shape = np.broadcast_shapes(*(np.shape(env[n]) for n in names))
        where = [f"{n} = {show(float(np.broadcast_to(np.asarray(env[n], float), shape)[at]))}{' s' * (n == 't')}"
                 for n in names] if at is not None else []
        return InputError(self.key or "expression", f"'{self.text}' {problem}" +
                          (f" at {', '.join(where)}" if where else "") + must,
                          "change the expression or the inputs it reads")

    def __str__(self) -> str:
        return self.text or repr(self.constant)
