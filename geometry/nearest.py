"""The point of a simplex mesh's body nearest to a given point: for coordinates that miss the
elements (a probe on the surface, off by round-off), with the tolerance of a point group
(:data:`gatetherm.geometry.mesh.SNAP_TOLERANCE`)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gatetherm.geometry.mesh import SNAP_TOLERANCE

INWARD = 1e-8
"""The point read is moved from the surface towards the centre of its element by this fraction
of the way, so that it lies in the element despite round-off (1e-8 of an element's size)."""


@dataclass(frozen=True)
class Nearest:
    """The point of the body nearest to a point outside it."""

    point: np.ndarray
    """The nearest point on the body's boundary, m."""
    inside: np.ndarray
    """That point moved into its element by :data:`INWARD` of the way to the element's centre, m."""
    distance: float
    """From the given point to :attr:`point`, m."""
    tolerance: float
    """The largest distance read at :attr:`inside`: :data:`SNAP_TOLERANCE` of the body's size (its
    bounding-box diagonal) or the longest edge of the element there, whichever is larger, m."""


def _facets(cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The boundary facets (in one element only) and the element of each."""
    n = cells.shape[1]
    faces = np.concatenate([np.delete(cells, i, axis=1) for i in range(n)])
    owner = np.tile(np.arange(len(cells)), n)
    _, first, count = np.unique(np.sort(faces, axis=1), axis=0, return_index=True, return_counts=True)
    once = first[count == 1]
    return faces[once], owner[once]


def _on_segments(a: np.ndarray, b: np.ndarray, x: np.ndarray) -> np.ndarray:
    d = b - a
    s = np.clip(((x - a) * d).sum(axis=1) / np.maximum((d * d).sum(axis=1), 1e-300), 0.0, 1.0)
    return a + s[:, None] * d


def _on_triangles(a: np.ndarray, b: np.ndarray, c: np.ndarray, x: np.ndarray) -> np.ndarray:
    e1, e2 = b - a, c - a
    G = np.stack([e1, e2], axis=2)  # (F, 3, 2)
    lam = np.linalg.solve(np.einsum("fki,fkj->fij", G, G) + 1e-300 * np.eye(2),
                          np.einsum("fki,fk->fi", G, x - a)[..., None])[..., 0]
    inner = (lam >= 0).all(axis=1) & (lam.sum(axis=1) <= 1)
    cands = [a + lam[:, :1] * e1 + lam[:, 1:] * e2, _on_segments(a, b, x), _on_segments(b, c, x),
             _on_segments(a, c, x)]
    dist = np.stack([np.where(inner, ((cands[0] - x) ** 2).sum(axis=1), np.inf)]
                    + [((y - x) ** 2).sum(axis=1) for y in cands[1:]])
    pick = np.argmin(dist, axis=0)
    return np.stack(cands)[pick, np.arange(len(a))]


def nearest_on_body(points: np.ndarray, cells: np.ndarray, x) -> Nearest:
    """The point of the body of ``points`` (N, dim), ``cells`` (E, dim+1) nearest to ``x``,
    on its boundary facets (for ``x`` outside the body), the distance and the tolerance
    within which ``x`` may be read there."""
    x = np.asarray(x, dtype=float)
    faces, owner = _facets(cells)
    P = points[faces]  # (F, dim, dim)
    near = _on_segments(P[:, 0], P[:, 1], x) if points.shape[1] == 2 else _on_triangles(P[:, 0], P[:, 1], P[:, 2], x)
    d2 = ((near - x) ** 2).sum(axis=1)
    k = int(np.argmin(d2))
    cell = points[cells[owner[k]]]
    edge = max(float(np.linalg.norm(cell[i] - cell[j])) for i in range(len(cell)) for j in range(i))
    used = points[np.unique(cells)]
    tol = max(SNAP_TOLERANCE * float(np.linalg.norm(np.ptp(used, axis=0))), edge)
    y = near[k]
    return Nearest(y, y + INWARD * (cell.mean(axis=0) - y), float(np.sqrt(d2[k])), tol)
