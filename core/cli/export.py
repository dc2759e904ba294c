"""``gatetherm export ccx``: a thermoelastic state as a CalculiX input deck, to check
gatetherm against an independent FE code."""
from __future__ import annotations


from gatetherm import InputError, write_text_atomic
from gatetherm.checks import json_text
from gatetherm.cli.options import add_model_options, refuse_model_options

#: What an export writes into --out; a rerun replaces all of it (ccx's own files are left).
OUTPUTS = ("job.inp", "gatetherm.json")


def register(sub) -> None:
    p = sub.add_parser("export", help="export a state for another code (ccx: CalculiX input deck)",
                       description="Write DIR/job.inp for CalculiX 2.20 (mesh, materials, supports, the temperature "
                       "field at one time, a static step, *NODE PRINT of U at every probe; run 'ccx job' in DIR) "
                       "and DIR/gatetherm.json with gatetherm's own displacements at the probes.")
    p.add_argument("format", choices=("ccx",), help="ccx: CalculiX")
    p.add_argument("case", nargs="?", metavar="CASE.toml", help="a case file (else the paper's frame, --condition)")
    p.add_argument("--condition", type=int, metavar="N", help="the paper's condition N (with --time)")
    p.add_argument("--time", type=float, metavar="MIN", help="time of the state, minutes (transient runs)")
    add_model_options(p)
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.set_defaults(func=run)


def run(args) -> int:
    import gatetherm as gt
    from gatetherm.outdir import output_dir
    from gatetherm.studies.run.ccx import check_time, export_state
    from gatetherm.studies.run.conditions import condition as check_condition

    if (args.case is None) == (args.condition is None):
        raise InputError("CASE.toml/--condition", "give one of the two", "e.g. --condition 1 --time 15")
    if args.case:
        refuse_model_options(args, "CASE.toml")
    if args.condition is not None:  # 0 is no condition (it ran condition 1)
        check_condition(args.condition)
    case = gt.load_case(args.case) if args.case else gt.gate_frame(args.dim, args.config, args.condition)
    what = str(args.case) if args.case else f"condition {args.condition}"
    if case.dim != 3:  # before the run
        raise InputError(f"{args.case}: mesh" if args.case else "--dim", "CalculiX export is for 3-D models",
                         "give a 3-D mesh" if args.case else "use --dim 3")
    schedule = case.schedule
    t = float(schedule.times[-1]) if args.time is None else args.time * 60.0
    t = check_time(schedule, t)
    with output_dir(args.out, OUTPUTS, keep=(args.config, *case.files)) as out:
        inp, info = export_state(case, schedule, t, f"gatetherm {what}, t = {t / 60:g} min")
        write_text_atomic(out / "job.inp", inp)
        write_text_atomic(out / "gatetherm.json", json_text(info, "gatetherm.json", indent=2))
    print(f"wrote {args.out}/job.inp ({info['vertices']} vertices) and gatetherm.json; run: cd {args.out} && ccx job")
    for name, v in info["relative_m"].items():
        print(f"gatetherm {name}: {v * 1e6:.6g} um")
    return 0
