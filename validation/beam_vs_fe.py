"""Beam theory against FE: K_i and K_C over l/l4 and beta (the paper's Figs. 7 and 8).

The studies are plain sweep studies (studies/sweep.py) on the *study frame*: the
paper model with ``l1 = l/2`` and the columns slenderised to ``l/h = SLENDERNESS``
(``h = l/SLENDERNESS``; the tank's x-extent scaled with ``h``), ``beta`` set through
``A_C`` and ``l4 = l/a``; the column is raised for tie bars above the arms and, in 3-D,
``t_C`` is raised until the tie bar fits behind the arms. FE values are the
element-exact load cases of solvers/reduced.py read at E (and at F).

Controlled series explain the gaps: the same sweep without the tank cavity, a
slenderness series ``l/h``, a tie-bar height series ``t_C`` and a mesh series; and
:func:`shear_coefficients` adds the columns' shear compliance to the beam theory.
Numbers only; studies/commands/validate.py runs the studies and writes the files.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from geometry.frame import MeshParams
from studies.config import Config
from studies.sweep import Study

SLENDERNESS = 8.0
"""l/h of the study frame."""
A_VALUES = tuple(round(float(a), 4) for a in np.r_[np.arange(0.5, 1.49, 0.05), np.arange(1.5, 5.01, 0.25)])
"""The swept l/l4: 0.05 steps up to 1.45 (the K_i minimum), 0.25 steps from 1.5 to 5."""
BETAS = (0.01, 0.03, 0.1, 0.3, 1.0)
ELEMENTS_ACROSS = {2: 16, 3: 5}
"""Mesh size = h / this, per dimension."""
SERIES_A = (0.6, 1.6, 3.0, 5.0)
SERIES_BETA = (0.01, 1.0)
SERIES_L_OVER_H = (3.0, 4.0, 6.0, 8.0, 12.0, 16.0)
SERIES_T_C = (0.01, 0.02, 0.04, 0.08)
MESH_POINTS = ((2.0, 0.01), (5.0, 1.0))
MESH_ACROSS = {2: (8, 16, 32), 3: (3, 5, 7)}
REL_TOL, ABS_TOL_UM = 0.15, 0.3
"""Acceptance: |FE - theory| <= max(REL_TOL |theory|, ABS_TOL_UM)."""
GAP_REL = 0.10
"""A 'gap' to explain: |FE - theory| > GAP_REL |theory| and > ABS_TOL_UM."""
SHEAR_FACTOR = 5.0 / 6.0
"""Timoshenko shear coefficient of a rectangular section."""


def mesh_key(dim: int) -> str:
    return "mesh.size_3d" if dim == 3 and hasattr(MeshParams(), "size_3d") else "mesh.size"


def _fixed(base: Config, dim: int, l_over_h: float, across: int, tank: bool = True) -> dict:
    h = base.model.frame.l / l_over_h
    out = {"derived.l_over_h": l_over_h, "derived.l1_over_l": 0.5, mesh_key(dim): round(h / across, 6)}
    if not tank:
        out["derived.tank_cavity"] = False
    return out


def _study(name, base, dim, fixed, grid) -> Study:
    return Study(name, dim, base, tuple(fixed.items()), tuple((k, tuple(v)) for k, v in grid.items()),
                 ("coefficients",))


def studies(base: Config, dim: int) -> dict[str, list[Study]]:
    """All studies of ``gatetherm validate beam``, by name (a list: one study per mesh size)."""
    n = ELEMENTS_ACROSS[dim]
    sweep_grid = {"derived.beta": BETAS, "derived.l_over_l4": A_VALUES}
    series = {"derived.beta": SERIES_BETA, "derived.l_over_l4": SERIES_A}
    return {
        "sweep": [_study("sweep", base, dim, _fixed(base, dim, SLENDERNESS, n), sweep_grid)],
        "no_tank": [_study("no_tank", base, dim, _fixed(base, dim, SLENDERNESS, n, tank=False), sweep_grid)],
        "slenderness": [_study(f"slenderness l/h={s:g}", base, dim, _fixed(base, dim, s, n, tank=False), series)
                        for s in SERIES_L_OVER_H],
        "tie_height": [_study("tie_height", base, dim, _fixed(base, dim, SLENDERNESS, n, tank=False),
                              {**series, "geometry.t_C": SERIES_T_C})],
        "mesh": [_study(f"mesh h/{m}", base, dim, _fixed(base, dim, SLENDERNESS, m),
                        {"derived.beta": (b,), "derived.l_over_l4": (a,)})
                 for m in MESH_ACROSS[dim] for a, b in MESH_POINTS],
    }


# --- beam theory with shear-flexible columns ---------------------------------------------------

def shear_coefficients(cfg: Config) -> tuple[float, float]:
    """K_i, K_C (um/K) of the beam theory with Timoshenko columns (shear area ``SHEAR_FACTOR h depth``).

    Same load path as eqs (7)-(24): the heated column's free displacement ``u(y)``, the
    tie-bar force ``P = [u(l4) + alpha_C theta_C l_C] / (1/k_C + 2 c(l4, l4))`` and
    ``delta = u(l) - 2 P c(l, l4)``, with the column compliance ``c(y, l4)`` (displacement
    at ``y`` per unit load at ``l4``) of bending plus shear ``min(y, l4) / (k G A)``.
    """
    p, m = cfg.model.frame, cfg.model
    tie = m.tie_material or m.material
    E, G = m.material.E, m.material.E / (2.0 * (1.0 + m.material.nu))
    EI, GA = E * p.depth * p.h ** 3 / 12.0, SHEAR_FACTOR * G * p.depth * p.h

    def u(y):  # free thermal displacement per K of theta_A - theta_B
        k = m.material.alpha / p.h
        return k * y ** 2 / 2 if y <= p.l1 else k * p.l1 * (y - p.l1 / 2)

    def c(y, s):  # displacement at y per unit load at s
        bend = y ** 2 * (3 * s - y) / (6 * EI) if y <= s else s ** 2 * (3 * y - s) / (6 * EI)
        return bend + min(y, s) / GA

    flex = p.l_C / (p.A_C * tie.E) + 2.0 * c(p.l4, p.l4)
    ki = u(p.l) - 2.0 * c(p.l, p.l4) * u(p.l4) / flex
    kc = 2.0 * c(p.l, p.l4) * tie.alpha * p.l_C / flex
    return ki * 1e6, kc * 1e6


# --- comparison ---------------------------------------------------------------------------

def _ok(rows):
    return [r for r in rows if r.get("status") == "ok"]


def agreement(fe: float, theory: float) -> tuple[bool, bool]:
    """(within the acceptance tolerance, a gap to explain) for values in um/K."""
    d = abs(fe - theory)
    return d <= max(REL_TOL * abs(theory), ABS_TOL_UM), d > max(GAP_REL * abs(theory), ABS_TOL_UM)


def csv_rows(rows) -> list[dict]:
    """The beam_vs_fe.csv rows: FE at E, normalised as the theory."""
    return [{"l_over_l4": r["derived.l_over_l4"], "beta": r["derived.beta"],
             "Ki_norm_theory": r["Ki_norm_theory"], "Ki_norm_fe": r["Ki_norm_fe"],
             "Kc_norm_theory": r["Kc_norm_theory"], "Kc_norm_fe": r["Kc_norm_fe"]} for r in _ok(rows)]


def error_rows(rows, no_tank_rows, configs: dict) -> list[dict]:
    """One row per point and coefficient: theory, FE at E and F, the no-tank FE, the
    shear-corrected theory (um/K), errors, the acceptance and the gap flag."""
    ref = {(r["derived.l_over_l4"], r["derived.beta"]): r for r in _ok(no_tank_rows)}
    out = []
    for r in _ok(rows):
        key = (r["derived.l_over_l4"], r["derived.beta"])
        shear = shear_coefficients(configs[key]) if key in configs else (np.nan, np.nan)
        for i, k in enumerate(("Ki", "Kc")):
            th, fe = r[f"{k}_theory"], r[f"{k}_E_fe"]
            ok, gap = agreement(fe, th)
            out.append({"coefficient": k, "l_over_l4": key[0], "beta": key[1], "theory_um_per_K": th,
                        "fe_E_um_per_K": fe, "fe_F_um_per_K": r[f"{k}_F_fe"],
                        "fe_no_tank_um_per_K": ref[key][f"{k}_E_fe"] if key in ref else np.nan,
                        "theory_shear_um_per_K": shear[i], "error_um_per_K": fe - th,
                        "error_rel": (fe - th) / th if th else np.nan, "within_tolerance": ok, "gap": gap})
    return out


def cause(e: dict) -> str:
    """The dominant reason of a gap, from the decomposition FE - theory =
    (FE - FE without tank) + (FE without tank - shear theory) + (shear theory - theory)."""
    parts = {"tank cavity": e["fe_E_um_per_K"] - e["fe_no_tank_um_per_K"],
             "column shear": e["theory_shear_um_per_K"] - e["theory_um_per_K"],
             "tie-bar bending / joints": e["fe_no_tank_um_per_K"] - e["theory_shear_um_per_K"]}
    total = e["error_um_per_K"]
    name, share = max(((n, v) for n, v in parts.items() if np.isfinite(v)),
                      key=lambda nv: nv[1] * np.sign(total), default=("unexplained", total))
    return name


def zero_crossings(rows, betas=(0.01, 0.03, 0.1), window=(0.7, 1.3), which="Ki_norm_fe"):
    """Per beta: sign changes of ``which`` over l/l4 (linear interpolation) and the
    smallest |value| with its l/l4 inside ``window``."""
    out = {}
    for b in betas:
        pts = sorted((r["derived.l_over_l4"], r[which]) for r in _ok(rows) if r["derived.beta"] == b)
        if not pts:
            continue
        a, v = map(np.asarray, zip(*pts))
        cross = [float(a[i] - v[i] * (a[i + 1] - a[i]) / (v[i + 1] - v[i]))
                 for i in range(len(a) - 1) if v[i] * v[i + 1] < 0]
        inside = (a >= window[0]) & (a <= window[1])
        j = int(np.argmin(np.where(inside, np.abs(v), np.inf)))
        out[b] = {"crossings": cross, "min_abs": float(abs(v[j])), "at": float(a[j]),
                  "min_norm": float(v[inside].min()), "at_min": float(a[inside][np.argmin(v[inside])])}
    return out


def convergence(rows_by_mesh: dict[int, list[dict]]) -> list[dict]:
    """Mesh series: per point, K (um/K) per elements-across-h and the change to the finest."""
    out = []
    finest = max(rows_by_mesh)
    for a, b in MESH_POINTS:
        vals = {m: next(r for r in _ok(rs) if r["derived.l_over_l4"] == a and r["derived.beta"] == b)
                for m, rs in rows_by_mesh.items()}
        for k in ("Ki_E_fe", "Kc_E_fe"):
            ref = vals[finest][k]
            out.append({"l_over_l4": a, "beta": b, "coefficient": k.split("_")[0],
                        **{f"h/{m}": vals[m][k] for m in sorted(vals)},
                        **{f"change h/{m}": (vals[m][k] - ref) / ref for m in sorted(vals) if m != finest},
                        "nodes": {m: vals[m]["nodes"] for m in sorted(vals)}})
    return out


def replace_frame(cfg: Config, **changes) -> Config:
    return dataclasses.replace(cfg, model=dataclasses.replace(
        cfg.model, frame=dataclasses.replace(cfg.model.frame, **changes)))
