"""``gatetherm reduce``: a reduced-order model of the frame's heat model, checked against FE.

Writes ``DIR/rom.npz`` (continuous-time ``A_on, B_on, A_off, B_off`` with E = identity, ``C``,
``T0``, string arrays ``inputs`` and ``outputs``; outputs are rises from T0 in K, δ in µm; the
zero state is the frame at T0), ``DIR/rom.key`` (by which ``gatetherm compensate --method rom
--out DIR`` recognises it as the model it would build) and, last, ``DIR/summary.json`` (states,
the error estimates, timings and, for conditions 1-3, ``max_delta_error_um`` against the full
FE run).
"""
from __future__ import annotations

import dataclasses
import time
from pathlib import Path

from gatetherm import InputError
from gatetherm.studies.cli.options import add_model_options

MAX_STATES = 200
#: What a run writes into --out; a rerun replaces all of it.
OUTPUTS = ("rom.npz", "rom.key", "summary.json")


def register(sub) -> None:
    p = sub.add_parser("reduce", help="reduced-order heat model (balanced truncation), checked on conditions 1-3",
                       description=__doc__.splitlines()[0])
    add_model_options(p)
    p.add_argument("--states", type=int, default=30, metavar="N", help="states of the reduced model (default 30)")
    p.add_argument("--no-check", action="store_true", help="skip the full FE runs of conditions 1-3")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.set_defaults(func=run)


def run(args) -> int:
    from gatetherm.outdir import output_dir
    from gatetherm.studies.run.config import load_config

    if not 2 <= args.states <= MAX_STATES:
        raise InputError("--states", f"{args.states} is outside 2..{MAX_STATES}", "e.g. --states 30")
    cfg = load_config(args.config)
    with output_dir(args.out, OUTPUTS, keep=(args.config,)) as out:
        return _reduce(args, cfg, out)


def _reduce(args, cfg, out: Path) -> int:
    from gatetherm.studies.run.output import write_json
    from gatetherm.studies.run.reduce import build_rom, check, rom_key, save_rom
    from gatetherm.studies.run.scenario import ScenarioCache

    cache = ScenarioCache()
    t0 = time.perf_counter()
    red = build_rom(cfg, args.dim, args.states, cache)
    seconds = time.perf_counter() - t0
    save_rom(red.rom, rom_key(cfg, args.dim, args.states), out)
    checks = [] if args.no_check else check(cfg, args.dim, red.rom, cache=cache)
    summary = {"states": red.rom.states, "dim": args.dim, "config": cfg.source,
               "nodes_full": int(red.basis.shape[0]), "inputs": list(red.rom.inputs), "outputs": list(red.rom.outputs),
               "error_bound_bt": red.error_bound, "static_delta_gain_error_um_per_K": red.static_gain_error,
               "hankel_singular_values": red.hankel, "reduction_seconds": round(seconds, 2),
               "seconds": {k: round(v, 2) for k, v in red.seconds.items()},
               "conditions": {str(c.condition): dataclasses.asdict(c) for c in checks}}
    if checks:
        summary["max_delta_error_um"] = max(c.max_delta_error_um for c in checks)
    write_json(out / "summary.json", summary)
    print(f"wrote {out}/rom.npz, summary.json: {red.rom.states} states from {red.basis.shape[0]} unknowns "
          f"in {seconds:.1f} s; BT bound on {red.error_bound['on']:.3g} / off {red.error_bound['off']:.3g}")
    for c in checks:
        print(f"condition {c.condition}: max |δ_rom − δ_FE| = {c.max_delta_error_um:.3f} µm, "
              f"θ {c.max_theta_error_K:.3f} K; 5-h run {c.rom_ms:.2f} ms (FE {c.fe_seconds:.1f} s)")
    return 0
