"""The hypotheses a diagnosis tries, of three kinds, each with one parameter.

* ``effect``: an effect the model leaves out (:mod:`gatetherm.solvers.effects`), on one of
  the case's targets: the effects the case declares (the paper frame's catalogue), else a
  heat source in every region without one, a foundation and a film to the room under every
  support, a resistance and a compliance of every joint, the room drifting, a thermocouple
  lag and (with a boundary mean ``base``) a drifting sensor stand;
* ``parameter``: a number of the case off its value (:mod:`gatetherm.studies.run.parameters`:
  film coefficients, fluid films, sources, initial temperature, material factors);
* ``geometry``: a dimension marked as uncertain off its value (the paper frame's tie bar, column
  width and tank wall; a case file's ``[case] uncertain`` parameters of its geometry script): a
  parameter whose every new value meshes the case again;
* ``sensor``: a fault of one recorded channel (:mod:`solvers.sensors`): thermocouple
  offset, gain, lag; displacement-sensor offset, gain, drift.

A set of hypotheses with values (an *assignment*) turns into a case (:func:`configure`):
parameters make the case again with its file's keys changed, effects switch on, sensor
faults go to ``sensors``; every run goes through the scenario path.
"""
from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass, field

from gatetherm.solvers.effects import resolve
from gatetherm.solvers.sensors import compose, faults_of
from gatetherm.studies.run.case import Case

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Piece:
    """One hypothesis and its parameter's plausible range (in the parameter's unit)."""

    kind: str
    name: str
    param: str
    unit: str
    lo: float
    hi: float
    log_scale: bool
    neutral: float | None
    """The value that changes nothing (a parameter's model value, a fault's identity);
    None for an effect (off is a limit, not a value)."""
    doc: str
    channel: str | None = None
    """The channel of a sensor piece."""
    rerun: bool = True
    """A new value needs a new model run; else it acts on a kept run."""
    linear: bool = False
    """The reported signal is linear in the value (sensor offset, gain, drift: fitted in closed form)."""
    target: str | None = None
    """The boundary, fluid, region or joint it acts on."""
    source: object = field(default=None, compare=False, repr=False)
    """A parameter piece's :class:`~gatetherm.studies.run.parameters.Parameter` (how a value is written)."""

    @property
    def key(self) -> str:
        return f"{self.kind}:{self.name}" + (f"@{self.channel}" if self.channel else "")

    @property
    def label(self) -> str:
        return f"{self.name}({self.channel})" if self.channel else self.name

    def describe(self) -> dict:
        """The ``--list-effects --json`` entry."""
        d = {"kind": self.kind, "name": self.name,
             "params": {self.param: {"unit": self.unit, "range": [self.lo, self.hi]}}, "doc": self.doc}
        if self.channel:
            d["channel"] = self.channel
        if self.target:
            d["target"] = self.target
        if self.kind == "effect":
            d["acts_on"] = "observation" if not self.rerun else "model"
        return d


def effect_keys(case: Case) -> list[str]:
    """The effects a diagnosis of ``case`` tries: those it declares, else one per target."""
    if case.targets.candidates is not None:
        return list(case.targets.candidates)
    p = case.problem
    heated = {s.region for s in p.sources}
    conditioned = {c.boundary for c in (*p.films, *p.fixed, *p.fluxes, *p.fluids)}
    keys = ["ambient_drift"] if p.films or p.faces else []
    keys += [f"heat_source@{r}" for r in p.materials if r not in heated] if p.heat else []
    joints = [*case.targets.joints, *(c.name for c in p.contacts),
              *(b for b in case.targets.interfaces if b not in {c.boundary for c in p.contacts})]
    kinds = ("joint_resistance",) * p.heat + ("joint_compliance",) * p.elastic
    keys += [f"{k}@{j}" for j in joints for k in kinds]
    keys += [f"compliant_base@{s.boundary}" for s in p.supports if s.stiffness is None]
    keys += [f"base_conduction@{s.boundary}" for s in p.supports if s.boundary not in conditioned and p.heat]
    keys += ["thermocouple_lag"] + (["stand_drift"] if case.targets.base_mean in dict(p.means) else [])
    return keys


def effect_pieces(case: Case, keys=None, has_ambient: bool = False) -> list[Piece]:
    """Effects as hypotheses (``keys``, default :func:`effect_keys`). Where the file records the
    room (``has_ambient``), the room drifting is the room the machine sees drifting away from the
    recorded one (the drift adds to the recorded value: a thermometer that does not see the
    machine's air), still a hypothesis (issue 51: a room drifting 0.51 K/h under a recorded
    constant 20 °C was otherwise left unexplained)."""
    out = []
    for k in effect_keys(case) if keys is None else keys:
        r = resolve(k, case.targets, "--effects")
        out.append(Piece("effect", k, r.effect.param, r.unit, r.lo, r.hi, r.log_scale, None, r.doc,
                         rerun=r.effect.acts_on != "observation", target=r.target))
    return out


def parameter_pieces(case: Case, names=None, uncertain=()) -> list[Piece]:
    """The case's parameters ``names`` (default: all), and the dimensions ``uncertain`` (keys such as
    ``geometry.l_C``, ``mesh.parameters.table_height``) besides those it marks, as hypotheses."""
    own = case.origin.parameters(case)
    more = case.origin.uncertain(case, [k for k in uncertain if k not in {q.name for q in own}]) if uncertain else ()
    return [Piece("geometry" if q.remesh else "parameter", q.name, q.param, q.unit, q.lo, q.hi, q.log_scale, q.value,
                  q.doc, target=q.target, source=q) for q in (*own, *more) if names is None or q.name in names]


def unmounted(case: Case, channels) -> dict[str, str]:
    """The temperature channels whose probe lies on a part the case says cannot carry a
    thermocouple (``[sensors] exclude``), with that part: {channel: part}."""
    if not case.unmountable:
        return {}
    from gatetherm.studies.run.simulate import column
    from gatetherm.studies.sensors.candidates import part_at

    p, out = case.problem, {}
    theta_C = {column(p, ("T", c))[0] for c in p.signals.theta_C}
    for probe in (q for q in p.probes if "T" in q.quantities):
        part = part_at(case.mesh, case.unmountable, probe.xyz)
        if part is not None:
            name = column(p, ("T", probe.name))[0]
            out.update({c: part for c in (name, *(("theta_C_degC",) if name in theta_C else ())) if c in channels})
    return out


def sensor_pieces(channels, case: Case | None = None) -> list[Piece]:
    """Faults of every channel (a lag only where the case sets none: two lags do not compose),
    none of a thermocouple on a part that cannot carry one (:func:`unmounted`)."""
    out = []
    skip = unmounted(case, channels) if case is not None else {}
    for c, part in skip.items():
        log.info("no sensor fault of %s: its probe lies on %s, which cannot carry a thermocouple ([sensors] "
                 "exclude)", c, part)
    for c in (c for c in channels if c not in skip):
        for f in faults_of(c).values():
            if f.name == "lag" and case is not None and "lag" in case.sensors.get(c, {}):
                continue
            out.append(Piece("sensor", f"sensor_{f.name}", f.name, f.unit, f.lo, f.hi, f.log_scale, f.identity,
                             f.doc, channel=c, rerun=False, linear=f.linear))
    return out


def catalogue(case: Case, channels, uncertain=()) -> list[Piece]:
    """Every hypothesis, as ``--list-effects`` shows them (``uncertain``: further dimensions)."""
    return effect_pieces(case) + parameter_pieces(case, uncertain=uncertain) + sensor_pieces(channels, case)


PROPORTIONAL = (frozenset({"parameter:expansion", "sensor:sensor_gain@delta_um"}),)
"""Pairs of hypotheses (keys) whose signals are proportional by construction: α of every
material scales δ and nothing else, and so does a gain of the δ sensor; only their product
shows in the data (where no other displacement channel is recorded)."""

Assignment = tuple  # ((Piece, value), ...) sorted by key: hashable


def assignment(values: dict) -> Assignment:
    return tuple(sorted(values.items(), key=lambda kv: kv[0].key))


def model_side(values: dict) -> Assignment:
    """The part of an assignment a model run depends on (effects and parameters)."""
    return assignment({p: v for p, v in values.items() if p.kind != "sensor"})


def configure(case: Case, values: dict) -> Case:
    """``case`` with the hypotheses ``values`` ({Piece: value}) in it."""
    effects, faults, overrides = dict(case.effects), {}, {}
    for p, v in values.items():
        if p.kind == "effect":
            effects[p.name] = float(v)
        elif p.kind == "sensor":
            faults.setdefault(p.channel, {})[p.param] = float(v)
        else:  # a parameter or a dimension
            overrides.update(p.source.overrides(v))
    made = case.with_overrides(overrides) if overrides else case
    return dataclasses.replace(made, effects=effects, sensors=compose(case.sensors, faults))
