"""How big a mesh will be, estimated before gmsh meshes, so that a mesh that cannot fit in
memory is refused at once instead of exhausting the machine: a user's geometry from the gmsh
model (in gmsh's process); the paper frame's from its parameters
(:func:`gatetherm.frame.build.check_mesh_size`, with these budgets)."""
from __future__ import annotations

import math
import os

import numpy as np

from gatetherm import InputError

REFERENCE_NODES = 52_812
"""Nodes of the default 3-D frame mesh, at which the constants below were measured."""
NODES_PER_ELEMENT = {2: 0.6, 3: 0.12}
"""Nodes per *estimated* element (:func:`gatetherm.frame.build.element_estimate`, :func:`model_estimate`): the frame's
2-D meshes 0.60-0.53 (7 509 to 53 592 nodes), 3-D 0.116-0.086 (52 812 to 779 457 nodes); the
larger, so that memory is not underestimated."""
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
BASE_BYTES = 0.15e9
"""The libraries and the interpreter, bytes (a 2-D condition of 7 509 nodes peaks at 0.16 GB)."""
BASE_BYTES_PER_NODE = {2: 6_500.0, 3: 8_000.0}
"""What a P1 condition holds besides its solvers' memory, per node: mesh, bases, matrices, load
and weight vectors, kept states and the transients of assembly and of the AMG set-up; fitted to
``benchmarks/scaling.py``'s peaks (3-D iterative: 2.58, 4.63 and 13.2 GB at 0.18, 0.33 and 0.96
million nodes; 2-D: 0.46 GB at 53 592 nodes)."""
HEAT_FACTORS = 4
"""Heat step matrices of a condition (a paper condition's: 60-s and 15-s steps, pump on and
off), each with a factor of its own on the direct path."""
FALLBACK_MEMORY = 8e9
"""Memory assumed where the operating system does not report it, bytes."""
CELL = {2: math.sqrt(3) / 4, 3: 1 / (6 * math.sqrt(2))}
"""Area (volume) of an equilateral triangle (regular tetrahedron) of unit edge."""
MAX_ELEMENTS = 50e6
"""Budget of elements a mesh may have (estimated before gmsh meshes, counted after): 50 million,
about 6 times the 3-D frame's at 20 times its default nodes (``benchmarks/scaling.py``)."""


def count_elements(measure: float, h: float, dim: int) -> float:
    """Elements of size ``h`` in ``measure`` (area, volume); inf where ``h ** dim`` underflows."""
    cell = CELL[dim] * h ** dim
    return measure / cell if cell > 0 else math.inf


def _measure(gmsh, d: int, t: int) -> float:
    """Length, area or volume of an entity (its bounding box's for the built-in kernel); 1 for a point."""
    if d == 0:
        return 1.0
    try:
        return float(gmsh.model.occ.getMass(d, t))
    except Exception:  # noqa: BLE001 - not an OpenCASCADE entity
        box = np.reshape(gmsh.model.getBoundingBox(d, t), (2, 3))
        return float(np.prod(np.sort(box[1] - box[0])[::-1][:d]))


def model_estimate(gmsh, dim: int) -> list[tuple[float, int | None, float]]:
    """Elements of the current gmsh model, by contribution, as (elements, field, size):
    the solids at their element size (field None: ``Mesh.MeshSizeMax``, the geometric mean
    of their points' sizes, the size factor, the size fields' far size) and each Threshold
    field (its tag: the elements within its distance of the entities it measures from, the
    size growing linearly from SizeMin to SizeMax; a solid in it all at SizeMin). The area
    (volume) per element of :func:`gatetherm.frame.build.element_estimate`. Transfinite counts are not seen.
    Against gmsh: 1.26 (T4), 2.03 (T1), 1.54 (the C-frame example) times its count."""
    opt, f = gmsh.option.getNumber, gmsh.model.mesh.field
    box = np.reshape(gmsh.model.getBoundingBox(-1, -1), (2, 3))
    lo, hi, factor = opt("Mesh.MeshSizeMin"), opt("Mesh.MeshSizeMax"), opt("Mesh.MeshSizeFactor")
    clip = lambda h: min(max(h * factor, lo), hi)  # noqa: E731
    thresholds = [t for t in f.list() if f.getType(t) == "Threshold"]
    far = min((clip(f.getNumber(t, "SizeMax")) for t in thresholds), default=hi)
    solids = [t for _, t in gmsh.model.getEntities(dim)]
    base, h_base = 0.0, math.inf
    for t in solids:
        pts = [p for p in gmsh.model.getBoundary([(dim, t)], recursive=True) if p[0] == 0]
        lc = [s for s in gmsh.model.mesh.getSizes(pts) if s > 0] if pts and opt("Mesh.MeshSizeFromPoints") else []
        h = min(clip(math.exp(np.mean(np.log(lc))) if lc else float(np.linalg.norm(box[1] - box[0]))), far)
        base += count_elements(_measure(gmsh, dim, t), h, dim)
        h_base = min(h_base, h)
    out = [(base, None, h_base)]
    total = sum(_measure(gmsh, dim, t) for t in solids)
    for tag in thresholds:
        src = int(f.getNumber(tag, "InField"))
        smin, smax = clip(f.getNumber(tag, "SizeMin")), clip(f.getNumber(tag, "SizeMax"))
        d0, d1 = f.getNumber(tag, "DistMin"), max(f.getNumber(tag, "DistMax"), f.getNumber(tag, "DistMin"))
        near = [(d, int(e)) for d, key in enumerate(("PointsList", "CurvesList", "SurfacesList"))
                for e in f.getNumbers(src, key)] if src in f.list() and f.getType(src) == "Distance" else []
        r = np.linspace(0.0, d1, 201)[1:]
        h = np.where(r <= d0, smin, smin + (smax - smin) * (r - d0) / max(d1 - d0, 1e-300))
        n = 0.0
        for d, e in near:
            if d == dim:  # inside a solid: all at SizeMin, then the ramp outside its boundary
                n += count_elements(_measure(gmsh, d, e), smin, dim)
                near += [(b, abs(t)) for b, t in gmsh.model.getBoundary([(d, e)], oriented=False)]
                continue
            shell = {1: 2.0 * np.ones_like(r), 2: 2 * np.pi * r, 3: 4 * np.pi * r ** 2}[dim - d]
            with np.errstate(divide="ignore", over="ignore"):  # inf where h ** dim underflows
                n += float(np.sum(_measure(gmsh, d, e) * shell / (CELL[dim] * h ** dim)) * (r[1] - r[0]))
        out.append((min(n, count_elements(total, smin, dim)), int(tag), float(f.getNumber(tag, "SizeMin"))))
    return out


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
    base = BASE_BYTES + BASE_BYTES_PER_NODE[dim] * nodes
    nnz1 = NONZEROS_PER_NODE[dim] * nodes
    direct = max(HEAT_FACTORS * factor_bytes(nodes, dim, 1) + amg_bytes(nodes, nnz1), factor_bytes(nodes, dim, dim))
    iterative = amg_bytes(nodes, nnz1) + amg_bytes(dim * nodes, dim ** 2 * nnz1)
    return {"direct": base + direct, "iterative": base + iterative}


def check_estimate(elements: float, dim: int, key: str, size: float) -> dict[str, float]:
    """Raise InputError naming ``key`` (an element size of ``size`` m, or a factor on the
    sizes) if a mesh of about ``elements`` elements of dimension ``dim`` needs more memory
    than the machine has on both solver paths (:func:`path_memory`); the fix gives the
    smallest admissible value (elements ∝ size^-dim). Also refused: more than
    :data:`MAX_ELEMENTS` (a size so small that the count is not even a number included). Else
    the predicted peak of each path."""
    unit = "" if "factor" in key else " m"
    if not math.isfinite(elements):
        check_count(elements, dim, key, size, unit)
    need, have = path_memory(elements * NODES_PER_ELEMENT[dim], dim), memory_bytes()
    low = min(need.values())
    if low > have:
        raise InputError(key, f"{size:g}{unit} gives about {elements:.2g} "
                         f"{'triangles' if dim == 2 else 'tetrahedra'} needing ~{low / 1e9:.3g} GB, more than the "
                         f"{have / 1e9:.3g} GB of memory of this machine",
                         f"raise it to at least {size * (low / have) ** (1 / dim):.2g}{unit}")
    check_count(elements, dim, key, size, unit)
    return need


def check_count(elements: float, dim: int, key: str, size: float, unit: str = " m", counted: bool = False) -> None:
    """InputError naming ``key`` if ``elements`` (estimated, or ``counted``) exceed :data:`MAX_ELEMENTS`."""
    if elements <= MAX_ELEMENTS:
        return
    kind = "triangles" if dim == 2 else "tetrahedra"
    got = f"{elements:.2g} {kind}" if math.isfinite(elements) else f"more {kind} than can be counted"
    fix = (f"raise it to at least {size * (elements / MAX_ELEMENTS) ** (1 / dim):.2g}{unit}"
           if math.isfinite(elements) and size > 0 else "give a size of about a tenth of the smallest part")
    about = "" if counted or not math.isfinite(elements) else "about "
    raise InputError(key, f"{size:g}{unit} gives {about}{got}, more than the budget of "
                     f"{MAX_ELEMENTS:.3g} elements", fix)
