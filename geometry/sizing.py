"""How big a frame mesh will be, estimated before gmsh runs, so that a mesh that cannot fit
in memory is refused at once instead of exhausting the machine."""
from __future__ import annotations

import math
import os

from gatetherm import InputError
from gatetherm.geometry.frame import Box, FrameParams, MeshParams, part_boxes, tank_box

BYTES_PER_ELEMENT = {2: 10_000, 3: 5_000}
"""Peak memory of a P1 condition per *estimated* element (:func:`element_estimate`), bytes, by
dimension: measured 6.8 kB per triangle (2-D, 14k to 207k elements), rounded up; in 3-D
3.3-3.4 kB per estimated tetrahedron from 53k to 177k nodes (``benchmarks/scaling.py``: 1.47 GB
at 52 812 nodes, 6.18 GB at 177 283), with room for the factor's faster growth on finer meshes."""
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


def check_estimate(elements: float, dim: int, key: str, size: float) -> None:
    """Raise InputError naming ``key`` (an element size of ``size`` m, or a factor on the
    sizes) if a mesh of about ``elements`` elements of dimension ``dim`` needs more memory
    than the machine has; the fix gives the smallest admissible value (elements ∝ size^-dim)."""
    need, have = elements * BYTES_PER_ELEMENT[dim], memory_bytes()
    if need > have:
        raise InputError(key, f"{size:g}{' m' if 'factor' not in key else ''} gives about {elements:.2g} "
                         f"{'triangles' if dim == 2 else 'tetrahedra'} needing ~{need / 1e9:.3g} GB, more than the "
                         f"{have / 1e9:.3g} GB of memory of this machine",
                         f"raise it to at least {size * (need / have) ** (1 / dim):.2g}{' m' if 'factor' not in key else ''}")


def check_mesh_size(p: FrameParams, m: MeshParams, dim: int) -> None:
    """Raise InputError naming the element size if the mesh would need more memory than the machine has."""
    key, s = ("mesh.size", m.size) if dim == 2 else ("mesh.size_3d", m.size_3d)
    check_estimate(element_estimate(p, m, dim), dim, key, s)
