"""Machine-zoo section: every capability on every shipped machine (``gatetherm validate zoo``)."""
from __future__ import annotations

from gatetherm.validation.report.result import Result, table


def result(matrix: dict, seconds: float) -> Result:
    """The section of a zoo ``matrix`` (:func:`gatetherm.validation.zoo.run_zoo`)."""
    from gatetherm.validation.zoo import MACHINES, _short

    caps = list(next(iter(matrix.values())))
    cells = [c for row in matrix.values() for c in row.values()]
    count = {s: sum(c["status"] == s for c in cells) for s in ("ok", "refused", "failed")}
    line = (f"{len(matrix)} machines × {len(caps)} capabilities in {seconds:.0f} s: {count['ok']} numbers, "
            f"{count['refused']} one-line refusals, {count['failed']} failed (an exception other than a refusal, "
            "or the cell's time limit).")
    units = {"diagnose": "factor", "export ccx": "%"}
    matrix_table = table("Every capability on every machine", ("machine", *(f"{c} [{units.get(c, 'µm')}]"
                                                                              for c in caps)),
                         [(m, *(_short(row[c]) for c in caps)) for m, row in matrix.items()],
                         note="What each number is: the list under the section's heading; every cell's line in "
                              "the next table.")
    lines = table("Every cell in one line", ("machine", "capability", "cell", "s"),
                  [(m, c, row[c]["text"], f"{row[c]['seconds']:g}") for m, row in matrix.items() for c in caps])
    kinds = table("The machines", ("machine", "kind", "case"),
                  [(m, MACHINES[m].kind, f"validation/examples/{MACHINES[m].folder}/case.toml") for m in matrix])
    return Result(tables=(kinds, matrix_table, lines), notes=(line,),
                  files=(("zoo.md", "the matrix and every cell"), ("zoo.json", "every cell in full")))


def compute(ctx) -> Result:
    import time

    from gatetherm.validation.zoo import write_zoo

    t0 = time.perf_counter()
    matrix = write_zoo(ctx.work, ctx.scope.get("machines"), timeout_s=ctx.scope["timeout_s"])
    return result(matrix, time.perf_counter() - t0)
