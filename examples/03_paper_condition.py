"""The seed paper's condition 1 on its gate frame, and its beam theory against the FE model.

``gt.gate_frame(dim=2)`` is the paper's frame (two inverted-L cast-iron columns joined by a tie
bar, an oil tank in the tool-side leg) as a 2-D plane-stress case; in condition 1 oil pre-heated
to 40 °C circulates through the tank, the pump switched off and on every hour for 5 h. The paper's predictor is
δ = K_i (θ_A − θ_B) − K_C θ_C; the example takes K_i, K_C from the beam theory and from the FE
frame under the theory's load cases, prints δ's first peak and how far each static predictor is
from the FE δ, and draws the three (``paper_condition1.png``).

    python examples/03_paper_condition.py [OUT_DIR]
"""
import sys
import tempfile
from pathlib import Path

import gatetherm as gt
import numpy as np

out = Path(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="gatetherm-"))
case = gt.gate_frame(dim=2)
run = gt.run(case, gt.condition(1))
s = run.summary()
print(f"first peak of delta {s['first_peak_um']:.2f} um at {s['first_peak_min']:.0f} min")

rise = {k: run[f"theta_{k}_degC"] - run[f"theta_{k}_degC"][0] for k in "ABC"}
ax = gt.plot.series(run, "delta_um")
for source in ("theory", "fe"):
    Ki, Kc = gt.beam_coefficients(case, source)
    predicted = Ki * (rise["A"] - rise["B"]) - Kc * rise["C"]
    rms = np.sqrt(np.mean((predicted - run["delta_um"]) ** 2))
    print(f"{source:>6}: K_i {Ki:.2f} um/K, K_C {Kc:.2f} um/K, RMS against FE delta {rms:.2f} um")
    ax.plot(run.time / 3600, predicted, "--", label=f"K_i(θ_A−θ_B) − K_C θ_C, K from {source}")
ax.legend(fontsize="small")
ax.set_title("condition 1: FE δ and the static predictor")
gt.plot.save(ax, out / "paper_condition1.png")
print(f"figure: {out / 'paper_condition1.png'}")
