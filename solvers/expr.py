"""Values of a case: a constant, or an expression of time, schedule inputs and position.

A case file gives a boundary temperature, an ambient, a source or a prescribed
temperature field as a number or as a string such as ``"ambient_degC"``,
``"100*sin(pi*t/40)"`` or ``"sqrt(x**2 + y**2) + z"``. The string is parsed once into
a restricted expression (numbers, names, + - * / **, comparisons and the functions of
:data:`FUNCTIONS`); nothing else of Python is reachable, so a case file cannot run code.
"""
from __future__ import annotations

import ast
import functools
import math
import operator
from dataclasses import dataclass
from typing import Mapping

import numpy as np

FUNCTIONS = {"sqrt": np.sqrt, "sin": np.sin, "cos": np.cos, "tan": np.tan, "exp": np.exp, "log": np.log,
             "abs": np.abs, "tanh": np.tanh, "atan2": np.arctan2, "min": np.minimum, "max": np.maximum}
"""Functions an expression may call."""
CONSTANTS = {"pi": math.pi}
_BINARY = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
           ast.Pow: operator.pow}
_COMPARE = {ast.Lt: operator.lt, ast.LtE: operator.le, ast.Gt: operator.gt, ast.GtE: operator.ge}


class ExpressionError(ValueError):
    """The text is not an admissible expression (the message says why)."""


def _check(node: ast.AST) -> None:
    if isinstance(node, ast.Expression):
        return _check(node.body)
    if isinstance(node, ast.Constant):
        if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
            raise ExpressionError(f"{node.value!r} is not a number")
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
        for a in node.args:
            _check(a)
        return None
    what = node.func.id if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) else type(node).__name__
    raise ExpressionError(f"'{what}' is not allowed (numbers, names, + - * / **, < > <= >=, and "
                          f"{', '.join(FUNCTIONS)})")


@functools.lru_cache(maxsize=1024)
def _parse(text: str) -> ast.Expression:
    """The checked syntax tree of ``text`` (memoised: a pure function of the text)."""
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as err:
        raise ExpressionError(f"cannot parse '{text}' ({err.msg})") from None
    _check(tree)
    return tree


def _eval(node: ast.AST, env: Mapping[str, object]):
    if isinstance(node, ast.Expression):
        return _eval(node.body, env)
    if isinstance(node, ast.Constant):
        return float(node.value)
    if isinstance(node, ast.Name):
        return env[node.id] if node.id in env else CONSTANTS[node.id]
    if isinstance(node, ast.BinOp):
        return _BINARY[type(node.op)](_eval(node.left, env), _eval(node.right, env))
    if isinstance(node, ast.UnaryOp):
        v = _eval(node.operand, env)
        return -v if isinstance(node.op, ast.USub) else v
    if isinstance(node, ast.Compare):
        return 1.0 * _COMPARE[type(node.ops[0])](_eval(node.left, env), _eval(node.comparators[0], env))
    return FUNCTIONS[node.func.id](*(_eval(a, env) for a in node.args))


@dataclass(frozen=True)
class Value:
    """A constant (``text`` empty) or an expression; :meth:`names` are the inputs it reads."""

    constant: float = 0.0
    """The value when there is no expression."""
    text: str = ""
    """The expression, as written."""

    @classmethod
    def of(cls, v: float | str) -> "Value":
        """A :class:`Value` from a number or an expression (:class:`ExpressionError` if invalid)."""
        if isinstance(v, Value):
            return v
        if isinstance(v, bool):
            raise ExpressionError(f"{v!r} is not a number")
        if isinstance(v, (int, float)):
            if not math.isfinite(v):
                raise ExpressionError(f"{v!r} is not finite")
            return cls(float(v))
        value = cls(0.0, str(v).strip())
        value.tree  # parse now: errors surface where the case is read
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
        """The value for the variables ``env`` (numbers or arrays, which broadcast)."""
        if self.is_constant:
            return self.constant
        return _eval(self.tree, env or {})

    def __str__(self) -> str:
        return self.text or repr(self.constant)
