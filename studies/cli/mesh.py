"""``gatetherm mesh``: build the frame mesh and write it as .msh and .vtu."""
from __future__ import annotations

from pathlib import Path

from gatetherm.geometry.build import build_mesh
from gatetherm.geometry.mesh import save_mesh
from gatetherm.studies.cli.options import add_model_options


def register(sub) -> None:
    p = sub.add_parser("mesh", help="mesh the frame; write DIR/mesh.msh and DIR/mesh.vtu")
    add_model_options(p)
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.set_defaults(func=run)


def run(args) -> int:
    from gatetherm.studies.run.config import load_config

    cfg = load_config(args.config).model
    fm = build_mesh(cfg.frame, args.dim, cfg.mesh)
    out = Path(args.out)
    for name in ("mesh.msh", "mesh.vtu"):
        save_mesh(fm, out / name)
        print(f"wrote {out / name}")
    c = fm.counts()
    print(f"{args.dim}-D frame: {c['nodes']} nodes, {c['elements']} elements")
    print(f"regions ({len(fm.regions)}): " + ", ".join(f"{k}={len(v)}" for k, v in fm.regions.items()))
    print(f"boundaries ({len(fm.boundaries)}): " + ", ".join(f"{k}={len(v)}" for k, v in fm.boundaries.items()))
    print(f"sensors ({len(fm.sensors)}): " + ", ".join(fm.sensors))
    return 0
