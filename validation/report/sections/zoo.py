"""Machine-zoo section: every capability on every shipped machine (``gatetherm validate zoo``)."""
from __future__ import annotations

from gatetherm.validation.report.result import Result, table

MEANING = (
    "run: δ's swing over the duty cycle (steady: its value); reduce: the largest error of δ of a "
    "reduced model of `gatetherm reduce`'s default size against FE on the case's schedule; paper, mlr, rom: `gatetherm compensate`'s residual band "
    "(max |δ_comp| after 10 min) with that method, the uncompensated band beside it in the cell's line; "
    "errormodel comp: the same for an error model fitted on the first half of the run and replayed as "
    "`compensate --model`; sweep: the change of δ's swing between the two points of a one-key study; "
    "sensors: held-out MAE of δ with three thermocouples placed as `gatetherm sensors` places them (8 training loads, 3 "
    "held out, 20 states), the case's own θ_A, θ_B, θ_C (a designer's choice) beside it; diagnose: the factor "
    "fitted to the hidden piece (a source made stronger in a P2 truth with noise; at most two pieces); "
    "errormodel: `errormodel fit` on the first 60 % and `predict` on the rest, RMS of δ's error there; "
    "report: `report --data` on the run, the largest drift of δ; export ccx: `export ccx` at the end of the "
    "run and CalculiX, the largest |δ_ccx/δ − 1| (acceptance 0.5 %). A refusal is the library's own "
    "one-line message (an `InputError`); FAILED is any other exception, a crash or the cell's time limit.",
    "The six new machines were written from docs/case-file.md and docs/data-format.md alone. Where the docs "
    "were silent or wrong: data-format.md "
    "calls `oil_degC` and `pump` required, but a case's schedule needs only the columns its values read; "
    "`[signals]` describes θ_A, θ_B, θ_C in the paper frame's words (heated column face, tie bar), with no "
    "word on choosing them on another machine; nothing says how a probe of a 3-D assembly becomes a mesh "
    "node (`export ccx` refuses probes that are not): points fragmented with the gantry's solids "
    "(`BooleanFragments{ Volume{:}; Point{:}; }`) lose its `feet` boundary on reading (\"supports.feet: unknown "
    "key\"), so the gantry gives its probes as coordinates of its boxes' corners (vertices, so nodes); nothing says which condition the axis "
    "r = 0 of an axisymmetric section needs (none).",
)


def result(matrix: dict, seconds: float) -> Result:
    """The section of a zoo ``matrix`` (:func:`gatetherm.validation.zoo.run_zoo`)."""
    from gatetherm.validation.zoo import MACHINES, short

    caps = list(next(iter(matrix.values())))
    cells = [c for row in matrix.values() for c in row.values()]
    count = {s: sum(c["status"] == s for c in cells) for s in ("ok", "refused", "failed")}
    line = (f"{len(matrix)} machines × {len(caps)} capabilities in {seconds:.0f} s: {count['ok']} numbers, "
            f"{count['refused']} one-line refusals, {count['failed']} failed (an exception other than a refusal, "
            "or the cell's time limit).")
    units = {"diagnose": "factor", "export ccx": "%"}
    matrix_table = table("Every capability on every machine", ("machine", *(f"{c} [{units.get(c, 'µm')}]"
                                                                              for c in caps)),
                         [(m, *(short(row[c]) for c in caps)) for m, row in matrix.items()],
                         note="What each number is: the list under the section's heading; every cell's line in "
                              "the next table.")
    lines = table("Every cell in one line", ("machine", "capability", "cell", "s"),
                  [(m, c, row[c]["text"], f"{row[c]['seconds']:g}") for m, row in matrix.items() for c in caps])
    kinds = table("The machines", ("machine", "kind", "case"),
                  [(m, MACHINES[m].kind, f"validation/examples/{MACHINES[m].folder}/case.toml") for m in matrix])
    return Result(tables=(kinds, matrix_table, lines), notes=(line, *MEANING),
                  files=(("zoo.md", "the matrix and every cell"), ("zoo.json", "every cell in full")))


def compute(ctx) -> Result:
    import time

    from gatetherm.validation.zoo import write_zoo

    t0 = time.perf_counter()
    matrix = write_zoo(ctx.work, ctx.scope.get("machines"), timeout_s=ctx.scope["timeout_s"])
    return result(matrix, time.perf_counter() - t0)
