"""The worked example of docs/errormodel.md: a PLC-style once-a-minute evaluation of channel ch1_um
of a model.json, against predict() on all samples.

    python docs/errormodel_plc.py fit/model.json fl_thermal_0-80.csv
"""
import json
import math
import sys

from gatetherm.studies.errormodel.model import load_model, predict
from gatetherm.studies.run.timeseries import read_timeseries

MODEL, DATA = sys.argv[1:3]
m = json.load(open(MODEL))
ch1, ref = m["targets"]["ch1_um"], m["reference_degC"]
ts = read_timeseries(DATA, required=("time_s",))
minute = ts.slice(slice(0, None, 4))            # what a PLC sampling once a minute sees (15-s data)
h, state = 60.0, {}                            # per lagged term: (x, s of the minute before)
smooth, read = m["settings"].get("smooth_s", 0.0), {}  # per sensor: (smoothed, reading of the minute before)


def lagged(x, s0, s, tau):                     # the exact first-order lag of a signal linear over h
    a = math.exp(-h / tau)
    return a * x + (1 - a) * s0 + (s - s0) * (1 - tau * (1 - a) / h)


for k in range(len(minute)):                   # the PLC task, once a minute
    offset = ch1["intercept_um"]
    for j, term in enumerate(ch1["terms"]):
        if term["kind"] == "sensor":
            r = minute[term["column"]][k]
            x, r0 = read.get(term["column"], (r, r))   # starts in steady state
            x = lagged(x, r0, r, smooth) if smooth > 0 else r
            read[term["column"]] = (x, r)
            offset += term["coefficient"] * (x - ref[term["column"]])
            continue
        s = (abs(minute[term["column"]][k]) / term["scale"]) ** term["exponent"]
        x, s0 = state.get(j, (s, s))             # starts in steady state
        x = lagged(x, s0, s, term["tau_s"])
        state[j] = (x, s)
        offset += term["coefficient"] * x
    if minute.time_s[k] == 27 * 3600:
        lags = ", ".join(f"{v[0]:.4f}" for v in state.values())
        sensors = ", ".join(f"{c} {v[0]:.3f}" for c, v in read.items())
        print(f"t = 27 h: lag x = {lags}; smoothed {sensors} degC; ch1 offset = {offset:.3f} um, "
              f"measured {minute['ch1_um'][k]:.3f} um")
print(f"predict() on the 15-s samples: {predict(load_model(MODEL), ts)['ch1_um'][ts.time_s == 27 * 3600][0]:.3f} um")
