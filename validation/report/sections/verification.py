"""Verification section: the observed orders and the exact cases the verification tests check,
computed by the same functions (validation/verification.py, verification_time.py)."""
from __future__ import annotations

import numpy as np

from gatetherm.validation import verification as v
from gatetherm.validation import verification_time as vt
from gatetherm.validation.report.result import Figure, Result, table


def _orders(scope) -> tuple[dict, dict, list]:
    spatial, rows = {}, []
    studies = [("heat L2", v.heat_mms_error, v.SPATIAL_HEAT, list(v.SPATIAL_HEAT)),
               ("elasticity L2", v.elastic_mms_error, v.SPATIAL_ELASTIC,
                ["2-D P1", "2-D P2", *scope["elastic_3d"]])]
    for name, error, levels, labels in studies:
        for label in labels:
            dim, order, lv = levels[label]
            h, err, p = v.spatial_study(error, dim, order, lv)
            kind = ", plane stress" if name.startswith("elast") and dim == 2 else ""
            spatial[f"{name}, {label}"] = (h, err, p)
            rows.append((f"{name}, {label}{kind} (levels {', '.join(map(str, lv))})", f"{p:.3f}", f"{order + 1}"))
    temporal = {}
    for label in vt.TIME_CASES:
        dt, err, p, expected = vt.time_order(label)
        temporal[label] = (dt, err, p)
        rows.append((f"time, {label} (dt {dt[0]:g} … {dt[-1]:g})", f"{p:.3f}", f"{expected:g}"))
    return spatial, temporal, rows


def _exact() -> list[tuple[str, str, str]]:
    free = [v.free_expansion(d, o) for d in (2, 3) for o in (1, 2)]
    linear = [v.linear_temperature(d, o) for d in (2, 3) for o in (1, 2)]
    fe, theory, adjoint = v.clamped_bar_tip()
    slab = {s: vt.slab_film_error(order=2, nx=20, dt=dt, scheme=vt.TimeScheme(th))
            for s, th, dt in (("Crank–Nicolson, dt 2 s", 0.5, 2.0), ("backward Euler, dt 1 s", 1.0, 1.0))}
    energy = {th: {k: float(np.abs(a).max()) for k, a in vt.imbalances(vt.frame_energy(th)).items()}
              for th in (1.0, 0.5)}
    pump = vt.pump_switch_errors()
    rows = [("free expansion under uniform ΔT, 2-D/3-D, P1/P2: max |σ| / (b ΔT)",
             f"{max(e['stress'] for e in free):.2g}", "0 (< 1e-10)"),
            ("free expansion: max |u − α ΔT x| / (α ΔT L)", f"{max(e['u'] for e in free):.2g}", "0 (< 1e-10)"),
            ("linear temperature field, P2: max |σ| / (b T_max)", f"{max(e['stress'] for e in linear):.2g}",
             "0 (< 1e-10)"),
            ("clamped bar, ΔT across the width, L/h = 20: tip / (−α ΔT L²/2h) − 1",
             f"{100 * (fe / theory - 1):+.2f} %", "within 1 % (beam theory)"),
            ("clamped bar: adjoint read-out / direct solve − 1", f"{adjoint / fe - 1:.1g}", "0 (< 1e-9)")]
    rows += [(f"1-D slab with a film against its Fourier series, {k}: max |Δθ|", f"{e:.2g}",
              "< 5e-5" if k.startswith("Crank") else "< 1e-3") for k, e in slab.items()]
    rows += [(f"frame energy balance per step, θ = {th:g}: solid / oil / hose",
              " / ".join(f"{x:.2g}" for x in e.values()), "0 (< 1e-8)") for th, e in energy.items()]
    rows += [(f"condition 2 on the verification frame, max |δ − δ(CN, 3.75 s)|, {k}", f"{e:.3f} µm",
              "< 0.1 µm" if k == "default" else "> 1 µm (under-resolved)") for k, e in pump.items()]
    return rows


def compute(ctx) -> Result:
    from gatetherm.validation.plots import save
    from gatetherm.validation.plots.verification import plot_orders

    spatial, temporal, rows = _orders(ctx.scope)
    save(plot_orders(spatial, temporal), ctx.work / "orders.png")
    orders = table("Observed convergence orders (least-squares slope of log error against log h or log dt)",
                   ("check", "observed", "expected"), rows,
                   note="Space: unit square refined n times (h = 2^-n) or unit cube of n³ cubes of six tetrahedra "
                        "(h = 1/n), manufactured solutions with every term of the weak forms. Time: the unit-square "
                        "heat system with the oil loop and a supply hose against its exact modal solution over "
                        "t = 0..2; 'pump off at t=1': error at t = 2 after the switch.")
    exact = table("Exact cases (to round-off where the answer is exact)", ("case", "gatetherm", "expected"),
                  _exact(), note="b: thermal stress modulus; the energy accounts are relative to the largest term "
                                 "of each step; the verification frame is the tests' fixed frame (0.02-m mesh).")
    return Result(tables=(orders, exact), figures=(Figure("orders.png", "Observed convergence: errors against element "
                                                          "size and time step, log-log; the legend gives each fitted "
                                                          "order"),))
