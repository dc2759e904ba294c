"""NAFEMS T4: steady heat conduction with convection, a published benchmark as a case file.

A 0.6 m x 1 m plate at 100 °C on one edge, cooled by a 750 W/(m² K) film to 0 °C on two others
(``validation/nafems/t4.toml`` and its ``t4.geo``). The benchmark's target is T = 18.25 °C at the
point E; the example prints gatetherm's value and its error and draws the temperature field
(``nafems_t4.png``).

    python examples/02_nafems_t4.py [OUT_DIR]
"""
import sys
import tempfile
from pathlib import Path

import gatetherm as gt

out = Path(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="gatetherm-"))
case = gt.load_case(Path(__file__).resolve().parents[1] / "validation/nafems/t4.toml")
run = gt.run(case)
T = run.summary()["probes"]["target"]["T_degC"]
print(f"T at E: {T:.3f} degC (target 18.25 degC, error {100 * (T / 18.25 - 1):+.2f} %), {len(case.mesh.points)} nodes")

ax = gt.plot.field(run, "T")
ax.plot(*case.mesh.sensor_xyz("target")[:2], "c*", ms=12)
ax.set_title("NAFEMS T4: steady temperature, E marked")
gt.plot.save(ax, out / "nafems_t4.png")
print(f"figure: {out / 'nafems_t4.png'}")
