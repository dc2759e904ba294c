"""``gatetherm beam``: the paper's normalised beam-theory coefficients (eqs 27-29, Figs. 7-8)."""
from __future__ import annotations

import argparse
import math

ORDER = 40  # its place in `gatetherm --help` (gatetherm.cli finds the command here)


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "beam",
        help="normalised K_i and K_C of the beam theory (l1 = l/2, same material)",
        description="Print K_i/(3 alpha l^2/8h) and K_C/(alpha l_C) of the paper's "
        "beam theory (eqs 27-29) for a tie bar at l/l4 and stiffness ratio beta.",
    )
    p.add_argument("--l-over-l4", type=float, required=True, metavar="A",
                   help="a = l/l4: cutting-area height over tie-bar height (> 0)")
    p.add_argument("--beta", type=float, required=True, metavar="B",
                   help="beta = 3 I l_C / (A_C l^3) (>= 0; inf = no tie bar)")
    p.add_argument("--json", action="store_true",
                   help='print one JSON object {"Ki_norm": ..., "Kc_norm": ...}')
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import gatetherm.api as gt

    a, b = args.l_over_l4, args.beta
    if not (math.isfinite(a) and a > 0):
        raise gt.InputError("--l-over-l4", f"must be a finite number > 0, got {a}",
                            "pass l/l4, e.g. --l-over-l4 1.5")
    if not b >= 0:  # also rejects nan
        raise gt.InputError("--beta", f"must be >= 0, got {b}", "pass e.g. --beta 0.1")
    print(gt.beam_normalised(a, b).summary(as_json=args.json))
    return 0
