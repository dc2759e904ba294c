"""A fitted thermal-error model's file, ``model.json`` (:func:`save_model`, :func:`load_model`).

The file (``format: gatetherm-errormodel/1``) holds, per target, the form, the terms with their
coefficients and units, the chosen sensors, the residuals on the fitting span, the held-out error
and the selection curve; once: the reference temperatures, the input scales, the fitting span.
The model itself (:class:`ErrorModel`, :class:`TargetModel`) is
:mod:`gatetherm.studies.errormodel.fitted`; :func:`predict`, which evaluates it with numpy only,
:mod:`gatetherm.studies.errormodel.prediction` (both importable from here too).
"""
from __future__ import annotations

import dataclasses
from pathlib import Path

from gatetherm import InputError, write_text_atomic
from gatetherm.checks import FINITE, KELVIN_LIKE, first_nonfinite, json_text, parse_json
from gatetherm.files import read_text
from gatetherm.studies.errormodel.fitted import (  # noqa: F401 (re-exported)
    FORMS, ErrorModel, TargetModel, residual_stats)
from gatetherm.studies.errormodel.prediction import (  # noqa: F401 (re-exported)
    _term_values, check_columns, input_gaps, predict, score)
from gatetherm.studies.errormodel.terms import Term

FORMAT = "gatetherm-errormodel/1"


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


FIX = "give a model.json from 'gatetherm errormodel fit'"
COEFFICIENT = 1e9
"""Largest coefficient or intercept a model file may hold (µm, µm/K …): beyond, an edit gone wrong."""


MAX_NAME = 100
"""Longest column name (a target, a sensor) a model file may hold."""


def _names(columns) -> str:
    return ", ".join(map(str, columns)) if isinstance(columns, list) and columns else "none"


def _number(value, lo: float = -COEFFICIENT, hi: float = COEFFICIENT) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and lo <= value <= hi


def _check_document(data: dict, where: str) -> None:
    """InputError naming the entry of a model file that is not what :func:`to_dict` writes: a
    hand edit that would otherwise be read without a word (a string coefficient, a missing
    intercept, a negative interval, an inverted range, a term reading its own target …)."""
    def need(ok, key: str, what: str):
        if not ok:
            raise InputError(f"{where}: {key}", what, FIX)

    targets = data.get("targets")
    need(isinstance(targets, dict) and targets, "targets", "must be a non-empty table of the targets' models")
    refs = data.get("reference_degC")
    refs = refs if isinstance(refs, dict) else {}
    for field, name in [("targets", n) for n in targets] + [("reference_degC", n) for n in refs]:
        need(len(name) <= MAX_NAME and name.isprintable(), f"{field} {name[:40]!r}" + ("…" if len(name) > 40 else ""),
             f"is not a column name of at most {MAX_NAME} printable characters ({len(name)} characters)")
    for s, v in refs.items():
        need(_number(v, -273.15, 1000.0), f"reference_degC.{s}", "must be a temperature in °C, -273.15 … 1000")
        need(not KELVIN_LIKE[0] <= v <= KELVIN_LIKE[1], f"reference_degC.{s}",
             f"is {v:g} °C: a temperature in kelvins? the references are °C (the file's fit gives them)")
    for name, d in targets.items():
        k = f"targets.{name}"
        need(isinstance(d, dict), k, "must be a table")
        need(_number(d.get("intercept_um")), f"{k}.intercept_um", f"must be a number within ±{COEFFICIENT:g} µm")
        need(isinstance(d.get("terms"), list) and d["terms"], f"{k}.terms", "must be a non-empty list of terms")
        for i, t in enumerate(d["terms"]):
            need(isinstance(t, dict), f"{k}.terms[{i}]", "must be a table")
            need(_number(t.get("coefficient")), f"{k}.terms[{i}].coefficient",
                 f"must be a number within ±{COEFFICIENT:g}")
            need(name not in (t.get("column"), t.get("other")), f"{k}.terms[{i}].column",
                 f"reads the target {name} itself: a model cannot read the column it predicts")
        read = [c for t in d["terms"] if t.get("kind") not in ("input", "drift")
                for c in (t.get("column"), t.get("other")) if c is not None]
        listed = d.get("sensors", read)
        need(isinstance(listed, list) and set(map(str, listed)) == set(map(str, read)), f"{k}.sensors",
             f"lists {_names(listed)} but its terms read {_names(read)}: a hand edit of one without the other")
        interval, ranges = d.get("interval", {}), d.get("ranges", [])
        widths = [v for key, v in interval.items() if key.endswith("_um")] if isinstance(interval, dict) else [None]
        need(all(_number(v, 0.0) for v in widths), f"{k}.interval", "its widths must be numbers >= 0 µm")
        pairs = ranges if isinstance(ranges, list) else [None]
        need(all(isinstance(r, list) and len(r) == 2 and all(_number(v, -1e300, 1e300) for v in r) and r[0] <= r[1]
                 for r in pairs), f"{k}.ranges", "each must be [low, high] with low <= high")
    span, settings = data.get("fit_span", {}), data.get("settings", {})
    ends = (span.get("start_s", 0.0), span.get("end_s", 1e300)) if isinstance(span, dict) else (None, None)
    need(all(_number(v, -1e300, 1e300) for v in ends) and ends[0] <= ends[1], "fit_span",
         "start_s and end_s must be numbers (s), start_s <= end_s")
    need(_number(data.get("max_gap_s", 300.0), 0.0, 1e300) and data.get("max_gap_s", 300.0) > 0, "max_gap_s",
         "must be a number > 0 s")
    need(isinstance(settings, dict) and _number(settings.get("smooth_s", 0.0), 0.0, 1e300), "settings.smooth_s",
         "must be a number >= 0 s")


def from_dict(data: dict, where: str = "model") -> ErrorModel:
    """Inverse of :func:`to_dict`; InputError naming the entry on a bad file."""
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise InputError(f"{where}: format", f"not a {FORMAT} file", FIX)
    _check_document(data, where)
    try:
        targets = []
        for name, d in data["targets"].items():
            terms = tuple(Term(**{k: v for k, v in t.items() if k not in ("coefficient", "unit", "label")})
                          for t in d["terms"])
            units = [(i, t["unit"], term.unit) for i, (t, term) in enumerate(zip(d["terms"], terms))
                     if "unit" in t and t["unit"] != term.unit]
            if units:
                i, given, unit = units[0]
                raise InputError(f"targets.{name}.terms[{i}].unit", f"is {given!r}, but the coefficient of such a "
                                 f"term is in {unit}", "give the coefficient in that unit")
            if d["form"] not in FORMS:
                raise InputError(f"{where}: targets.{name}.form", f"unknown {d['form']!r}", f"use {', '.join(FORMS)}")
            targets.append(TargetModel(name, d["form"], terms, tuple(float(t["coefficient"]) for t in d["terms"]),
                                       float(d["intercept_um"]), d.get("residual", {}),
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
    for field, given in zip(names, (targets, candidates or (), inputs or ())):
        long = next((c for c in given if len(str(c)) > MAX_NAME or not str(c).isprintable()), None)
        if long is not None:
            raise InputError(f"{field} {str(long)[:40]!r}…", f"is not a column name of at most {MAX_NAME} printable "
                             f"characters ({len(str(long))} characters)", "rename the column (a model file keeps it)")
    twice = next((t for i, t in enumerate(targets) if t in targets[:i]), None)
    if twice is not None:
        raise InputError(f"{names[0]} {twice}", "is named twice", f"name {twice} once")
    if "time_s" in targets:
        raise InputError(f"{names[0]} time_s", "is the time, not a displacement", "name displacement columns, um")
    for field, given in zip(names[1:], (candidates or (), inputs or ())):
        if "time_s" in given:  # the clock is no sensor: a fit on it is a drift in disguise, fitted to the record
            raise InputError(f"{field} time_s", "is the time, not a sensor or an input",
                             f"drop time_s from {field} (a slow drift is a term of its own: docs/errormodel.md)")
        twice = next((c for i, c in enumerate(given) if c in given[:i]), None)
        if twice is not None:
            raise InputError(f"{field} {twice}", "is named twice", f"name {twice} once")
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
