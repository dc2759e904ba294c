"""Beam theory against FE: K_i and K_C over l/l4 and beta (the paper's Figs. 7 and 8).

The studies are plain sweep studies (studies/sweep.py) on the *study frame*: the
paper model with ``l1 = l/2`` and the columns slenderised to ``l/h = SLENDERNESS``
(``h = l/SLENDERNESS``; the tank's x-extent scaled with ``h``), ``beta`` set through
``A_C`` and ``l4 = l/a``; the column is raised for tie bars above the arms and, in 3-D,
``t_C`` is raised until the tie bar fits behind the arms. FE values are the
element-exact load cases of core/frame/loadcases.py read at E (and at F).

Controlled series explain the gaps: the same sweep without the tank cavity, a
slenderness series ``l/h``, a tie-bar height series ``t_C`` and a mesh series; and
:func:`shear_coefficients` adds the columns' shear compliance to the beam theory.
Numbers only; validation/beam_study.py runs the studies and writes the files, and
validation/beam_vs_fe_report.py turns the rows into report.md.
"""
from __future__ import annotations

import numpy as np

from gatetherm.frame.geometry import MeshParams
from gatetherm.frame.beam import column_I
from gatetherm.frame.config import Config
from gatetherm.frame.sweeppoint import FRAME
from gatetherm.studies.sweeps.sweep import Study

SLENDERNESS = 8.0
"""l/h of the study frame."""
A_VALUES = {2: tuple(round(float(a), 4) for a in np.r_[np.arange(0.5, 1.49, 0.05), np.arange(1.5, 5.01, 0.25)]),
            3: (0.8, 0.85, 0.9, 0.95, 1.0, 1.05, 1.1, 1.15, 1.2, 1.3, 1.4, 1.5, 1.75, 2.0, 2.5, 3.0, 3.5, 4.0,
                4.5, 5.0)}
"""The swept l/l4 per dimension: fine steps near the K_i minimum, coarser up to 5. 3-D starts at
0.8: taller columns exceed the direct solver's 30k DOFs (P2, h/2) and AMG-CG on P2 tetrahedra
took ~500 s per point here."""
BETAS = (0.01, 0.03, 0.1, 0.3, 1.0)
ORDER = 2
"""Polynomial degree of the FE (P2 resolves the column bending on coarse meshes)."""
ELEMENTS_ACROSS = {2: 6, 3: 2}
"""Mesh size = h / this, per dimension."""
SERIES_A = (0.6, 1.6, 3.0, 5.0)
SERIES_BETA = (0.01, 1.0)
SERIES_L_OVER_H = (3.0, 4.0, 6.0, 8.0, 12.0, 16.0)
SERIES_T_C = (0.01, 0.02, 0.04, 0.08)
MESH_POINTS = {2: ((2.0, 0.01), (5.0, 1.0)), 3: ((2.0, 0.01),)}
MESH_ACROSS = {2: (3, 4, 6, 8, 12), 3: (2, 3)}
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
    out = {"derived.l_over_h": l_over_h, "derived.l1_over_l": 0.5, mesh_key(dim): round(h / across, 6),
           "model.order": ORDER}
    if not tank:
        out["derived.tank_cavity"] = False
    return out


def _study(name, base, dim, fixed, grid) -> Study:
    return Study(name, dim, base, tuple(fixed.items()), tuple((k, tuple(v)) for k, v in grid.items()),
                 ("coefficients",), frame=FRAME)


def studies(base: Config, dim: int, a_every: int = 1, series: bool = True) -> dict[str, list[Study]]:
    """All studies of ``gatetherm validate beam`` by name; the controlled series are 2-D only
    (a 3-D point costs about ten 2-D ones). A subset: every ``a_every``-th l/l4 value, and
    without the controlled and mesh series unless ``series``."""
    n = ELEMENTS_ACROSS[dim]
    sweep = {"derived.beta": BETAS, "derived.l_over_l4": A_VALUES[dim][::a_every]}
    controlled = {"derived.beta": SERIES_BETA, "derived.l_over_l4": SERIES_A}
    out = {"sweep": [_study("sweep", base, dim, _fixed(base, dim, SLENDERNESS, n), sweep)],
           "no_tank": [_study("no_tank", base, dim, _fixed(base, dim, SLENDERNESS, n, tank=False), sweep)],
           "slenderness": [], "tie_height": [],
           "mesh": [_study(f"mesh h/{m}", base, dim, _fixed(base, dim, SLENDERNESS, m),
                           {"derived.beta": (b,), "derived.l_over_l4": (a,)})
                    for m in MESH_ACROSS[dim] for a, b in MESH_POINTS[dim]] if series else []}
    if dim == 2 and series:
        out["slenderness"] = [_study(f"slenderness l/h={s:g}", base, dim, _fixed(base, dim, s, n, tank=False),
                                     controlled) for s in SERIES_L_OVER_H]
        out["tie_height"] = [_study("tie_height", base, dim, _fixed(base, dim, SLENDERNESS, n, tank=False),
                                    {**controlled, "geometry.t_C": SERIES_T_C})]
    return out


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
    EI, GA = E * column_I(p), SHEAR_FACTOR * G * p.depth * p.h

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

def collect(tasks, records) -> list[dict]:
    """Table rows of the points (studies.sweep.table) plus the shear-corrected theory (um/K)."""
    from gatetherm.studies.sweeps.sweep import table

    _, rows = table(tasks, records)
    for t, r in zip(tasks, rows):
        if r["status"] == "ok":
            r["Ki_shear"], r["Kc_shear"] = shear_coefficients(t.config)
    return rows


def _ok(rows):
    return [r for r in rows if r.get("status") == "ok"]


def _point(r) -> tuple[float, float]:
    return r["derived.l_over_l4"], r["derived.beta"]


def agreement(fe: float, theory: float) -> tuple[bool, bool]:
    """(within the acceptance tolerance, a gap to explain) for values in um/K."""
    d = abs(fe - theory)
    return d <= max(REL_TOL * abs(theory), ABS_TOL_UM), d > max(GAP_REL * abs(theory), ABS_TOL_UM)


def csv_rows(rows) -> list[dict]:
    """The beam_vs_fe.csv rows: FE at E, normalised as the theory."""
    return [{"l_over_l4": r["derived.l_over_l4"], "beta": r["derived.beta"],
             "Ki_norm_theory": r["Ki_norm_theory"], "Ki_norm_fe": r["Ki_norm_fe"],
             "Kc_norm_theory": r["Kc_norm_theory"], "Kc_norm_fe": r["Kc_norm_fe"]} for r in _ok(rows)]


PARTS = ("tank cavity", "column shear", "tie-bar joint and finite width")


def error_rows(rows, no_tank_rows) -> list[dict]:
    """One row per point and coefficient (um/K): theory, FE at E and at F, the errors, the
    acceptance and gap flags, and the gap split into the parts of :data:`PARTS`:
    FE - FE without tank, shear theory - theory, FE without tank - shear theory."""
    ref = {_point(r): r for r in _ok(no_tank_rows)}
    out = []
    for r in _ok(rows):
        for k in ("Ki", "Kc"):
            th, fe = r[f"{k}_theory"], r[f"{k}_E_fe"]
            nt = ref[_point(r)][f"{k}_E_fe"] if _point(r) in ref else np.nan
            ok, gap = agreement(fe, th)
            parts = (fe - nt, r[f"{k}_shear"] - th, nt - r[f"{k}_shear"])
            finite = [(n, v) for n, v in zip(PARTS, parts) if np.isfinite(v)]
            main = max(finite, key=lambda nv: nv[1] * np.sign(fe - th))[0] if finite else ""
            out.append({"coefficient": k, "l_over_l4": _point(r)[0], "beta": _point(r)[1],
                        "theory_um_per_K": th, "fe_E_um_per_K": fe, "fe_F_um_per_K": r[f"{k}_F_fe"],
                        "error_um_per_K": fe - th, "error_rel": (fe - th) / th if th else np.nan,
                        "within_tolerance": ok, "gap": gap, "fe_no_tank_um_per_K": nt,
                        "theory_shear_um_per_K": r[f"{k}_shear"],
                        **{f"part_{n.split()[0]}_um_per_K": v for n, v in zip(PARTS, parts)},
                        "main_cause": main if gap or not ok else ""})
    return out


def series_rows(rows, variable: str) -> list[dict]:
    """A controlled series: relative errors of FE and of the shear theory against the theory."""
    out = []
    for r in _ok(rows):
        a, b = _point(r)
        row = {variable: r[variable], "l_over_l4": a, "beta": b, "point": f"l/l4={a:g}, beta={b:g}"}
        for k in ("Ki", "Kc"):
            th = r[f"{k}_theory"]
            row.update({f"{k}_theory": th, f"{k}_fe": r[f"{k}_E_fe"], f"{k}_shear": r[f"{k}_shear"],
                        f"{k}_fe_rel_error": r[f"{k}_E_fe"] / th - 1.0,
                        f"{k}_shear_rel_error": r[f"{k}_shear"] / th - 1.0,
                        f"{k}_fe_error_um_per_K": r[f"{k}_E_fe"] - th})
        out.append(row)
    return out


def zero_crossings(rows, betas=(0.01, 0.03, 0.1), window=(0.7, 1.3), which="Ki_norm_fe") -> dict:
    """Per beta: sign changes of ``which`` over l/l4 (linear interpolation) and the
    smallest value and smallest |value| inside ``window``."""
    out = {}
    for b in betas:
        pts = sorted((a, r[which]) for r in _ok(rows) for a, bb in [_point(r)] if bb == b)
        if not pts:
            continue
        a, v = map(np.asarray, zip(*pts))
        cross = [float(a[i] - v[i] * (a[i + 1] - a[i]) / (v[i + 1] - v[i]))
                 for i in range(len(a) - 1) if v[i] * v[i + 1] < 0]
        inside = (a >= window[0]) & (a <= window[1])
        j = int(np.argmin(np.where(inside, np.abs(v), np.inf)))
        k = int(np.argmin(np.where(inside, v, np.inf)))
        out[b] = {"crossings": cross, "min_abs": float(abs(v[j])), "at_min_abs": float(a[j]),
                  "min": float(v[k]), "at_min": float(a[k]), "free": float(v[0])}
    return out


def convergence(mesh_rows: list[list[dict]], dim: int) -> list[dict]:
    """Mesh series (the rows of studies()["mesh"], in order): per point and coefficient,
    K (um/K) per elements across h and the largest change relative to the finest mesh."""
    rows_by_mesh: dict[int, list[dict]] = {m: [] for m in MESH_ACROSS[dim]}
    per_mesh = len(mesh_rows) // len(MESH_ACROSS[dim])
    for i, rows in enumerate(mesh_rows):
        rows_by_mesh[MESH_ACROSS[dim][i // per_mesh]] += rows
    out = []
    finest = max(rows_by_mesh)
    for a, b in MESH_POINTS[dim]:
        vals = {m: next((r for r in _ok(rs) if _point(r) == (a, b)), None) for m, rs in rows_by_mesh.items()}
        vals = {m: v for m, v in vals.items() if v}
        if finest not in vals:
            continue
        for k in ("Ki", "Kc"):
            ref = vals[finest][f"{k}_E_fe"]
            row = {"l_over_l4": a, "beta": b, "coefficient": k}
            row.update({f"h/{m}": vals[m][f"{k}_E_fe"] for m in sorted(vals)})
            row["max_rel_change"] = max(abs(v[f"{k}_E_fe"] / ref - 1.0) for v in vals.values())
            row["mesh nodes"] = " / ".join(str(vals[m]["nodes"]) for m in sorted(vals))
            out.append(row)
    return out


def cavity_stiffness_ratio(cfg: Config, dim: int) -> float:
    """I of the column section through the tank cavity over I of the full section (2-D: the
    cavity runs through the depth; 3-D: it is tank_depth deep)."""
    p = cfg.model.frame
    x0, x1 = p.tank_wall, p.tank_wall + p.tank_width
    frac = 1.0 if dim == 2 else p.tank_depth / p.depth
    parts = [(p.h, p.h / 2, 1.0), (x1 - x0, 0.5 * (x0 + x1), -frac)]  # (width, centre, sign)
    area = sum(w * s for w, _, s in parts)
    xc = sum(w * c * s for w, c, s in parts) / area
    i_net = sum(s * (w ** 3 / 12 + w * (c - xc) ** 2) for w, c, s in parts)
    return i_net / (p.h ** 3 / 12)
