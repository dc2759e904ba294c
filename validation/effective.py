"""Effective K_i, K_C: least squares on the transient condition runs, beside the
static load-case values and the beam theory, and how well each predicts delta.

Every run starts from the same uniform state, so ``delta = K_i (theta_A - theta_B) -
K_C theta_C`` (eq 21, rises from t = 0) can be fitted per run or on the three runs
together. Each coefficient pair is scored by the RMS (um) of ``delta - prediction``
over each 5-h run, delta at the tips F (the measured quantity). Numbers only.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from gatetherm.frame.config import Config

log = logging.getLogger(__name__)

CONDITIONS = (1, 2, 3)


@dataclass(frozen=True)
class Source:
    """One coefficient pair and its prediction error per run."""

    name: str
    Ki: float
    """Um/K."""
    Kc: float
    """Um/K."""
    rms_um: dict[int, float]
    """Condition -> RMS of delta - (Ki dtheta_AB - Kc theta_C) over the run, um."""
    max_um: dict[int, float]
    """Condition -> largest |delta - prediction| over the run, um."""


def _series(cols):
    from gatetherm.studies.run.timeseries import TimeSeries

    return TimeSeries({k: cols[k] for k in ("time_s", "theta_A_degC", "theta_B_degC", "theta_C_degC",
                                            "delta_um")})


def score(name: str, ki: float, kc: float, runs: dict[int, dict]) -> Source:
    """RMS and largest error (um) of eq (21) with (ki, kc) on every run."""
    rms, worst = {}, {}
    for c, cols in runs.items():
        dab = (cols["theta_A_degC"] - cols["theta_A_degC"][0]) - (cols["theta_B_degC"] - cols["theta_B_degC"][0])
        err = cols["delta_um"] - (ki * dab - kc * (cols["theta_C_degC"] - cols["theta_C_degC"][0]))
        rms[c], worst[c] = float(np.sqrt(np.mean(err ** 2))), float(np.max(np.abs(err)))
    return Source(name, float(ki), float(kc), rms, worst)


def condition_runs(cfg: Config, dim: int) -> tuple[object, dict[int, dict]]:
    """The model and its run columns for conditions 1-3."""
    from gatetherm.frame.case import condition_runs
    from gatetherm.studies.run.scenario import ScenarioCache

    runs = condition_runs(cfg, dim, CONDITIONS, ScenarioCache())
    return runs[CONDITIONS[0]].model, {c: r.columns for c, r in runs.items()}


def effective_coefficients(cfg: Config, dim: int = 2) -> list[Source]:
    """Theory, FE load cases (at F) and least-squares fits (per run and pooled),
    each scored on all three runs."""
    from gatetherm.frame.loadcases import fe_coefficients
    from gatetherm.frame.beam import theory_coefficients
    from gatetherm.studies.control.regression import fit_coefficients

    model, runs = condition_runs(cfg, dim)
    fe = fe_coefficients(model)
    sources = [score("beam theory (eqs 22-24)", *theory_coefficients(cfg.model), runs),
               score("FE load cases at F", fe.Ki_F * 1e6, fe.Kc_F * 1e6, runs)]
    for c, cols in runs.items():
        sources.append(score(f"least squares, condition {c}", *fit_coefficients(_series(cols)), runs))
    pooled = {k: np.concatenate([runs[c][k] for c in CONDITIONS]) for k in runs[CONDITIONS[0]]}
    sources.append(score("least squares, conditions 1-3", *fit_coefficients(_series(pooled)), runs))
    return sources


def table_rows(sources: list[Source]) -> list[dict]:
    """Flat rows for a CSV / markdown table."""
    return [{"source": s.name, "Ki_um_per_K": s.Ki, "Kc_um_per_K": s.Kc,
             **{f"rms_cond{c}_um": s.rms_um[c] for c in CONDITIONS},
             **{f"max_cond{c}_um": s.max_um[c] for c in CONDITIONS}} for s in sources]
