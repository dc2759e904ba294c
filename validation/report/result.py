"""What a report section returns: tables, figures, notes and links, stored as JSON."""
from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path

from gatetherm import write_text_atomic


@dataclass(frozen=True)
class Table:
    """A table of preformatted cells."""

    title: str
    """What the table shows (the caption's first sentence)."""
    columns: tuple[str, ...]
    """Column headings."""
    rows: tuple[tuple[str, ...], ...]
    """Cells, formatted (numbers with their units where the heading has none)."""
    note: str = ""
    """A sentence under the table (units, tolerances, what a mark means)."""


@dataclass(frozen=True)
class Figure:
    """A picture in the section's folder."""

    file: str
    """File name inside the section's folder."""
    caption: str
    """What it shows (the command, version and date are added on the page)."""


@dataclass(frozen=True)
class Result:
    """A computed section."""

    tables: tuple[Table, ...] = ()
    """In page order."""
    figures: tuple[Figure, ...] = ()
    """In page order."""
    notes: tuple[str, ...] = ()
    """Paragraphs: the key figures in sentences (`code` in backticks)."""
    files: tuple[tuple[str, str], ...] = ()
    """(file in the section's folder, what it is): tables, reports and decks to download."""
    stamp: dict = field(default_factory=dict)
    """How it was made: digest, version, code digest, date, seconds, load, full (set by the builder)."""


def table(title: str, columns, rows, **kw) -> Table:
    """A :class:`Table` from any iterables of cells (converted to strings)."""
    return Table(title, tuple(str(c) for c in columns), tuple(tuple(str(c) for c in r) for r in rows), **kw)


def cell(v) -> str:
    """A table cell: whole numbers as they are, other numbers to 4 significant digits, booleans
    yes/no, None and NaN as a dash, a list as its cells joined by " + "."""
    if isinstance(v, bool):
        return "yes" if v else "no"
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "—"
    if isinstance(v, (list, tuple)):
        return " + ".join(map(cell, v)) or "—"
    if isinstance(v, int):
        return str(v).replace("-", "−")
    if isinstance(v, float):
        return f"{v:.4g}".replace("-", "−")
    return str(v)


def from_dicts(title: str, rows: list[dict], columns=None, **kw) -> Table:
    """A :class:`Table` of dict rows (``columns``: their keys to show, default the first row's)."""
    columns = list(columns or (rows[0] if rows else []))
    return table(title, columns, [[cell(r.get(c)) for c in columns] for r in rows], **kw)


def dump(result: Result, path: Path) -> None:
    write_text_atomic(path, json.dumps(asdict(result), indent=1, ensure_ascii=False) + "\n")


def load(path: Path) -> Result:
    d = json.loads(Path(path).read_text(encoding="utf-8"))
    return Result(tables=tuple(Table(t["title"], tuple(t["columns"]), tuple(tuple(r) for r in t["rows"]),
                                     t.get("note", ""))
                        for t in d["tables"]),
                  figures=tuple(Figure(**f) for f in d["figures"]), notes=tuple(d["notes"]),
                  files=tuple(tuple(f) for f in d["files"]), stamp=d["stamp"])
