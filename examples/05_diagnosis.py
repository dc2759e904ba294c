"""Diagnosing a hidden effect: a heat source the model does not know, found from noisy data.

A "measurement" of the C-frame is made with 40 W heating its arm (the headstock), which the case
does not have, recorded at the sensors' resolution (0.1 µm, 0.05 K) with noise. ``gt.diagnose``
replays the case with the measured inputs, finds where model and data disagree, and looks for the
missing piece among hypotheses of the case (here, to keep it short: a heat source in the
column, the arm or the table, the free surfaces' film coefficient and the spindle's power; by
default every effect, parameter and sensor fault the case lists). Prints the verdict and the
piece it names with its fitted value; draws the residuals per channel (``diagnosis.png``).

    python examples/05_diagnosis.py [OUT_DIR]
"""
import csv
import sys
import tempfile
from pathlib import Path

import gatetherm as gt
import numpy as np

out = Path(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="gatetherm-"))
out.mkdir(parents=True, exist_ok=True)
case = gt.load_case(Path(__file__).resolve().parents[1] / "validation/examples/c_frame/case.toml")
truth = gt.run(case, effects={"heat_source@arm": 40.0}, keep=())

rng = np.random.default_rng(7)
resolution = {"delta_um": 0.1, "theta_A_degC": 0.05, "theta_B_degC": 0.05, "theta_C_degC": 0.05}
columns = {"time_s": truth.time, "spindle_W": truth["spindle_W"], "ambient_degC": truth["ambient_degC"]}
for name, r in resolution.items():
    columns[name] = np.round((truth[name] + rng.normal(0.0, r, len(truth.time))) / r) * r
measured = out / "measured.csv"
with open(measured, "w", newline="") as f:
    f.write("# format: gatetherm-timeseries/1\n")
    writer = csv.writer(f)
    writer.writerow(columns)
    writer.writerows(zip(*(np.round(v, 6) for v in columns.values())))

d = gt.diagnose(case, measured, effects=("heat_source@column", "heat_source@arm", "heat_source@table"),
                parameters=("film_free", "source_spindle"), sensors=False, p2_check=False)
pieces = ", ".join(f"{p.piece.name} = {p.value:.1f} ± {p.sigma:.1f}" for p in d.pieces)
print(f"verdict: {d.verdict}; pieces: {pieces}")
axes = gt.plot.residuals(d)
gt.plot.save(axes, out / "diagnosis.png")
print(f"figure: {out / 'diagnosis.png'}")
