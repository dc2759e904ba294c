"""Choosing the regressors by held-out error inside the fitting span.

Held-out error: blocked cross-validation. The fitting span's rows are cut into ``K`` contiguous
blocks of equal length; each block in turn is predicted by the least-squares fit on the others,
and the mean absolute error over all rows is averaged over several ``K`` (default 4 … 8), so that
the estimate does not hang on where one set of block edges falls. With ``chain`` (forward
chaining) only the latest blocks are predicted, each by the fit on the rows before it: the error
of a model on hours later than any it was fitted on. With explicit ``blocks`` (one per run) each
run is predicted by the fit on the others. Blocks are hours long, so the
held-out rows are not near-copies of neighbouring fitting rows, as they would be with a shuffled
split of a slow signal.

Every candidate regressor is a linear combination ``w`` of *base columns* (temperature rises,
lagged rises, lagged inputs, a column of ones): a sensor is a unit vector, a difference
``theta_a - theta_b`` the vector ``e_a - e_b``. Per block the Gram matrices of the base columns are
formed once; any model's are ``W^T G W``, so a cross-validated error costs a few small solves.

* :func:`forward`: greedy forward selection. Each step adds the candidate with the lowest held-out
  error, within the budget of sensors and input terms, until the budget is spent (a step may
  raise the error: a greedy path can need a detour); :func:`choose` then takes the smallest model
  on the path whose error is within ``min_gain`` (relative) of the path's lowest: fewer
  parameters unless more predict measurably better.
* :func:`exhaustive`: every model of a fixed shape (the paper's ``K_i (theta_a - theta_b) -
  K_C theta_c``: all pairs a, b and third sensors c).

Sensor noise (``penalty``): each base column ``j`` may carry independent noise of variance
``d_j`` (a thermocouple's: its resolution squared). The coefficients then minimise the expected
squared error on noisy readings, ``|y - Z W c|^2 + n c^T W^T diag(d) W c`` (:func:`noisy_least_squares`,
ridge regression scaled by the noise variance, the intercept unpenalised), in every fold as in the
final fit: a coefficient is only as large as the noise lets it be identified.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np


class CrossValidation:
    """Held-out error of least squares on combinations of the base columns ``Z`` (n x p): blocked
    cross-validation (every block predicted by the fit on all others), explicit blocks (one per
    run: leave one run out), or forward chaining (each of the latest blocks predicted by the fit
    on the rows before it only, as a control will use the model)."""

    def __init__(self, Z: np.ndarray, y: np.ndarray, folds=(4, 5, 6, 7, 8), blocks=None, penalty=None,
                 chain: bool = False, noisy: bool = False):
        """``blocks``: explicit ``(start, stop)`` row ranges that partition the rows once (e.g. one
        per separate run, leave-one-run-out) instead of the equal blocks of ``folds``. ``penalty``:
        the noise variance of each base column (module docstring); None = noise-free. ``chain``:
        forward chaining: for each ``K`` in ``folds`` the rows are cut into ``K`` equal blocks and
        each of the last ``ceil(K / 2)`` blocks is predicted by the fit on the rows before it.
        ``noisy``: the held-out error is the expected one on readings carrying the ``penalty``
        noise (:func:`noisy_mae`), so that selection weighs what the noise adds to a prediction."""
        self.Z, self.y, n = Z, y, len(y)
        self.D = np.zeros(Z.shape[1]) if penalty is None else np.asarray(penalty, float)
        if blocks is not None:
            self.blocks, self.partitions = [(int(lo), int(hi)) for lo, hi in blocks], 1
            if sorted(self.blocks)[0][0] != 0 or sum(hi - lo for lo, hi in self.blocks) != n or len(self.blocks) < 2:
                raise ValueError("blocks must partition the rows into at least two ranges")
            fits = [None] * len(self.blocks)
        else:
            if n < 2 * max(folds):
                raise ValueError(f"{n} samples are too few for {max(folds)} blocks")
            self.blocks, fits = [], []
            for k in folds:
                edges = np.linspace(0, n, k + 1).astype(int)
                for i, (lo, hi) in enumerate(itertools.pairwise(edges)):
                    if not chain or i >= k - (k + 1) // 2:
                        self.blocks.append((int(lo), int(hi)))
                        fits.append(int(lo) if chain else None)
            self.partitions = len(folds)
        self.G = Z.T @ Z
        self.r = Z.T @ y
        Gb = [Z[lo:hi].T @ Z[lo:hi] for lo, hi in self.blocks]
        rb = [Z[lo:hi].T @ y[lo:hi] for lo, hi in self.blocks]
        # each fold's normal equations: all rows but its block, or (chain) the rows before it
        self.Gf = np.array([self.G - g if f is None else Z[:f].T @ Z[:f] for g, f in zip(Gb, fits)])
        self.rf = np.array([self.r - b if f is None else Z[:f].T @ y[:f] for b, f in zip(rb, fits)])
        self._Zf = np.asfortranarray(Z)  # columns gathered fast by error_of
        self.n_fit = np.array([n - (hi - lo) if f is None else f for (lo, hi), f in zip(self.blocks, fits)], float)
        self.n_test = sum(hi - lo for lo, hi in self.blocks)
        self.noisy = bool(noisy) and bool(np.any(self.D))

    def _mae(self, r: np.ndarray, c: np.ndarray, W: np.ndarray) -> float:
        """Sum of the absolute held-out residuals ``r``; expected on noisy readings with ``noisy``."""
        if not self.noisy:
            return float(np.abs(r).sum())
        return float(noisy_mae(r, float(np.sqrt((W @ c) ** 2 @ self.D))).sum())

    def coefficients(self, W: np.ndarray) -> np.ndarray | None:
        """Per fold the coefficients of the regressors ``Z @ W`` (folds x m); None if singular."""
        W = np.asarray(W)
        P = W.T @ (self.D[:, None] * W)
        A = np.einsum("pi,fpq,qj->fij", W, self.Gf, W) + self.n_fit[:, None, None] * P[None]
        try:
            return np.linalg.solve(A, (self.rf @ W)[..., None])[..., 0]
        except np.linalg.LinAlgError:
            return None

    def residuals(self, W: np.ndarray) -> list[np.ndarray]:
        """Per fold the held-out residuals (predicted - measured, unit of y) of the model ``Z @ W``,
        in the order of :attr:`blocks`; empty if singular."""
        C = self.coefficients(W)
        if C is None:
            return []
        return [self.Z[lo:hi] @ (W @ c) - self.y[lo:hi] for (lo, hi), c in zip(self.blocks, C)]

    def error(self, W: np.ndarray) -> float:
        """Held-out mean absolute error (unit of y) of the model with regressors ``Z @ W``; inf if singular."""
        W = np.asarray(W)
        if W.ndim == 2 and W.size and np.all((W == 0) | (W == 1)) and np.all(W.sum(axis=0) == 1):
            return self.error_of(np.argmax(W, axis=0))  # the columns are base columns
        C = self.coefficients(W)
        if C is None:
            return np.inf
        r = [self.Z[lo:hi] @ (W @ c) - self.y[lo:hi] for (lo, hi), c in zip(self.blocks, C)]
        return sum(self._mae(x, c, W) for x, c in zip(r, C)) / self.n_test

    def error_of(self, columns) -> float:
        """:meth:`error` of the model whose regressors are the base columns ``columns`` (indices):
        the fast path for selections among many base columns, every fold's normal equations
        indexed out of the Gram matrices and solved at once."""
        cols = list(columns)
        P = self.n_fit[:, None, None] * np.diag(self.D[cols])[None]
        try:
            C = np.linalg.solve(self.Gf[:, cols][:, :, cols] + P, self.rf[:, cols][..., None])[..., 0]
        except np.linalg.LinAlgError:
            return np.inf
        Zs = self._Zf[:, cols]
        if self.noisy:
            W = np.eye(self.Z.shape[1])[:, cols]
            total = sum(self._mae(Zs[lo:hi] @ c - self.y[lo:hi], c, W) for (lo, hi), c in zip(self.blocks, C))
            return total / self.n_test
        total = sum(np.abs(Zs[lo:hi] @ c - self.y[lo:hi]).sum() for (lo, hi), c in zip(self.blocks, C))
        return float(total) / self.n_test


@dataclass(frozen=True, eq=False)
class Candidate:
    """A regressor that selection may add."""

    index: int
    """Its position in the caller's list of terms."""
    w: np.ndarray
    """Combination of the base columns."""
    sensors: frozenset
    """The temperature columns it reads (what the sensor budget counts)."""
    is_input: bool
    """True for an operating-input term (what the input budget counts)."""


@dataclass(frozen=True)
class Step:
    """One model on the selection path."""

    chosen: tuple[int, ...]
    """Candidate indices, in the order added."""
    cv_mae: float
    """Held-out mean absolute error, unit of the target."""
    sensors: int
    """Distinct temperature columns read."""


def forward(cv: CrossValidation, candidates: list[Candidate], fixed: np.ndarray, max_sensors: int,
            max_inputs: int) -> list[Step]:
    """Greedy forward selection (module docstring). ``fixed`` (p x m, m may be 0) are the columns
    always in the model (the intercept). Returns the path, the first step being ``fixed`` alone."""
    chosen: list[Candidate] = []
    path = [Step((), cv.error(fixed) if fixed.shape[1] else np.inf, 0)]
    while True:
        used = frozenset().union(*(c.sensors for c in chosen))
        inputs = sum(c.is_input for c in chosen)
        pool = [c for c in candidates if c not in chosen and len(used | c.sensors) <= max_sensors
                and (not c.is_input or inputs < max_inputs)]
        scored = [(cv.error(np.column_stack([fixed] + [d.w for d in chosen] + [c.w])), k) for k, c in enumerate(pool)]
        scored = [(e, k) for e, k in scored if np.isfinite(e)]  # a term that makes the model singular adds nothing
        if not scored:
            return path
        err, k = min(scored)
        chosen.append(pool[k])
        path.append(Step(tuple(c.index for c in chosen), err, len(used | pool[k].sensors)))


def choose(path: list[Step], min_gain: float) -> Step:
    """The first step whose held-out error is within ``min_gain`` (relative) of the path's lowest."""
    best = min(s.cv_mae for s in path)
    return next(s for s in path if s.cv_mae <= best * (1.0 + min_gain))


def exhaustive(cv: CrossValidation, models) -> list[tuple[float, tuple]]:
    """Held-out error of every ``(key, W)`` in ``models``, best first: ``[(cv_mae, key), ...]``."""
    return sorted((cv.error(W), key) for key, W in models)


def noisy_least_squares(X: np.ndarray, y: np.ndarray, variance=None) -> np.ndarray:
    """Coefficients minimising ``|y - X c|^2 + n sum_j variance_j c_j^2`` (module docstring;
    ``variance`` per column of ``X``, 0 for the intercept; None or all 0: plain least squares)."""
    if variance is None or not np.any(variance):
        return np.linalg.lstsq(X, y, rcond=None)[0]
    rows = np.diag(np.sqrt(len(y) * np.asarray(variance, float)))
    return np.linalg.lstsq(np.vstack([X, rows]), np.r_[y, np.zeros(X.shape[1])], rcond=None)[0]


def noisy_mae(r: np.ndarray, sd: float) -> np.ndarray:
    """Expected ``|r + e|`` for ``e`` normal with standard deviation ``sd`` (the folded normal's mean):
    ``sd sqrt(2/pi) exp(-r^2 / 2 sd^2) + r erf(r / (sd sqrt 2))``; ``|r|`` for ``sd = 0``."""
    from scipy.special import erf

    if sd <= 0:
        return np.abs(r)
    return sd * np.sqrt(2 / np.pi) * np.exp(-r**2 / (2 * sd**2)) + r * erf(r / (sd * np.sqrt(2)))


def informative(values: np.ndarray, min_span: float) -> bool:
    """True if ``values`` span at least ``min_span`` (a signal below that carries no information)."""
    return bool(np.ptp(values) >= min_span)
