"""Export a thermoelastic state to CalculiX (``ccx`` 2.20), an independent FE code.

``job.inp`` holds the mesh (3-D: C3D4, C3D10 at P2; 2-D: CPE3/CPE6 plane strain, and plane
stress as plane strain with the equivalent material (:func:`plane_strain_equivalent`:
CalculiX's CPS3/CPS6 are a slab of the section's thickness, plane stress only as it goes to
0), CAX3/CAX6 axisymmetric, x = r, y = z; nodes and orientation:
:mod:`~gatetherm.studies.run.ccx_mesh`), a material per region (with ``*DENSITY`` under
gravity; the 2-D thickness on ``*SOLID SECTION``, none for CAX), the fixed and prescribed
displacements (``*BOUNDARY``), the temperature field at one time (``*TEMPERATURE`` over
``*INITIAL CONDITIONS`` at the stress-free temperature), the mechanical loads at that time
(gravity ``*DLOAD GRAV``, a pressure ``*DLOAD Pn`` on the element faces, tractions, forces on a
boundary and point forces as ``*CLOAD`` of gatetherm's consistent nodal forces), the bonded
sides of every contact tied node to node (``*EQUATION``) and one static step with
``*NODE PRINT`` of ``U`` on a node set per probe. A probe that is not a node prints the nodes
of its element; :func:`probes_from_dat` interpolates them with the element's shape functions,
as gatetherm does. A contact's conductance is in the temperatures (the jump across the
interface is written on the twin nodes); ccx solves no heat.

Refused, one line each (``InputError``): a case without displacement (no E, ν), without any
fixed support (an empty ``*BOUNDARY``), an elastic foundation, a contact with a joint
stiffness, a pressure on an inner boundary, a temperature per region that jumps on nodes the
regions share.
"""
from __future__ import annotations

import dataclasses
import re

import numpy as np
from skfem import CellBasis

from gatetherm import InputError
from gatetherm.solvers.model import Model, prescribed_at
from gatetherm.studies.run.formats import check_time  # noqa: F401 - also offered here
from gatetherm.studies.run.ccx_mesh import connectivity, element_type, faces, interpolation, set_name, twin_groups

_set = set_name


def num(x) -> str:
    """A number as CalculiX reads it: at most 20 characters (ccx cuts longer fields, so that
    repr's ``8.703947368421051e-06`` would read as 8.70…), 13 significant digits."""
    return f"{float(x):.13g}"


def _lines(values, per_line: int = 16) -> list[str]:
    values = list(values)
    return [", ".join(str(v) for v in values[i:i + per_line]) for i in range(0, len(values), per_line)]


PLANE_STRESS_NOTE = (
    "** plane stress is written as plane strain (CPE3/CPE6) of the same thickness with the equivalent material",
    "** E' = E (1 + 2 nu) / (1 + nu)^2, nu' = nu / (1 + nu), alpha' = alpha (1 + nu) / (1 + 2 nu): the same in-plane",
    "** displacements and stresses. CalculiX's CPS3/CPS6 are a slab of the section's thickness, plane stress only",
    "** as the thickness goes to 0 (docs/cli.md, gatetherm export).")


def plane_strain_equivalent(mat) -> tuple[float, float, float]:
    """(E', ν', α') of the plane strain material whose in-plane response is the plane stress
    response of ``mat`` (Pa, 1, 1/K)."""
    E, nu, alpha = mat.E, mat.nu, mat.alpha
    return E * (1 + 2 * nu) / (1 + nu) ** 2, nu / (1 + nu), alpha * (1 + nu) / (1 + 2 * nu)


def refuse(problem) -> None:
    """InputError for what a deck cannot hold (see the module's docstring), before any run."""
    p = problem
    if not p.elastic:
        raise InputError("materials", "the case solves no displacement: there is nothing for CalculiX to compare",
                         "give E and nu of every region")
    soft = next((s for s in p.supports if s.stiffness is not None), None)
    if soft is not None:
        raise InputError(f"supports.{soft.boundary}", "an elastic foundation is not exported to CalculiX",
                         "export with the boundary fixed (type = \"clamped\" or \"normal\")")
    if not p.supports:
        raise InputError("supports", "the case holds no displacement: CalculiX would get an empty *BOUNDARY",
                         "add a [supports] table that fixes the body")
    joint = next((c for c in p.contacts if c.stiffness is not None), None)
    if joint is not None:
        raise InputError(f"contacts.{joint.name}.stiffness", "an elastic joint layer has no CalculiX counterpart "
                         "in the export (ccx has no zero-thickness layer element)",
                         "export with the contact bonded (drop stiffness); its conductance is kept")


def _temperatures(model: Model, U, basis, cells) -> np.ndarray | None:
    """Nodal temperatures (°C): the heat state, or the prescribed field (None without one)."""
    p = model.problem
    if not p.thermal:
        return None
    if U is not None:
        return U[:model.heat.n_solid]
    if not p.prescribed_regions:
        return prescribed_at(model, basis.doflocs)
    T = np.full(basis.N, np.nan)
    for region, idx in model.mesh.subdomains.items():
        nodes = np.unique(cells[idx])
        value = p.prescribed_regions.get(region, 0.0)
        if np.any(np.isfinite(T[nodes]) & (T[nodes] != value)):
            raise InputError("temperature", f"the temperature per region jumps at nodes region {region} shares: "
                             "CalculiX's nodal temperatures cannot hold the jump",
                             "prescribe a continuous [temperature] field, or solve for the temperature")
        T[nodes] = value
    return np.nan_to_num(T, nan=p.T_ref)


def _nodal_forces(model: Model, env) -> np.ndarray:
    """gatetherm's consistent nodal forces (N, elastic DOFs) of the tractions, boundary forces
    and point forces at the inputs ``env``."""
    from gatetherm.solvers.loads import mechanical_terms

    p = model.problem
    q = dataclasses.replace(p, gravity=(), supports=(), loads=tuple(x for x in p.loads if x.kind != "pressure"))
    terms = mechanical_terms(q, model.mesh, model.elastic.basis, model.fields, model.fmesh.sensors, None)
    return np.zeros(model.elastic.basis.N) if terms is None else terms.F @ terms.at(env)


def job_inp(model: Model, U: np.ndarray | None, title: str, env=None) -> tuple[str, dict]:
    """The input deck for the heat state ``U`` (None: the problem's prescribed temperature,
    or none) and the loads at the inputs ``env``; and the probes' nodes and weights
    ({probe: {"set", "nodes" (1-based), "weights"}})."""
    from gatetherm.solvers.elasticity import support_dofs
    from gatetherm.solvers.fem import element

    refuse(model.problem)
    p, env = model.problem, env or {}
    dim, mesh = model.dim, model.mesh
    basis = model.heat.basis if model.heat is not None else CellBasis(mesh, element(dim, p.order))
    vb = model.elastic.basis
    if vb.N != dim * basis.N:
        raise RuntimeError("the elastic basis does not interleave the scalar basis's DOFs")
    cells = connectivity(basis)
    nodes = basis.doflocs.T
    T = _temperatures(model, U, basis, cells)
    note = PLANE_STRESS_NOTE if dim == 2 and p.plane == "stress" else ()
    L = [f"** {title}", *note, "*HEADING", title[:80], "*NODE"]
    L += [f"{i + 1}, " + ", ".join(num(c) for c in (*x, *[0.0] * (3 - dim))) for i, x in enumerate(nodes)]
    etype = element_type(dim, p.plane, p.order)  # plane stress: CPE and the equivalent material
    for region, idx in mesh.subdomains.items():
        L.append(f"*ELEMENT, TYPE={etype}, ELSET={_set(region)}")
        L += [f"{e + 1}, " + ", ".join(str(n + 1) for n in cells[e]) for e in idx]
    for region, mat in p.materials.items():
        E, nu, alpha = plane_strain_equivalent(mat) if dim == 2 and p.plane == "stress" else (mat.E, mat.nu, mat.alpha)
        L += [f"*MATERIAL, NAME={_set(region)}", "*ELASTIC", f"{num(E)}, {num(nu)}"]
        if T is not None:
            L += [f"*EXPANSION, ZERO={num(p.T_ref)}", num(alpha)]
        if p.gravity:
            L += ["*DENSITY", num(mat.rho)]
        L.append(f"*SOLID SECTION, ELSET={_set(region)}, MATERIAL={_set(region)}")
        if dim == 2 and not p.axisymmetric:
            L.append(num(p.thickness.get(region, 1.0)))
    fixed: dict[tuple[int, int], float] = {}  # (node, component): displacement, m; a later support wins
    for s in p.supports:
        for k, c in enumerate(s.components):
            value = float(s.values[k](env)) if s.values else 0.0
            for d in support_dofs(vb, mesh, s.boundary, (c,), model.fmesh.lines):
                fixed[(int(d) // dim, c)] = value
    equations = []
    for group in twin_groups(basis, p.contacts):
        for c in range(dim):
            held = [fixed[(int(n), c)] for n in group if (int(n), c) in fixed]
            if held:  # held on one side: on all, no equation
                fixed.update({(int(n), c): held[-1] for n in group})
            else:
                equations += [(int(n), c, int(group[0])) for n in group[1:]]
    for n, c, m in equations:
        L += ["*EQUATION", "2", f"{n + 1}, {c + 1}, 1.0, {m + 1}, {c + 1}, -1.0"]
    probes = {}
    for pr, (idx, w) in zip(p.probes, interpolation(basis, [pr.xyz for pr in p.probes])):
        probes[pr.name] = {"set": probe_set(pr.name), "nodes": [int(i) + 1 for i in idx], "weights": w.tolist()}
        L += [f"*NSET, NSET={probe_set(pr.name)}", *_lines(idx + 1)]
    if T is not None:
        L += ["*INITIAL CONDITIONS, TYPE=TEMPERATURE"] + [f"{i + 1}, {num(p.T_ref)}" for i in range(len(nodes))]
    L += ["*STEP", "*STATIC", "*BOUNDARY"]
    L += [f"{n + 1}, {c + 1}, {c + 1}" + (f", {num(v)}" if v else "") for (n, c), v in sorted(fixed.items())]
    if T is not None:
        L += ["*TEMPERATURE"] + [f"{i + 1}, {num(v)}" for i, v in enumerate(T)]
    g = np.array([float(v(env)) for v in p.gravity] + [0.0] * (3 - len(p.gravity)))
    if np.any(g):
        G = float(np.linalg.norm(g))
        L += ["*DLOAD"] + [f"{_set(r)}, GRAV, {num(G)}, " + ", ".join(num(x) for x in g / G)
                           for r in mesh.subdomains]
    for load in p.loads:
        if load.kind == "pressure" and float(load.values[0](env)) != 0.0:
            value = float(load.values[0](env))
            L += ["*DLOAD"] + [f"{e + 1}, P{k}, {num(value)}"
                               for e, k in faces(mesh, cells, load.boundary, f"loads.{load.boundary}")]
    f = _nodal_forces(model, env)
    nz = np.flatnonzero(f)
    if len(nz):
        L += ["*CLOAD"] + [f"{d // dim + 1}, {d % dim + 1}, {num(f[d])}" for d in nz]
    for name in probes:
        L += [f"*NODE PRINT, NSET={probe_set(name)}", "U"]
    L += ["*END STEP"]
    return "\n".join(L) + "\n", probes


def read_dat(text: str) -> dict[str, dict[int, np.ndarray]]:
    """Displacements (m) per node set from ``job.dat``: {set: {node: (ux, uy, uz)}}."""
    out: dict[str, dict[int, np.ndarray]] = {}
    current = None
    for line in text.splitlines():
        m = re.match(r"\s*displacements \(vx,vy,vz\) for set (\S+)", line)
        if m:
            current = out.setdefault(m.group(1), {})
            continue
        parts = line.split()
        if current is None or not parts:
            continue
        try:
            current[int(parts[0])] = np.array([float(v) for v in parts[1:4]])
        except ValueError:
            current = None
    return out


def probe_set(name: str) -> str:
    """The node set of a probe in ``job.inp``."""
    return f"P_{_set(name)}"


def export_state(case, schedule, t: float, title: str, on_step=None) -> tuple[str, dict]:
    """Run ``case`` through ``schedule`` and export the state at ``t`` (s, a step of the run):
    (``job.inp`` text, ``gatetherm.json`` content: gatetherm's displacement at every probe and
    its relative displacements in m, the probes' nodes and weights, the mesh size).
    ``on_step(i, n)`` is called after each of the run's ``n`` samples."""
    from gatetherm.solvers.heat import environment
    from gatetherm.solvers.model import static_displacement
    from gatetherm.studies.run.scenario import run_scenario

    t = check_time(schedule, t)
    try:  # before the run
        refuse(case.problem)
    except InputError as err:
        raise err.at(str(case.path or "")) from None
    env = environment(schedule.drive, t)
    run = run_scenario(case, schedule, keep_times=[t], on_step=on_step)
    model = run.model
    U = next((s[1] for s in run.result.states if abs(s[0] - t) < 1e-6), None)
    if model.heat is not None and U is None:
        U = run.result.states[-1][1]  # a steady run keeps its one state
    u = model.displacement_field(U, env) if U is not None else static_displacement(model, env)
    at = {pr.name: [float(model.elastic.point_functional(pr.xyz, c) @ u) for c in range(model.dim)]
          for pr in model.problem.probes}
    inp, probes = job_inp(model, U, title, env)
    rel = {r.name: {"a": r.a, "b": r.b, "axis": r.axis} for r in model.problem.relative}
    return inp, {"title": title, "time_s": t, "element": element_type(model.dim, model.problem.plane,
                                                                         model.problem.order),
                 "probes_m": at,
                 "relative_m": {n: at[r["a"]][r["axis"]] - at[r["b"]][r["axis"]] for n, r in rel.items()},
                 "relative": rel, "probes": probes, "probe_sets": {k: v["set"] for k, v in probes.items()},
                 "vertices": int(model.mesh.nvertices), "nodes": int(model.elastic.basis.N // model.dim),
                 "elements": int(model.mesh.nelements), "order": model.problem.order}


def probes_from_dat(dat: str, info: dict) -> dict[str, np.ndarray]:
    """Each probe's displacement (m, x y z) from CalculiX's ``job.dat``: its nodes'
    displacements weighted by the shape functions in ``info`` (:func:`export_state`)."""
    d = read_dat(dat)
    return {name: sum(w * d[pr["set"]][n] for n, w in zip(pr["nodes"], pr["weights"]))
            for name, pr in info["probes"].items()}


def relative_from_dat(dat: str, info: dict) -> dict[str, float]:
    """The relative displacements (m) of ``info`` (:func:`export_state`) from CalculiX's ``job.dat``."""
    u = probes_from_dat(dat, info)
    return {name: float(u[r["a"]][r["axis"]] - u[r["b"]][r["axis"]]) for name, r in info["relative"].items()}


def run_ccx(folder, info: dict, timeout: float = 3600.0) -> dict:
    """Run ``ccx job`` in ``folder`` (the deck of ``info``) and read its displacements back:
    {"probes_m": {probe: [ux, uy(, uz)]}, "relative_m": {name: m}, "worst": the largest
    difference of a probe displacement from gatetherm's over gatetherm's largest}."""
    import shutil
    import subprocess
    from pathlib import Path

    exe = shutil.which("ccx")
    if exe is None:
        raise InputError("--run", "CalculiX (ccx) is not installed", "install it (Debian: apt-get install "
                         "calculix-ccx) or run 'ccx job' in the folder yourself")
    folder = Path(folder)
    run = subprocess.run([exe, "job"], cwd=folder, capture_output=True, text=True, timeout=timeout)
    (folder / "ccx.log").write_text(run.stdout + run.stderr)
    if run.returncode != 0 or "ERROR" in run.stdout or not (folder / "job.dat").exists():
        raise ChildProcessError(f"ccx failed (exit {run.returncode}); see {folder / 'ccx.log'}")
    dat = (folder / "job.dat").read_text()
    u = probes_from_dat(dat, info)
    g = {k: np.asarray(v) for k, v in info["probes_m"].items()}
    scale = max((np.abs(v).max() for v in g.values()), default=0.0)
    worst = max((np.abs(u[k][:len(v)] - v).max() for k, v in g.items()), default=0.0) / scale if scale else 0.0
    return {"probes_m": {k: [float(x) for x in v[:len(g[k])]] for k, v in u.items()},
            "relative_m": relative_from_dat(dat, info), "worst": float(worst)}
