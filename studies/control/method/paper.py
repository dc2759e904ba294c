"""The ``paper`` method: the paper's adaptive predictor (:mod:`..compensator`, eqs 30–38) with K_i,
K_C given, from the beam theory (``theory``), from FE load cases (``fe``) or fitted on the run
itself (``fit``); step-wise :class:`~gatetherm.studies.control.stepwise.PaperStepper`."""
from __future__ import annotations

import logging

from gatetherm.studies.control.method import Batch, Job, Method, Setup

log = logging.getLogger(__name__)


def batch(job: Job) -> Batch:
    """The paper's predictor over the recorded series, its benefit checked with K fitted before the
    held-out span where K is fitted on the record."""
    from gatetherm.studies.control import benefit as held
    from gatetherm.studies.control.compensator import NEEDED, compensate as paper_loop
    from gatetherm.studies.control.methods import coefficients_noted, refitted
    from gatetherm.studies.control.regression import fit_coefficients_noted, prediction_noise_um
    from gatetherm.studies.run.timeseries import validate_complete

    ts, s, params, actuator = job.ts, job.settings, job.settings.params, job.actuator
    validate_complete(ts, NEEDED)
    ki, kc, source, note = coefficients_noted(job.case, ts, s, job.cache)
    loop = paper_loop(ts, ki, kc, params, actuator)
    if source == "fit":
        before = held.before(ts, s.held_out)
        checked = refitted(lambda: paper_loop(ts, *fit_coefficients_noted(before, s.resolution_K)[:2], params,
                                              actuator),
                           f"K_i, K_C fitted on the first {100 * (1 - s.held_out):.0f} % of the record")
    else:
        checked = loop, f"as applied (K_i, K_C from {source}, nothing fitted on the record)"
    noise = prediction_noise_um((ki, kc), s.resolution_K, difference_first=True)
    every = f"update every {params.update_interval_s / 60:g} min"
    return Batch(loop, {"Ki_um_per_K": ki, "Kc_um_per_K": kc, "k_source": source, "sensor_noise_um": noise},
                 f"K_i {ki:.6g} um/K, K_C {kc:.6g} um/K ({source}), {every}",
                 f"K_i {ki:.4g}, K_C {kc:.4g} um/K ({source}; {s.resolution_K:g}-K sensor noise adds ±{noise:.2g} um)",
                 checked, notes=(note,) if note else (),
                 model=f"K_i, K_C from the {'beam theory' if source == 'theory' else 'FE load cases'}"
                 if source in ("theory", "fe") else "")


def stepper(setup: Setup):
    """K_i, K_C as the batch form chooses them by default, on the case's own run; the label says what
    the fit left out (a difference spanning under ten resolutions gets no weight)."""
    from gatetherm.studies.control.methods import Settings, coefficients_noted
    from gatetherm.studies.control.stepwise import PaperStepper
    from gatetherm.studies.run.scenario import run_scenario

    ki, kc, source, note = coefficients_noted(setup.case, run_scenario(setup.case).series({}), Settings(), None)
    if note:
        log.warning("%s (on the case's own run)", note)
    return PaperStepper(ki, kc, setup.params), f"paper (K_i {ki:.4g}, K_C {kc:.4g} um/K, {source})" + \
        (f"; {note}" if note else "")


METHOD = Method("paper", batch, stepper, order=10, summary="the paper's procedure", doc=__doc__)
