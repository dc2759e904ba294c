"""Every public function's arguments checked against its annotations where it is called, before
any work: :func:`checked` wraps the functions :mod:`gatetherm.api` offers.

An argument of the wrong type is a :class:`TypeError` naming it (``out: got int 5, expected a
str or path``); a float that is NaN or infinite (where the default is finite), a fraction where a
whole number belongs, or a value outside a ``Literal`` is a :class:`gatetherm.InputError` naming it. A string where a list belongs is
refused (it would be read letter by letter); the items of a list and the keys and values of a
mapping are checked too. A parameter without an annotation is checked by its name's
convention: ``on_*`` and ``stopped`` are functions, ``out`` a folder's path
(:data:`CONVENTIONS`); ``tests/test_api_boundary.py`` fails on a public parameter that is neither.
Ranges and names (a positive count, a known column) stay with each function.
"""
from __future__ import annotations

import collections.abc as abc
import dataclasses
import functools
import inspect
import math
import numbers
import os
import types
import typing

import numpy as np

from gatetherm import InputError
from gatetherm.checks import _short

CONVENTIONS = {"on_progress": typing.Optional[abc.Callable[[int, int], None]],
               "on_step": typing.Optional[abc.Callable[[int, int], None]], "on_": typing.Optional[abc.Callable],
               "stopped": typing.Optional[abc.Callable],
               "out": typing.Union[str, os.PathLike, None]}
"""Annotations of unannotated parameters by name (a prefix ending in ``_`` or the whole name)."""
FIXES = {"Case": "make one with gt.load_case(path) or gt.gate_frame()",
         "Schedule": "make one with gt.condition(n) or gt.schedule_file(path, case)",
         "Run": "make one with gt.run(case)", "Config": "give a model file's path",
         "TimeSeries": "read one with gatetherm.studies.run.timeseries.read_timeseries(path)"}
"""How to make a value of the classes the API takes (by class name), for the TypeError's fix."""
INFINITE = "infinity allowed"
"""``Annotated[float, INFINITE]``: a parameter that takes ``math.inf`` (with a meaning its docstring
gives: ``beam_normalised``'s beta, no tie bar); NaN is refused still."""
FloatOrInf = typing.Annotated[float, INFINITE]
"""A float that may be infinite."""
_SEQUENCES = (list, tuple, set, frozenset, range, np.ndarray, abc.Sequence, abc.Set, abc.KeysView, abc.ValuesView)


def hint_of(param: inspect.Parameter, hints: dict):
    """The annotation that checks ``param``: its own, else :data:`CONVENTIONS`' (None: none)."""
    if param.name in hints:
        return hints[param.name]
    for key, hint in CONVENTIONS.items():
        if param.name == key or key.endswith("_") and param.name.startswith(key):
            return hint
    return None


def accepts(value, hint) -> bool:
    """Whether ``value`` is of the type ``hint`` says (items of containers included)."""
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if hint is typing.Any or hint is object:
        return True
    if hint is None or hint is type(None):
        return value is None
    if origin is typing.Annotated:
        return accepts(value, args[0])
    if origin in (typing.Union, types.UnionType):
        return any(accepts(value, a) for a in args)
    if origin is typing.Literal:
        return any(isinstance(value, type(a)) for a in args)
    if hint is bool:
        return isinstance(value, (bool, np.bool_))
    if hint is int:  # a float is a range matter (InputError: not whole), a bool a type error
        return isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))
    if hint is float:
        return isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))
    if origin is abc.Callable or hint is abc.Callable or hint is typing.Callable:
        return callable(value)
    if origin in (abc.Mapping, dict, abc.MutableMapping) or hint in (dict, abc.Mapping):
        return isinstance(value, abc.Mapping) and (not args or all(accepts(k, args[0]) and accepts(v, args[1])
                                                                   for k, v in value.items()))
    if origin in (list, tuple, set, frozenset, abc.Sequence, abc.Iterable, abc.Collection, abc.Set) or \
            hint in (list, tuple, abc.Sequence, abc.Iterable):
        if isinstance(value, (str, bytes)) or not isinstance(value, _SEQUENCES):
            return False
        if origin is tuple and args and args[-1] is not Ellipsis:
            return len(value) == len(args) and all(accepts(v, a) for v, a in zip(value, args))
        if origin is tuple and args:
            return all(accepts(v, args[0]) for v in value)
        return not args or all(accepts(v, args[0]) for v in value)
    if isinstance(hint, type):
        return hint is os.PathLike and isinstance(value, os.PathLike) or isinstance(value, hint)
    return True  # a Protocol, a TypeVar …: not checked here


def describe(hint) -> str:
    """What ``hint`` asks for, in words (``a str or path``, ``a list of str``, ``a function``)."""
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin is typing.Annotated:
        return describe(args[0])
    if origin in (typing.Union, types.UnionType):
        words = list(dict.fromkeys(describe(a) for a in args if a is not type(None)))
        if "a str" in words and "a path" in words:
            words[words.index("a str")] = "a str or path"
            words.remove("a path")
        words += ["None"] if type(None) in args else []
        return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " or " + words[-1]
    if origin is typing.Literal:
        return "one of " + ", ".join(map(repr, args))
    if hint is os.PathLike:
        return "a path"
    if hint in (int, float):
        return {int: "a whole number", float: "a number"}[hint]
    if origin is abc.Callable or hint in (abc.Callable, typing.Callable):
        return "a function"
    if origin in (abc.Mapping, dict, abc.MutableMapping) or hint in (dict, abc.Mapping):
        return "a mapping" + (f" of {_bare(describe(args[0]))} to {_bare(describe(args[1]))}" if args else "")
    if origin in (list, tuple, set, frozenset, abc.Sequence, abc.Iterable, abc.Collection, abc.Set):
        if origin is tuple and args and args[-1] is not Ellipsis:
            return "a (" + ", ".join(describe(a) for a in args) + ")"
        return "a list" + (f" of {_bare(describe(args[0]))}" if args else "")
    return f"a {getattr(hint, '__name__', str(hint))}"


def _bare(words: str) -> str:
    """``words`` without a leading article (``a list of str``, not ``of a str``)."""
    return words.removeprefix("a ").removeprefix("an ")


def _number(value, hint, kind) -> bool:
    """Whether ``hint`` asks for a ``kind`` (int or float; alone or with None) and ``value`` is a number."""
    args = typing.get_args(hint) if typing.get_origin(hint) in (typing.Union, types.UnionType) else (hint,)
    return kind in args and isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))


def check(name: str, value, hint, default=inspect.Parameter.empty) -> None:
    """Raise TypeError (wrong type) or InputError (a NaN, an infinity, a value outside a
    ``Literal``) naming the argument ``name``."""
    if not accepts(value, hint):
        kinds = typing.get_args(hint) if typing.get_origin(hint) in (typing.Union, types.UnionType) else (hint,)
        fixes = [FIXES[k.__name__] for k in kinds if getattr(k, "__name__", "") in FIXES]
        raise TypeError(f"{name}: got {type(value).__name__} {_short(value)}, expected {describe(hint)}"
                        + (f"; {fixes[0]}" if fixes else ""))
    _check_arity(name, value, hint)
    if _number(value, hint, float) and not math.isfinite(value) and not (isinstance(default, float)
                                                                         and math.isinf(default)) \
            and not (math.isinf(value) and INFINITE in getattr(hint, "__metadata__", ())):
        raise InputError(name, f"got {value!r}, must be a finite number", "give a number")
    if typing.get_origin(hint) is typing.Annotated and INFINITE in typing.get_args(hint)[1:] and \
            _number(value, float, float) and math.isnan(value):
        raise InputError(name, "got nan, must be a number (or infinite)", "give a number")
    if _number(value, hint, int) and not _number(value, hint, float) and not float(value).is_integer():
        raise InputError(name, f"got {value!r}, must be a whole number", "give a whole number")
    literal = [a for a in (typing.get_args(hint) if typing.get_origin(hint) in (typing.Union, types.UnionType)
                           else (hint,)) if typing.get_origin(a) is typing.Literal]
    if literal and value is not None and value not in typing.get_args(literal[0]):
        raise InputError(name, f"got {value!r}", f"choose one of {', '.join(map(repr, typing.get_args(literal[0])))}")


def _check_arity(name: str, value, hint) -> None:
    """TypeError naming ``name`` if ``value``, a function where ``hint`` is ``Callable[[A, B], R]``,
    cannot be called with that many arguments (it would fail inside the work, naming nothing)."""
    kinds = typing.get_args(hint) if typing.get_origin(hint) in (typing.Union, types.UnionType) else (hint,)
    params = [typing.get_args(k)[0] for k in kinds if typing.get_origin(k) is abc.Callable and typing.get_args(k)
              and isinstance(typing.get_args(k)[0], list)]
    if not params or not callable(value):
        return
    try:
        inspect.signature(value).bind(*range(len(params[0])))
    except ValueError:  # a builtin without a signature: not checked
        return
    except TypeError as err:
        raise TypeError(f"{name}: {_short(value)} cannot be called with {len(params[0])} arguments ({err}); give a "
                        f"function of {len(params[0])} arguments, e.g. lambda i, n: print(i, n)") from None


def checked(fn):
    """``fn`` with its arguments checked (:func:`check`) before it runs; its name, signature and
    docstring kept."""
    sig = inspect.signature(fn)
    hints = typing.get_type_hints(fn, include_extras=True)
    rules = {p.name: (hint_of(p, hints), p.default) for p in sig.parameters.values()
             if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD) and hint_of(p, hints) is not None}

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        try:
            bound = sig.bind(*args, **kwargs)
        except TypeError as err:
            raise TypeError(f"{fn.__name__}: {err}") from None
        for name, value in bound.arguments.items():
            if name in rules:
                check(name, value, *rules[name])
        return fn(*args, **kwargs)

    wrapper.__checked__ = True
    return wrapper


def settings_argument(cls, settings: dict, function: str) -> dict:
    """``settings`` (a function's ``**settings``) if each is a field of the dataclass ``cls`` of
    the type its annotation says (:func:`check`), else a one-line :class:`TypeError` naming it
    (an unknown one: listing the known ones). Fields of a number, bool or str are checked;
    containers are the function's (it may take another form of them)."""
    known = [f.name for f in dataclasses.fields(cls)]
    unknown = [k for k in settings if k not in known]
    if unknown:
        raise TypeError(f"{unknown[0]}: is not a setting of {function}; settings: {', '.join(known)}")
    hints = typing.get_type_hints(cls, include_extras=True)
    defaults = {f.name: f.default for f in dataclasses.fields(cls)}
    for name, value in settings.items():
        kinds = typing.get_args(hints[name]) if typing.get_origin(hints[name]) in (typing.Union, types.UnionType) \
            else (hints[name],)
        if set(kinds) - {type(None)} <= {int, float, bool, str}:  # a container may come in the caller's form
            check(name, value, hints[name], defaults[name])
    return settings
