"""An assembly: two steel blocks through a bolted joint, heated at one end and pulled at the other.

``validation/examples/joint/case.toml`` (from ``docs/case-file.md``): a carbon-steel and a
stainless-steel block meet at a joint that conducts 2000 W/(m² K) and is an elastic layer; the hot
end is held at 100 °C and clamped, the cold end at 0 °C and pulled with 1 kN. Heat flows through
the blocks and the joint in series, so the mid-block temperatures have a closed form
(89.09 °C and 36.36 °C, a 5.45 K jump across the joint). Prints them against gatetherm's and the
end's displacement; draws the temperature and the von Mises stress (``assembly.png``).

    python examples/07_assembly.py [OUT_DIR]
"""
import sys
import tempfile
from pathlib import Path

import gatetherm as gt
from matplotlib.figure import Figure

out = Path(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="gatetherm-"))
case = gt.load_case(Path(__file__).resolve().parents[1] / "validation/examples/joint/case.toml")
run = gt.run(case)
probes = run.summary()["probes"]
q = 100.0 / (0.1 / 50 + 1 / 2000 + 0.1 / 15)  # W/m², through the series of resistances
for name, exact in (("a", 100 - q * 0.05 / 50), ("b", q * 0.05 / 15)):
    print(f"T_{name} {probes[name]['T_degC']:.4f} degC (closed form {exact:.4f} degC)")
print(f"end of the stainless block moves {probes['end']['ux_um']:.2f} um in x")

fig = Figure(figsize=(10, 3.2))
left, right = fig.subplots(1, 2)
gt.plot.field(run, "T", ax=left)
gt.plot.field(run, "von_mises", ax=right)
gt.plot.save(fig, out / "assembly.png")
print(f"figure: {out / 'assembly.png'}")
