"""``gatetherm twin``: a virtual machine over OPC UA for testing ``gatetherm live`` without a machine.

Runs the case's reduced model (--states states) on its schedule (or --schedule) in --speed times
real time and serves its signals in the node layout of docs/live.md: ``time_s`` (the machine's
clock), the schedule's inputs, the thermocouples and ``delta_um`` with the sensors' noise and
resolution, and ``delta_residual_um``, δ with the ``offset_um`` written to it applied as an ideal axis
offset (or, with --actuator, through the case's [actuator]). Prints one line when it ends (--until, or the schedule's end).
"""
from __future__ import annotations

from gatetherm.api import InputError

ORDER = 140  # its place in `gatetherm --help` (gatetherm.cli finds the command here)


def register(sub) -> None:
    p = sub.add_parser("twin", help="a virtual machine over OPC UA: a case's reduced model in K x real time",
                       description=__doc__.splitlines()[0])
    p.add_argument("case", metavar="CASE.toml", help="the machine's case file")
    p.add_argument("--endpoint", required=True, metavar="URL", help="where to serve, opc.tcp://127.0.0.1:PORT")
    p.add_argument("--speed", type=float, default=1.0, metavar="K", help="machine seconds per wall second (default 1)")
    p.add_argument("--schedule", metavar="S.csv", help="the inputs (default: the case's schedule)")
    p.add_argument("--until", type=float, metavar="SECONDS", help="machine time to stop at (default: the "
                   "schedule's end)")
    p.add_argument("--start", type=float, default=0.0, metavar="SECONDS",
                   help="machine time to start serving at (a twin restarted mid-run; default 0)")
    p.add_argument("--states", type=int, default=30, metavar="N", help="states of the reduced model (default 30)")
    p.add_argument("--actuator", action="store_true", help="apply the correction through the case's [actuator] "
                   "(its piezo model) instead of as an ideal axis offset")
    p.add_argument("--wait", action="store_true", help="start the clock once a client has written offset_um")
    p.add_argument("--fault", action="append", default=[], metavar="COL:FROM:TO",
                   help="the column reads NaN from .. to (machine s), a sensor fault (repeatable)")
    p.add_argument("--seed", type=int, default=0, metavar="N", help="seed of the sensor noise (default 0)")
    p.add_argument("--machines", type=int, default=1, metavar="N", help="serve N machines from this process, "
                   "machine i in namespace urn:gatetherm:machine:i (a map file per service; default 1: the "
                   "default layout)")
    p.set_defaults(func=run)


def run(args) -> int:
    import gatetherm.api as api

    faults = []
    for text in args.fault:
        try:
            name, lo, hi = text.split(":")
            faults.append((name, float(lo), float(hi)))
        except ValueError:
            raise InputError(f"--fault {text}", "is not COL:FROM:TO", "e.g. --fault theta_A_degC:3600:3720") from None
    res = api.twin(args.case, args.endpoint, args.speed, schedule=args.schedule, until=args.until, start=args.start,
                   states=args.states, seed=args.seed, actuator=args.actuator, wait=args.wait, faults=tuple(faults),
                   machines=args.machines)
    if not res["served"]:
        print("twin: stopped before a client connected")
        return 0
    band = res["compensated_band_after_10_min_um"]
    several = f" of {res['machines']} machines" if res["machines"] > 1 else ""
    print(f"twin: served {res['served']} samples{several}, t = {res['start_s']:g} .. {res['end_s']:g} s; "
          f"compensated delta after 10 min within +/-{band:.2f} um")
    return 0
