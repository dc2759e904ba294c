"""Parts of a 3-D run, each against the way it was made before, on the 3-D frame.

    python benchmarks/assembly_parts.py [--rounds 5] [--factor 1] [--parts NAME ...]

Each variant once, as a run calls it, in a new interpreter set up as a command is
(``gt.configure()``): what a part costs there is mostly memory touched for the first time.
The pairs, the variants interleaved per round: the node-pair pattern's map of element entries
(``p1.Pattern``, each entry looked up in its row) against one searchsorted over all pairs; the
stress projection's right-hand sides of one field applied element by element
(``stress.ElementStress``, nothing to set up) against the six matrices of before, assembled and
applied; one field file written raw (``geometry.vtu.write_vtu``) against meshio's VTU writer; the
check of a mesh read from a file (``geometry.mesh.check_mesh``: facets matched by sorted integer
keys, each element edge once) against its code before (``np.unique`` of byte records, which
numpy 2.4 hashes, and all 16 node pairs of a tetrahedron). From 2026-12-06: reading the frame's
binary gmsh 2.2 file (``geometry.msh22``) against meshio's reader; the vector DOF basis made on one
element and widened (``fem.dof_basis``) against scikit-fem's on every element; the mesh check in
chunks of elements, facets of the elements touching the boundaries, against its code of 12-05
(whole arrays, every element's facets); the mesh's nodes by a mask against ``np.unique``; the METIS
order with one refinement pass per level against METIS's default; shared facets of two boundaries
by keys against a loop over tuples; the free displacement DOFs (those the mounting face does not
hold) by a mask (``fem.complement``) against ``np.setdiff1d``. From 2026-12-06 night: the
elastic stiffness with its element matrices made a chunk of elements at a time
(``p1.Pattern.blocks``) against all at once. ``--factor F`` meshes the frame with about F times
the default nodes (as ``benchmarks/scaling.py``); ``--parts`` runs only the pairs named.
Prints the medians, their ratios, each variant's new memory (its peak resident set above its
start; freed memory the process keeps is reused first), and that the results agree
(docs/performance.md, "2026-12-04", "2026-12-06 night" and "Against DOLFINx"; a METIS order is
compared as a permutation only).
"""
from __future__ import annotations

import argparse
import os
import pickle
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
import scipy.sparse as sp

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from scaling import mesh_file as sized_frame  # noqa: E402  (benchmarks/ is not a package)

PAIRS = {"pattern": ("by rows", "searchsorted"),
         "stress rhs": ("element by element", "six matrices"), "field file": ("raw", "meshio"),
         "mesh check": ("sorted keys", "np.unique"), "mesh read": ("whole arrays", "meshio"),
         "dof basis": ("one element", "every element"), "mesh check 12-06": ("chunks", "whole"),
         "mesh nodes": ("mask", "np.unique"), "METIS order": ("one pass", "ten passes"),
         "shared facets": ("keys", "tuples"), "free DOFs": ("mask", "setdiff1d"),
         "stiffness": ("chunks", "at once")}


def variants(fm, work: str):
    """``{(part, variant): make}`` on the FrameMesh ``fm``; each ``make()`` returns its result
    (a field file's path, in the folder ``work``)."""
    import meshio

    from skfem import CellBasis, ElementVector

    from gatetherm.geometry import msh22
    from gatetherm.geometry.mesh import check_mesh, facet_keys, find_facets, to_meshio
    from gatetherm.geometry.vtu import write_vtu
    from gatetherm.solvers import p1
    from gatetherm.solvers.fem import complement, dof_basis, element, to_skfem
    from gatetherm.solvers.linsolve import nd_order
    from gatetherm.solvers.stress import _INDEX, COMPONENTS, ElementStress
    from gatetherm.studies.run.case import _overlapping

    cells, n, k = fm.cells.astype(np.int64), len(fm.points), 4
    G, vol = p1.gradients(fm.points, cells)
    rng = np.random.default_rng(0)
    lam, mu = rng.uniform(1.0, 2.0, len(vol)) * 6e10, rng.uniform(1.0, 2.0, len(vol)) * 4e10
    comps, u = COMPONENTS[(3, "stress")], rng.normal(size=3 * n)
    data = {"T": rng.normal(size=n), "u": rng.normal(size=(n, 3)),
            **{f"sigma_{c}": rng.normal(size=n) for c in comps}, "von_mises": rng.normal(size=n)}
    pattern = p1.Pattern(cells, n)

    def searched():  # p1.Pattern before
        i, j = np.repeat(cells, k, axis=1).ravel(), np.tile(cells, (1, k)).ravel()
        A = sp.csr_matrix((np.ones(len(i), dtype=np.int8), (i, j)), shape=(n, n))
        rows = np.repeat(np.arange(n, dtype=np.int64) * n, np.diff(A.indptr))
        return np.searchsorted(rows + A.indices, i.astype(np.int64) * n + j)

    def six_matrices():  # stress._p1_recovery before, and Recovery.field's products
        def s_form(i, j):
            def form(_, b, G, vol, lam, mu):
                sv = mu[:, None] * ((j == b) * G[:, :, i] + (i == b) * G[:, :, j]) + (lam[:, None] * G[:, :, b] if i == j else 0.0)
                return np.broadcast_to((vol / k)[:, None, None] * sv[:, None, :], (len(vol), k, k))
            return form
        S = {c: pattern.blocks(s_form(*_INDEX[c]), 1, 3, G, vol, lam, mu) for c in comps}
        t0 = time.perf_counter()
        out = {c: S[c] @ u for c in comps}
        return {**out, "product s": time.perf_counter() - t0,
                "GB": sum(m.data.nbytes + m.indices.nbytes for m in S.values()) / 1e9}

    def checked_before():  # geometry.mesh.check_mesh before (the mesh is sound: both return, neither raises)
        X = fm.points[fm.cells]
        size = np.abs(np.linalg.det(X[:, 1:] - X[:, :1]))
        edge = np.linalg.norm(X[:, :, None] - X[:, None, :], axis=-1).max(axis=(1, 2))
        assert not (size <= 1e-10 * edge ** 3).any()
        rows = np.sort(np.vstack([np.delete(fm.cells, i, axis=1) for i in range(4)]), axis=1)
        key = lambda a: np.ascontiguousarray(a, dtype=np.int64).view(f"V{8 * a.shape[1]}").ravel()  # noqa: E731
        facets = np.unique(key(rows))
        assert all(np.isin(key(np.sort(f, axis=1)), facets).all() for f in fm.boundaries.values())
        return np.ones(1)

    def checked_12_05():  # geometry.mesh.check_mesh of 2026-12-05 (the mesh is sound: both return)
        X = fm.points[fm.cells]
        E = X[:, 1:] - X[:, :1]
        size = np.abs(np.einsum("ij,ij->i", E[:, 0], np.cross(E[:, 1], E[:, 2])))
        i, j = np.triu_indices(4, 1)
        edge2 = np.einsum("ijk,ijk->ij", X[:, i] - X[:, j], X[:, i] - X[:, j]).max(axis=1)
        assert not (size <= 1e-10 * edge2 ** 1.5).any()
        facets = np.sort(facet_keys(np.vstack([np.delete(fm.cells, i, axis=1) for i in range(4)]), n))
        assert all(find_facets(facets, f, n) is not None for f in fm.boundaries.values())
        return np.ones(1)

    def metis_default():  # linsolve.nd_order before: METIS's default refinement
        import pymetis

        G = pattern.graph()
        G.setdiag(0)
        G.eliminate_zeros()
        return np.sort(pymetis.nested_dissection(pymetis.CSRAdjacency(G.indptr.astype(np.int32),
                                                                      G.indices.astype(np.int32)))[0])

    def shared_by_tuples():  # studies.run.case._overlapping before
        owner: dict = {}
        for b in names:
            for f in map(tuple, np.sort(fm.boundaries[b], axis=1)):
                if owner.setdefault(f, b) != b:
                    return np.full(1, 2.0)
        return np.ones(1)

    def nodes_by_mask():
        used = np.zeros(n, dtype=bool)
        used[fm.cells.ravel()] = True
        return np.flatnonzero(used)

    def stiffness_at_once():  # p1.stiffness before 2026-12-06 night: all element matrices at once
        dot, Gl, Gm = p1.conduction(G, vol, mu), (lam * vol)[:, None, None] * G, (mu * vol)[:, None, None] * G
        data = np.empty((pattern.nnz, 3, 3))
        for a in range(3):
            for b in range(3):
                out = Gl[:, :, a][:, :, None] * G[:, :, b][:, None, :]
                out += Gm[:, :, b][:, :, None] * G[:, :, a][:, None, :]
                if a == b:
                    out += dot
                data[:, a, b] = np.bincount(pattern.inv, weights=out.ravel(), minlength=pattern.nnz)
        return sp.bsr_matrix((data, pattern.indices, pattern.indptr), shape=(3 * n, 3 * n)).tocsr()

    msh, mesh, names = os.path.join(work, "frame.msh"), to_skfem(fm), list(fm.boundaries)
    vector, none = ElementVector(element(3, 1)), (np.zeros((3, 0)), np.zeros(0))
    held = (3 * np.unique(fm.boundaries["mounting_face"])[:, None] + np.arange(3)).ravel()

    def written(write):  # the file's path: read back after the timing
        path = os.path.join(work, "f.vtu")
        write(path)
        return path

    return {("pattern", "by rows"): lambda: p1.Pattern(cells, n).inv, ("pattern", "searchsorted"): searched,
            ("stress rhs", "element by element"): lambda: ElementStress(cells, G, vol, lam, mu, comps, n)(u),
            ("stress rhs", "six matrices"): six_matrices,
            ("mesh check", "sorted keys"): lambda: check_mesh(fm, "mesh") or np.ones(1),
            ("mesh check", "np.unique"): checked_before,
            ("field file", "raw"): lambda: written(lambda p: write_vtu(p, fm, data)),
            ("field file", "meshio"): lambda: written(lambda p: meshio.write(p, to_meshio(fm, data), file_format="vtu",
                                                                             compression=None)),
            ("mesh read", "whole arrays"): lambda: msh22.read_binary(open(msh, "rb").read()).points,
            ("mesh read", "meshio"): lambda: meshio.gmsh.read(msh).points,
            ("dof basis", "one element"): lambda: dof_basis(mesh, vector).element_dofs,
            ("dof basis", "every element"): lambda: CellBasis(mesh, vector, quadrature=none,
                                                              disable_doflocs=True).element_dofs,
            ("mesh check 12-06", "chunks"): lambda: check_mesh(fm, "mesh") or np.ones(1),
            ("mesh check 12-06", "whole"): checked_12_05,
            ("mesh nodes", "mask"): nodes_by_mask, ("mesh nodes", "np.unique"): lambda: np.unique(fm.cells),
            ("METIS order", "one pass"): lambda: np.sort(nd_order(pattern.graph())),
            ("METIS order", "ten passes"): metis_default,
            ("shared facets", "keys"): lambda: np.full(1, 2.0) if _overlapping(fm, names) else np.ones(1),
            ("shared facets", "tuples"): shared_by_tuples,
            ("free DOFs", "mask"): lambda: complement(3 * n, held),
            ("free DOFs", "setdiff1d"): lambda: np.setdiff1d(np.arange(3 * n), held),
            ("stiffness", "chunks"): lambda: p1.stiffness(pattern, G, vol, lam, mu),
            ("stiffness", "at once"): stiffness_at_once}


def _part(mesh_file: str, part: str, variant: str, result_file: str) -> None:
    """In the new interpreter: time one variant, its result pickled for the comparison."""
    import gatetherm as gt

    gt.configure()
    with open(mesh_file, "rb") as f:
        fm = pickle.load(f)  # written by this script's parent
    make = variants(fm, os.path.dirname(result_file))[(part, variant)]
    with open("/proc/self/clear_refs", "w") as f:
        f.write("5")  # the peak resident memory (VmHWM) starts again from now
    before = _status("VmRSS")
    t0 = time.perf_counter()
    out = make()
    secs = time.perf_counter() - t0
    grown = _status("VmHWM") - before  # the peak above the start
    if isinstance(out, str):  # a field file
        import meshio

        out = meshio.read(out).point_data["u"]
    with open(result_file, "wb") as f:
        pickle.dump((secs, out, grown), f)


def _status(field: str) -> float:
    """A memory figure of /proc/self/status, bytes."""
    with open("/proc/self/status") as f:
        return 1024.0 * next(int(line.split()[1]) for line in f if line.startswith(field + ":"))


def _same(a, b) -> float:
    """Largest relative difference of two results (arrays, matrices or dicts of arrays)."""
    if isinstance(a, dict):
        return max(_same(a[c], b[c]) for c in a)
    a, b = (x.toarray() if sp.issparse(x) and x.shape[0] < 1000 else x for x in (a, b))
    return float(abs(a - b).max() / abs(b).max())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--factor", type=float, default=1.0,
                    help="the frame meshed with about this many times the default nodes (as benchmarks/scaling.py)")
    ap.add_argument("--parts", nargs="+", choices=list(PAIRS), default=list(PAIRS), help="the pairs to run (all)")
    ap.add_argument("--part", nargs=4, help=argparse.SUPPRESS)  # one variant, in a new interpreter
    args = ap.parse_args()
    if args.part:
        return _part(*args.part)
    import gatetherm as gt
    from gatetherm.geometry.mesh import save_mesh

    with tempfile.TemporaryDirectory() as folder:
        fm = gt.gate_frame(dim=3, config=sized_frame(3, args.factor, folder)[0]).mesh
    times: dict = {}
    peaks: dict = {}
    with tempfile.TemporaryDirectory() as tmp:
        mesh_file = os.path.join(tmp, "mesh.pkl")
        with open(mesh_file, "wb") as f:
            pickle.dump(fm, f)
        save_mesh(fm, os.path.join(tmp, "frame.msh"))  # the file the reads read
        print(f"3-D frame: {len(fm.points)} nodes, {len(fm.cells)} elements", flush=True)
        results = {}
        for r in range(args.rounds):
            for part in args.parts:
                pair = PAIRS[part]
                for variant in (pair if r % 2 == 0 else pair[::-1]):
                    out = os.path.join(tmp, "result.pkl")
                    subprocess.run([sys.executable, __file__, "--part", mesh_file, part, variant, out], check=True)
                    with open(out, "rb") as f:
                        secs, results[part, variant], grown = pickle.load(f)
                    times.setdefault((part, variant), []).append(secs)
                    peaks.setdefault((part, variant), []).append(grown / 1e9)
    print(f"medians of {args.rounds} rounds, each variant once in a new interpreter, s:")
    for part in args.parts:
        new, old = PAIRS[part]
        a, b = statistics.median(times[part, new]), statistics.median(times[part, old])
        print(f"  {part:16s} {new:19s} {a:6.3f}  {old:13s} {b:6.3f}  {a / b:5.2f} x  "
              f"(runs {', '.join(f'{t:.2f}' for t in times[part, new])} against "
              f"{', '.join(f'{t:.2f}' for t in times[part, old])}); largest relative difference "
              f"{_same(results[part, new], results[part, old]):.1e}; peak above the start "
              f"{statistics.median(peaks[part, new]):.3f} against {statistics.median(peaks[part, old]):.3f} GB")
    held = results.get(("stress rhs", "six matrices"))
    if held is not None:
        print(f"the six matrices of the stress projection held {held['GB']:.3f} GB; their products with one field "
              f"took {held['product s']:.3f} s (the last round)")


if __name__ == "__main__":
    main()
