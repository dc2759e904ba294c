"""A motor-spindle unit heated by its bearings, from the spindle's speed profile alone.

``validation/examples/spindle_unit/case.toml``: an axisymmetric shaft, housing and two bearings;
the schedule has one column, the speed ``n_spindle`` (1 h at 4000, 1 h at 8000 1/min, 1 h at
rest). Each bearing's loss is Palmgren's friction torque at that speed (``kind = "bearing"``),
the nose's film the rotating-cylinder correlation at the same speed, the housing cooled by a
jacket. Prints each bearing's loss at both speeds and the tool's axial growth; draws the losses
and the growth against time beside the temperature at the end of the 8000-1/min hour
(``spindle_unit.png``).

    python examples/08_spindle_unit.py [OUT_DIR]
"""
import sys
import tempfile
from pathlib import Path

import gatetherm as gt
from matplotlib.figure import Figure

out = Path(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="gatetherm-"))
case = gt.load_case(Path(__file__).resolve().parents[1] / "validation/examples/spindle_unit/case.toml")
run = gt.run(case)
t = run.time
for name in ("front_bearing", "rear_bearing"):
    P = run[f"P_{name}_W"]
    print(f"{name}: {P[t == 1800.0][0]:.1f} W at 4000 1/min, {P[t == 5400.0][0]:.1f} W at 8000 1/min")
growth = run["delta_um"]
print(f"tool growth {growth[t == 3600.0][0]:.2f} um after 1 h, {growth[t == 7200.0][0]:.2f} um after 2 h, "
      f"{growth[-1]:.2f} um after 1 h at rest")

fig = Figure(figsize=(10, 3.6))
left, mid, right = fig.subplots(1, 3, gridspec_kw={"width_ratios": [1.4, 1.4, 0.6]})
gt.plot.series(run, "P_front_bearing_W", "P_rear_bearing_W", ax=left)
left.set_ylabel("bearing loss (W)")
gt.plot.series(run, "delta_um", ax=mid)
mid.set_ylabel("tool growth (µm)")
gt.plot.field(run, "T", t=7200.0, ax=right)
gt.plot.save(fig, out / "spindle_unit.png")
print(f"figure: {out / 'spindle_unit.png'}")
