"""The compute functions of the report's sections: each takes a
:class:`~gatetherm.validation.report.registry.Context` and returns a
:class:`~gatetherm.validation.report.result.Result`, writing its figures into the context's folder."""

