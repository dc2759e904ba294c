"""The peer problem in DOLFINx (run by benchmarks/peer.py in the environment of
benchmarks/setup_dolfinx.sh): gatetherm's own 3-D frame mesh (``gatetherm mesh --dim 3``),
P1 heat from 20 °C, NSTEPS backward-Euler steps of 60 s with films to 40 °C oil on
``tank_wall`` (260 W/(m² K)) and to 20 °C air on ``free_surface`` (8 W/(m² K)), the mounting
face insulated, heat by MUMPS LU factorised once; then one thermoelastic solve (mounting
face clamped) by CG with GAMG on the rigid-body modes; δ = u_x(F_L) − u_x(F_R).

    python dolfinx_frame.py MESH.msh [NSTEPS]     → one JSON line: part times (s), T_A, T_B, δ (µm)
"""
import time

T_START = time.perf_counter()
import json  # noqa: E402
import sys  # noqa: E402

import dolfinx_solver  # noqa: E402,F401  (before dolfinx and petsc4py)
import gmsh  # noqa: E402
import numpy as np  # noqa: E402
import ufl  # noqa: E402
from dolfinx import fem, geometry, io, la  # noqa: E402
from dolfinx.fem.petsc import assemble_matrix, assemble_vector, create_vector  # noqa: E402
from mpi4py import MPI  # noqa: E402
from petsc4py import PETSc  # noqa: E402

K, RHO_C, H_AIR, H_OIL, T_AIR, T_OIL, T_REF, DT = 48.0, 7250.0 * 510.0, 8.0, 260.0, 20.0, 40.0, 20.0, 60.0
E, NU, ALPHA = 1.2e11, 0.26, 1.05e-5
path, nsteps = sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 300
comm, parts = MPI.COMM_SELF, {}


def lap(name, t0):
    parts[name] = time.perf_counter() - t0
    return time.perf_counter()


t = time.perf_counter()
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.merge(path)
points = {}
for d, tag in gmsh.model.getPhysicalGroups(0):
    _, xyz, _ = gmsh.model.mesh.getNodes(0, gmsh.model.getEntitiesForPhysicalGroup(d, tag)[0], includeBoundary=True)
    points[gmsh.model.getPhysicalName(d, tag)] = np.asarray(xyz[:3])
data = io.gmsh.model_to_mesh(gmsh.model, comm, 0, gdim=3)
gmsh.finalize()
mesh, facets = data.mesh, data.facet_tags
tag = {name: int(g[1]) for name, g in data.physical_groups.items()}
t = lap("mesh_read", t)

V = fem.functionspace(mesh, ("Lagrange", 1))
u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
ds = ufl.Measure("ds", domain=mesh, subdomain_data=facets)
air, oil = ds(tag["free_surface"]), ds(tag["tank_wall"])
A = assemble_matrix(fem.form(RHO_C / DT * u * v * ufl.dx + K * ufl.inner(ufl.grad(u), ufl.grad(v)) * ufl.dx
                             + H_AIR * u * v * air + H_OIL * u * v * oil))
A.assemble()
M = assemble_matrix(fem.form(RHO_C / DT * u * v * ufl.dx))
M.assemble()
f = assemble_vector(fem.form(H_AIR * T_AIR * v * air + H_OIL * T_OIL * v * oil))
b = create_vector(V)
T = fem.Function(V)
T.x.array[:] = T_REF
t = lap("heat_assembly", t)
ksp = PETSc.KSP().create(comm)
ksp.setOperators(A)
ksp.setType("preonly")
ksp.getPC().setType("lu")
ksp.getPC().setFactorSolverType("mumps")
ksp.setUp()
t = lap("heat_factor", t)
for _ in range(nsteps):
    M.mult(T.x.petsc_vec, b)
    b.axpy(1.0, f)
    ksp.solve(b, T.x.petsc_vec)
t = lap("heat_steps", t)

W = fem.functionspace(mesh, ("Lagrange", 1, (3,)))
lam, mu = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
w, z = ufl.TrialFunction(W), ufl.TestFunction(W)


def eps(q):
    return ufl.sym(ufl.grad(q))


bc = fem.dirichletbc(np.zeros(3), fem.locate_dofs_topological(W, 2, facets.find(tag["mounting_face"])), W)
Ae = assemble_matrix(fem.form(ufl.inner(2 * mu * eps(w) + lam * ufl.tr(eps(w)) * ufl.Identity(3), eps(z)) * ufl.dx),
                     bcs=[bc])
Ae.assemble()
be = assemble_vector(fem.form((3 * lam + 2 * mu) * ALPHA * (T - T_REF) * ufl.div(z) * ufl.dx))
fem.petsc.set_bc(be, [bc])
x = W.tabulate_dof_coordinates()
modes = [la.vector(W.dofmap.index_map, bs=3, dtype=PETSc.ScalarType) for _ in range(6)]
for i in range(3):
    modes[i].array.reshape(-1, 3)[:, i] = 1.0
R = [m.array.reshape(-1, 3) for m in modes]
R[3][:, 0], R[3][:, 1] = -x[:, 1], x[:, 0]
R[4][:, 1], R[4][:, 2] = -x[:, 2], x[:, 1]
R[5][:, 2], R[5][:, 0] = x[:, 0], -x[:, 2]
la.orthonormalize(modes)
Ae.setNearNullSpace(PETSc.NullSpace().create(vectors=[m.petsc_vec for m in modes], comm=comm))
kspe = PETSc.KSP().create(comm)
kspe.setOperators(Ae)
kspe.setType("cg")
kspe.getPC().setType("gamg")
kspe.setTolerances(rtol=1e-9)
t = lap("elastic_setup", t)
uh = fem.Function(W)
kspe.solve(be, uh.x.petsc_vec)
t = lap("elastic_solve", t)

names = ["A", "B", "F_L", "F_R"]
pts = np.array([points[s] for s in names])
tree = geometry.bb_tree(mesh, 3)
cells = geometry.compute_colliding_cells(mesh, geometry.compute_collisions_points(tree, pts), pts)
val = {s: (T.eval(pts[i], cells.links(i)[:1])[0], uh.eval(pts[i], cells.links(i)[:1])[0])
       for i, s in enumerate(names)}
print(json.dumps({"tool": "dolfinx", "nsteps": nsteps, "nodes": mesh.geometry.index_map().size_global,
                  "T_A": float(val["A"][0]), "T_B": float(val["B"][0]),
                  "delta_um": float((val["F_L"][1] - val["F_R"][1]) * 1e6), "elastic_its": kspe.getIterationNumber(),
                  **{k: round(s, 3) for k, s in parts.items()}, "total": round(time.perf_counter() - T_START, 3)}),
      flush=True)
