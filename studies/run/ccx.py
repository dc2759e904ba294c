"""Export a thermoelastic state to CalculiX (``ccx`` 2.20), an independent FE code.

``job.inp`` holds the mesh (C3D4, or C3D10 for quadratic elements), a material per
region, the supports, the temperature field at one time as ``*TEMPERATURE`` over
``*INITIAL CONDITIONS`` at the stress-free temperature, one static step, and a node set
per probe with ``*NODE PRINT`` of ``U``, so that ``ccx job`` prints the probes'
displacements to ``job.dat`` (:func:`read_dat` reads them back).
"""
from __future__ import annotations

import re

import numpy as np

from gatetherm import InputError
from gatetherm.solvers.model import Model, prescribed_at

_PAIRS = ((0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3))
"""Edges of a tetrahedron in the order of C3D10's mid-side nodes 5-10 (and scikit-fem's)."""


def _set(name: str) -> str:
    """A CalculiX set name (letters, digits, underscores, at most 80 characters)."""
    return re.sub(r"\W", "_", name).upper()[:80]


def _lines(values, per_line: int = 16) -> list[str]:
    values = list(values)
    return [", ".join(str(v) for v in values[i:i + per_line]) for i in range(0, len(values), per_line)]


def job_inp(model: Model, U: np.ndarray | None, title: str) -> str:
    """The input deck for the heat state ``U`` (None: the problem's prescribed temperature)."""
    p = model.problem
    if model.dim != 3:
        raise InputError("--dim", "CalculiX export is for 3-D models", "use --dim 3")
    if any(s.stiffness is not None for s in p.supports):
        raise InputError("supports", "an elastic foundation has no CalculiX counterpart here",
                         "export a model with fixed supports")
    if model.terms is not None or p.contacts or not p.thermal:
        raise InputError("loads", "the export writes the thermal load only (no mechanical loads, joints or purely "
                         "mechanical cases)", "export a case without [gravity], [loads], [contacts] and displacement "
                         "supports")
    fm, order = model.fmesh, p.order
    cells = fm.cells.copy()
    X = fm.points[cells]
    neg = np.einsum("ij,ij->i", np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0]), X[:, 3] - X[:, 0]) < 0
    cells[neg] = cells[neg][:, [1, 0, 2, 3]]  # C3D4: positive volume
    from skfem import CellBasis

    from gatetherm.solvers.fem import element

    basis = model.heat.basis if model.heat is not None else CellBasis(model.mesh, element(3, order))
    nodes = basis.doflocs.T  # vertices first (the mesh's numbering), then mid-edges for P2
    T = U[:model.heat.n_solid] if U is not None else prescribed_at(model, nodes.T)
    if order == 2:
        edge_dof = {tuple(sorted(basis.mesh.t[[a, c], e])): basis.element_dofs[4 + k, e]
                    for e in range(basis.mesh.nelements) for k, (a, c) in enumerate(_PAIRS)}
        mids = np.array([[edge_dof[tuple(sorted((c[a], c[b])))] for a, b in _PAIRS] for c in cells])
        cells = np.hstack([cells, mids])
    L = [f"** {title}", "*HEADING", title[:80], "*NODE"]
    L += [f"{i + 1}, {float(x[0])!r}, {float(x[1])!r}, {float(x[2])!r}" for i, x in enumerate(nodes)]
    for region, idx in fm.regions.items():
        L.append(f"*ELEMENT, TYPE={'C3D10' if order == 2 else 'C3D4'}, ELSET={_set(region)}")
        L += [f"{e + 1}, " + ", ".join(str(n + 1) for n in cells[e]) for e in idx]
    for region, mat in p.materials.items():
        L += [f"*MATERIAL, NAME={_set(region)}", "*ELASTIC", f"{mat.E!r}, {mat.nu!r}",
              f"*EXPANSION, ZERO={p.T_ref!r}", f"{mat.alpha!r}",
              f"*SOLID SECTION, ELSET={_set(region)}, MATERIAL={_set(region)}"]
    bnodes = {}
    for s in p.supports:
        facet_nodes = np.unique(fm.boundaries[s.boundary])
        bnodes[s.boundary] = facet_nodes if order == 1 else np.unique(np.r_[facet_nodes,
                                                                            _facet_mids(cells, facet_nodes)])
    for name, keep in bnodes.items():
        L += [f"*NSET, NSET=B_{_set(name)}", *_lines(keep + 1)]
    probe_node = {}
    for pr in p.probes:
        d = np.linalg.norm(nodes - np.asarray(pr.xyz), axis=1)
        i = int(np.argmin(d))
        if d[i] > 1e-9 * max(np.ptp(nodes, axis=0).max(), 1.0):
            raise InputError(f"probe {pr.name}", "is not a node of the mesh", "put probes on mesh points")
        probe_node[pr.name] = i
        L += [f"*NSET, NSET=P_{_set(pr.name)}", str(i + 1)]
    L += ["*INITIAL CONDITIONS, TYPE=TEMPERATURE"] + [f"{i + 1}, {p.T_ref!r}" for i in range(len(nodes))]
    L += ["*STEP", "*STATIC", "*BOUNDARY"]
    for s in p.supports:
        L += [f"B_{_set(s.boundary)}, {c + 1}, {c + 1}" for c in s.components]
    L += ["*TEMPERATURE"] + [f"{i + 1}, {float(v)!r}" for i, v in enumerate(T)]
    for name in probe_node:
        L += [f"*NODE PRINT, NSET=P_{_set(name)}", "U"]
    L += ["*END STEP"]
    return "\n".join(L) + "\n"


def _facet_mids(cells: np.ndarray, facet_nodes: np.ndarray) -> np.ndarray:
    """Mid-side nodes of the C3D10 cells whose both edge ends lie on a boundary."""
    on = np.isin(cells[:, :4], facet_nodes)
    out = [cells[on[:, a] & on[:, b], 4 + k] for k, (a, b) in enumerate(_PAIRS)]
    return np.concatenate(out)


def read_dat(text: str) -> dict[str, np.ndarray]:
    """Displacements (m) per probe node set from ``job.dat``: {probe set: (ux, uy, uz)}."""
    out, current = {}, None
    for line in text.splitlines():
        m = re.match(r"\s*displacements \(vx,vy,vz\) for set (\S+)", line)
        if m:
            current = m.group(1)
            continue
        parts = line.split()
        if current and len(parts) == 4:
            try:
                out[current] = np.array([float(v) for v in parts[1:]])
            except ValueError:
                pass
            current = None
    return out


def probe_set(name: str) -> str:
    """The node set of a probe in ``job.inp``."""
    return f"P_{_set(name)}"


def check_time(schedule, t: float) -> float:
    """The step of ``schedule`` at ``t`` (s, within 1e-6 s); InputError if there is none."""
    near = [float(s) for s in schedule.times if abs(t - s) < 1e-6]
    if not near:
        raise InputError("--time", f"{t / 60:g} min is not a step of the run", "give a whole minute of the run")
    return near[0]


def export_state(case, schedule, t: float, title: str) -> tuple[str, dict]:
    """Run ``case`` through ``schedule`` and export the state
    at ``t`` (s, a step of the run): (``job.inp`` text, ``gatetherm.json`` content: gatetherm's
    relative displacements in m, the probe sets they compare and the mesh size)."""
    from gatetherm.studies.run.scenario import run_scenario

    t = check_time(schedule, t)
    run = run_scenario(case, schedule, keep_times=[t])
    (_, U), = [s for s in run.result.states if abs(s[0] - t) < 1e-6]
    model = run.model
    u = {}
    if U is not None:
        u = {k[1]: float(v) for k, v in zip(model.readout.keys, model.read(U)) if k[0] == "relative"}
    probes = {pr.name: probe_set(pr.name) for pr in model.problem.probes}
    rel = {r.name: {"a": probes[r.a], "b": probes[r.b], "axis": r.axis} for r in model.problem.relative}
    return job_inp(model, U, title), {"title": title, "time_s": t, "relative_m": u, "relative": rel,
                                      "probe_sets": probes, "vertices": len(model.fmesh.points),
                                      "elements": len(model.fmesh.cells), "order": model.problem.order}


def relative_from_dat(dat: str, info: dict) -> dict[str, float]:
    """The relative displacements (m) of ``info`` (:func:`export_state`) from CalculiX's ``job.dat``."""
    d = read_dat(dat)
    return {name: float(d[r["a"]][r["axis"]] - d[r["b"]][r["axis"]]) for name, r in info["relative"].items()}
