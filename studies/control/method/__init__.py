"""The compensation methods, one module each: ``paper``, ``mlr``, ``rom``, ``errormodel``.

A method is one :class:`Method` object, ``METHOD`` of a module of this package (found here, no list
to edit) or given to :func:`register`: its name, its batch form (``batch(job) -> Batch``: a whole
recorded series, :func:`gatetherm.studies.control.methods.compensate`) and its step-wise form
(``stepper(setup) -> (Stepper, label)``: one sample at a time, ``gatetherm live`` and ``twin``,
:mod:`gatetherm.studies.control.stepwise`). :data:`~gatetherm.studies.control.methods.METHODS`,
``gatetherm compensate --method`` and ``gatetherm live --method`` (:func:`offered`) and
:func:`gatetherm.api.live` read them from here.

A method module imports its numerics inside its functions: finding the methods costs nothing.
"""
from __future__ import annotations

import importlib
import pkgutil
from dataclasses import dataclass, field
from typing import Any, Callable

from gatetherm import InputError


@dataclass(frozen=True)
class Job:
    """What a batch compensation is given (:func:`gatetherm.studies.control.methods.compensate`)."""

    ts: Any
    """The run (a TimeSeries): θ_A, θ_B, θ_C and δ, or what the method reads."""
    case: Any
    """The model (a Case) or None."""
    settings: Any
    """The :class:`~gatetherm.studies.control.methods.Settings`."""
    actuator: Any = None
    rom: Any = None
    rom_dir: Any = None
    cache: Any = None
    source: str = "--data"
    """What the series is, for messages."""
    rom_source: str | None = None


@dataclass(frozen=True)
class Batch:
    """A method's compensated loop and what the summary says of it."""

    loop: Any
    """The closed loop (:class:`~gatetherm.studies.control.compensator.ClosedLoop`)."""
    extra: dict
    """The method's entries of the summary."""
    label: str
    """What was done, for metadata."""
    head: str
    """One line for the terminal."""
    checked: tuple = (None, "")
    """(the loop of the held-out benefit check or None, its basis), unless :attr:`benefit` is given."""
    benefit: Any = None
    """The held-out :class:`~gatetherm.studies.control.benefit.Benefit`, where the method measures it itself."""
    notes: tuple = ()
    """Warnings for the summary."""
    model: str = ""
    """What of the case the correction uses ('' nothing: fitted on the record), named where its
    prediction misses more than δ itself (:func:`gatetherm.studies.control.benefit.over_record`)."""


@dataclass(frozen=True)
class Setup:
    """What a step-wise compensator is built from (``gatetherm live``/``twin``, :func:`gatetherm.api.live`)."""

    case: Any
    """The machine's case (None where the method needs none)."""
    params: Any
    """The :class:`~gatetherm.studies.control.compensator.CompensatorParams`."""
    states: int = 30
    """rom: states of the reduced model."""
    out: Any = None
    """The service's folder (a reduced model is kept there)."""
    schedule: Any = None
    """The inputs known in advance (a Schedule)."""
    model: Any = None
    """errormodel: the fitted model (an ErrorModel)."""
    target: str | None = None
    """errormodel: its compensated channel (default: its only one)."""


@dataclass(frozen=True)
class Method:
    """A compensation method."""

    name: str
    """Its name (``--method NAME``, ``Settings(method=NAME)``)."""
    batch: Callable[[Job], Batch]
    """Compensate a whole recorded series."""
    stepper: Callable[[Setup], tuple] | None = None
    """Its step-wise compensator and a label, for ``live``/``twin`` (None: batch only)."""
    order: int = 100
    """Its place among the methods (choices, messages)."""
    offered: bool = True
    """A ``--method`` choice (errormodel is chosen by giving a fitted model instead)."""
    title: str = ""
    """How a message names it (default its name)."""
    summary: str = ""
    """A few words for the ``--method`` help."""
    doc: str = field(default="", compare=False)


_METHODS: dict[str, Method] = {}
_FOUND: list[bool] = []


def register(method: Method) -> Method:
    """Add ``method`` (a method of a plug-in or a test; the shipped ones are the modules here)."""
    _load()
    _METHODS[method.name] = method
    return method


def _load() -> None:
    """Find the ``METHOD`` of every module of this package (once)."""
    if not _FOUND:
        for info in pkgutil.iter_modules(__path__):
            method = getattr(importlib.import_module(f"{__name__}.{info.name}"), "METHOD", None)
            if method is not None:
                _METHODS.setdefault(method.name, method)
        _FOUND.append(True)


def methods() -> list[Method]:
    """Every method, in order."""
    _load()
    return sorted(_METHODS.values(), key=lambda m: (m.order, m.name))


def names() -> tuple[str, ...]:
    """Every method's name, in order."""
    return tuple(m.name for m in methods())


def offered(stepwise: bool = False) -> tuple[str, ...]:
    """The names ``--method`` offers: ``compensate``'s, or with ``stepwise`` ``live``'s (those with a stepper)."""
    return tuple(m.name for m in methods() if m.offered and (m.stepper or not stepwise))


def either(names) -> str:
    """``a, b or c``."""
    names = list(names)
    return " or ".join(x for x in (", ".join(names[:-1]), names[-1] if names else "") if x)


def get(name: str, option: str = "--method") -> Method:
    """The method ``name``; InputError naming those there are."""
    found = {m.name: m for m in methods()}
    if name not in found:
        raise InputError(option, f"unknown method {name!r}", f"choose from {', '.join(found)}")
    return found[name]
