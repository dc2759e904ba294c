"""Writers for a run directory: the time series, fields for ParaView, summary JSON, picture input."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from gatetherm import atomic_path, write_text_atomic
from gatetherm.geometry.mesh import to_meshio
from gatetherm.solvers.model import Model, static_fields


def nodal_fields(model: Model, U: np.ndarray | None) -> dict[str, np.ndarray]:
    """Temperature (°C), displacement (m, 3 components) and stress (Pa: components
    ``sigma_xx`` … and ``von_mises``) at the mesh nodes, for the heat state ``U`` (None:
    the prescribed temperature of a problem without a heat solve)."""
    if U is None:
        return static_fields(model)
    T = U[:model.heat.n_solid][model.heat.basis.nodal_dofs[0]]
    out = {"T": T}
    if model.elastic is not None:
        u_dofs = model.displacement_field(U)
        u = np.zeros((len(T), 3))
        u[:, : model.dim] = u_dofs[model.elastic.basis.nodal_dofs].T
        out["u"] = u
        out.update({f"sigma_{k}" if k != "von_mises" else k: v for k, v in model.stress_field(u_dofs, U).items()})
    return out


def write_fields(model: Model, states, out: Path) -> list[Path]:
    """One ``.vtu`` per saved state (point arrays of :func:`nodal_fields`) with a
    ``fields.pvd`` collection, and the same as one XDMF time series, ``fields.xdmf`` (one
    mesh, every step; XML, no HDF5): ParaView opens either as one animated data set."""
    import meshio

    out.mkdir(parents=True, exist_ok=True)
    written, entries, steps = [], [], []
    minutes = all(abs(t / 60 - round(t / 60)) < 1e-9 for t, _ in states)
    for k, (t, U) in enumerate(states):
        name = f"fields_{int(round(t / 60)):04d}min.vtu" if minutes else f"fields_{k:04d}.vtu"
        data = nodal_fields(model, U)
        with atomic_path(out / name) as tmp:
            meshio.write(tmp, to_meshio(model.fmesh, data), file_format="vtu")
        entries.append(f'    <DataSet timestep="{t:g}" file="{name}"/>')
        written.append(out / name)
        steps.append((t, data))
    pvd = ('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n  <Collection>\n'
           + "\n".join(entries) + "\n  </Collection>\n</VTKFile>\n")
    write_text_atomic(out / "fields.pvd", pvd)
    write_xdmf(model, steps, out / "fields.xdmf")
    return written + [out / "fields.pvd", out / "fields.xdmf"]


def write_xdmf(model: Model, steps, path: Path) -> None:
    """``steps`` [(t, point arrays)] as an XDMF time series on the volume cells (cell
    array ``region``: the index of the cell's region in the mesh's region order)."""
    import meshio

    fm = model.fmesh
    pts = np.zeros((len(fm.points), 3))
    pts[:, :fm.dim] = fm.points
    region = np.zeros(len(fm.cells), dtype=np.int32)
    for i, idx in enumerate(fm.regions.values()):
        region[idx] = i
    cell = "triangle" if fm.dim == 2 else "tetra"
    with atomic_path(path) as tmp:
        with meshio.xdmf.TimeSeriesWriter(tmp, data_format="XML") as w:
            w.write_points_cells(pts, [(cell, fm.cells)])
            for t, data in steps:
                w.write_data(t, point_data=data, cell_data={"region": [region]})


def pyvista_grid(model: Model, U: np.ndarray):
    """A pyvista grid of the frame volume cells with point arrays ``T`` and ``u``."""
    import pyvista as pv

    mm = to_meshio(model.fmesh, nodal_fields(model, U))
    cell_type = "tetra" if model.dim == 3 else "triangle"
    grid = pv.from_meshio(mm)
    keep = np.flatnonzero(grid.celltypes == {"tetra": 10, "triangle": 5}[cell_type])
    return grid.extract_cells(keep)


def write_json(path: Path, data: dict) -> None:
    write_text_atomic(path, json.dumps(data, indent=2, sort_keys=True) + "\n")


def write_run(out: Path, run, metadata: dict[str, str], field_times) -> None:
    """``out/timeseries.csv`` (what the sensors report) and the fields at ``field_times``
    (``out/fields``) of a :class:`~gatetherm.studies.run.scenario.ScenarioRun`."""
    from gatetherm.studies.run.timeseries import FORMAT, write_timeseries

    write_timeseries(out / "timeseries.csv", run.series({"format": FORMAT, **metadata}))
    write_fields(run.model, [(t, U) for t, U in run.result.states if t in field_times], out / "fields")


def deformed_grid(run, t_pic: float):
    """(time, pyvista grid with the point arrays of :func:`nodal_fields`) of the kept state
    nearest ``t_pic`` (s)."""
    t, U = min(run.result.states, key=lambda s: abs(s[0] - t_pic))
    return t, pyvista_grid(run.model, U)


def probe_summary(problem, cols: dict[str, np.ndarray]) -> dict:
    """``{"probes": {NAME: {QUANTITY: value}}, "relative": {NAME: µm}}`` at the last sample
    (quantities ``T_degC``, ``ux_um`` …, ``sigma_xx_MPa`` …, ``von_mises_MPa``)."""
    from gatetherm.solvers.problem import AXES
    from gatetherm.solvers.stress import COMPONENTS
    from gatetherm.studies.run.simulate import column

    def last(key):
        name, _ = column(problem, key)
        return float(cols[name][-1]) if name in cols else None

    probes = {}
    for pr in problem.probes:
        q = {}
        if "T" in pr.quantities:
            q["T_degC"] = last(("T", pr.name))
        if "u" in pr.quantities and problem.elastic:
            q.update({f"u{a}_um": last(("u", pr.name, a)) for a in AXES[:problem.dim]})
        if "sigma" in pr.quantities and problem.elastic:
            q.update({f"sigma_{c}_MPa": last(("sigma", pr.name, c)) for c in COMPONENTS[(problem.dim, problem.plane)]})
            q["von_mises_MPa"] = float(cols[f"von_mises_{pr.name}_MPa"][-1])
        probes[pr.name] = q
    return {"probes": probes, "relative": {r.name: last(("relative", r.name)) for r in problem.relative}}
