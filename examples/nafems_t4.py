"""NAFEMS T4, steady heat conduction with convection: a case file run through the API.

A 0.6 m x 1 m plate at 100 °C on one edge, cooled by a 750 W/(m² K) film on two others. The
benchmark's target is T = 18.25 °C at the point E; the example prints gatetherm's value and
its error and draws the temperature field (``nafems_t4.png``).
"""
import gatetherm as gt
from gallery import field_axes, output_folder, save, shipped
from matplotlib.figure import Figure

out = output_folder()
case = gt.load_case(shipped("nafems/t4.toml"))
run = gt.run(case)
T = run.summary()["probes"]["target"]["T_degC"]
print(f"T at E: {T:.3f} °C (target 18.25 °C, error {100 * (T / 18.25 - 1):+.3f} %), {len(case.mesh.points)} nodes")

fig = Figure(figsize=(5, 6))
ax = field_axes(fig.add_subplot(), case.mesh, run.field("T"), "T [°C]")
ax.plot(*case.mesh.sensor_xyz("target")[:2], "c*", ms=12)
ax.set_title("NAFEMS T4: steady temperature")
save(fig, out, "nafems_t4.png")
