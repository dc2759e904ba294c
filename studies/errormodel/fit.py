"""Fitting thermal-error models to measured displacements (:func:`fit_error_model`).

Per target, inside the fitting span and by the held-out error of :mod:`.select` (forward selection
to the budget, then the smallest model on the path within ``min_gain`` of the best):

* ``static``: ``delta = c0 + sum_k K_k theta_k`` over at most ``max_sensors`` temperature rises
  (and, with ``differences``, differences ``theta_a - theta_b``);
* ``dynamic``: the same candidates plus each operating input as ``lag_tau[(|u|/u_max)^p]`` for
  ``p`` in ``exponents`` and ``tau`` on the grid ``input_taus_s`` (at most ``max_inputs`` such
  terms), and, with ``sensor_taus_s``, lagged rises ``lag_tau[theta_k]``;
* then (``refine``) the time constants are refined continuously (least squares on the fitting
  span, within the grid's range) and each term is dropped whose removal raises the held-out error
  by less than ``min_gain`` (two grid lags bracketing one time constant become one lag);
* ``paper``: ``delta = K_i (theta_a - theta_b) - K_C theta_c`` (eq 21, no intercept), every
  triple a, b, c of the candidates tried.

``form="auto"`` fits ``static`` and ``dynamic`` and keeps ``dynamic`` only if its held-out error is
lower by at least ``min_gain``. The fit is deterministic: no random numbers; ties go to the
candidate listed first. The coefficients come from least squares on all valid rows of the span.

What the sensors' noise allows (docs/errormodel.md, "Sensor noise"), with ``resolution_K`` the
thermocouples' resolution, taken as the standard deviation of their noise:

* a temperature term (rise, difference, lagged rise) whose values span less than
  :data:`SPAN_RESOLUTIONS` resolutions in the fitting span is not offered: it gets no weight;
* every least squares, in the held-out folds and the final fit, minimises the expected squared
  error on readings with that noise, ``|y - X c|^2 + n sum_k sigma_k^2 c_k^2`` (sigma_k the noise
  of term k: :func:`~gatetherm.studies.errormodel.terms.noise_sd`), so that each coefficient is
  bounded by what the noise makes identifiable; ``noise_um``, the noise the sensors then add to
  the prediction (``sqrt(sum sigma_k^2 c_k^2)``), is recorded per target.
"""
from __future__ import annotations

import dataclasses
import logging

import numpy as np

from gatetherm import InputError
from gatetherm.studies.errormodel import select
from gatetherm.studies.errormodel.fitparams import (  # noqa: F401 (re-exported)
    CV_KINDS, FIT_FORMS, SPAN_RESOLUTIONS, FitParams)
from gatetherm.studies.errormodel.model import ErrorModel, TargetModel, check_leakage, residual_stats
from gatetherm.studies.errormodel.paper import fit_paper_form
from gatetherm.studies.errormodel.runs import Runs
from gatetherm.studies.errormodel.terms import Term
from gatetherm.studies.errormodel.trust import calibrate, calibrate_forward, term_ranges
from gatetherm.studies.errormodel.tune import held_out, refine, variances

log = logging.getLogger(__name__)


def fraction_span(t_s: np.ndarray, lo: float, hi: float) -> tuple[float, float]:
    """The span from fraction ``lo`` to ``hi`` of the time from the first to the last sample, s."""
    if not 0 <= lo < hi <= 1:
        raise InputError("fit span (--fit-span, span)", f"{lo:g}:{hi:g} is not 0 <= start < end <= 1", "e.g. 0:0.6")
    return t_s[0] + lo * (t_s[-1] - t_s[0]), t_s[0] + hi * (t_s[-1] - t_s[0])


def default_candidates(names, targets) -> tuple[str, ...]:
    """Every temperature column (``*_degC``) that is not a target."""
    return tuple(n for n in names if n.endswith("_degC") and n not in targets)


def fit_error_model(series, targets, candidates=None, inputs=(), params: FitParams = FitParams(),
                    span: tuple[float, float] | None = None, source: str = "") -> ErrorModel:
    """Fit a thermal-error model of each target column, on one run or several.

    Parameters
    ----------
    series : mapping or TimeSeries, or a list of them
        One run, or several runs of the same machine (each homed anew: its own reference, the
        model's value at its start its zero; :mod:`gatetherm.studies.errormodel.runs`). Each has
        ``time_s`` (s, increasing), the targets (um; NaN = not measured), the candidate temperature
        columns (degC) and the inputs (e.g. ``spindle_rpm``, 1/min).
    targets : sequence of str
        Displacement columns to model, um.
    candidates : sequence of str, optional
        Temperature columns to choose sensors from; default every ``*_degC`` column.
    inputs : sequence of str
        Operating inputs for the dynamic terms; none = static and paper forms only.
    params : FitParams
        Budgets, grids, cross-validation and form.
    span : (float, float) or list of them, optional
        Fitting span ``(start_s, end_s)`` of ``time_s``, s, both included, per run or one for all;
        default each run whole.
    source : str
        Where the data came from (recorded in the model; several files separated by ``", "``).

    Returns
    -------
    ErrorModel
        Models of the targets (with their held-out 90 % intervals), the reference temperatures
        (first valid sample in the span, degC; none for several runs) and the span; see
        :mod:`gatetherm.studies.errormodel.model`.
    """
    model = _fit(series, targets, candidates, inputs, params, span, source)
    if isinstance(series, (list, tuple)) and len(series) >= 3:  # how sure: each run as a new one
        model = _run_intervals(model, list(series), targets, candidates, inputs, params, span)
    return model


def _run_intervals(model: ErrorModel, runs, targets, candidates, inputs, params: FitParams, span) -> ErrorModel:
    """``model`` with each target's 90 % interval calibrated on every run predicted by the whole fit
    (terms, form, time constants; the readings unsmoothed, as the model's) made on the other runs
    alone, as a run it never saw (:func:`~gatetherm.studies.errormodel.trust.calibrate`: the runs' own
    90 % quantiles, conformal over runs)."""
    from gatetherm.studies.errormodel.model import predict

    spans = span if isinstance(span, list) else [span] * len(runs)
    params = dataclasses.replace(params, smooth_grid_s=())
    res: dict[str, list] = {m.target: [] for m in model.targets}
    for i, run in enumerate(runs):
        rest = [r for j, r in enumerate(runs) if j != i]
        inner = _fit(rest, targets, candidates, inputs, params, [s for j, s in enumerate(spans) if j != i])
        p, t = predict(inner, run), np.asarray(run["time_s"], float)
        keep = (t >= spans[i][0]) & (t <= spans[i][1]) if spans[i] is not None else np.ones(t.size, bool)
        for m in model.targets:
            y = np.asarray(run[m.target], float)
            ok = keep & np.isfinite(y) & np.isfinite(p[m.target])
            res[m.target].append(p[m.target][ok] - (y[ok] - y[ok][0]) if ok.any() else np.zeros(0))
    out = []
    for m in model.targets:
        edges = np.cumsum([0] + [r.size for r in res[m.target]])
        out.append(dataclasses.replace(m, interval={**calibrate(res[m.target], list(zip(edges[:-1], edges[1:])),
                                                                chain=False), "calibration": "runs"}))
    return dataclasses.replace(model, targets=tuple(out))


def _fit(series, targets, candidates, inputs, params: FitParams, span, source: str = "") -> ErrorModel:
    """:func:`fit_error_model`, its intervals from the chosen model's held-out residuals."""
    several = isinstance(series, (list, tuple)) and len(series) >= 3
    if params.smooth_grid_s and several:  # left to the readings as they are: docs/errormodel.md, "Several runs"
        log.info("three or more runs: the readings are not smoothed (smooth_grid_s is tried within one or two runs)")
        params = dataclasses.replace(params, smooth_grid_s=())
    if params.smooth_grid_s:
        fits = {float(v): _fit(series, targets, candidates, inputs,
                               dataclasses.replace(params, smooth_s=float(v), smooth_grid_s=()), span, source)
                for v in dict.fromkeys((params.smooth_s, *params.smooth_grid_s))}
        held = {v: float(sum(m.held_out_mae_um for m in f.targets)) for v, f in fits.items()}
        best = min(held, key=held.get)  # ties: the first listed, smooth_s
        log.info("readings smoothed over %g s: held-out error %s", best, held)
        f = fits[best]
        return dataclasses.replace(f, settings={**f.settings, "smooth_grid_s": list(params.smooth_grid_s),
                                                "smooth_held_out_um": {f"{v:g}": e for v, e in held.items()}})
    runs = list(series) if isinstance(series, (list, tuple)) else [series]
    if not runs:
        raise InputError("data", "no run given", "give at least one data file")
    sources = [s.strip() for s in str(source).split(", ")] if source else []
    names = tuple(runs[0].names if hasattr(runs[0], "names") else runs[0])
    targets = tuple(targets)
    candidates = tuple(candidates) if candidates is not None else default_candidates(names, targets)
    check_leakage(targets, candidates, tuple(inputs))
    for k, ts in enumerate(runs):
        have = tuple(ts.names if hasattr(ts, "names") else ts)
        for name in ("time_s", *targets, *candidates, *inputs):
            if name not in have:
                where = sources[k] if k < len(sources) else (source or getattr(ts, "source", "") or "data")
                raise InputError(f"{where}: column {name}", "missing", f"columns are {', '.join(have)}")
    if not targets or not candidates:
        raise InputError("targets/candidates", "none given", "name at least one target and one temperature column")
    spans = span if isinstance(span, list) else [span] * len(runs)
    spans = [s if s is not None else (float(np.asarray(ts["time_s"])[0]), float(np.asarray(ts["time_s"])[-1]))
             for s, ts in zip(spans, runs)]
    data = Runs(runs, candidates, inputs, spans, params.max_gap_s, sources, params.smooth_s, params.anchor_s)
    base = _base_terms(candidates, inputs, data, params)
    B = np.column_stack([np.ones(data.time.size)] + [data.column(b) for b in base])
    models = [_fit_target(data.target(y), y, data, base, B, params) for y in targets]
    for m in models:
        if not m.terms:  # nothing chosen: a constant is no model of a thermal error, and says so
            log.warning("%s: no candidate column explains it (none varies beyond %g resolutions of %g K, or none "
                        "lowers the held-out error): the model is a constant; give temperatures that change over the "
                        "run", m.target, SPAN_RESOLUTIONS, params.resolution_K)
    used = {s for m in models for s in m.sensors}
    reference = data.reference()
    lo, hi = spans[0] if len(runs) == 1 else (spans[0][0], spans[-1][1])
    return ErrorModel(tuple(models), {c: reference[c] for c in candidates if c in used and c in reference},
                      {"start_s": float(lo), "end_s": float(hi), "samples": int(data.ok.sum()), "source": str(source),
                       "runs": len(runs)},
                      params.max_gap_s, _settings(params, candidates, inputs), run_reference=data.anchored)


def _settings(params: FitParams, candidates, inputs) -> dict:
    return {**dataclasses.asdict(params), "candidates": list(candidates), "inputs": list(inputs)}


def _base_terms(candidates, inputs, data: Runs, params: FitParams) -> list[Term]:
    base = [Term("sensor", c, tau_s=tau) for c in candidates for tau in (None, *params.sensor_taus_s)]
    if params.drift and data.anchored and params.form != "paper":  # within one run a trend is the heating itself
        base.append(Term("drift", "time_s"))
    if params.form in ("auto", "dynamic"):
        for u in inputs:
            scale = float(max(np.max(np.abs(c[u][r])) for c, r in zip(data.cols, data.rows)))
            if scale == 0:
                log.warning("input %s is 0 throughout the fitting span: not used", u)
                continue
            base += [Term("input", u, tau_s=tau, exponent=p, scale=scale)
                     for p in params.exponents for tau in params.input_taus_s]
    if params.form == "static":
        base = [b for b in base if b.tau_s is None]
    return base



def _candidates(base: list[Term], B, params: FitParams, dynamic: bool) -> tuple[list, list[select.Candidate]]:
    """Terms offered to the forward selection and their combination vectors (column 0 = ones);
    ``B`` are the base columns on the fitting rows."""
    terms, cands, p = [], [], len(base) + 1
    min_span = SPAN_RESOLUTIONS * params.resolution_K
    for j, b in enumerate(base):
        free = b.kind in ("input", "drift")
        if (dynamic or b.tau_s is None) and (free or select.informative(B[:, j + 1], min_span)):
            w = np.zeros(p)
            w[j + 1] = 1.0
            terms.append(b)
            cands.append(select.Candidate(len(cands), w, frozenset(() if free else (b.column,)), b.kind == "input"))
    if params.differences:
        plain = [j for j, b in enumerate(base) if b.kind == "sensor" and b.tau_s is None]
        for i, k in [(i, k) for n, i in enumerate(plain) for k in plain[n + 1:]]:
            w = np.zeros(p)
            w[i + 1], w[k + 1] = 1.0, -1.0
            if not select.informative(B @ w, min_span):
                continue
            terms.append(Term("difference", base[i].column, other=base[k].column))
            cands.append(select.Candidate(len(cands), w, frozenset((base[i].column, base[k].column)), False))
    return terms, cands



def _fit_target(y_all, name, data: Runs, base, B, params: FitParams) -> TargetModel:
    y_all = np.asarray(y_all, float)
    rows = data.ok & np.isfinite(y_all)
    if rows.sum() < 4 * max(params.folds):
        raise InputError(f"target {name}", f"only {rows.sum()} valid samples in the fitting span",
                         f"give at least {4 * max(params.folds)}")
    cv = held_out(B[rows], y_all[rows], data, rows, params, variances(base, data, params))
    if params.form == "paper":
        return fit_paper_form(cv, name, base, B, y_all, rows, SPAN_RESOLUTIONS * params.resolution_K)
    forms = {"auto": ("static", "dynamic"), "static": ("static",), "dynamic": ("dynamic",)}[params.form]
    has_dynamic = any(b.tau_s is not None for b in base)
    fits, selection, pool = {}, [], {}
    intercept = np.eye(len(base) + 1)[:, :1]
    for form in forms:
        if form == "dynamic" and not has_dynamic:
            continue
        terms, cands = _candidates(base, B[rows], params, form == "dynamic")
        path = select.forward(cv, cands, intercept, params.max_sensors, params.max_inputs)
        pick = select.choose(path, params.min_gain)
        fits[form] = refine([terms[k] for k in pick.chosen], pick.cv_mae, data, y_all, rows, params) \
            if params.refine else ([terms[k] for k in pick.chosen], pick.cv_mae)
        selection += [{"form": form, "terms": [terms[k].label for k in s.chosen], "sensors": s.sensors,
                       "cv_mae_um": s.cv_mae} for s in path]
        if params.choose_latest and data.blocks(rows) is None:
            pool[form] = [[terms[k] for k in s.chosen] for s in path if s.chosen] + [fits[form][0]]
    if pool:
        terms, cv_mae, form = _latest(pool, data, y_all, rows, params)
    else:
        form = "dynamic" if "dynamic" in fits and ("static" not in fits or
                                                   fits["dynamic"][1] < fits["static"][1] * (1 - params.min_gain)) \
            else "static"
        terms, cv_mae = fits[form]
    X = np.column_stack([np.ones(data.time.size)] + [data.column(term) for term in terms])
    var = variances(terms, data, params)
    c = select.noisy_least_squares(X[rows], y_all[rows], var)
    if data.blocks(rows) is None:  # one or two runs: calibrated as a control uses it, on the latest blocks
        final = held_out(X[rows], y_all[rows], data, rows, dataclasses.replace(params, cv="chain"), var)
        interval = calibrate_forward(final.residuals(np.eye(X.shape[1])), final.blocks, data.clock[rows])
    else:
        final = held_out(X[rows], y_all[rows], data, rows, params, var)
        interval = calibrate(final.residuals(np.eye(X.shape[1])), final.blocks, chain=False)
    return TargetModel(name, form, tuple(terms), tuple(float(v) for v in c[1:]), float(c[0]),
                       residual_stats(X[rows] @ c - y_all[rows]), float(cv_mae), tuple(selection),
                       float(np.sqrt(var @ c**2)), interval, term_ranges(X[rows, 1:]))


def _latest(pool: dict, data: Runs, y_all, rows, params: FitParams):
    """The candidate of ``pool`` (form -> lists of terms) chosen by the forward-chaining error on the
    latest blocks of the fitting rows (``params.choose_latest``; with ``latest_score="mean"`` the mean of
    that and the blocked error): the one of the fewest terms (ties: the first listed) whose error is
    within ``min_gain`` of the lowest. Its terms, that error and its form."""
    chain = dataclasses.replace(params, cv="chain")
    scored = []
    for form, models in pool.items():
        for terms in models:
            X = np.column_stack([np.ones(data.time.size)] + [data.column(term) for term in terms])
            var = variances(terms, data, params)
            err = held_out(X[rows], y_all[rows], data, rows, chain, var).error(np.eye(X.shape[1]))
            if params.latest_score == "mean":  # fixed weights: half the latest blocks', half the whole span's
                blocked = dataclasses.replace(params, cv="blocked")
                err = 0.5 * (err + held_out(X[rows], y_all[rows], data, rows, blocked, var).error(np.eye(X.shape[1])))
            scored.append((len(terms), len(scored), err, terms, form))
    lowest = min(s[2] for s in scored)
    _, _, err, terms, form = min(s for s in scored if s[2] <= lowest * (1 + params.min_gain))
    log.info("chosen on the latest blocks: %s, %s (%s error %.4g; lowest %.4g)", form,
             ", ".join(t.label for t in terms), "forward-chaining" if params.latest_score == "chain" else "mean", err,
             lowest)
    return terms, err, form
