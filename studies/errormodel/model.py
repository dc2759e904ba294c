"""A fitted thermal-error model, its ``model.json`` and its evaluation.

Per target (a displacement column, um)::

    delta(t) = c0 + sum_j b_j x_j(t)

with ``x_j`` the :class:`~gatetherm.studies.errormodel.terms.Term` values (temperature rises
from the model's reference temperatures, K; operating inputs through first-order lags) and
``b_j`` in um/K or um. The file (``format: gatetherm-errormodel/1``) holds, per target, the form,
the terms with their coefficients and units, the chosen sensors, the residuals on the fitting span,
the held-out error and the selection curve; once: the reference temperatures, the input scales,
the fitting span. :func:`predict` evaluates it with numpy only.
"""
from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gatetherm import InputError, write_text_atomic
from gatetherm.checks import FINITE, first_nonfinite, json_text, parse_json
from gatetherm.files import read_text
from gatetherm.studies.errormodel.terms import GapReport, Term, evaluate, fill_gaps, readings

log = logging.getLogger(__name__)

FORMAT = "gatetherm-errormodel/1"
FORMS = ("static", "dynamic", "paper")
"""static: sensors (and differences) only; dynamic: also lags (inputs, temperatures);
paper: ``K_i (theta_a - theta_b) - K_C theta_c`` without intercept (eq 21)."""


@dataclass(frozen=True)
class TargetModel:
    """The model of one target column."""

    target: str
    """The predicted column, um."""
    form: str
    """One of :data:`FORMS`."""
    terms: tuple[Term, ...]
    """The regressors."""
    coefficients: tuple[float, ...]
    """One per term, um/K (sensor, difference) or um (input)."""
    intercept_um: float = 0.0
    """Constant c0, um (0 in the paper's form)."""
    residual: dict = field(default_factory=dict)
    """On the fitting span: ``mae_um``, ``rms_um``, ``max_abs_um``, ``samples``."""
    held_out_mae_um: float | None = None
    """Mean absolute error of the blocked cross-validation inside the fitting span, um."""
    selection: tuple[dict, ...] = ()
    """The forward-selection path: per step ``terms`` (labels), ``sensors`` (count), ``cv_mae_um``."""
    noise_um: float | None = None
    """Standard deviation the temperature sensors' noise adds to the prediction, um:
    ``sqrt(sum_k (c_k sigma_k)^2)`` at the fit's sensor resolution (None: not recorded)."""
    interval: dict = field(default_factory=dict)
    """The 90 % interval from held-out residuals (:func:`~gatetherm.studies.errormodel.trust.calibrate`):
    ``half_width_um`` (um), ``coverage`` (fraction of held-out samples inside, out of sample),
    ``samples``, ``level``; empty: not calibrated."""
    ranges: tuple = ()
    """Per term its (smallest, largest) value on the fitting rows (the drift detector's reference)."""

    @property
    def sensors(self) -> tuple[str, ...]:
        """The temperature columns the model reads, in term order."""
        cols = [c for t in self.terms if t.kind not in ("input", "drift") for c in t.columns]
        return tuple(dict.fromkeys(cols))

    @property
    def columns(self) -> tuple[str, ...]:
        """Every column the model reads."""
        return tuple(dict.fromkeys(c for t in self.terms for c in t.columns))


@dataclass(frozen=True)
class ErrorModel:
    """Thermal-error models of one or more targets fitted on one series."""

    targets: tuple[TargetModel, ...]
    """One model per target."""
    reference_degC: dict[str, float]
    """Temperature of each used sensor that the rises are taken from, degC (default: its first
    valid sample in the fitting span)."""
    fit_span: dict
    """``start_s``, ``end_s`` (s) and ``samples`` of the fitting span; ``source``: the data file."""
    max_gap_s: float = 300.0
    """Longest gap (s) in a used column that predictions bridge (linear fill); longer gaps are NaN."""
    settings: dict = field(default_factory=dict)
    """The fit settings (:class:`~gatetherm.studies.errormodel.fit.FitParams`) as a dict."""
    run_reference: bool = False
    """True (fitted on several runs): every predicted file is its own run, its rises taken from its
    first sample and the prediction zero there (:mod:`~gatetherm.studies.errormodel.runs`)."""

    @property
    def columns(self) -> tuple[str, ...]:
        """Every column any target model reads."""
        return tuple(dict.fromkeys(c for m in self.targets for c in m.columns))

    def target(self, name: str) -> TargetModel:
        """The model of target ``name``."""
        for m in self.targets:
            if m.target == name:
                return m
        raise InputError(f"target {name}", "not in the model", f"use one of {', '.join(self.names)}")

    @property
    def names(self) -> tuple[str, ...]:
        """The target columns."""
        return tuple(m.target for m in self.targets)


def residual_stats(r: np.ndarray) -> dict:
    """MAE, RMS and largest absolute value (um) and count of residuals ``r`` (um)."""
    return {"mae_um": float(np.mean(np.abs(r))), "rms_um": float(np.sqrt(np.mean(r**2))),
            "max_abs_um": float(np.max(np.abs(r))), "samples": int(r.size)}


def check_columns(model: ErrorModel, columns, where: str = "data") -> None:
    """Raise InputError if ``columns`` (a mapping or TimeSeries) lacks ``time_s`` or a column the model reads."""
    for name in ("time_s", *model.columns):
        if name not in columns:
            raise InputError(f"{getattr(columns, 'source', '') or where}: column {name}", "missing; the model reads it",
                             f"give a file with the columns {', '.join(('time_s',) + model.columns)}")


def _filled(model: ErrorModel, columns) -> tuple[dict, np.ndarray, dict[str, GapReport]]:
    check_columns(model, columns)
    t = np.asarray(columns["time_s"], float)
    cols, bad, reports = {}, np.zeros(t.size, bool), {}
    for name in model.columns:
        try:
            cols[name], long, reports[name] = fill_gaps(t, columns[name], model.max_gap_s)
        except ValueError:
            raise InputError(f"column {name}", "has no valid sample", "give measured values") from None
        smooth, anchor = (float(model.settings.get(k, 0.0)) for k in ("smooth_s", "anchor_s"))
        if name not in model.settings.get("inputs", ()) and (smooth > 0 or anchor > 0):
            cols[name] = readings(t, cols[name], smooth, anchor)  # as the fit read them
        bad |= long
    return cols, bad, reports


def input_gaps(model: ErrorModel, columns) -> dict[str, GapReport]:
    """Per column the model reads, what :func:`predict` fills (only columns with gaps)."""
    return {k: r for k, r in _filled(model, columns)[2].items() if r.filled}


def _references(model: ErrorModel, cols, t: np.ndarray) -> dict:
    if not model.run_reference:
        return {**model.reference_degC, "time_s": float(model.fit_span.get("start_s", t[0]))}
    return {**{c: float(v[0]) for c, v in cols.items()}, "time_s": float(t[0])}


def _term_values(model: ErrorModel, columns):
    cols, bad, _ = _filled(model, columns)
    t = np.asarray(columns["time_s"], float)
    ref = _references(model, cols, t)
    values = {}
    for m in model.targets:
        vs = [evaluate(term, t, cols, ref) for term in m.terms]
        values[m.target] = [v - v[0] for v in vs] if model.run_reference else vs
    return values, bad, t


def predict(model: ErrorModel, columns) -> dict[str, np.ndarray]:
    """Evaluate the model at the samples of ``columns``.

    Parameters
    ----------
    model : ErrorModel
        From :func:`~gatetherm.studies.errormodel.fit.fit_error_model` or :func:`load_model`.
    columns : mapping or TimeSeries
        ``time_s`` (s, increasing) and every column the model reads (degC, the inputs' units).
        Missing samples (NaN) are filled linearly (held at the ends); in gaps longer than
        ``model.max_gap_s`` the prediction is NaN. Lags start in steady state at the first sample.
        A model fitted on several runs takes the file as a run of its own: rises from its first
        sample, the prediction 0 there.

    Returns
    -------
    dict
        Target name -> predicted displacement at each sample, um.
    """
    values, bad, t = _term_values(model, columns)
    out = {}
    for m in model.targets:
        y = np.full(t.size, 0.0 if model.run_reference else m.intercept_um)
        for v, b in zip(values[m.target], m.coefficients):
            y += b * v
        y[bad] = np.nan
        out[m.target] = y
    return out


def score(predicted: dict[str, np.ndarray], columns) -> dict[str, dict]:
    """Per predicted target: ``predicted_samples``, and where ``columns`` has the target measured,
    :func:`residual_stats` of measured - predicted over the samples where both exist (um)."""
    out = {}
    for name, p in predicted.items():
        entry = {"predicted_samples": int(np.isfinite(p).sum())}
        if name in columns:
            r = np.asarray(columns[name], float) - p
            r = r[np.isfinite(r)]
            entry.update(residual_stats(r) if r.size else {"samples": 0})
        out[name] = entry
    return out


def to_dict(model: ErrorModel) -> dict:
    """The JSON-ready content of ``model.json``."""
    def term(t: Term, b: float) -> dict:
        d = {k: v for k, v in dataclasses.asdict(t).items() if v is not None}
        if t.kind != "input":
            d.pop("exponent"), d.pop("scale")
        return {**d, "coefficient": b, "unit": t.unit, "label": t.label}

    targets = {m.target: {"form": m.form, "sensors": list(m.sensors), "intercept_um": m.intercept_um,
                          "terms": [term(t, b) for t, b in zip(m.terms, m.coefficients)],
                          "residual": m.residual, "held_out_mae_um": m.held_out_mae_um,
                          "selection": list(m.selection), "noise_um": m.noise_um, "interval": m.interval,
                          "ranges": [list(r) for r in m.ranges]} for m in model.targets}
    return {"format": FORMAT, "fit_span": model.fit_span, "reference_degC": model.reference_degC,
            "run_reference": model.run_reference, "max_gap_s": model.max_gap_s, "settings": model.settings,
            "targets": targets}


def from_dict(data: dict, where: str = "model") -> ErrorModel:
    """Inverse of :func:`to_dict`; InputError naming the entry on a bad file."""
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise InputError(f"{where}: format", f"not a {FORMAT} file",
                         "give a model.json from 'gatetherm errormodel fit'")
    try:
        targets = []
        for name, d in data["targets"].items():
            terms = tuple(Term(**{k: v for k, v in t.items() if k not in ("coefficient", "unit", "label")})
                          for t in d["terms"])
            if d["form"] not in FORMS:
                raise InputError(f"{where}: targets.{name}.form", f"unknown {d['form']!r}", f"use {', '.join(FORMS)}")
            targets.append(TargetModel(name, d["form"], terms, tuple(float(t["coefficient"]) for t in d["terms"]),
                                       float(d.get("intercept_um", 0.0)), d.get("residual", {}),
                                       d.get("held_out_mae_um"), tuple(d.get("selection", ())),
                                       d.get("noise_um"), dict(d.get("interval", {})),
                                       tuple(tuple(float(v) for v in r) for r in d.get("ranges", ()))))
        ref = {str(k): float(v) for k, v in data["reference_degC"].items()}
        model = ErrorModel(tuple(targets), ref, dict(data.get("fit_span", {})), float(data.get("max_gap_s", 300.0)),
                           dict(data.get("settings", {})), bool(data.get("run_reference", False)))
    except InputError as err:
        raise err.at(where) from None
    except (KeyError, TypeError, ValueError, AttributeError) as err:
        raise InputError(where, f"malformed model ({type(err).__name__}: {err})",
                         "give a model.json from 'gatetherm errormodel fit'") from None
    for key in ("start_s", "end_s"):  # read back as numbers by predict: a string would fail there
        if key in model.fit_span:
            FINITE.check(f"{where}: fit_span.{key}", model.fit_span[key], "give a model.json from 'gatetherm errormodel fit'")
    missing = [s for m in model.targets for s in m.sensors if s not in ref]
    if missing and not model.run_reference:
        raise InputError(f"{where}: reference_degC", f"no reference for {missing[0]}", "add its reference temperature")
    if not model.targets:
        raise InputError(f"{where}: targets", "is empty: the model predicts nothing",
                         "give a model.json from 'gatetherm errormodel fit'")
    bad = first_nonfinite(to_dict(model))
    if bad is not None:
        raise InputError(f"{where}: {bad[0]}", f"is {bad[1]}, not a finite number",
                         "give a model.json from 'gatetherm errormodel fit'")
    _refuse_leaks(model, where)
    return model


def check_leakage(targets, candidates=(), inputs=(), names=("targets", "candidates", "inputs")) -> None:
    """InputError if a target is among the candidate sensors or the inputs (``names``: how the
    caller calls the three): a model of a channel that reads the channel itself predicts nothing
    (its held-out error would be round-off) and would be silently wrong; also a target named
    twice, or the time column as a target."""
    twice = next((t for i, t in enumerate(targets) if t in targets[:i]), None)
    if twice is not None:
        raise InputError(f"{names[0]} {twice}", "is named twice", f"name {twice} once")
    if "time_s" in targets:
        raise InputError(f"{names[0]} time_s", "is the time, not a displacement", "name displacement columns, um")
    for field, given in zip(names[1:], (candidates or (), inputs or ())):
        leak = [c for c in given if c in set(targets)]
        if leak:
            raise InputError(f"{field} {leak[0]}", f"is a target ({names[0]}): a model cannot read the column it "
                             "predicts", f"drop {leak[0]} from {field}")


def _refuse_leaks(model: ErrorModel, where: str) -> None:
    """InputError if a target's model reads the target itself (or another column of the model's
    targets): a prediction of a channel from itself is no prediction."""
    for m in model.targets:
        leak = [c for c in m.columns if c == m.target]
        if leak:
            raise InputError(f"{where}: targets.{m.target}", "reads its own target column",
                             "fit the model again without it among the candidates and inputs")


def save_model(path, model: ErrorModel) -> None:
    """Write ``model`` to ``path`` as JSON, atomically; NonFiniteError naming the quantity if
    a number of it is NaN or infinite (nothing is written then)."""
    write_text_atomic(path, json_text(to_dict(model), Path(path).name, indent=1))


def load_model(path) -> ErrorModel:
    """Read a ``model.json``.

    Parameters
    ----------
    path : str or Path
        A file written by :func:`save_model` (``gatetherm errormodel fit``).

    Returns
    -------
    ErrorModel
    """
    fix = "give a model.json from 'gatetherm errormodel fit'"
    data = parse_json(read_text(Path(path), fix=fix), str(path), fix)
    return from_dict(data, str(path))
