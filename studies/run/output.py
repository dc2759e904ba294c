"""Writers for a run directory: the time series, fields for ParaView, summary JSON, picture input."""
from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Callable

import numpy as np

from gatetherm import atomic_path, write_text_atomic
from gatetherm.checks import json_text
from gatetherm.geometry.mesh import to_meshio
from gatetherm.geometry.vtu import write_vtu
from gatetherm.process import give_back
from gatetherm.solvers.helper import Pending
from gatetherm.solvers.model import Model, field_recovery, static_fields


def nodal_fields(model: Model, U: np.ndarray | None, rec=None, stress: bool = True,
                 u_dofs: np.ndarray | None = None, env=None) -> dict[str, np.ndarray]:
    """Temperature (°C), displacement (m, 3 components) and stress (Pa: components
    ``sigma_xx`` … and ``von_mises``) at the mesh nodes, for the heat state ``U`` (None:
    the prescribed temperature of a problem without a heat solve). ``rec``: the model's
    :func:`~gatetherm.solvers.model.field_recovery`, to share among states; ``u_dofs``:
    the displacement of ``U``, if solved already; ``env``: the inputs of the loads' values."""
    if U is None:
        return static_fields(model, env)
    T = U[:model.heat.n_solid][model.heat.basis.nodal_dofs[0]]
    out = {"T": T}
    if model.elastic is not None:
        u_dofs = model.displacement_field(U, env) if u_dofs is None else u_dofs
        u = np.zeros((len(T), 3))
        u[:, : model.dim] = u_dofs[model.elastic.basis.nodal_dofs].T
        out["u"] = u
        if stress:
            out.update({f"sigma_{k}" if k != "von_mises" else k: v
                        for k, v in model.stress_field(u_dofs, U, rec).items()})
    return out


class Solved(Mapping):
    """Displacement DOFs by time, each solved (or waited for) when first looked up."""

    def __init__(self, pending: dict):
        self._pending = pending

    def __getitem__(self, t: float) -> np.ndarray:
        return self._pending[t].result()

    def __iter__(self):
        return iter(self._pending)

    def __len__(self) -> int:
        return len(self._pending)

    def __contains__(self, t) -> bool:  # not Mapping's: it looks the value up
        return t in self._pending

    def ready(self, t: float) -> bool:
        """Whether the displacement at ``t`` is in (looking it up does not wait)."""
        return self._pending[t].done()


def displacements(model: Model, states, envs=None, ahead=None) -> Solved:
    """The displacement DOFs of the heat states ``[(t, U)]`` by time (with the loads for
    the inputs ``envs`` by time): those of ``ahead`` (by time, :class:`~gatetherm.solvers.helper.Pending`:
    solved during the march) as they come, the others in one elastic solve, or, where the
    elastic solver runs in a helper, one solve each in their order, looked up as they come.
    A factor is released after its solve: the writers and pictures that follow need memory of
    their own (in 3-D a factor holds 0.86 GB)."""
    if model.elastic is None or model.heat is None or not states:
        return Solved({})
    ahead, envs = ahead or {}, envs or {}
    out = {t: ahead[t] for t, _ in states if t in ahead}
    rest = [(t, U) for t, U in states if t not in ahead]
    if model.elastic.solve.background:
        out.update({t: model.displacement_later(U, envs.get(t)) for t, U in rest})
    elif rest:
        u = model.displacement_field(np.column_stack([U for _, U in rest]), [envs.get(t) for t, _ in rest])
        model.elastic.solve.release()
        out.update({t: Pending.of(u[:, k]) for k, (t, _) in enumerate(rest)})
    return Solved(out)


def write_fields(model: Model, states, out: Path, solved: dict[float, np.ndarray] | None = None,
                 envs=None, between: Callable[[], None] | None = None) -> list[Path]:
    """One ``.vtu`` per saved state (point arrays of :func:`nodal_fields`) with a
    ``fields.pvd`` collection, and the same as one XDMF time series, ``fields.xdmf`` with
    ``fields.h5`` (one mesh, every step): ParaView opens either as one animated data set.
    ``solved``: their :func:`displacements`, if found already; ``envs``: the inputs by time;
    ``between``: called before each state is written."""
    out.mkdir(parents=True, exist_ok=True)
    written, entries, steps = [], [], []
    minutes = all(abs(t / 60 - round(t / 60)) < 1e-9 for t, _ in states)
    solved = displacements(model, states, envs) if solved is None else solved
    rec = field_recovery(model) if solved else None
    for k, (t, U) in enumerate(states):
        if between is not None:
            between()
        name = f"fields_{int(round(t / 60)):04d}min.vtu" if minutes else f"fields_{k:04d}.vtu"
        data = nodal_fields(model, U, rec, u_dofs=solved.get(t), env=(envs or {}).get(t))
        with atomic_path(out / name) as tmp:
            write_vtu(tmp, model.fmesh, data)
        entries.append(f'    <DataSet timestep="{t:g}" file="{name}"/>')
        written.append(out / name)
        steps.append((t, data))
    pvd = ('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n  <Collection>\n'
           + "\n".join(entries) + "\n  </Collection>\n</VTKFile>\n")
    write_text_atomic(out / "fields.pvd", pvd)
    write_xdmf(model, steps, out / "fields.xdmf")
    return written + [out / "fields.pvd", out / "fields.xdmf", out / "fields.h5"]


_XDMF_CELL = {"triangle": ("Triangle", 3), "tetra": ("Tetrahedron", 4)}


def write_xdmf(model: Model, steps, path: Path) -> None:
    """``steps`` [(t, point arrays)] as an XDMF time series on the volume cells, the arrays in
    ``<path stem>.h5`` beside it (HDF5: the ASCII form took 21 s for a 3-D run); cell array
    ``region``: the index of the cell's region in the mesh's region order. Both files are
    written under temporary names and renamed, the HDF5 file first."""
    import h5py

    fm = model.fmesh
    pts = np.zeros((len(fm.points), 3))
    pts[:, :fm.dim] = fm.points
    region = np.zeros(len(fm.cells), dtype=np.int32)
    for i, idx in enumerate(fm.regions.values()):
        region[idx] = i
    kind, k = _XDMF_CELL["triangle" if fm.dim == 2 else "tetra"]
    h5 = path.with_suffix(".h5")

    def item(name, a):
        a = np.asarray(a)
        dtype = ("Int", "4") if a.dtype.kind in "iu" else ("Float", "8")
        return (f'<DataItem Dimensions="{" ".join(map(str, a.shape))}" NumberType="{dtype[0]}" '
                f'Precision="{dtype[1]}" Format="HDF">{h5.name}:/{name}</DataItem>')

    def attribute(name, a, center, key):
        kind_ = "Vector" if np.ndim(a) == 2 else "Scalar"
        return f'<Attribute Name="{name}" AttributeType="{kind_}" Center="{center}">{item(key, a)}</Attribute>'

    grids, cells = [], fm.cells.astype(np.int64)
    with atomic_path(h5) as tmp, h5py.File(tmp, "w") as f:
        f["points"], f["cells"], f["region"] = pts, cells, region
        for n, (t, data) in enumerate(steps):
            attrs = [attribute("region", region, "Cell", "region")]
            for name, a in data.items():
                f[f"step{n}/{name}"] = np.asarray(a, dtype=float)
                attrs.append(attribute(name, a, "Node", f"step{n}/{name}"))
            grids.append(f'<Grid Name="step{n}" GridType="Uniform"><Time Value="{t!r}"/>'
                         f'<Topology TopologyType="{kind}" NumberOfElements="{len(fm.cells)}" NodesPerElement="{k}">'
                         f'{item("cells", cells)}</Topology>'
                         f'<Geometry GeometryType="XYZ">{item("points", pts)}</Geometry>{"".join(attrs)}</Grid>')
    write_text_atomic(path, '<?xml version="1.0"?>\n<Xdmf Version="3.0"><Domain>'
                      '<Grid Name="fields" GridType="Collection" CollectionType="Temporal">\n'
                      + "\n".join(grids) + "\n</Grid></Domain></Xdmf>\n")


def volume_grid(fmesh, point_data: dict[str, np.ndarray]):
    """A pyvista grid of the volume cells of ``fmesh`` (triangles in 2-D, tetrahedra in 3-D)
    with the nodal arrays ``point_data``."""
    import pyvista as pv

    grid = pv.from_meshio(to_meshio(fmesh, point_data))
    return grid.extract_cells(np.flatnonzero(grid.celltypes == (10 if fmesh.dim == 3 else 5)))


def write_json(path: Path, data: dict) -> None:
    write_text_atomic(path, json_text(data, Path(path).name, indent=2, sort_keys=True))


def nearest_state(run, t: float) -> tuple[float, np.ndarray]:
    """The kept ``(time, state)`` of a run nearest ``t`` (s)."""
    return min(run.result.states, key=lambda s: abs(s[0] - t))


def write_run(out: Path, run, metadata: dict[str, str], field_times, picture_times=(),
              solved_hook=None, release: bool = False) -> Solved:
    """``out/timeseries.csv`` (what the sensors report) and the fields at ``field_times``
    (``out/fields``) of a :class:`~gatetherm.studies.run.scenario.ScenarioRun`; returns the
    :func:`displacements` of those states and of the states nearest ``picture_times`` (those
    first), which ``solved_hook`` (if given) is called with as soon as those of the picture
    states are in: before the fields are written, or while they are (a helper process solves).
    ``release``: the model's elastic solver is asked for nothing more (a one-shot run), so a
    helper process ends once it has solved these (:meth:`~gatetherm.solvers.linsolve.SPDSolver.retire`)."""
    from gatetherm.studies.run.timeseries import FORMAT, write_timeseries

    give_back()  # the march's freed memory (its heat solvers'), not kept beside the helper and the painter
    write_timeseries(out / "timeseries.csv", run.series({"format": FORMAT, **metadata}))
    states = [(t, U) for t, U in run.result.states if t in field_times]
    pictured = dict(nearest_state(run, tp) for tp in picture_times)
    extra = [(t, U) for t, U in pictured.items() if t not in field_times]
    solved = displacements(run.model, extra + states, run.result.envs, run.result.solved)
    if release and run.model.elastic is not None:
        run.model.elastic.solve.retire()
    hook = [solved_hook] if solved_hook is not None else []

    def between():
        if hook and all(solved.ready(t) for t in pictured if t in solved):
            hook.pop()(solved)
    between()
    write_fields(run.model, states, out / "fields", solved, run.result.envs, between)
    if hook:
        hook.pop()(solved)
    return solved


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
