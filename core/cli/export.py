"""``gatetherm export ccx``: a thermoelastic state as a CalculiX input deck, to check
gatetherm against an independent FE code."""
from __future__ import annotations

from gatetherm.cli.options import Progress, add_model_options, refuse_model_options

ORDER = 120  # its place in `gatetherm --help` (gatetherm.cli finds the command here)

DESCRIPTION = (
    "Write DIR/job.inp for CalculiX 2.20 (run 'ccx job' in DIR) and DIR/gatetherm.json with gatetherm's own "
    "displacements at the probes. Written: the mesh (3-D: C3D4, C3D10 at order 2; 2-D plane strain: CPE3/CPE6 of "
    "each region's thickness; 2-D plane stress: CPE3/CPE6 with the equivalent material E(1+2nu)/(1+nu)^2, "
    "nu/(1+nu), alpha(1+nu)/(1+2nu), the same in-plane displacements (CalculiX's CPS3/CPS6 are a slab of the "
    "section's thickness, plane stress only as it goes to 0); axisymmetric: CAX3/CAX6, x = r, y = z, loads of the "
    "whole ring), a material per region, fixed and prescribed supports (*BOUNDARY), the temperature field at one "
    "time (*TEMPERATURE; a contact conductance is the temperature jump on the two sides' nodes), gravity (*DLOAD "
    "GRAV), pressures (*DLOAD Pn on the element faces), tractions, boundary and point forces (*CLOAD of gatetherm's "
    "consistent nodal forces), bonded contacts (the two sides tied node to node, *EQUATION), a static step and "
    "*NODE PRINT of U at every probe (a probe that is not a node prints its element's nodes; gatetherm.json holds "
    "their shape-function weights, and the probe's displacement is their weighted sum, as gatetherm interpolates "
    "it). Refused, one line each: a case without E and nu, without a fixed support (no empty *BOUNDARY), an "
    "elastic foundation ([supports] foundation), a joint stiffness ([contacts] stiffness), a pressure on an inner "
    "boundary, a temperature per region ([temperature.regions]) that jumps on nodes two regions share.")


def register(sub) -> None:
    p = sub.add_parser("export", help="export a state for another code (ccx: CalculiX input deck)",
                       description=DESCRIPTION)
    p.add_argument("format", choices=("ccx",), help="ccx: CalculiX")
    p.add_argument("case", nargs="?", metavar="CASE.toml", help="a case file, 2-D or 3-D (else the paper's frame, "
                   "--condition)")
    p.add_argument("--condition", type=int, metavar="N", help="the paper's condition N (with --time)")
    p.add_argument("--time", type=float, metavar="MIN", help="time of the state, minutes (default: the run's end)")
    add_model_options(p)
    p.add_argument("--run", action="store_true", help="also run 'ccx job' in DIR (CalculiX installed) and print "
                   "CalculiX's relative displacements beside gatetherm's and the largest probe difference")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.set_defaults(func=run)


def run(args) -> int:
    import gatetherm.api as gt

    if (args.case is None) == (args.condition is None):
        raise gt.InputError("CASE.toml/--condition", "give one of the two", "e.g. --condition 1 --time 15")
    if args.case:
        refuse_model_options(args, "CASE.toml")
    res = gt.export_case(args.case, condition=args.condition, time=None if args.time is None else args.time * 60.0,
                         dim=args.dim, config=args.config, run=args.run, out=args.out,
                         on_progress=Progress(f"export {args.case or f'condition {args.condition}'}"))
    print(res.summary())
    return 0
