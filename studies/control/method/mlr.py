"""The ``mlr`` method: a static regression of δ on θ_A, θ_B, θ_C fitted on the case's own schedule,
forecasting one sample ahead from the extrapolated temperatures (the paper's latency; the industry
baseline); step-wise :class:`~gatetherm.studies.control.stepwise.RegressionStepper`."""
from __future__ import annotations

import logging

from gatetherm import InputError
from gatetherm.studies.control.method import Batch, Job, Method, Setup

log = logging.getLogger(__name__)


def batch(job: Job) -> Batch:
    """The regression trained on the model's run, replayed on the record; its benefit checked with the
    regression fitted on the first part of the model's run."""
    from gatetherm.studies.control import benefit as held
    from gatetherm.studies.control.compensator import NEEDED, close_loop, external_prediction
    from gatetherm.studies.control.methods import refitted
    from gatetherm.studies.control.regression import THETAS, fit_regression, prediction_noise_um, \
        regression_forecast
    from gatetherm.studies.run.scenario import run_scenario
    from gatetherm.studies.run.timeseries import validate_complete

    ts, case, s, params, actuator = job.ts, job.case, job.settings, job.settings.params, job.actuator
    validate_complete(ts, NEEDED)
    if case is None:
        raise InputError("--method mlr", "needs a model to train on", "give --case, or the frame's --config/--dim")
    train = run_scenario(case, cache=job.cache).series({})
    mlr = fit_regression(train, THETAS, s.resolution_K)
    notes = (f"{mlr.warning} (on the model's own run, {case.schedule.label})",) if mlr.warning else ()
    loop = close_loop(ts, external_prediction(ts, regression_forecast(mlr, ts), params), params, actuator)
    checked = refitted(lambda: close_loop(ts, external_prediction(ts, regression_forecast(
        fit_regression(held.before(train, s.held_out), THETAS, s.resolution_K), ts), params), params, actuator),
        f"regression fitted on the first {100 * (1 - s.held_out):.0f} % of the model's run")
    noise = prediction_noise_um(mlr.coefficients, s.resolution_K)
    extra = {"regression": {"intercept_um": mlr.intercept_um, **dict(zip(mlr.features, mlr.coefficients))},
             "sensor_noise_um": noise}
    label = f"regression on theta_A, theta_B, theta_C ({case.schedule.label} of the model), 1-sample forecast, " \
        f"update every {params.update_interval_s / 60:g} min"
    return Batch(loop, extra, label, f"mlr ({label}; {s.resolution_K:g}-K sensor noise adds ±{noise:.2g} um)",
                 checked, notes=notes, model="the regression trained on its run")


def stepper(setup: Setup):
    """The regression fitted on the case's own run; the label says what the fit left out or bounded."""
    from gatetherm.studies.control.regression import THETAS, fit_regression
    from gatetherm.studies.control.stepwise import RegressionStepper
    from gatetherm.studies.run.scenario import run_scenario

    mlr = fit_regression(run_scenario(setup.case).series({}), THETAS)
    if mlr.warning:
        log.warning("%s (on the case's own run)", mlr.warning)
    return RegressionStepper(mlr, setup.params), "mlr" + (f" ({mlr.warning})" if mlr.warning else "")


METHOD = Method("mlr", batch, stepper, order=20, summary="regression baseline", doc=__doc__)
