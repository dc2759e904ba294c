"""The VTU writer: what meshio's writer gives (the same arrays, read back exactly by meshio
and by VTK through pyvista), for the 2-D and 3-D frames with point data of one and three
components."""
from __future__ import annotations

import numpy as np
import pytest

from gatetherm.geometry.mesh import to_meshio
from gatetherm.geometry.vtu import write_vtu


@pytest.mark.parametrize("dim", [2, 3])
def test_vtu_holds_what_meshio_writes(dim, frame_2d, frame_3d, tmp_path):
    import meshio
    import pyvista as pv

    fm = frame_2d if dim == 2 else frame_3d
    rng = np.random.default_rng(dim)
    data = {"T": rng.normal(size=len(fm.points)), "u": rng.normal(size=(len(fm.points), 3)),
            "von_mises": rng.normal(size=len(fm.points))}
    write_vtu(tmp_path / "raw.vtu", fm, data)
    meshio.write(tmp_path / "meshio.vtu", to_meshio(fm, data), file_format="vtu")
    ours, theirs = meshio.read(tmp_path / "raw.vtu"), meshio.read(tmp_path / "meshio.vtu")
    assert np.array_equal(ours.points, theirs.points)
    assert [c.type for c in ours.cells] == [c.type for c in theirs.cells]
    assert all(np.array_equal(a.data, b.data) for a, b in zip(ours.cells, theirs.cells))
    assert list(ours.point_data) == list(theirs.point_data) == list(data)
    assert all(np.array_equal(ours.point_data[k], theirs.point_data[k]) for k in data)
    assert list(ours.cell_data) == list(theirs.cell_data)
    assert all(np.array_equal(a, b) for k in ours.cell_data for a, b in zip(ours.cell_data[k], theirs.cell_data[k]))
    grid, ref = pv.read(tmp_path / "raw.vtu"), pv.read(tmp_path / "meshio.vtu")
    assert (grid.n_points, grid.n_cells) == (ref.n_points, ref.n_cells) == (len(fm.points), len(grid.celltypes))
    assert np.array_equal(grid.celltypes, ref.celltypes) and np.array_equal(grid.cell_connectivity, ref.cell_connectivity)
    np.testing.assert_array_equal(grid.point_data["u"], data["u"])
    np.testing.assert_array_equal(grid.cell_data["group:tie_bar"], ref.cell_data["group:tie_bar"])
