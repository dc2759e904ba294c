"""What a :class:`~gatetherm.studies.run.case.Case` knows of how it was made, as protocols: its
origin (:class:`Origin`: a case file's :class:`~gatetherm.studies.run.case.CaseFile`, the paper
frame's generator origin) and what a generator made it from (:class:`ModelParameters`: the
frame's model configuration). Generic code uses these members only and imports no generator.
``case``: the :class:`~gatetherm.studies.run.case.Case` (not imported here: it imports this module)."""
from __future__ import annotations

import dataclasses
import hashlib
import json
from typing import TYPE_CHECKING, ClassVar, Protocol, runtime_checkable

if TYPE_CHECKING:
    from gatetherm.solvers.heat import TimeScheme
    from gatetherm.studies.run.parameters import Parameter


@runtime_checkable
class Origin(Protocol):
    """How a case was made, to be made again with some of its keys changed."""

    ORDER: ClassVar[str]
    """The dotted key of the element order (``case.order``, ``model.order``)."""

    def remake(self, overrides: dict, previous=None):
        """The case made again with ``overrides`` ({dotted key: value}); ``previous``'s mesh and
        schedule reused where nothing they depend on changed."""

    def parameters(self, case) -> tuple[Parameter, ...]:
        """The numbers of the case a diagnosis may move (its hypotheses)."""

    def uncertain(self, case, keys) -> tuple[Parameter, ...]:
        """Further parameters named by ``keys`` (``--uncertain``)."""

    def model_file(self, case, header: str = "") -> str | None:
        """The text of a file that makes ``case`` again (None: the origin's file is not rewritten)."""


@runtime_checkable
class ModelParameters(Protocol):
    """What a generator made a case from (the paper frame's model configuration), kept on its
    model for analyses that only such a model has (beam theory, load cases at named tips)."""

    order: int
    """Polynomial degree of temperature and displacement."""
    scheme: TimeScheme
    """Time stepping of the heat equation."""


def scheme_digest(cfg: ModelParameters) -> str:
    """Eight hex digits naming the numerical scheme of ``cfg`` (a model's parameters or a
    :class:`~gatetherm.solvers.problem.Problem`): element order, time stepping and the linear
    solvers' settings (not the physics)."""
    from gatetherm.solvers import linsolve

    blob = json.dumps({"order": cfg.order, "time": dataclasses.asdict(cfg.scheme), "linear": linsolve.SETTINGS},
                      sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()[:8]
