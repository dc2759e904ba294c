"""Speed and scaling section: the tables the benchmark scripts last wrote to
``benchmarks/results/*.json`` (``{"date", "machine", "command", "columns", "rows", "notes"}``),
shown as they are; a file not there is "not measured yet". The section never runs a benchmark:
they take long and want a quiet machine."""
from __future__ import annotations

import json

from gatetherm.validation.report.registry import BENCHMARK_FILES, BENCHMARKS
from gatetherm.validation.report.result import Result, cell, table


def benchmark_table(name: str, data: dict, command: str):
    """The table of one benchmark result file: its columns and rows as they are, captioned with the
    command, date and machine it records."""
    cmd = (data.get("command") or command).strip()
    return table(f"{name}: measured by `{cmd}` on {data.get('machine', 'an unrecorded machine')}, "
                 f"{data.get('date', 'undated')}", data["columns"], [[cell(v) for v in r] for r in data["rows"]],
                 note="; ".join(str(n) for n in data.get("notes", ())))


def compute(ctx) -> Result:
    tables, notes = [], []
    for name, command in BENCHMARK_FILES.items():
        path = BENCHMARKS / name
        if not path.is_file():
            notes.append(f"`benchmarks/results/{name}`: not measured yet (`{command}` writes it).")
            continue
        try:
            tables.append(benchmark_table(name, json.loads(path.read_text(encoding="utf-8")), command))
        except (ValueError, KeyError, TypeError, AttributeError) as err:
            notes.append(f"`benchmarks/results/{name}` is not a benchmark table ({type(err).__name__}: {err}); "
                         f"rerun `{command}`.")
    return Result(tables=tuple(tables), notes=tuple(notes))
