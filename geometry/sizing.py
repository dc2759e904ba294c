"""How big a frame mesh will be, estimated before gmsh runs, so that a mesh that cannot fit
in memory is refused at once instead of exhausting the machine."""
from __future__ import annotations

import math
import os

from gatetherm import InputError
from gatetherm.geometry.frame import Box, FrameParams, MeshParams, part_boxes, tank_box

REFERENCE_NODES = 52_812
"""Nodes of the default 3-D frame mesh, at which the constants below were measured."""
NODES_PER_ELEMENT = {2: 0.52, 3: 0.21}
"""Nodes per *estimated* element (:func:`element_estimate`) of the frame's meshes: 2-D 7 509
nodes for 14 400 estimated triangles; 3-D 52 812 to 332 616 nodes for 2.5 to 1.6 × 10⁵
estimated tetrahedra per 10⁵ nodes (the estimate is high by 1.5-2.1)."""
NONZEROS_PER_NODE = {2: 7.0, 3: 13.6}
"""Entries per row of a scalar P1 matrix (the node graph plus the diagonal); the elastic
matrix has ``block²`` times as many per node."""
FACTOR = {2: (7_509, 1.66e5, 1.19, 6.1e6, 1.58), 3: (REFERENCE_NODES, 8.3e6, 1.46, 3.1e9, 2.05)}
"""Sparse Cholesky factors of P1 matrices in a METIS order, by dimension: (reference nodes,
factor entries there per block², their growth exponent, flops per block³, their exponent),
``block`` the DOFs per node. Measured with PARDISO on the frame's heat (1 DOF per node) and
elastic matrices: 3-D at 1, 2 and 4 × the default nodes, 8.45, 20.2 and 49.2 million entries
for heat, 73.2, 177 and 429 million for elasticity, 3.2 and 82 GFlop at the default; 2-D at 1
and 8 × the default section (7 509 and 53 592 nodes), 0.167 and 1.74 million for heat."""
BYTES_PER_ENTRY = (11.5, 300.0)
"""PARDISO's memory per factor entry and per unknown, numeric and symbolic (0.81 GB for 73
million entries and 155 664 unknowns; 5.9 MB for 0.17 million and 7 509)."""
AMG_BYTES_PER_NONZERO = 36.0
"""AMG-CG's memory per matrix nonzero: the matrix (12) and the hierarchy (21-23 measured, heat
and elasticity)."""
BASE_BYTES_PER_NODE = {2: 6_000.0, 3: 5_000.0}
"""What a P1 condition holds besides its solvers, per node: mesh, bases, matrices, load and
weight vectors, kept states and the libraries' own (measured ``simulate --dim 3``: 0.4 GB at the
reference)."""
HEAT_FACTORS = 2
"""Heat step factors held at once on the direct path (the long steps of each pump state; the
short steps after a switch are solved iteratively, see :mod:`gatetherm.solvers.heat`)."""
FALLBACK_MEMORY = 8e9
"""Memory assumed where the operating system does not report it, bytes."""


def element_estimate(p: FrameParams, m: MeshParams, dim: int) -> float:
    """Elements of the mesh of ``p`` at ``m``'s size: the frame's area (volume) over that of
    an equilateral triangle (regular tetrahedron) of the element size. Against gmsh's counts
    from 3k to 200k elements: up to 25 % low in 2-D (the refinement near the tank and the
    joints), 1.5 to 2.1 times high in 3-D."""
    def measure(b: Box) -> float:
        return math.prod(b[2 * i + 1] - b[2 * i] for i in range(dim))

    total = sum(map(measure, part_boxes(p, dim).values())) - measure(tank_box(p, dim))
    s = m.size if dim == 2 else m.size_3d
    return total / (math.sqrt(3) / 4 * s ** 2 if dim == 2 else s ** 3 / (6 * math.sqrt(2)))


def memory_bytes() -> float:
    """Physical memory of this machine, bytes."""
    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, ValueError, OSError):
        return FALLBACK_MEMORY


def factor_entries(nodes: float, dim: int, block: int = 1) -> float:
    """Predicted entries of the Cholesky factor of a P1 matrix on ``nodes`` nodes with
    ``block`` DOFs per node."""
    ref, c, p, _, _ = FACTOR[dim]
    return c * block ** 2 * (nodes / ref) ** p


def factor_flops(nodes: float, dim: int, block: int = 1) -> float:
    """Predicted flops of that factorisation."""
    ref, _, _, c, p = FACTOR[dim]
    return c * block ** 3 * (nodes / ref) ** p


def factor_bytes(nodes: float, dim: int, block: int = 1) -> float:
    """Predicted memory of that factor, bytes."""
    return BYTES_PER_ENTRY[0] * factor_entries(nodes, dim, block) + BYTES_PER_ENTRY[1] * block * nodes


def amg_bytes(n: int, nnz: float) -> float:
    """Predicted memory of AMG-CG on a matrix of ``n`` unknowns and ``nnz`` nonzeros, bytes:
    the matrix, the hierarchy and the kept solutions of the Galerkin start."""
    return AMG_BYTES_PER_NONZERO * nnz + 2 * 6 * 8 * n


def path_memory(nodes: float, dim: int) -> dict[str, float]:
    """Predicted peak memory of a P1 condition on ``nodes`` nodes, bytes, by solver path: the
    larger of the heat factors and the elastic factor ("direct"), or AMG-CG for both
    ("iterative"), over what the condition holds besides (:data:`BASE_BYTES_PER_NODE`)."""
    base = BASE_BYTES_PER_NODE[dim] * nodes
    nnz1 = NONZEROS_PER_NODE[dim] * nodes
    direct = max(HEAT_FACTORS * factor_bytes(nodes, dim, 1) + amg_bytes(nodes, nnz1), factor_bytes(nodes, dim, dim))
    iterative = amg_bytes(nodes, nnz1) + amg_bytes(dim * nodes, dim ** 2 * nnz1)
    return {"direct": base + direct, "iterative": base + iterative}


def check_mesh_size(p: FrameParams, m: MeshParams, dim: int) -> dict[str, float]:
    """Raise InputError naming the element size if the mesh would need more memory than the
    machine has on both solver paths; else the predicted peak of each path (bytes)."""
    n = element_estimate(p, m, dim)
    need, have = path_memory(n * NODES_PER_ELEMENT[dim], dim), memory_bytes()
    if min(need.values()) > have:
        key, s = ("mesh.size", m.size) if dim == 2 else ("mesh.size_3d", m.size_3d)
        low = min(need.values())
        raise InputError(key, f"{s:g} m gives about {n:.2g} {'triangles' if dim == 2 else 'tetrahedra'} needing "
                         f"~{low / 1e9:.3g} GB, more than the {have / 1e9:.3g} GB of memory of this machine",
                         f"raise it to at least {s * (low / have) ** (1 / dim):.2g} m")
    return need
