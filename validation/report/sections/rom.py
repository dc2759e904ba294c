"""Reduced-order model section: the reduced model against the FE runs and the paper / MLR /
reduced-model compensation table of ``gatetherm validate rom``, with its figures."""
from __future__ import annotations

from gatetherm.validation.report.result import Figure, Result, table
from gatetherm.validation import paper_model


def compute(ctx) -> Result:
    from gatetherm.frame.problem import EFFECTS
    from gatetherm.validation import rom_study as rs
    from gatetherm.validation.plots import save
    from gatetherm.validation.plots.rom import plot_rom_bands, plot_rom_error

    effects = ctx.scope["effects"]
    st = rs.write_rom_study(ctx.work, paper_model(), ctx.scope["dims"], conditions=ctx.scope["conditions"],
                            effects=EFFECTS if effects == "all" else effects)
    save(plot_rom_error(st.errors), ctx.work / "rom_error.png")
    save(plot_rom_bands(st.rows), ctx.work / "rom_bands.png")
    checks = table("The reduced model against full FE runs (1-min samples)", rs.CHECK_COLUMNS, rs.check_rows(st.checks),
                   note="Built in: assembly and reduction, wall time on this machine (load average "
                                            "at the top of the section); 5-h run: the reduced march alone.")
    study = table("Compensation: the paper's procedure, the regression (MLR) and the reduced model (µm)", rs.COLUMNS,
                  rs.rows_text(st.rows), note=rs.LEGEND)
    figures = (Figure("rom_error.png", "δ of the 30-state reduced model minus δ of the FE run, conditions 1-3"),
               Figure("rom_bands.png", "Residual band of each compensator per case (log scale); the targets are "
                                       "3 µm on the default models and 5 µm on the hidden-effect runs"))
    return Result(tables=(checks, study), figures=figures, notes=tuple(rs.verdicts(st.rows)),
                  files=(("rom_study.md", "the study as Markdown"), ("rom_study.csv", "every case")))
