"""Three parts of a 3-D run, each against the way it was made before, on the 3-D frame.

    python benchmarks/assembly_parts.py [--rounds 5]

Per round, in turn (the pairs interleaved): the elastic stiffness from the node-pair pattern with
the symmetric blocks found once (``p1.stiffness``) against all nine blocks summed; the stress
projection's right-hand sides per unit displacement applied element by element
(``stress.ElementStress``: set up free, one field's six components) against the six assembled
matrices of before (their assembly, one field's products); one field file written raw
(``geometry.vtu.write_vtu``) against meshio's VTU writer. Prints the medians, their ratios and
the largest difference of the results (docs/performance.md, "2026-12-04").
"""
from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time

import numpy as np


def timed(f):
    t0 = time.perf_counter()
    out = f()
    return time.perf_counter() - t0, out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args()
    import meshio

    import gatetherm as gt
    from gatetherm.geometry.mesh import to_meshio
    from gatetherm.geometry.vtu import write_vtu
    from gatetherm.solvers import p1
    from gatetherm.solvers.fem import to_skfem
    from gatetherm.solvers.stress import _INDEX, COMPONENTS, ElementStress

    gt.configure()
    fm = gt.gate_frame(dim=3).mesh
    mesh = to_skfem(fm)
    s = p1.simplices(mesh)
    G, vol, pattern, cells = s.G, s.vol, s.pattern, mesh.t.T
    rng = np.random.default_rng(0)
    lam, mu = rng.uniform(1.0, 2.0, len(vol)) * 6e10, rng.uniform(1.0, 2.0, len(vol)) * 4e10
    comps, k, n = COMPONENTS[(3, "stress")], 4, mesh.nvertices
    u = rng.normal(size=3 * n)
    data = {"T": rng.normal(size=n), "u": rng.normal(size=(n, 3)),
            **{f"sigma_{c}": rng.normal(size=n) for c in comps}, "von_mises": rng.normal(size=n)}
    print(f"3-D frame: {n} nodes, {len(vol)} elements, {pattern.nnz} node pairs", flush=True)

    def nine_blocks():  # p1.stiffness before: every block (a, b) summed, a, b = 0..2
        dot = p1.conduction(G, vol, mu)
        Gl, Gm = (lam * vol)[:, None, None] * G, (mu * vol)[:, None, None] * G

        def entry(a, b):
            out = Gl[:, :, a][:, :, None] * G[:, :, b][:, None, :]
            out += Gm[:, :, b][:, :, None] * G[:, :, a][:, None, :]
            return out + dot if a == b else out
        return pattern.blocks(entry, 3, 3)

    def assembled():  # stress._p1_recovery before: six matrices of 1 x 3 blocks per node pair
        def s_entry(i, j):
            def entry(_, b):
                sv = mu[:, None] * ((j == b) * G[:, :, i] + (i == b) * G[:, :, j]) + (lam[:, None] * G[:, :, b] if i == j else 0.0)
                return np.broadcast_to((vol / k)[:, None, None] * sv[:, None, :], (len(vol), k, k))
            return entry
        return {c: pattern.blocks(s_entry(*_INDEX[c]), 1, 3) for c in comps}

    element = ElementStress(cells, G, vol, lam, mu, comps, n)
    times: dict[str, list[float]] = {}
    worst = {"stiffness": 0.0, "right-hand sides": 0.0}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(args.rounds):
            t_new, K = timed(lambda: p1.stiffness(pattern, G, vol, lam, mu))
            t_old, K0 = timed(nine_blocks)
            worst["stiffness"] = max(worst["stiffness"], abs(K - K0).max() / abs(K0).max())
            t_set, held = timed(assembled)
            t_mat, by_matrix = timed(lambda: {c: held[c] @ u for c in comps})
            t_el, by_element = timed(lambda: element(u))
            worst["right-hand sides"] = max(worst["right-hand sides"], max(
                abs(by_element[c] - by_matrix[c]).max() / abs(by_matrix[c]).max() for c in comps))
            bytes_S = sum(m.data.nbytes + m.indices.nbytes + m.indptr.nbytes for m in held.values())
            held = None
            t_raw, _ = timed(lambda: write_vtu(os.path.join(tmp, "raw.vtu"), fm, data))
            t_mio, _ = timed(lambda: meshio.write(os.path.join(tmp, "meshio.vtu"), to_meshio(fm, data),
                                                  file_format="vtu", compression=None))
            for key, t in (("stiffness, symmetric blocks", t_new), ("stiffness, nine blocks", t_old),
                           ("stress rhs: assembly of the six matrices", t_set),
                           ("stress rhs: one field by the matrices", t_mat),
                           ("stress rhs: one field element by element", t_el),
                           ("field file, raw", t_raw), ("field file, meshio", t_mio)):
                times.setdefault(key, []).append(t)
        sizes = {f: os.path.getsize(os.path.join(tmp, f)) / 1e6 for f in ("raw.vtu", "meshio.vtu")}
    med = {key: statistics.median(v) for key, v in times.items()}
    print(f"medians of {args.rounds} rounds, s:")
    for key, t in med.items():
        print(f"  {key:45s} {t:7.3f}")
    print(f"stiffness: symmetric / nine {med['stiffness, symmetric blocks'] / med['stiffness, nine blocks']:.2f} x, "
          f"largest relative difference {worst['stiffness']:.1e}")
    print(f"stress rhs: the six matrices held {bytes_S / 1e9:.3f} GB; element by element one field costs "
          f"{med['stress rhs: one field element by element'] - med['stress rhs: one field by the matrices']:.3f} s more, "
          f"their assembly {med['stress rhs: assembly of the six matrices']:.3f} s once; largest relative difference "
          f"{worst['right-hand sides']:.1e}")
    print(f"field file: raw / meshio {med['field file, raw'] / med['field file, meshio']:.2f} x, "
          f"{sizes['raw.vtu']:.1f} MB against {sizes['meshio.vtu']:.1f} MB")


if __name__ == "__main__":
    main()
