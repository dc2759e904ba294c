"""A reader of binary gmsh 2.2 files (what :func:`gatetherm.geometry.mesh.save_mesh` and
``gatetherm mesh`` write) in whole-array reads: meshio's reader walks the elements' tags
one by one in Python (the 3-D frame's 257k elements: 0.012 s against meshio's 0.104 s,
``benchmarks/assembly_parts.py``). Anything
else (ASCII, 4.1, other sections or element types) is left to meshio."""
from __future__ import annotations

import numpy as np

TYPES = {1: ("line", 2), 2: ("triangle", 3), 4: ("tetra", 4), 8: ("line3", 3), 9: ("triangle6", 6),
         11: ("tetra10", 10), 15: ("vertex", 1)}
"""gmsh element types read: meshio's name and the nodes per element."""
SECTIONS = ("PhysicalNames", "Nodes", "Elements")
"""The sections read after ``$MeshFormat``; a file with another is left to meshio."""


class _Buffer:
    """The file's bytes and a read position: lines of text, arrays of binary."""

    def __init__(self, data: bytes):
        self.data, self.pos = data, 0

    def line(self) -> str:
        end = self.data.index(b"\n", self.pos)
        text, self.pos = self.data[self.pos:end].decode("utf-8").strip(), end + 1
        return text

    def end(self, section: str) -> None:
        """Past the end of ``section`` (and the line end after a binary block)."""
        line = self.line()
        if line != "$End" + section and (line or self.line() != "$End" + section):
            raise ValueError(f"${section} does not end where its counts say")

    def array(self, dtype, count: int) -> np.ndarray:
        out = np.frombuffer(self.data, dtype=dtype, count=count, offset=self.pos)
        self.pos += out.nbytes
        return out


def read_binary(data: bytes):
    """The ``meshio.Mesh`` of a binary gmsh 2.2 file's bytes, as meshio's reader makes it
    (consecutive blocks of one element type merged; the corners first, higher-order nodes in
    gmsh's order), or None for a file this reader leaves to meshio. A truncated file raises
    ``ValueError``."""
    import meshio

    buf = _Buffer(data)
    if buf.line() != "$MeshFormat" or buf.line().split() != ["2.2", "1", "8"] or buf.array("<i4", 1)[0] != 1:
        return None
    names, points, tags, blocks = {}, None, None, []
    buf.end("MeshFormat")
    while buf.pos < len(data):
        section = buf.line()[1:]
        if section == "PhysicalNames":
            for _ in range(int(buf.line())):
                dim, tag, name = buf.line().split(maxsplit=2)
                names[name.strip('"')] = np.array([int(tag), int(dim)])
        elif section == "Nodes":
            nodes = buf.array([("tag", "<i4"), ("x", "<f8", (3,))], int(buf.line()))
            points, tags = np.array(nodes["x"]), nodes["tag"]
        elif section == "Elements":
            blocks = _elements(buf, int(buf.line()))
        if section not in SECTIONS or blocks is None:
            return None
        buf.end(section)
    if points is None:
        raise ValueError("no $Nodes section")
    return meshio.Mesh(points, [(kind, _positions(tags, conn)) for kind, conn, _ in blocks],
                       cell_data={"gmsh:physical": [phys for *_, phys in blocks]}, field_data=names)


def _positions(tags: np.ndarray, conn: np.ndarray) -> np.ndarray:
    """The positions in ``tags`` (the nodes' numbers, in file order) of the node numbers ``conn``:
    by a table where the numbers are about as many as the nodes, else by sorted search (a file
    numbering its nodes sparsely); a number of no node raises ``ValueError``."""
    if int(tags.max()) <= 4 * len(tags) + 1000:
        table = np.full(int(tags.max()) + 1, -1, dtype=np.int64)
        table[tags] = np.arange(len(tags))
        at = np.where((conn >= 0) & (conn < len(table)), table[np.clip(conn, 0, len(table) - 1)], -1)
    else:
        order = np.argsort(tags, kind="stable")
        i = np.minimum(np.searchsorted(tags[order], conn), len(tags) - 1)
        at = np.where(tags[order][i] == conn, order[i], -1)
    if (at < 0).any():
        raise ValueError(f"an element has node {int(conn[at < 0][0])}, which $Nodes does not list")
    return at


def _elements(buf: _Buffer, count: int):
    """(meshio type, node tags, physical tags) per run of one element type; None for a type
    not in :data:`TYPES`."""
    runs: list[tuple[str, list, list]] = []
    while count > 0:
        etype, follow, ntags = (int(v) for v in buf.array("<i4", 3))
        if etype not in TYPES or follow <= 0:
            return None
        kind, nodes = TYPES[etype]
        rec = buf.array("<i4", follow * (1 + ntags + nodes)).reshape(follow, -1)
        phys = rec[:, 1] if ntags else np.zeros(follow, dtype=np.int32)
        if not runs or runs[-1][0] != kind:
            runs.append((kind, [], []))
        runs[-1][1].append(rec[:, 1 + ntags:])
        runs[-1][2].append(phys)
        count -= follow
    return [(kind, np.vstack(conn), np.concatenate(phys)) for kind, conn, phys in runs]
