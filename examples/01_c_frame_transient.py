"""A C-frame machining centre, 6 h transient: the tool drifts towards the table as the spindle heats.

The shipped case ``validation/examples/c_frame/case.toml`` (2-D plane stress: a grey-iron bed,
column and head, a steel spindle housing heated 120 W for 2 h and 200 W for 2 h from its schedule,
the room warming 0.25 K/h) run through the API. Prints δ (tool–table approach) and the spindle
housing's temperature at 6 h and the largest δ; draws δ against time beside the temperature field
at the end (``c_frame_transient.png``, the README's picture).

    python examples/01_c_frame_transient.py [OUT_DIR]
"""
import sys
import tempfile
from pathlib import Path

import gatetherm as gt
from matplotlib.figure import Figure

out = Path(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="gatetherm-"))
case = gt.load_case(Path(__file__).resolve().parents[1] / "validation/examples/c_frame/case.toml")
run = gt.run(case)
delta = run["delta_um"]
print(f"after {run.time[-1] / 3600:.0f} h: delta {delta[-1]:.2f} um, spindle housing {run['T_TS_degC'][-1]:.2f} degC; "
      f"largest delta {delta.max():.2f} um at {run.time[delta.argmax()] / 3600:.2f} h")

fig = Figure(figsize=(11, 4.2))
left, right = fig.subplots(1, 2, width_ratios=(1, 1.3))
gt.plot.series(run, "delta_um", "drift_x_um", ax=left).set_title("tool against table")
gt.plot.field(run, "T", ax=right)
gt.plot.save(fig, out / "c_frame_transient.png")
print(f"figure: {out / 'c_frame_transient.png'}")
