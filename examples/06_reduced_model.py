"""Building and checking a reduced model: 2036 FE nodes down to 30 states, checked against FE.

``gt.reduce`` reduces the C-frame's heat model by balanced truncation (pyMOR) to a linear
system of 30 states whose outputs are the case's probes, δ and θ; ``gt.check_rom`` runs the full
FE model on the case's schedule and compares every output. Prints the error bound, the largest
errors of δ and θ_C and the time of a reduced 6-h run against the FE one; draws the Hankel
singular values that set the truncation and the largest error of every output
(``reduced_model.png``).

    python examples/06_reduced_model.py [OUT_DIR]
"""
import sys
import tempfile
from pathlib import Path

import gatetherm as gt
from matplotlib.figure import Figure

out = Path(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="gatetherm-"))
case = gt.load_case(Path(__file__).resolve().parents[1] / "validation/examples/c_frame/case.toml")
reduction = gt.reduce(case, states=30)
check, = gt.check_rom(case, reduction.rom)
bound = max(reduction.error_bound.values())
print(f"{reduction.rom.states} states, balanced-truncation bound {bound:.1e}; "
      f"largest error against FE: delta {check.errors['delta_um']:.4f} um, "
      f"theta_C {check.errors['theta_C_degC']:.5f} K; 6-h run {check.rom_ms:.1f} ms against {check.fe_seconds:.2f} s")

fig = Figure(figsize=(10, 4))
left, right = fig.subplots(1, 2)
for mode, values in reduction.hankel.items():
    left.semilogy(range(1, len(values) + 1), values, "o-", ms=3, label=mode or "the one mode (no pump)")
left.set(xlabel="index", ylabel="Hankel singular value", title="balanced truncation")
left.legend(fontsize="small")
names = [n for n in check.errors if n.endswith(("_um", "_degC"))]
right.barh(names, [check.errors[n] for n in names])
right.set(xscale="log", xlabel="largest |reduced − FE| (µm or K)", title="against the FE run")
right.tick_params(axis="y", labelsize=7)
gt.plot.save(fig, out / "reduced_model.png")
print(f"figure: {out / 'reduced_model.png'}")
