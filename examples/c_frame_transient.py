"""The C-frame machining centre, 6 h transient: δ between tool and table, and a field.

The shipped case ``validation/examples/c_frame/case.toml`` (2-D plane stress, a spindle heated by
120 W and 200 W phases from its schedule, the room warming) run through the API. The example
prints δ and the spindle housing's temperature at 6 h and the largest δ, and draws δ against time
beside the temperature field at the end (``c_frame_transient.png``).
"""
import gatetherm as gt
import numpy as np
from gallery import field_axes, output_folder, save, shipped
from matplotlib.figure import Figure

out = output_folder()
case = gt.load_case(shipped("examples/c_frame/case.toml"))
run = gt.run(case)
delta = run["delta_um"]
print(f"after {run.time[-1] / 3600:.0f} h: delta = {delta[-1]:.2f} um, spindle housing {run['T_TS_degC'][-1]:.2f} °C;"
      f" largest delta {delta.max():.2f} um at {run.time[np.argmax(delta)] / 3600:.2f} h")

fig = Figure(figsize=(11, 4.5))
left, right = fig.subplots(1, 2, width_ratios=(1, 1.3))
gt.plot.series(run, "delta_um", "drift_x_um", ax=left)
left.set_title("tool against table")
field_axes(right, case.mesh, run.field("T"), "T [°C]")
right.set_title(f"temperature at {run.time[-1] / 3600:.0f} h")
save(fig, out, "c_frame_transient.png")
