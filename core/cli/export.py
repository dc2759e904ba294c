"""``gatetherm export ccx``: a thermoelastic state as a CalculiX input deck, to check
gatetherm against an independent FE code."""
from __future__ import annotations

from gatetherm import InputError
from gatetherm.cli.options import add_model_options, refuse_model_options

#: What an export writes into --out; a rerun replaces all of it (ccx's own files are left).
OUTPUTS = ("job.inp", "gatetherm.json", "ccx.log")

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
    import gatetherm as gt
    from gatetherm.outdir import output_dir
    from gatetherm.studies.run.ccx import check_time
    from gatetherm.studies.run.conditions import condition as check_condition

    if (args.case is None) == (args.condition is None):
        raise InputError("CASE.toml/--condition", "give one of the two", "e.g. --condition 1 --time 15")
    if args.case:
        refuse_model_options(args, "CASE.toml")
    if args.condition is not None:  # 0 is no condition (it ran condition 1)
        check_condition(args.condition)
    case = gt.load_case(args.case) if args.case else gt.gate_frame(args.dim, args.config, args.condition)
    what = str(args.case) if args.case else f"condition {args.condition}"
    schedule = case.schedule
    t = check_time(schedule, float(schedule.times[-1]) if args.time is None else args.time * 60.0)
    with output_dir(args.out, OUTPUTS, keep=(args.config, *case.files)) as out:
        info = gt.export_ccx(case, out, t, schedule=schedule, title=f"gatetherm {what}, t = {t / 60:g} min",
                             run=args.run)
    print(f"wrote {args.out}/job.inp ({info['element']}, {info['nodes']} nodes) and gatetherm.json"
          + ("" if args.run else f"; run: cd {args.out} && ccx job"))
    ccx = info.get("calculix")
    for name, v in info["relative_m"].items():
        print(f"gatetherm {name}: {v * 1e6:.6g} um" + (f", CalculiX {ccx['relative_m'][name] * 1e6:.6g} um "
                                                      f"({ccx['relative_m'][name] / v - 1:+.1e})" if ccx and v else ""))
    if ccx:
        print(f"CalculiX against gatetherm at the probes: largest difference {ccx['worst']:.1e} of the largest "
              "displacement")
    return 0
