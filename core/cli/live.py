"""``gatetherm live``: compensate a machine over OPC UA, a step of the compensator every period.

Reads the sensors and inputs named in the map (default: the layout ``gatetherm twin`` serves,
docs/live.md) every --period of the machine's clock (``time_s``), steps the compensator (--method
paper, mlr or rom on --case, or a fitted --model), writes the offset (um) and logs every sample and
correction to DIR/live.csv (flushed each period), its state to DIR/state.json (a restart into the
same --out resumes), the guards' events to DIR/events.log and, when it ends, DIR/summary.json. A
second ``live`` on the same --out refuses. SIGINT/SIGTERM end it between two periods.
"""
from __future__ import annotations

from gatetherm import InputError


def register(sub) -> None:
    p = sub.add_parser("live", help="compensate a machine over OPC UA, a compensator step every period",
                       description=__doc__.splitlines()[0])
    p.add_argument("--case", metavar="CASE.toml", help="the machine's case file (paper, mlr, rom)")
    p.add_argument("--method", choices=("paper", "mlr", "rom"), default="rom", help="compensation method (default rom)")
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
    p.add_argument("--status-port", type=int, metavar="N", help="serve a status page on http://127.0.0.1:N/ "
                   "(the last hours of delta and the correction, each sensor's health, the guards)")
    p.add_argument("--quiet", action="store_true", help="no line per period")
    p.set_defaults(func=run)


def run(args) -> int:
    import gatetherm as gt
    from gatetherm.validation.live.twin import endpoint_url

    endpoint_url(args.endpoint)  # a bad endpoint fails before the case is read

    if args.model is None and args.case is None:
        raise InputError("--case/--model", "give the machine's case (or a fitted model)", "e.g. --case case.toml")
    case = gt.load_case(args.case) if args.case else None

    def line(row):
        if not args.quiet:
            print(f"t = {row['time_s']:8g} s  delta {row.get('delta_um', float('nan')):7.2f} um  offset "
                  f"{row['offset_um']:7.2f} um{'  held' if row['held'] else ''}{'  limited' if row['limited'] else ''}",
                  flush=True)

    res = gt.live(case, args.method, endpoint=args.endpoint, out=args.out, model=args.model, target=args.target,
                  map=args.map, period=args.period, until=args.until, states=args.states, schedule=args.schedule,
                  status_port=args.status_port, on_period=line)
    band = res.get("compensated_band_um")
    print(f"live: {res['periods']} periods logged to {args.out}/live.csv, {res['missed']} missed, {res['held']} held, "
          f"{res['limited']} limited, {res['reconnects']} reconnects"
          + (f"; compensated delta after 10 min within +/-{band:.2f} um" if band is not None else ""))
    return 0
