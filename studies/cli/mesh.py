"""``gatetherm mesh``: build the frame mesh and write it as .msh and .vtu."""
from __future__ import annotations

from gatetherm.geometry.build import build_mesh
from gatetherm.geometry.mesh import save_mesh
from gatetherm.studies.cli.options import add_model_options

#: What a run writes into --out; a rerun replaces all of it.
OUTPUTS = ("mesh.msh", "mesh.vtu")


def register(sub) -> None:
    p = sub.add_parser("mesh", help="mesh the frame; write DIR/mesh.msh and DIR/mesh.vtu")
    add_model_options(p)
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.set_defaults(func=run)


def run(args) -> int:
    from gatetherm.outdir import output_dir
    from gatetherm.studies.run.config import load_config

    cfg = load_config(args.config).model
    with output_dir(args.out, OUTPUTS, keep=(args.config,)) as out:
        fm = build_mesh(cfg.frame, args.dim, cfg.mesh)
        for name in OUTPUTS:
            save_mesh(fm, out / name)
            print(f"wrote {out / name}")
    c = fm.counts()
    print(f"{args.dim}-D frame: {c['nodes']} nodes, {c['elements']} elements")
    print(f"regions ({len(fm.regions)}): " + ", ".join(f"{k}={len(v)}" for k, v in fm.regions.items()))
    print(f"boundaries ({len(fm.boundaries)}): " + ", ".join(f"{k}={len(v)}" for k, v in fm.boundaries.items()))
    print(f"sensors ({len(fm.sensors)}): " + ", ".join(fm.sensors))
    return 0
