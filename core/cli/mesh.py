"""``gatetherm mesh``: build the frame mesh, write it as .msh and .vtu, and the frame as a
case file (``case.toml`` with ``schedule.csv``: a paper condition) that ``gatetherm run``
runs and a user can copy."""
from __future__ import annotations

from pathlib import Path

from gatetherm.geometry.mesh import save_mesh
from gatetherm.cli.options import add_model_options

#: What a run writes into --out; a rerun replaces all of it.
OUTPUTS = ("mesh.msh", "mesh.vtu", "case.toml", "schedule.csv")


def register(sub) -> None:
    p = sub.add_parser("mesh", help="mesh the frame; write DIR/mesh.msh, mesh.vtu and the frame as DIR/case.toml")
    add_model_options(p)
    p.add_argument("--condition", type=int, default=1, metavar="N",
                   help="the paper's condition written as the case's schedule.csv (default 1)")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.set_defaults(func=run)


def run(args) -> int:
    import gatetherm as gt
    from gatetherm.outdir import output_dir
    from gatetherm.studies.run.frame_case import write_frame_case

    from gatetherm.studies.run.conditions import condition as check_condition

    check_condition(args.condition)  # a bad number fails (naming --condition) before the model is built
    with output_dir(args.out, OUTPUTS, keep=(args.config,)) as out:
        case = gt.gate_frame(args.dim, args.config, args.condition)
        fm = case.mesh
        for name in OUTPUTS[:2]:
            save_mesh(fm, out / name)
            print(f"wrote {Path(args.out) / name}")
        write_frame_case(case, args.condition, out)
    out = Path(args.out)
    print(f"wrote {out / 'case.toml'} and {out / 'schedule.csv'} (the frame as a case: gatetherm run {out / 'case.toml'})")
    c = fm.counts()
    print(f"{args.dim}-D frame: {c['nodes']} nodes, {c['elements']} elements")
    print(f"regions ({len(fm.regions)}): " + ", ".join(f"{k}={len(v)}" for k, v in fm.regions.items()))
    print(f"boundaries ({len(fm.boundaries)}): " + ", ".join(f"{k}={len(v)}" for k, v in fm.boundaries.items()))
    print(f"sensors ({len(fm.sensors)}): " + ", ".join(fm.sensors))
    return 0
