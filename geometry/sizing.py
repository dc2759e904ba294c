"""How big a mesh will be, estimated before gmsh meshes, so that a mesh that cannot fit in
memory is refused at once instead of exhausting the machine: the frame's from its
parameters, a user's geometry from the gmsh model (in gmsh's process)."""
from __future__ import annotations

import math
import os

import numpy as np

from gatetherm import InputError
from gatetherm.geometry.frame import Box, FrameParams, MeshParams, part_boxes, tank_box

BYTES_PER_ELEMENT = {2: 10_000, 3: 5_000}
"""Peak memory of a P1 condition per *estimated* element (:func:`element_estimate`), bytes, by
dimension: measured 6.8 kB per triangle (2-D, 14k to 207k elements), rounded up; in 3-D
3.3-3.4 kB per estimated tetrahedron from 53k to 177k nodes (``benchmarks/scaling.py``: 1.47 GB
at 52 812 nodes, 6.18 GB at 177 283), with room for the factor's faster growth on finer meshes."""
FALLBACK_MEMORY = 8e9
"""Memory assumed where the operating system does not report it, bytes."""
CELL = {2: math.sqrt(3) / 4, 3: 1 / (6 * math.sqrt(2))}
"""Area (volume) of an equilateral triangle (regular tetrahedron) of unit edge."""


def element_estimate(p: FrameParams, m: MeshParams, dim: int) -> float:
    """Elements of the mesh of ``p`` at ``m``'s size: the frame's area (volume) over that of
    an equilateral triangle (regular tetrahedron) of the element size. Against gmsh's counts
    from 3k to 200k elements: up to 25 % low in 2-D (the refinement near the tank and the
    joints), 1.5 to 2.1 times high in 3-D."""
    def measure(b: Box) -> float:
        return math.prod(b[2 * i + 1] - b[2 * i] for i in range(dim))

    total = sum(map(measure, part_boxes(p, dim).values())) - measure(tank_box(p, dim))
    s = m.size if dim == 2 else m.size_3d
    return total / (CELL[dim] * s ** dim)


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
    (volume) per element of :func:`element_estimate`. Transfinite counts are not seen.
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
        base += _measure(gmsh, dim, t) / (CELL[dim] * h ** dim)
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
                n += _measure(gmsh, d, e) / (CELL[dim] * smin ** dim)
                near += [(b, abs(t)) for b, t in gmsh.model.getBoundary([(d, e)], oriented=False)]
                continue
            shell = {1: 2.0 * np.ones_like(r), 2: 2 * np.pi * r, 3: 4 * np.pi * r ** 2}[dim - d]
            n += float(np.sum(_measure(gmsh, d, e) * shell / (CELL[dim] * h ** dim)) * (r[1] - r[0]))
        out.append((min(n, total / (CELL[dim] * smin ** dim)), int(tag), float(f.getNumber(tag, "SizeMin"))))
    return out


def memory_bytes() -> float:
    """Physical memory of this machine, bytes."""
    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, ValueError, OSError):
        return FALLBACK_MEMORY


def check_estimate(elements: float, dim: int, key: str, size: float) -> None:
    """Raise InputError naming ``key`` (an element size of ``size`` m, or a factor on the
    sizes) if a mesh of about ``elements`` elements of dimension ``dim`` needs more memory
    than the machine has; the fix gives the smallest admissible value (elements ∝ size^-dim)."""
    need, have = elements * BYTES_PER_ELEMENT[dim], memory_bytes()
    unit = "" if "factor" in key else " m"
    if need > have:
        raise InputError(key, f"{size:g}{unit} gives about {elements:.2g} "
                         f"{'triangles' if dim == 2 else 'tetrahedra'} needing ~{need / 1e9:.3g} GB, more than the "
                         f"{have / 1e9:.3g} GB of memory of this machine",
                         f"raise it to at least {size * (need / have) ** (1 / dim):.2g}{unit}")


def check_mesh_size(p: FrameParams, m: MeshParams, dim: int) -> None:
    """Raise InputError naming the element size if the mesh would need more memory than the machine has."""
    key, s = ("mesh.size", m.size) if dim == 2 else ("mesh.size_3d", m.size_3d)
    check_estimate(element_estimate(p, m, dim), dim, key, s)
