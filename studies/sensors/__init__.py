"""Sensor placement: which few surface points, measured, predict a machine's thermal drift best
(``gatetherm sensors``; docs/sensors.md).

:mod:`.candidates` where a sensor may go, :mod:`.loads` the duty cycles it is trained and judged
on, :mod:`.reduced` the candidates' temperatures from the case's reduced model, :mod:`.screen`
the output-weighted pivoted-QR shortlist, :mod:`.greedy` the choice with the errormodel family,
:mod:`.models` the chosen set's ``model.json`` and held-out error, :mod:`.place`
:func:`~.place.place_sensors`, :mod:`.result` the :class:`~.result.Placement` and its files,
:mod:`.check` the independent check by FE runs.
"""
