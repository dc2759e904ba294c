"""The validation studies (:mod:`gatetherm.api`): :func:`validate` regenerates one of them
(docs/validation.md) into a folder and returns what it found. Each target is an entry of
:data:`TARGETS`; the studies themselves live in :mod:`gatetherm.validation`."""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from gatetherm import InputError

PUBLIC = ("Validation", "validate")  # offered as gt.NAME (gatetherm.api finds them here)


@dataclass(frozen=True)
class Validation:
    """What :func:`validate` returns (the study's files are written by then)."""

    target: str
    """The study (a key of :data:`TARGETS`)."""
    out: str
    """The folder written."""
    text: str
    """What the study says at its end (a table, accuracies, the best parameters …), as ``gatetherm
    validate`` prints it after the lines it streamed."""
    data: object = None
    """The study's own return value (rows, accuracies, the zoo's matrix …), where it has one."""

    def summary(self) -> str:
        """:attr:`text`: what ``gatetherm validate TARGET`` prints last."""
        return self.text


def _config(o):
    from gatetherm.frame.config import load_config

    return load_config(o.get("config"))


def _beam(out, o, on_line, on_progress):
    from gatetherm.validation.beam_study import write_beam_study

    s = write_beam_study(out, _config(o), o.get("dim", 2), o.get("workers", 1), o.get("scheduler"), on_progress)
    return "\n".join(s["lines"]) + "\n", s


def _design(out, o, on_line, on_progress):
    from gatetherm.validation.design_study import write_design_study

    lines = write_design_study(out, _config(o), o.get("dim", 2), o.get("workers", 1), o.get("scheduler"), on_progress)
    return "\n".join(lines) + "\n", lines


def _paper(out, o, on_line, on_progress):
    from gatetherm.validation.paper_table import write_paper_table

    return write_paper_table(out, _config(o), list(o.get("dims", (2, 3))), o.get("reuse", False)), None


def _compensation(out, o, on_line, on_progress):
    from gatetherm.validation.compensation_study import markdown, write_compensation_study

    rows = write_compensation_study(out, _config(o), o.get("dim", 2))
    return markdown(rows), rows


def _rom(out, o, on_line, on_progress):
    from gatetherm.validation.rom_study import write_rom_study

    def row(r):
        on_line(f"{r.case}, condition {r.condition}, {r.data}: paper {r.paper_um:.2f}, MLR {r.mlr_um:.2f}, "
                f"rom {r.rom_5min_um:.2f} / {r.rom_event_um:.2f} µm ({r.rom_updates} updates)")
    study = write_rom_study(out, _config(o), list(o.get("dims", (2, 3))), on_row=row)
    return study.markdown, study


def _hidden(out, o, on_line, on_progress):
    from gatetherm.validation.hidden_effects import ALL_CASES, row_line, write_hidden_effects

    effects = set(o["effects"]) if o.get("effects") else set(ALL_CASES)
    if effects - set(ALL_CASES):
        raise InputError(o.get("named_effects", "effects"), f"unknown {', '.join(sorted(effects - set(ALL_CASES)))}",
                         f"choose from {', '.join(ALL_CASES)}")
    acc, rows = write_hidden_effects(out, o.get("workers", 2), o.get("seed", 6), tuple(o.get("conditions", (1, 2, 3))),
                                     effects, o.get("mesh_size"), on_row=lambda row: on_line(row_line(row)))
    return "".join(f"{k}: {v}\n" for k, v in acc.items()), acc


def _compound(out, o, on_line, on_progress):
    from gatetherm.validation.compound_study import row_line, write_compound

    figures, _ = write_compound(out, o.get("workers", 2), o.get("seed", 14), o.get("pairs", 48), o.get("single", True),
                                o.get("mesh_size"), on_row=lambda row: on_line(row_line(row)))
    return "".join(f"{k}: {v}\n" for k, v in figures.items()), figures


def _case_diagnosis(out, o, on_line, on_progress):
    from gatetherm.validation.case_diagnosis import C_FRAME, write_case_diagnosis

    line, rows = write_case_diagnosis(out, Path(o["case"]) if o.get("case") else C_FRAME, o.get("seed", 10),
                                      on_row=lambda r: on_line(f"{r['scenario']}: {r['verdict']}, "
                                                               f"{' + '.join(r['pieces']) or 'nothing'} named"))
    return line + "\n", rows


def _zoo(out, o, on_line, on_progress):
    from gatetherm.api.zoo import validate_zoo

    matrix = validate_zoo(out, o.get("machines"), timeout_s=o.get("timeout"),
                          on_cell=lambda m, c, cell: on_line(f"{m}, {c}: {cell['text']}"))
    cells = [c for row in matrix.values() for c in row.values()]
    return (f"wrote {out}/zoo.md and zoo.json: {len(matrix)} machines x {len(next(iter(matrix.values())))} "
            f"capabilities, {sum(c['status'] == 'ok' for c in cells)} numbers, "
            f"{sum(c['status'] == 'refused' for c in cells)} refusals, "
            f"{sum(c['status'] == 'failed' for c in cells)} failed\n"), matrix


def _calibrate(out, o, on_line, on_progress):
    from gatetherm.validation.calibrate_paper import calibrate

    best = calibrate(o.get("evals", 150), o.get("mesh_size", 0.012), on_better=on_line)
    return "\n# best parameters (to paste into studies/data/paper.toml)\n" + "\n".join(best) + "\n", best


TARGETS = {
    "beam": ("beam theory vs FE: K_i, K_C over l/l4 and beta, error table, series, report", _beam),
    "design": ("tie-bar position minimising the 5-h swing of delta; a second tie bar above the arms", _design),
    "paper": ("the paper's conditions 1-3 in 2-D and 3-D against its reported figures", _paper),
    "compensation": ("the paper's compensator, the regression baseline and the piezo on conditions 1-3",
                     _compensation),
    "rom": ("paper vs regression vs reduced-model compensation: conditions 1-3 in 2-D/3-D, hidden effects", _rom),
    "hidden-effects": ("diagnose runs with a hidden catalogue effect, noise only, outside effects, mismatches",
                       _hidden),
    "compound": ("diagnose runs with two hidden pieces at once (effects, parameters off, sensor faults), "
                 "then the hidden-effect cases", _compound),
    "case-diagnosis": ("diagnose runs of a case file's frame (the C-frame) with hidden pieces of the case",
                       _case_diagnosis),
    "zoo": ("every capability on every shipped machine (validation/examples): the matrix zoo.md, zoo.json", _zoo),
    "calibrate": ("refit the default paper model to the paper's figures (a record of the procedure)", _calibrate),
}
"""Study name -> (what it does, its function)."""

OPTIONS = {
    "beam": ("config", "dim", "workers", "scheduler"), "design": ("config", "dim", "workers", "scheduler"),
    "paper": ("config", "dims", "reuse"), "compensation": ("config", "dim"), "rom": ("config", "dims"),
    "hidden-effects": ("workers", "seed", "conditions", "effects", "mesh_size"),
    "compound": ("workers", "seed", "pairs", "single", "mesh_size"), "case-diagnosis": ("case", "seed"),
    "zoo": ("machines", "timeout"), "calibrate": ("evals", "mesh_size"),
}
"""Study name -> the settings it takes (the keyword arguments of :func:`validate`)."""


def validate(target: str, out: str | os.PathLike, *, on_line=None, on_progress=None, **options) -> Validation:
    """Regenerate a validation study (docs/validation.md) into ``out``: its tables, figures and reports.

    ``out`` is locked while the study runs and a killed run's temporaries are removed
    (:func:`gatetherm.outdir.output_dir`); a study's own files are rewritten, or resumed, by the study.

    Parameters
    ----------
    target : str
        A key of :data:`TARGETS`: ``beam``, ``design``, ``paper``, ``compensation``, ``rom``,
        ``hidden-effects``, ``compound``, ``case-diagnosis``, ``zoo``, ``calibrate``.
    out : path
        Output directory.
    on_line : callable, optional
        ``on_line(text)`` for each line a study reports as it goes (a case, a cell, a better fit).
    on_progress : callable, optional
        ``on_progress(i, n)`` as points finish (``beam``, ``design``).
    **options
        The study's settings, as ``gatetherm validate TARGET --help`` lists them: ``config`` (a
        model file's path), ``dim`` (2 or 3), ``dims``, ``workers``, ``scheduler``, ``reuse``,
        ``seed``, ``conditions`` (of 1, 2, 3), ``effects`` (names), ``mesh_size`` (m), ``pairs``,
        ``single``, ``case`` (a case file's path), ``machines``, ``timeout`` (s), ``evals``.

    Returns
    -------
    Validation
        ``.text`` (what the study says at its end) and ``.data`` (its own return value); ``.summary()``.

    Raises
    ------
    InputError
        An unknown target, a bad setting, a bad model or case file.
    """
    from gatetherm.outdir import output_dir

    if target not in TARGETS:
        raise InputError("target", f"{target!r} is not a validation study", f"choose from {', '.join(TARGETS)}")
    unknown = sorted(set(options) - set(OPTIONS[target]))
    if unknown:
        raise TypeError(f"{unknown[0]}: not a setting of the {target} study; it takes "
                        f"{', '.join(OPTIONS[target])}")
    on_line = on_line or (lambda text: None)
    with output_dir(out):
        text, data = TARGETS[target][1](Path(out), options, on_line, on_progress)
    return Validation(target, str(out), text, data)
