"""``gatetherm live``: compensate a machine over OPC UA, a step of the compensator every period.

Reads the sensors and inputs named in the map (default: the layout ``gatetherm twin`` serves,
docs/live.md) every --period of the machine's clock (``time_s``), steps the compensator (--method
paper, mlr or rom on --case, or a fitted --model), writes the offset (um) and logs every sample and
correction to DIR/live.csv (flushed each period), its state to DIR/state.json (a restart into the
same --out resumes), the guards' events to DIR/events.log and, when it ends, DIR/summary.json. A
second ``live`` on the same --out refuses. SIGINT/SIGTERM end it between two periods. Where the
machine reports its measured delta, a compensation that leaves delta worse than none over the last
--window periods (by more than --margin um) is warned once, flagged (``worse``) and by default ramped
to zero (--fallback). With --model and --axis TARGET=S (two or more probes along the axis) it also
writes a gradient along the axis and its reference position (--reference).
"""
from __future__ import annotations

from gatetherm.api import InputError

ORDER = 150  # its place in `gatetherm --help` (gatetherm.cli finds the command here)


def register(sub) -> None:
    p = sub.add_parser("live", help="compensate a machine over OPC UA, a compensator step every period",
                       description=__doc__.splitlines()[0])
    p.add_argument("--case", metavar="CASE.toml", help="the machine's case file (paper, mlr, rom)")
    from gatetherm.api import STEPWISE_METHODS  # read now: every method registered (studies/control/method/)

    p.add_argument("--method", choices=STEPWISE_METHODS, default="rom", help="compensation method (default rom)")
    p.add_argument("--model", metavar="MODEL.json", help="a model from 'gatetherm errormodel fit' instead of --method")
    p.add_argument("--target", metavar="COL", help="--model: the compensated channel")
    p.add_argument("--endpoint", required=True, metavar="URL", help="the control's OPC UA server, opc.tcp://HOST:PORT")
    p.add_argument("--out", required=True, metavar="DIR", help="directory of the log, the state and the lock")
    p.add_argument("--map", metavar="MAP.toml", help="node ids of the control (default: the twin's layout)")
    p.add_argument("--period", type=float, default=60.0, metavar="S", help="period on the machine's clock, s "
                   "(default 60)")
    p.add_argument("--until", type=float, metavar="SECONDS", help="machine time to stop after (default: run until "
                   "stopped)")
    p.add_argument("--states", type=int, default=30, metavar="N", help="rom: states of the reduced model (default 30)")
    p.add_argument("--schedule", metavar="S.csv", help="rom: the inputs known in advance (default: the case's)")
    p.add_argument("--window", type=int, default=30, metavar="N", help="never-worse monitor: periods compared "
                   "(default 30)")
    p.add_argument("--margin", type=float, default=1.0, metavar="UM", help="never-worse monitor: how much larger the "
                   "compensated |delta| may be before it counts as worse, um (default 1)")
    p.add_argument("--fallback", choices=("zero", "hold", "warn"), default="zero", help="after a worse verdict: ramp "
                   "the correction to zero, hold it, or only warn (default zero)")
    p.add_argument("--axis", action="append", default=[], metavar="TARGET=S", help="--model: a target's probe "
                   "position along the axis, m (repeat, two or more: a gradient is written)")
    p.add_argument("--reference", type=float, metavar="S", help="--axis: reference position of the offset, m "
                   "(default the smallest probe position)")
    p.add_argument("--status-port", type=int, metavar="N", help="serve a status page on http://127.0.0.1:N/ "
                   "(the last hours of delta and the correction, each sensor's health, the guards)")
    p.add_argument("--quiet", action="store_true", help="no line per period")
    p.set_defaults(func=run)


def _axis(items) -> dict:
    axis = {}
    for text in items:
        name, sep, value = text.partition("=")
        try:
            axis[name.strip()] = float(value)
        except ValueError:
            raise InputError(f"--axis {text}", "is not TARGET=S", "e.g. --axis delta_x0_um=0.25") from None
        if not sep or not name.strip():
            raise InputError(f"--axis {text}", "is not TARGET=S", "e.g. --axis delta_x0_um=0.25")
    return axis


def run(args) -> int:
    import gatetherm.api as api

    def line(row):
        if not args.quiet:
            grad = row.get("gradient_um_per_m")
            print(f"t = {row['time_s']:8g} s  delta {row.get('delta_um', float('nan')):7.2f} um  offset "
                  f"{row['offset_um']:7.2f} um" + (f"  gradient {grad:7.2f} um/m" if grad is not None else "")
                  + f"{'  held' if row['held'] else ''}{'  limited' if row['limited'] else ''}"
                  + f"{'  worse' if row.get('worse') else ''}", flush=True)

    res = api.live(args.case, args.method, endpoint=args.endpoint, out=args.out, model=args.model, target=args.target,
                   map=args.map, period=args.period, until=args.until, states=args.states, schedule=args.schedule,
                   monitor={"window": args.window, "margin_um": args.margin, "fallback": args.fallback}, axis=_axis(args.axis) or None,
                   reference=args.reference, status_port=args.status_port, on_period=line)
    band = res.get("compensated_band_um")
    print(f"live: {res['periods']} periods logged to {args.out}/live.csv, {res['missed']} missed, {res['held']} held, "
          f"{res['limited']} limited, {res['reconnects']} reconnects"
          + (f"; compensated delta after 10 min within +/-{band:.2f} um" if band is not None else "")
          + (f"; compensation made delta worse ({res['worse']} periods fallen back)" if res["monitor"] == "worse" else ""))
    return 0
