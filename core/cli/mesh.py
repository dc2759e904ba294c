"""``gatetherm mesh``: build the frame mesh, write it as .msh and .vtu, and the frame as a
case file (``case.toml`` with ``schedule.csv``: a paper condition) that ``gatetherm run``
runs and a user can copy."""
from __future__ import annotations

from gatetherm.cli.options import add_model_options

ORDER = 20  # its place in `gatetherm --help` (gatetherm.cli finds the command here)


def register(sub) -> None:
    p = sub.add_parser("mesh", help="mesh the paper's frame (a case file's mesh is made by run); write DIR/mesh.msh, "
                                    "mesh.vtu and the frame as DIR/case.toml")
    add_model_options(p)
    p.add_argument("--condition", type=int, default=1, metavar="N",
                   help="the paper's condition written as the case's schedule.csv (default 1)")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.set_defaults(func=run)


def run(args) -> int:
    import gatetherm.api as gt

    print(gt.mesh_frame(args.dim, args.config, args.condition, out=args.out).summary())
    return 0
