"""The time scheme of a transient run: a parameter of the problem, kept apart from the heat
solver (:mod:`gatetherm.solvers.heat`) so that a problem is read without the FE libraries (a
painting process unpickles one without importing them)."""
from __future__ import annotations

from dataclasses import dataclass

from gatetherm.checks import Range, admissible


@admissible(theta=Range(0.5, 1.0), restart=Range(1, 1000, whole=True), restart_intervals=Range(0, 1000, whole=True))
@dataclass(frozen=True)
class TimeScheme:
    """The θ-method with Rannacher start-up at input switches."""

    theta: float = 0.5
    """1: backward Euler; 0.5: Crank–Nicolson (second order)."""
    restart: int = 4
    """Steps into which each of the ``restart_intervals`` intervals after a pump switch (and
    at the start) is divided; for θ < 1 the very first of them is two backward-Euler half
    steps, which damp the stiff modes the switch excites (oil, wall film) instead of
    letting CN ring. 1: no grading."""
    restart_intervals: int = 3
    """How many intervals after a switch are divided."""
