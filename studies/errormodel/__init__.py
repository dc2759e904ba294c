"""Thermal-error models fitted to a machine's measurements (docs/errormodel.md).

:mod:`.terms` the regressors (temperature rises, differences, lagged inputs), :mod:`.select` the
held-out error and the sensor selection, :mod:`.fit` :func:`~.fit.fit_error_model` (its settings
:mod:`.fitparams`, the refinement of a selection :mod:`.tune`), :mod:`.paper` the paper's form,
:mod:`.fitted` the fitted model, :mod:`.model` its ``model.json``,
:mod:`.prediction` :func:`~.prediction.predict`, :mod:`.runs` the fitting data of one run or
several, :mod:`.trust` the 90 % interval and the drift check, :mod:`.refit` the refit on a
window, :mod:`.replay` the model in the compensation loop.
"""
