"""How the supports hold an elastic body: the displacement DOFs they hold (:func:`support_dofs`,
:func:`fixed_dofs`), the mesh's connected pieces (:func:`parts`) and the rigid-body modes the
supports and springs leave free (:func:`free_modes`), a free part refused as bad input. The
elastic system is :mod:`gatetherm.solvers.elasticity`."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from skfem import CellBasis

from gatetherm import InputError
from gatetherm.solvers.linsolve import rigid_body_modes

MODE_NAMES = {2: ("translation x", "translation y", "rotation about z"),
              3: ("translation x", "translation y", "translation z", "rotation about z",
                  "rotation about x", "rotation about y")}
"""Rigid-body modes in the order of :func:`~gatetherm.solvers.linsolve.rigid_body_modes`."""


def support_dofs(vb: CellBasis, mesh, boundary: str, components, lines=None) -> np.ndarray:
    """The displacement DOFs of ``components`` on a boundary, or (3-D) on a line of
    ``lines`` (name: node pairs). With DOFs at the nodes only (P1), the facets' nodes give
    them directly, interleaved as scikit-fem numbers them (its general path builds the
    mesh's edges: 0.6 s on the 3-D frame)."""
    dim = mesh.dim()
    if lines and boundary in lines:
        pairs = np.sort(lines[boundary], axis=1)
        out = [vb.nodal_dofs[c, np.unique(pairs)] for c in components]
        if vb.edge_dofs.size:
            index = {tuple(e): i for i, e in enumerate(np.sort(mesh.edges, axis=0).T.tolist())}
            edges = [index[tuple(e)] for e in pairs.tolist()]
            out += [vb.edge_dofs[c, edges] for c in components]
        return np.concatenate(out)
    if vb.N == dim * mesh.nvertices:
        return (dim * np.unique(mesh.facets[:, mesh.boundaries[boundary]])[:, None] + list(components)).ravel()
    names = [f"u^{c + 1}" for c in range(dim)]
    return vb.get_dofs(mesh.boundaries[boundary]).all([names[c] for c in components])


def fixed_dofs(vb: CellBasis, mesh, supports, lines=None) -> np.ndarray:
    """Displacement DOFs held (at zero or a prescribed value) by the supports without a
    foundation stiffness."""
    out = [support_dofs(vb, mesh, s.boundary, s.components, lines) for s in supports if s.stiffness is None]
    return np.unique(np.concatenate(out)) if out else np.zeros(0, dtype=np.int64)


def parts(vb: CellBasis) -> list[np.ndarray]:
    """The DOFs of every connected piece of the mesh (elements sharing a DOF)."""
    from scipy.sparse.csgraph import connected_components

    ed = vb.element_dofs
    e = ed.shape[1]
    graph = sp.coo_matrix((np.ones(ed.size), (np.tile(np.arange(e), ed.shape[0]), e + ed.ravel())),
                          shape=(e + vb.N, e + vb.N))
    label = connected_components(graph, directed=False)[1][e:]
    return [np.flatnonzero(label == k) for k in np.unique(label)]


def free_modes(vb: CellBasis, fixed: np.ndarray, springs=(), pieces=None,
               axisymmetric: bool = False) -> list[tuple[int, str]]:
    """Rigid-body modes the supports and the spring matrices (foundations, joints) leave
    free, as (piece, name of :data:`MODE_NAMES`): ``pieces`` are the DOF sets of the
    mesh's connected pieces (None: one). An axisymmetric body has one: translation y."""
    dim = vb.mesh.dim()
    R0 = rigid_body_modes(vb.doflocs, vb.split_indices())
    names = MODE_NAMES[dim]
    if axisymmetric:
        R0, names = R0[:, [1]], names[1:2]
    blocks = []
    for p in pieces or [np.arange(vb.N)]:
        R = np.zeros_like(R0)
        R[p] = R0[p]
        blocks.append(R)
    R = np.hstack(blocks)
    R = R / np.linalg.norm(R, axis=0)
    G = R[fixed].T @ R[fixed]
    for K in springs:
        G = G + _held_by(K, R)
    w, V = np.linalg.eigh(G)
    loose = V[:, w < 1e-10 * max(w.max(), 1.0)]
    m = len(names)
    return [(int(i) // m, names[int(i) % m]) for i in np.argmax(np.abs(loose), axis=0)]


def _held_by(K, R: np.ndarray) -> np.ndarray:
    """The energy ``Rᵀ K R`` of the rigid modes ``R`` in the spring matrix ``K`` (a foundation or
    a joint), in units of the energy its diagonal alone would give them (``Rᵀ diag(K) R``): O(1)
    for a mode the spring holds, round-off for one it carries along (a rigid motion of both sides
    of a joint). Scaled by its own largest entry instead, a joint's round-off became O(1) with
    either sign, and a held assembly was refused at P2 (issue 51)."""
    F = R.T @ (K @ R)
    diag = np.asarray(abs(K.diagonal()) if hasattr(K, "diagonal") else np.abs(np.diag(K)), dtype=float)
    scale = float(((R * R).T @ diag).max())
    if scale <= 0.0:
        return np.zeros_like(F)
    F = (F + F.T) / (2.0 * scale)
    w, V = np.linalg.eigh(F)  # a spring only holds: no round-off of either sign
    return (V * np.clip(w, 0.0, None)) @ V.T


def _refuse_loose(vb: CellBasis, mesh, loose, pieces) -> None:
    """The first free part as an :class:`~gatetherm.InputError` naming its regions."""
    piece = loose[0][0]
    modes = ", ".join(dict.fromkeys(n for p, n in loose if p == piece))
    if pieces is None:
        regions = list(mesh.subdomains)
    else:
        regions = [r for r, els in mesh.subdomains.items() if np.isin(vb.element_dofs[0, els[0]], pieces[piece])]
    raise InputError("supports", f"the part made of region{'s' * (len(regions) > 1)} {', '.join(regions)} is free to "
                     f"move ({modes})", "hold more displacement components (clamped, normal, fixed) or add a "
                     "foundation, or join the part to a held one (a contact stiffness in both directions)")
