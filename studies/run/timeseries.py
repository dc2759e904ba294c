"""The gatetherm time-series file (docs/data-format.md, version 1).

One CSV format for simulated and measured runs: ``# key: value`` metadata lines,
one header row, then numbers; an empty field is a missing sample (NaN). UTF-8, with or
without a byte-order mark, any line ends. Temperatures, displacements and times must lie in
their admissible ranges (:data:`COLUMN_RANGES`).
In memory a run is a :class:`TimeSeries`: named float columns in file order
plus the metadata. Reading validates the file and reports the first problem
as one :class:`~geometry.errors.InputError` line naming file, line, data row
and column.
"""
from __future__ import annotations

import csv
import difflib
import logging
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gatetherm import InputError, atomic_path
from gatetherm.checks import CELSIUS, KELVIN_LIKE, Range, _short, show
from gatetherm.files import read_text

log = logging.getLogger(__name__)

FORMAT = "gatetherm-timeseries/1"
SUPPLY, PUMP, AMBIENT = "oil_degC", "pump", "ambient_degC"
"""The inputs of an oil supply unit and the room: the format's input columns (the paper frame's inputs)."""
INPUT_COLUMNS = ("time_s", SUPPLY, PUMP)
OUTPUT_COLUMNS = ("theta_A_degC", "theta_B_degC", "theta_C_degC", "delta_um")
#: Optional columns of the format; anything else is kept but reported as unknown.
OPTIONAL_COLUMNS = (AMBIENT, "u_piezo_um")
_SENSOR_COLUMN = re.compile(r"^T_\w+_degC$")
#: Admissible values of the columns whose name matches a pattern (the first that does);
#: any other column holds finite numbers.
COLUMN_RANGES = ((re.compile(r"_degC$"), CELSIUS), (re.compile(r"_um$"), Range(-1e6, 1e6, unit="µm")),
                 (re.compile(r"^time_s$"), Range(-1e10, 1e10, unit="s")))
MAX_STEPS = 1_000_000
"""Most time steps a run is simulated or resampled in (694 days of 60-s steps)."""


def check_steps(span_s: float, step_s: float, where: str) -> int:
    """The number of ``step_s`` steps in ``span_s``, if at most :data:`MAX_STEPS`."""
    n = int(span_s // step_s)
    if n > MAX_STEPS:
        raise InputError(where, f"{span_s:g} s are {n} steps of {step_s:g} s, more than {MAX_STEPS}",
                         "give a shorter run")
    return n


@dataclass(frozen=True)
class TimeSeries:
    """A run: equally long float columns (NaN = missing) in file order, and metadata."""

    columns: dict[str, np.ndarray]
    """Column name -> values in the column's unit (s, degC, um, 0/1); read-only copies."""
    metadata: dict[str, str] = field(default_factory=dict)
    """'# key: value' lines of the file, e.g. {"format": FORMAT, "condition": "2"}."""
    source: str = field(default="", compare=False, repr=False)
    """The file it was read from, named by the messages about its columns; empty when made in memory."""

    def __post_init__(self):
        cols = {}
        for name, values in self.columns.items():
            arr = np.array(values, dtype=float).reshape(-1)
            arr.setflags(write=False)
            cols[str(name)] = arr
        lengths = {len(a) for a in cols.values()}
        if len(lengths) > 1:
            raise ValueError(f"columns differ in length: {({k: len(a) for k, a in cols.items()})}")
        object.__setattr__(self, "columns", cols)
        object.__setattr__(self, "metadata", {str(k): str(v) for k, v in self.metadata.items()})

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self.columns[name]
        except KeyError:
            raise KeyError(f"no column {name!r}; columns are {', '.join(self.columns)}") from None

    def __contains__(self, name: object) -> bool:
        return name in self.columns

    def __len__(self) -> int:
        return len(next(iter(self.columns.values()))) if self.columns else 0

    @property
    def names(self) -> tuple[str, ...]:
        """Column names in file order."""
        return tuple(self.columns)

    @property
    def time_s(self) -> np.ndarray:
        """Sample times in s."""
        return self["time_s"]

    def with_columns(self, **arrays) -> TimeSeries:
        """A new series with these columns replaced in place or appended at the end."""
        return TimeSeries({**self.columns, **arrays}, dict(self.metadata), self.source)

    def slice(self, mask_or_slice) -> TimeSeries:
        """A new series with the rows selected by a boolean mask, index array or slice."""
        return TimeSeries({k: v[mask_or_slice] for k, v in self.columns.items()}, dict(self.metadata), self.source)


def rises(ts: TimeSeries, name: str) -> np.ndarray:
    """Temperature rise of column ``name`` from its first sample (the beam-theory theta), K."""
    values = ts[name]
    if len(values) == 0 or np.isnan(values[0]):
        raise InputError(name, "the first sample is missing, so the rise is undefined",
                         "give a value at the first time step")
    return values - values[0]


def alike(name: str, columns, what: str = "columns") -> str:
    """``; columns alike: a, b`` for the ``columns`` that look like ``name`` (difflib), else ``""``."""
    close = difflib.get_close_matches(name, list(columns), n=3, cutoff=0.6)
    return f"; {what} alike: {', '.join(close)}" if close else ""


def missing_column(name: str, columns, source: str = "", named_by: str = "") -> InputError:
    """The error for a column ``name`` that the file ``source`` (with ``columns``) lacks: blamed on
    the option or key ``named_by`` that named it, if given, else on the file; with its columns that
    look alike."""
    file = source or "the data"
    if named_by:
        return InputError(named_by, f"{name!r} is not a column of {file}",
                          f"name a column of the file{alike(name, columns)} (its columns: {', '.join(columns)})")
    return InputError(f"{source}: column {name}" if source else f"column {name}", "missing",
                      f"add a {name} column{alike(name, columns)}")


def validate_complete(ts: TimeSeries, names, source: str = "") -> None:
    """Raise InputError naming the file (``source``, else the series') and the first data row where any
    of ``names`` is missing."""
    source = source or ts.source
    where = f"{source}: " if source else ""
    for name in names:
        if name not in ts:
            raise missing_column(name, ts.names, source)
    missing = np.zeros(len(ts), dtype=bool)
    for name in names:
        missing |= np.isnan(ts[name])
    if missing.any():
        row = int(np.argmax(missing))
        col = next(n for n in names if np.isnan(ts[n][row]))
        at = f" (time_s = {ts.time_s[row]:.10g})" if "time_s" in ts else ""
        raise InputError(f"{where}data row {row + 1}{at}, column {col}", "value missing",
                         "this analysis needs every sample; fill or remove the row")


_DECIMAL = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
"""A number as a data file writes it: decimal digits, a point, an exponent."""


def _csv_rows(path: Path, lines: list[str], first: int):
    """(line number, fields) of the CSV ``lines`` from index ``first`` on; a line the csv module
    cannot read (a field of more than 128 kB) is one line naming it."""
    reader = csv.reader(lines[first:])
    try:
        for fields in reader:
            yield first + reader.line_num, fields
    except csv.Error as err:
        raise InputError(f"{path}, line {first + reader.line_num}", f"not CSV ({err})",
                         "give one number per field (docs/data-format.md)") from None


def _parse_value(text: str, where: str) -> float:
    text = text.strip()
    if not text:
        return math.nan
    try:
        value = float(text) if _DECIMAL.fullmatch(text) else math.nan  # not Python's 4_0, ４０ or 'infinity'
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise InputError(where, f"non-numeric value {_short(text)}",
                         "write a decimal number, or leave the field empty for a missing sample")
    return value


def read_timeseries(path, required=INPUT_COLUMNS + OUTPUT_COLUMNS, named_by: dict | None = None) -> TimeSeries:
    """Read and validate a time-series CSV; see the module docstring and docs/data-format.md.
    ``required``: the columns it must have; ``named_by``: for those named by the user, the option or
    key that named each (``{"ch1_um": "--targets"}``), blamed when the file lacks it."""
    path = Path(path)
    lines = read_text(path, fix="give a time-series CSV file (docs/data-format.md)").splitlines()
    metadata: dict[str, str] = {}
    lineno = 0
    while lineno < len(lines) and (not lines[lineno].strip() or lines[lineno].lstrip().startswith("#")):
        key, sep, value = lines[lineno].lstrip().lstrip("#").partition(":")
        if sep and key.strip():
            metadata[key.strip()] = value.strip()
        lineno += 1
    if lineno == len(lines):
        raise InputError(str(path), "no header row", "add a header line naming the columns")
    header = [h.strip() for h in next(_csv_rows(path, lines, lineno))[1]]
    header_line = lineno + 1
    fmt = metadata.get("format", FORMAT)
    if fmt != FORMAT:
        raise InputError(f"{path}: metadata format", f"unsupported {fmt!r}", f"expected {FORMAT!r}")
    for i, name in enumerate(header):
        if not name or name in header[:i]:
            raise InputError(f"{path}, line {header_line}", f"empty or repeated column name {name!r}",
                             "give every column a unique name")
    for name in required:
        if name in (named_by or {}) and name not in header:
            raise missing_column(name, header, str(path), named_by[name])
        if name not in header:
            raise InputError(f"{path}, line {header_line}", f"missing required column {name!r}",
                             f"add it to the header (required: {', '.join(required)}){alike(name, header)}")
    unknown = [h for h in header if h not in INPUT_COLUMNS + OUTPUT_COLUMNS + OPTIONAL_COLUMNS
               and not _SENSOR_COLUMN.match(h)]
    if unknown:
        log.info("%s: keeping columns not in %s: %s", path, FORMAT, ", ".join(unknown))

    rows, linenos = [], []
    for k, fields in _csv_rows(path, lines, lineno + 1):
        if not fields or (len(fields) == 1 and not fields[0].strip()):
            continue
        where = f"{path}, line {k} (data row {len(rows) + 1})"
        if len(fields) != len(header):
            raise InputError(where, f"{len(fields)} fields for {len(header)} columns",
                             "give one field per column (empty for a missing sample)")
        rows.append([_parse_value(v, f"{where}, column {h}") for v, h in zip(fields, header)])
        linenos.append(k)
    if not rows:
        raise InputError(str(path), "no data rows", "add at least one sample after the header")
    data = np.array(rows, dtype=float)
    cols = {h: data[:, i] for i, h in enumerate(header)}

    def fail(row: int, column: str, problem: str, fix: str):
        raise InputError(f"{path}, line {linenos[row]} (data row {row + 1}), column {column}", problem, fix)

    if "time_s" in cols:
        t = cols["time_s"]
        if np.isnan(t).any():
            fail(int(np.argmax(np.isnan(t))), "time_s", "time missing", "every row needs a time")
        bad = np.flatnonzero(np.diff(t) <= 0)
        if bad.size:
            r = int(bad[0]) + 1
            fail(r, "time_s", f"time {t[r]:.10g} s is not after the previous {t[r - 1]:.10g} s",
                 "times must strictly increase; sort the rows or remove the duplicate")
    if "pump" in cols:
        p = cols["pump"]
        bad = np.flatnonzero(~np.isnan(p) & (p != 0) & (p != 1))
        if bad.size:
            fail(int(bad[0]), "pump", f"value {p[bad[0]]:g} is not 0 or 1", "write 1 (on) or 0 (off)")
    for name, values in cols.items():
        rng = next((r for pattern, r in COLUMN_RANGES if pattern.search(name)), None)
        bad = np.flatnonzero(~np.isnan(values) & ~rng.mask(values)) if rng else ()
        if len(bad):
            fail(int(bad[0]), name, f"got {show(values[bad[0]])}, must be {rng}", "check the value and its unit")
        finite = values[np.isfinite(values)]
        if name.endswith("_degC") and finite.size and KELVIN_LIKE[0] <= finite.min() and finite.max() <= KELVIN_LIKE[1]:
            log.warning("%s, column %s: every value lies in 253-373, a machine's surroundings in kelvins "
                        "(%.6g K is %.6g °C); the column is in °C", path, name, finite[0], finite[0] - 273.15)
    return TimeSeries(cols, metadata, str(path))


def _format_value(x: float) -> str:
    """Shortest text that reads back as exactly ``x``; empty for NaN."""
    if math.isnan(x):
        return ""
    if x.is_integer() and abs(x) < 1e15:
        return str(int(x))
    return repr(x)


def write_timeseries(path, ts: TimeSeries) -> None:
    """Write ``ts`` atomically: format line, other metadata, header, exact numbers."""
    for key, value in ts.metadata.items():
        if ":" in key or "\n" in key or "\n" in value or not key.strip():
            raise InputError(f"metadata {key!r}", "cannot be written as '# key: value'",
                             "use a key without ':' and single-line values")
    for name, values in ts.columns.items():
        if any(c in name for c in ',"\n') or name.startswith("#"):
            raise InputError(f"column {name!r}", "cannot be written as a CSV header field",
                             "use a name without commas, quotes or a leading '#'")
        if np.isinf(values).any():
            raise InputError(f"column {name}", "contains an infinite value", "use finite numbers or NaN")
    lines = [f"# format: {FORMAT}"]
    lines += [f"# {k}: {v}" for k, v in ts.metadata.items() if k != "format"]
    lines.append(",".join(ts.names))
    table = np.column_stack(list(ts.columns.values())) if ts.columns else np.empty((0, 0))
    lines += [",".join(_format_value(x) for x in row) for row in table.tolist()]
    with atomic_path(path) as tmp:
        Path(tmp).write_text("\n".join(lines) + "\n", encoding="utf-8")
