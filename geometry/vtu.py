"""VTU files (VTK's XML unstructured grid) written directly: the arrays of
:func:`gatetherm.geometry.mesh.mesh_arrays` and the point data, raw in one appended block.

meshio's writer encodes every array as base64 text inside the XML: about 0.1 s for one field
file of the 3-D frame (40 MB), seven per run; raw bytes take a fifth of that in 28 MB
(``benchmarks/assembly_parts.py``), and ParaView, VTK and meshio read them alike
(``tests/test_vtu.py``).
"""
from __future__ import annotations

import os
import sys
from xml.sax.saxutils import quoteattr

import numpy as np

from gatetherm.geometry.mesh import FrameMesh, mesh_arrays

VTK_TYPES = {"vertex": 1, "line": 3, "triangle": 5, "tetra": 10}
"""VTK's cell type numbers of the cell blocks."""
_TYPES = {np.dtype(t): n for t, n in [("float64", "Float64"), ("float32", "Float32"), ("int64", "Int64"),
                                      ("int32", "Int32"), ("int8", "Int8"), ("uint8", "UInt8")]}


def write_vtu(path: str | os.PathLike, m: FrameMesh, point_data: dict[str, np.ndarray]) -> None:
    """Write ``m`` with the nodal arrays ``point_data`` (N,) or (N, c) to ``path`` (over any
    file there: write to a temporary one, :func:`gatetherm.atomic_path`)."""
    pts, blocks, cell_data, _ = mesh_arrays(m)
    order = "LittleEndian" if sys.byteorder == "little" else "BigEndian"
    conn = np.concatenate([c.ravel() for _, c in blocks])
    offsets = np.cumsum(np.concatenate([np.full(len(c), c.shape[1], dtype=np.int64) for _, c in blocks]))
    types = np.concatenate([np.full(len(c), VTK_TYPES[t], dtype=np.uint8) for t, c in blocks])
    arrays, xml, end = [], [], [0]  # end: the appended block's length so far

    def add(name: str, a: np.ndarray) -> str:
        a = np.ascontiguousarray(a)
        if a.dtype not in _TYPES:
            a = a.astype(np.float64)
        at, end[0] = end[0], end[0] + 8 + a.nbytes
        arrays.append(a)
        comps = f' NumberOfComponents="{a.shape[1]}"' if a.ndim == 2 else ""
        return (f'<DataArray type="{_TYPES[a.dtype]}" Name={quoteattr(name)}{comps} format="appended" '
                f'offset="{at}"/>')

    xml.append(f'<Points>{add("Points", pts)}</Points>')
    xml.append("<Cells>" + "".join(add(n, a) for n, a in (("connectivity", conn), ("offsets", offsets),
                                                             ("types", types))) + "</Cells>")
    xml.append("<PointData>" + "".join(add(n, np.asarray(a)) for n, a in point_data.items()) + "</PointData>")
    xml.append("<CellData>" + "".join(add(n, np.concatenate(a)) for n, a in cell_data.items()) + "</CellData>")
    head = (f'<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="1.0" byte_order="{order}" '
            f'header_type="UInt64">\n<UnstructuredGrid>\n<Piece NumberOfPoints="{len(pts)}" '
            f'NumberOfCells="{len(types)}">\n' + "\n".join(xml)
            + '\n</Piece>\n</UnstructuredGrid>\n<AppendedData encoding="raw">\n_')
    with open(path, "wb") as f:
        f.write(head.encode())
        for a in arrays:
            f.write(np.uint64(a.nbytes).tobytes())
            f.write(memoryview(a).cast("B"))
        f.write(b"\n</AppendedData>\n</VTKFile>\n")
