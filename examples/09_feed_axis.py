"""A feed axis driven by an NC program: a ball screw's nut and a guide's carriage that travel.

``validation/examples/feed_axis/``: ``program.nc`` (strokes of the table at 3, 6 and 12 m/min with
dwells) becomes a schedule of the axis position and velocity (``gt.nc_schedule``, run 20 times
back to back: 62.5 min); the nut's loss (preload drag and load friction at the screw's speed)
travels along the screw with the table, the carriage's along its rail, the screw's two bearings
turn at its speed. Prints each element's mean loss and the screw's growth from its fixed bearing
to its far end after the hour; draws the growth against time beside the temperature at
the end (``feed_axis.png``).

    python examples/09_feed_axis.py [OUT_DIR]
"""
import sys
import tempfile
from pathlib import Path

import gatetherm as gt
from matplotlib.figure import Figure

out = Path(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="gatetherm-"))
here = Path(__file__).resolve().parents[1] / "validation/examples/feed_axis"
schedule = gt.nc_schedule(here / "program.nc", step_s=0.5, repeat=20)
print(f"program: {schedule.time_s[-1]:.1f} s, {len(schedule)} samples")
run = gt.run(gt.load_case(here / "case.toml"))
losses = run.summary()["losses"]
print("mean losses: " + ", ".join(f"{k[2:-2]} {v['mean_W']:.2f} W" for k, v in losses.items()))
print(f"screw growth after 1 h: {run['delta_um'][-1]:.1f} um, screw end at {run['T_screw_end_degC'][-1]:.2f} degC")

fig = Figure(figsize=(10, 3.6))
left, right = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.0, 1.6]})
gt.plot.series(run, "delta_um", ax=left)
left.set_ylabel("screw growth (µm)")
gt.plot.field(run, "T", t=run.time[-1], ax=right)
gt.plot.save(fig, out / "feed_axis.png")
print(f"figure: {out / 'feed_axis.png'}")
