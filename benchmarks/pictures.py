"""What each picture of a 2-D run costs, and two ways of drawing them that were tried.

    python benchmarks/pictures.py [--rounds 5] [--deformed-3d]

One condition-1 run of ``gate_frame(dim=2)`` (the states of the deformed picture kept), then
per round (interleaved) each picture ``gatetherm simulate`` writes, drawn on a new figure by the library's
plot function: the medians of plotting, ``tight_layout`` and drawing with writing the PNG (to
memory) at 200 dpi (:data:`gatetherm.validation.plots.DPI`), 150 and 100 dpi, 200 dpi with
PNG compression level 1, and 200 dpi by the library's writer (:func:`gatetherm.validation.plots.save`:
zlib's run-length strategy; to a file). Last, the four drawn in turn against in four threads at once
(docs/performance.md, "The 2-D default condition").

``--deformed-3d`` instead: one condition-1 run of ``gate_frame(dim=3)``, then per round
(interleaved) its deformed picture drawn as a painting process gets it (its arguments pickled and
unpickled, then :func:`~gatetherm.validation.plots.field.render_deformed` and the PNG) from the
body's surface (``deformed``: what the library hands the painter) and from the whole mesh and
its nodal fields (before): the medians, the pickled sizes and how many pixels differ.
"""
from __future__ import annotations

import argparse
import io
import os
import statistics
import tempfile
import threading
import time

import numpy as np


def pictures(res):
    """``{name: make}``: a function drawing each picture of the run ``res`` on a new figure."""
    from gatetherm.validation.plots.field import draw_deformed
    from gatetherm.validation.plots.run import plot_channels, plot_fluids, plot_response

    run, cols = res.scenario, res.columns
    t = res.summary()["first_peak_min"] * 60.0
    return {"channels": lambda: plot_channels(cols, "x"), "response": lambda: plot_response(cols, "x"),
            "oil_temperatures": lambda: plot_fluids(cols, run.model.problem, "x"),
            "deformed": lambda: draw_deformed(run, t, lambda s: "x")}


def draw(make, dpi=200, compress=6, library=False) -> tuple[float, float, float]:
    """Seconds to plot, lay out and draw + write one picture (``library``: by ``save``, to a file)."""
    t0 = time.perf_counter()
    fig = np.asarray(make(), dtype=object).flat[0].figure
    t1 = time.perf_counter()
    fig.tight_layout()
    t2 = time.perf_counter()
    if library:
        from gatetherm.validation.plots import save

        with tempfile.TemporaryDirectory() as tmp:
            save(fig, os.path.join(tmp, "p.png"), dpi=dpi, tight=False)
    else:
        fig.savefig(io.BytesIO(), format="png", dpi=dpi, pil_kwargs={"compress_level": compress})
    return t1 - t0, t2 - t1, time.perf_counter() - t2


def deformed_3d(rounds: int) -> None:
    """The 3-D deformed picture from the surface and from the whole mesh (see the module's text)."""
    import pickle

    import matplotlib.image

    import gatetherm as gt
    from gatetherm.studies.run.output import nearest_state, nodal_fields
    from gatetherm.validation.plots import save
    from gatetherm.validation.plots.field import deformed, render_deformed

    res = gt.run(gt.gate_frame(3))
    run = res.scenario
    t = nearest_state(run, res.summary()["first_peak_min"] * 60.0)[0]
    surface, fields, title, scale = deformed(run, t, "x")
    ways = {"surface": (surface, fields), "whole mesh": (run.model.fmesh, nodal_fields(run.model, dict(
        run.result.states)[t], stress=False))}
    seen = {name: [] for name in ways}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(rounds + 1):  # the first round warms pyvista up
            for name, args in ways.items():
                t0 = time.perf_counter()
                blob = pickle.dumps(args)
                save(render_deformed(*pickle.loads(blob), title, scale), os.path.join(tmp, f"{name}.png"))
                if r:
                    seen[name].append(time.perf_counter() - t0)
        a, b = (np.round(255 * matplotlib.image.imread(os.path.join(tmp, f"{n}.png"))) for n in ways)
    for name, args in ways.items():
        print(f"{name:10s} {statistics.median(seen[name]):.3f} s (runs {', '.join(f'{x:.3f}' for x in seen[name])}), "
              f"pickled {len(pickle.dumps(args)) / 1e6:.1f} MB")
    d = np.abs(a - b).max(axis=-1)
    print(f"pixels differing: {np.count_nonzero(d)} of {d.size}, by more than one level: {np.count_nonzero(d > 1)}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--deformed-3d", action="store_true", help="the 3-D deformed picture: surface or whole mesh")
    args = ap.parse_args()
    if args.deformed_3d:
        deformed_3d(args.rounds)
        return

    import gatetherm as gt

    case = gt.gate_frame(2)
    times = [float(t) for t in case.schedule.times]
    res = gt.run(case, case.schedule, keep=[t for t in times if t % 300.0 == 0.0] + times[-1:])
    makes = pictures(res)
    t0 = time.perf_counter()
    draw(makes["channels"])  # matplotlib's import and first draw
    print(f"matplotlib's import and the first picture: {time.perf_counter() - t0:.3f} s")
    variants = {"200 dpi": {}, "150 dpi": {"dpi": 150}, "100 dpi": {"dpi": 100}, "200 dpi, compression 1": {"compress": 1},
                "200 dpi, library writer": {"library": True}}
    seen = {(label, name): [] for label in variants for name in makes}
    for _ in range(args.rounds):  # interleaved: each round draws every variant in turn
        for label, kw in variants.items():
            for name, make in makes.items():
                seen[label, name].append(draw(make, **kw))
    for label in variants:
        parts = {name: np.median(seen[label, name], axis=0) for name in makes}
        for name, (plot, tight, png) in parts.items():
            print(f"{label:24s} {name:17s} plot {plot:.3f} s, tight layout {tight:.3f} s, draw and PNG {png:.3f} s")
        print(f"{label:24s} all four          {sum(map(sum, parts.values())):.3f} s")
    serial, threaded = [], []
    for _ in range(args.rounds):
        t0 = time.perf_counter()
        for make in makes.values():
            draw(make)
        serial.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        workers = [threading.Thread(target=draw, args=(make,)) for make in makes.values()]
        for w in workers:
            w.start()
        for w in workers:
            w.join()
        threaded.append(time.perf_counter() - t0)
    print(f"the four in turn {statistics.median(serial):.3f} s, in four threads {statistics.median(threaded):.3f} s "
          f"(medians of {args.rounds})")


if __name__ == "__main__":
    main()
