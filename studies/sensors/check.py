"""The independent check of a placement by full FE runs (no reduced model).

The case is made again with the chosen points as ``[probes]`` (for a case file through its own
reading, as a user pastes ``sensors.toml``: ``probes.S1.point = [x, y]``; for a generated case by
adding the probes to its problem). Every training and held-out load is run in full
(:func:`~gatetherm.studies.run.scenario.run_scenario`); the probes' temperatures get the same
noise as in the placement (same seed, node and load key); the placement model's terms are fitted by
least squares on the training runs and the held-out runs are predicted with them.
"""
from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass

import numpy as np

from gatetherm.solvers.problem import Probe
from gatetherm.studies.errormodel.model import ErrorModel, residual_stats
from gatetherm.studies.errormodel.terms import evaluate
from gatetherm.studies.run.case import CaseFile
from gatetherm.studies.run.scenario import ScenarioCache, run_scenario
from gatetherm.studies.sensors.models import held_out_mae
from gatetherm.studies.sensors.screen import load_key, noise


WORSE = 1.25
"""An FE-checked error beyond this multiple of the placement's own is warned of."""


@dataclass(frozen=True)
class FECheck:
    """The placement's model refitted on FE runs and scored on FE runs of the held-out loads."""

    held_out_mae_um: dict[str, float]
    """Per target, MAE over the held-out FE runs, um."""
    placement_mae_um: dict[str, float]
    """Per target, the placement's own held-out MAE (reduced model), um."""
    temperature_error_K: float
    """Largest |reduced model - FE| of the chosen sensors' temperatures over the held-out loads, K."""
    runs: int
    seconds: float

    @property
    def ratio(self) -> dict[str, float]:
        """Per target, FE-checked over the placement's held-out error."""
        return {k: v / self.placement_mae_um[k] for k, v in self.held_out_mae_um.items()}

    @property
    def warning(self) -> str:
        """One line where the FE-checked error exceeds the placement's by more than :data:`WORSE`
        (the points were chosen on a reduced model that does not hold), else ''."""
        off = {k: r for k, r in self.ratio.items() if r > WORSE}
        if not off:
            return ""
        k = max(off, key=off.get)
        return (f"the FE check's held-out MAE of {k} is {off[k]:.2f} × the placement's ({self.held_out_mae_um[k]:.3g} "
                f"against {self.placement_mae_um[k]:.3g} um; the sensors' temperatures up to "
                f"{self.temperature_error_K:.2g} K off FE): the points were chosen on a reduced model that does not "
                "hold for these loads (too few states, films held at constants, a pump switching modes); place with "
                "more --states or with the loads the machine sees (--range, e.g. pump=1:1 for a pump that never stops)")

    def summary(self) -> dict:
        return {**dataclasses.asdict(self), "ratio": self.ratio, "warning": self.warning}


def with_probes(case, sensors):
    """``case`` with a temperature probe at each of ``sensors`` (:class:`~.result.Sensor`)."""
    if isinstance(case.origin, CaseFile):
        return case.with_overrides({k: v for s in sensors for k, v in
                                    ((f"probes.{s.name}.point", list(s.xyz)), (f"probes.{s.name}.quantities", ["T"]))})
    probes = tuple(Probe(s.name, tuple(s.xyz), ("T",)) for s in sensors)
    return dataclasses.replace(case, problem=dataclasses.replace(case.problem, probes=case.problem.probes + probes))


def _noisy(cols, placement, label):
    s = placement.settings
    out = dict(cols)
    for x in placement.sensors:
        out[x.column] = cols[x.column] + noise(s.seed, f"node {x.node}", label, len(cols["time_s"]), s.noise_K)
    return out


def fe_check(case, placement, cache: ScenarioCache | None = None) -> FECheck:
    """Check ``placement`` of ``case`` by FE runs (module docstring)."""
    t0 = time.perf_counter()
    checked = with_probes(case, placement.sensors)
    cache = cache or ScenarioCache()
    runs = {x.label: run_scenario(checked, x, cache=cache).columns for x in (*placement.training, *placement.held_out)}
    train = [_noisy(runs[x.label], placement, load_key("training", i)) for i, x in enumerate(placement.training)]
    held = [_noisy(runs[x.label], placement, load_key("held-out", i)) for i, x in enumerate(placement.held_out)]
    model = placement.model
    refitted = []
    for m in model.targets:
        X = np.vstack([np.column_stack([np.ones(len(c["time_s"]))] + [evaluate(t, c["time_s"], c, model.reference_degC)
                                                                       for t in m.terms]) for c in train])
        y = np.concatenate([c[m.target] for c in train])
        c = np.linalg.lstsq(X, y, rcond=None)[0]
        refitted.append(dataclasses.replace(m, coefficients=tuple(map(float, c[1:])), intercept_um=float(c[0]),
                                            residual=residual_stats(X @ c - y)))
    fitted = ErrorModel(tuple(refitted), model.reference_degC, model.fit_span, model.max_gap_s, model.settings)
    err = held_out_mae(fitted, held, [{m.target: c[m.target] for m in model.targets} for c in held])
    dT = max(float(np.max(np.abs(placement.held_temperatures[x.label][:, k] - runs[x.label][s.column])))
             for x in placement.held_out for k, s in enumerate(placement.sensors))
    return FECheck(err, dict(placement.curve[-1].held_out_mae_um), dT, len(runs), time.perf_counter() - t0)
