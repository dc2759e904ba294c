"""Screening thousands of candidates in the reduced space: a shortlist for the refinement.

The candidates' temperature snapshots over the training loads are ``Theta = X R^T`` (samples x
candidates: the reduced states ``X`` times the candidates' basis rows ``R``, :mod:`.reduced`), of
rank at most the number of states, so their SVD costs one small QR: with the centred states
``X_c = Q S0`` and ``S0 R^T = P S W^T``, ``Theta_c = (Q P) S W^T``. The temporal modes ``U = Q P``
are weighted by what the targets (the relative displacements, centred, um) have along them and
by how far they stand above the sensor noise: ``w_k = |U_k^T Y_c| s_k^2 / (s_k^2 + N sigma^2)``
(N samples, sigma the noise, K). Column-pivoted QR of ``diag(w) W^T`` (Q-DEIM) orders the
candidates by how well they resolve the output-weighted modes; the first ``rank`` pivots and each
pivot's ``neighbours`` nearest candidates are the shortlist.
"""
from __future__ import annotations

import zlib

import numpy as np
import scipy.linalg as sla
from scipy.spatial import cKDTree


def load_key(role: str, index: int) -> str:
    """The noise key of the ``index``-th (from 0) load of ``role`` (``training``, ``held-out``): its
    place, not its label (a schedule file's label holds its path, which differs from copy to copy)."""
    return f"{role} {index + 1}"


def noise(seed: int, key: str, load: str, n: int, sigma_K: float) -> np.ndarray:
    """The sensor noise of channel ``key`` (a node or a probe) in load ``load`` (:func:`load_key`):
    ``n`` normal samples of standard deviation ``sigma_K`` (K), the same for the same seed, channel
    and load."""
    if sigma_K == 0:
        return np.zeros(n)
    rng = np.random.default_rng([int(seed), zlib.crc32(key.encode()), zlib.crc32(load.encode())])
    return rng.normal(0.0, sigma_K, n)


def mode_weights(X: np.ndarray, Y: np.ndarray, rows: np.ndarray, sigma_K: float):
    """(weights w, singular values s, candidate modes W^T) of the snapshots ``X rows^T`` (module docstring)."""
    Xc, Yc = X - X.mean(axis=0), Y - Y.mean(axis=0)
    Q, S0 = np.linalg.qr(Xc)
    P, s, Wt = np.linalg.svd(S0 @ rows.T, full_matrices=False)
    along = np.linalg.norm((Q @ P).T @ Yc, axis=1)
    return along * s**2 / (s**2 + len(X) * sigma_K**2 + 1e-300), s, Wt


def shortlist(X: np.ndarray, Y: np.ndarray, rows: np.ndarray, xyz: np.ndarray, sigma_K: float,
              neighbours: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """(shortlist, pivots): indices into the candidates (``rows``, ``xyz``) of the output-weighted
    Q-DEIM pivots and their nearest neighbours, sorted; and the pivots in pivot order."""
    w, _, Wt = mode_weights(X, Y, rows, sigma_K)
    rank = int(np.sum(w > 1e-9 * w.max())) if w.max() > 0 else 1
    _, _, piv = sla.qr(w[:rank, None] * Wt[:rank], mode="economic", pivoting=True)
    pivots = piv[:rank]
    near = cKDTree(xyz).query(xyz[pivots], k=min(neighbours + 1, len(xyz)))[1]
    return np.unique(np.concatenate([pivots, np.ravel(near)])), pivots
