"""Beam-theory section: K_i and K_C of the beam theory against the FE load cases over l/l4
and β (Figs. 7-8 analogues: theory curves, FE markers), the error table per coefficient and
β, and the effective coefficients of the transient runs (``gatetherm validate beam``)."""
from __future__ import annotations

from gatetherm.validation import paper_model
from gatetherm.validation.report.result import Figure, Result, from_dicts


def compute(ctx) -> Result:
    from gatetherm.validation.beam_study import write_beam_study

    s = ctx.scope
    out = write_beam_study(ctx.work, paper_model(), s["dim"], ctx.workers, a_every=s["a_every"], series=s["series"])
    figures = [Figure("fig7_Ki.png", "Fig. 7 analogue: K_i / (3αl²/8h) against l/l4, beam theory (lines) and FE "
                      "(markers) for five β, l1 = l/2, with the tank cavity"),
               Figure("fig8_Kc.png", "Fig. 8 analogue: K_C / (α l_C) against l/l4, beam theory (lines) and FE "
                      "(markers)"),
               Figure("fig7_Ki_no_tank.png", "Fig. 7 analogue without the tank cavity"),
               Figure("fig8_Kc_no_tank.png", "Fig. 8 analogue without the tank cavity")]
    if s["series"]:
        figures += [Figure(f"{name}_{k}.png", f"{k}: relative error of FE against the theory, {what}, no tank cavity")
                    for name, what in (("slenderness", "over the slenderness l/h"),
                                       ("tie_height", "over the tie-bar height t_C")) for k in ("Ki", "Kc")]
    errors = from_dicts(f"Errors of FE against the beam theory, {s['dim']}-D, per coefficient and β", out["by_beta"],
                        note="Tolerance |FE − theory| ≤ max(15 % |theory|, 0.3 µm/K); a gap: > 10 % and > 0.3 µm/K; "
                             "every gap is split into tank cavity, column shear and tie-bar joint parts in report.md.")
    effective = from_dicts("Effective K_i, K_C (µm/K) on the paper model and the error of δ = K_i(θ_A − θ_B) − K_C θ_C "
                           "over the three 5-h runs (µm)", out["effective"])
    return Result(tables=(errors, effective), figures=tuple(figures), notes=tuple(out["lines"][1:]),
                  files=(("report.md", "the full report: set-up, every gap split into its parts, series"),
                         ("errors.csv", "every value: theory, FE at E and F, error, parts"),
                         ("beam_vs_fe.csv", "the normalised curves")))
