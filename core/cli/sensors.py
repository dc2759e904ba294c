"""``gatetherm sensors``: where to put the thermocouples of any case (or the paper's frame), from its
reduced model: the surface points whose temperatures predict every relative displacement best on
held-out duty cycles (docs/sensors.md; the library: gatetherm.place_sensors).

Writes ``DIR/sensors.toml`` (the chosen points as ``[probes]`` to paste into a case),
``DIR/model.json``, ``DIR/curve.csv``, ``DIR/curve.png``, ``DIR/machine.png`` and, last,
``DIR/summary.json`` (:func:`gatetherm.api.write_placement`).
"""
from __future__ import annotations

from gatetherm.api import POSITIVE, InputError, Range
from gatetherm.api.sensors import OUTPUTS, sensor_study
from gatetherm.cli.options import Progress, add_model_options, number, refuse_model_options

ORDER = 110  # its place in `gatetherm --help` (gatetherm.cli finds the command here)

__all__ = ["OUTPUTS", "register", "run"]
COUNT, LOADS, STATES = Range(1, 50, whole=True), Range(0, 500, whole=True), Range(2, 200, whole=True)
NOISE, LENGTH = Range(0.0, unit="K"), Range(0.0, unit="m")
SEED = Range(0, 2**32 - 1, whole=True)
SPAN = Range(-1e9, 1e9)
"""What a bound of ``--range`` may be, in the input's unit (°C, W, 1/min …)."""


def _floats(text: str, option: str, fix: str, rng: Range = Range()) -> list[float]:
    try:
        values = [float(v) for v in text.replace(":", ",").split(",")]
    except ValueError:
        raise InputError(option, f"{text!r} is not a list of numbers", fix) from None
    for v in values:
        rng.check(option, v, fix)
    return values


def register(sub) -> None:
    p = sub.add_parser("sensors", help="where to put the thermocouples: sensor placement from the FE model",
                       description=__doc__.split("\n\n")[0])
    p.add_argument("--case", metavar="CASE.toml", help="a case file (default: the paper's frame, --dim/--config)")
    add_model_options(p)
    p.add_argument("--mesh-factor", type=number(POSITIVE), metavar="F",
                   help="with --case: mesh its geometry with the element sizes times F")
    p.add_argument("--count", type=number(COUNT), default=3, metavar="K", help="sensors to place (default 3)")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.add_argument("--candidates", metavar="NAME,...", help="boundaries whose nodes are candidates "
                   "(default: the outer surface)")
    p.add_argument("--spacing", type=number(LENGTH), default=0.0, metavar="M", help="thin the candidates to this "
                   "spacing, m")
    p.add_argument("--exclude", action="append", default=[], metavar="X0,Y0[,Z0],X1,Y1[,Z1]",
                   help="a box (low corner, high corner, m) no sensor may lie in; repeatable")
    p.add_argument("--min-distance", type=number(LENGTH), default=0.0, metavar="M",
                   help="least distance between two chosen sensors, m")
    p.add_argument("--noise-K", type=number(NOISE), default=0.05, metavar="K", help="sensor noise, K (default 0.05)")
    p.add_argument("--schedules", nargs="+", metavar="FILE.csv", help="training duty cycles instead of the "
                   "generated ones (the data format; the case's own schedule is added)")
    p.add_argument("--held-out", nargs="+", metavar="FILE.csv", help="duty cycles to judge on (default: the paper's "
                   "conditions 1-3 for the frame's inputs, else generated)")
    p.add_argument("--loads", type=number(LOADS), default=20, metavar="N", help="generated training loads (default 20)")
    p.add_argument("--range", action="append", default=[], metavar="NAME=LO:HI",
                   help="range of an input in the generated loads (default: its span over the case's schedules); "
                   "repeatable")
    p.add_argument("--seed", type=number(SEED), default=0, metavar="N",
                   help="seed of the generated loads and the noise (0 to 2^32 - 1)")
    p.add_argument("--states", type=number(STATES), default=30, metavar="N", help="states of the reduced model (default 30)")
    p.add_argument("--form", choices=("auto", "static", "dynamic"), default="auto",
                   help="error-model family (default auto: dynamic only if 3%% better)")
    p.add_argument("--check", action="store_true",
                   help="also check by full FE runs of every load with probes at the chosen points")
    p.set_defaults(func=run)


def _settings(args, dim: int) -> dict:
    boxes = []
    for text in args.exclude:
        v = _floats(text, "--exclude", f"e.g. --exclude {'0,0,0.2,0.1' if dim == 2 else '0,0,0,0.2,0.1,0.1'}")
        if len(v) != 2 * dim or any(a > b for a, b in zip(v[:dim], v[dim:])):
            raise InputError(f"--exclude {text}", f"is not a {dim}-D box", f"give {2 * dim} numbers: the low "
                             "corner, then the high one")
        boxes.append((v[:dim], v[dim:]))
    ranges = {}
    for text in args.range:
        name, _, span = text.partition("=")
        v = _floats(span, f"--range {name}", f"e.g. --range {name or 'spindle_W'}=0:200", SPAN)
        if not name or len(v) != 2:
            raise InputError(f"--range {text}", "is not NAME=LO:HI", "e.g. --range spindle_W=0:200")
        if v[0] > v[1]:
            raise InputError(f"--range {text}", "its low end is above its high end", f"e.g. --range {name}=0:200")
        ranges[name] = (v[0], v[1])
    names = tuple(n.strip() for n in (args.candidates or "").split(",") if n.strip())
    return {"boundaries": names, "spacing_m": args.spacing, "exclude": boxes, "min_distance_m": args.min_distance,
            "noise_K": args.noise_K, "loads": args.loads, "ranges": ranges, "seed": args.seed, "states": args.states,
            "form": args.form}


def run(args) -> int:
    from gatetherm.api import gate_frame, load_case

    if args.case is not None:
        refuse_model_options(args)
        case = load_case(args.case, args.mesh_factor or 1.0)
    elif args.mesh_factor is not None:
        raise InputError("--mesh-factor", "goes with --case only", "give --config with a finer mesh for the frame")
    else:
        case = gate_frame(args.dim, args.config)
    study = sensor_study(case, args.count, schedules=args.schedules or (), held_out=args.held_out or (),
                         check=args.check, on_progress=Progress("sensors"), **_settings(args, case.dim))
    study.write(args.out)
    print(study.summary(args.out))
    return 0
