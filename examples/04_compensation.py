"""Compensating the C-frame's drift: the paper's adaptive predictor, a regression, a reduced model.

The C-frame's run drives its actuator (the case's ``[actuator]``: a piezo stack with dead band and
hysteresis) with three predictors of δ: ``paper`` (the seed paper's δ = R_i K_i (θ_A − θ_B) −
R_C K_C θ_C, K fitted, R adapted on line, updated every 5 min), ``mlr`` (a static regression on
θ_A, θ_B, θ_C) and ``rom`` (a reduced heat model with a Kalman filter and predictive updates).
Prints each method's residual band (what is left of δ), its updates and what it left out (the
regression gives no weight to a thermocouple spanning under ten resolutions); draws the
compensated δ (``compensation.png``).

    python examples/04_compensation.py [OUT_DIR]
"""
import sys
import tempfile
from pathlib import Path

import gatetherm as gt

out = Path(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="gatetherm-"))
case = gt.load_case(Path(__file__).resolve().parents[1] / "validation/examples/c_frame/case.toml")
run = gt.run(case, keep=())
ax = gt.plot.series(run, "delta_um")
for method in ("paper", "mlr", "rom"):
    result = gt.compensate(run, method=method)
    s = result.summary
    print(f"{method:>5}: residual band {s['residual_band_um']:.2f} um, prediction error band "
          f"{s['prediction_error_band_um']:.2f} um, {s['updates']} updates")
    for note in s["warnings"]:  # what the method left out or bounded, and why
        print(f"       {note}")
    ax.plot(result.loop.t_s / 3600, result.loop.delta_comp_um, label=f"compensated, {method}")
ax.legend(fontsize="small")
ax.set_title(f"C-frame: δ = {run['delta_um'].max():.0f} µm at most, and what is left")
gt.plot.save(ax, out / "compensation.png")
print(f"figure: {out / 'compensation.png'}")
