"""What ``gatetherm live`` keeps in its output directory: a lock, the log ``live.csv`` in the data
format (a row per period, flushed and synced as it is written), the compensator's state
``state.json`` (written atomically after the row), the guards' events ``events.log`` and, at the
end, ``summary.json`` (:func:`summarize`).

On a restart the rows after the state's last period (a row written, the state not yet) and a
trailing partial line are cut, so the log continues exactly where the state resumes.
"""
from __future__ import annotations

import fcntl
import json
import logging
import math
import os
from pathlib import Path

import numpy as np

from gatetherm import InputError, write_text_atomic
from gatetherm.studies.run.timeseries import FORMAT

log = logging.getLogger(__name__)

LOG, STATE, EVENTS, LOCK = "live.csv", "state.json", "events.log", "live.lock"


def lock(directory: Path):
    """Hold ``DIR/live.lock`` (released when the process ends, however it ends); InputError if
    another process holds it, or for a file in the way."""
    from gatetherm.outdir import check_path

    check_path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    fd = os.open(directory / LOCK, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        other = Path(directory / LOCK).read_text(errors="replace").strip() or "?"
        os.close(fd)
        raise InputError(f"--out {directory}", f"another gatetherm live (pid {other}) is running on it",
                         "stop it first, or give another --out") from None
    os.ftruncate(fd, 0)
    os.write(fd, f"{os.getpid()}\n".encode())
    return fd


def _text(x) -> str:
    if isinstance(x, str):
        return x
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return ""
    x = float(x)
    return str(int(x)) if x.is_integer() and abs(x) < 1e15 else repr(x)


def _data_rows(path: Path) -> int:
    """Rows after the header line of a log."""
    lines = [line for line in path.read_text(encoding="utf-8").splitlines() if line and not line.startswith("#")]
    return max(len(lines) - 1, 0)


class Journal:
    """The log, the state and the events of one output directory."""

    def __init__(self, directory: Path, columns, metadata: dict):
        self.dir, self.columns = Path(directory), tuple(columns)
        self.path = self.dir / LOG
        self.dir.mkdir(parents=True, exist_ok=True)
        self.state = self._read_state()
        if self.state is not None and self.path.exists():
            self._trim(self.state.get("t_logged"))
        elif self.path.exists() and _data_rows(self.path):
            raise InputError(str(self.path), f"has rows but {self.dir / STATE} is missing",
                             "give another --out (a log without its state cannot be continued)")
        if not self.path.exists() or self.path.stat().st_size == 0:
            head = [f"# format: {FORMAT}", *(f"# {k}: {v}" for k, v in metadata.items()), ",".join(self.columns)]
            with open(self.path, "w", encoding="utf-8") as f:
                f.write("\n".join(head) + "\n")
                f.flush()
                os.fsync(f.fileno())
        else:
            header = next(line for line in self.path.read_text(encoding="utf-8").splitlines()
                          if not line.startswith("#"))
            if tuple(header.split(",")) != self.columns:
                raise InputError(f"{self.path}", "was written with other columns",
                                 "resume with the same case, method and map, or give another --out")
        self.file = open(self.path, "a", encoding="utf-8")
        self.events = open(self.dir / EVENTS, "a", encoding="utf-8")

    def _read_state(self):
        p = self.dir / STATE
        if not p.exists():
            return None
        try:
            return json.loads(p.read_text(encoding="utf-8"))
        except ValueError:
            raise InputError(str(p), "is not readable JSON", "remove it to start afresh (the log is kept)") from None

    def _trim(self, t_logged) -> None:
        """Cut a partial last line and the rows after ``t_logged`` (s)."""
        lines = self.path.read_text(encoding="utf-8").split("\n")
        complete = lines[:-1]  # the text after the last newline is partial (or empty)
        keep, data = [], False
        for line in complete:
            if not line.startswith("#") and data:
                t = float(line.split(",", 1)[0])
                if t_logged is None or t > t_logged + 1e-9:
                    continue
            if not line.startswith("#"):
                data = True
            keep.append(line)
        text = "\n".join(keep) + "\n"
        if text != "\n".join(lines):
            write_text_atomic(self.path, text)

    def row(self, values: dict) -> None:
        """Append one period's row; flushed and synced before it returns."""
        self.file.write(",".join(_text(values.get(c)) for c in self.columns) + "\n")
        self.file.flush()
        os.fsync(self.file.fileno())

    def save(self, state: dict) -> None:
        """Write the state (atomically), after the row it accounts for."""
        self.state = state
        write_text_atomic(self.dir / STATE, json.dumps(state, allow_nan=False) + "\n")

    def event(self, t, what: str) -> None:
        """One line in ``events.log``: the machine time and what a guard did."""
        self.events.write(f"{_text(t) or '-'} {what}\n")
        self.events.flush()

    def close(self) -> None:
        self.file.close()
        self.events.close()


def summarize(directory, counts: dict, settle_s: float = 600.0) -> dict:
    """The run's summary from ``live.csv``: the counts, the never-worse monitor's verdict
    (``monitor``: "not worse", "worse" or "inactive (no delta_um read)"; ``worse_verdict``: its
    figures) and, where the machine reports its compensated δ, its band after the first
    ``settle_s`` of machine time (µm); written to ``summary.json``."""
    from gatetherm.studies.run.timeseries import read_timeseries

    lines = [x for x in (directory / "live.csv").read_text(encoding="utf-8").splitlines() if x and x[0] != "#"]
    if len(lines) < 2:  # stopped before its first period (no connection yet): nothing to summarise but the counts
        out = {**counts, "rows": 0, "first_s": None, "last_s": None, "monitor": "inactive (no period)",
               "worse_verdict": None}
        write_text_atomic(directory / "summary.json", json.dumps(out, indent=2, allow_nan=False) + "\n")
        return out
    ts = read_timeseries(directory / "live.csv", required=("time_s",))
    out = {**counts, "rows": len(ts.time_s), "first_s": float(ts.time_s[0]) if len(ts.time_s) else None,
           "last_s": float(ts.time_s[-1]) if len(ts.time_s) else None}
    if "delta_residual_um" in ts and len(ts.time_s):
        late = ts.time_s >= ts.time_s[0] + settle_s
        comp = ts["delta_residual_um"][late]
        out["compensated_band_um"] = float(np.nanmax(np.abs(comp))) if np.isfinite(comp).any() else None
    state = directory / "state.json"
    watch = json.loads(state.read_text(encoding="utf-8")).get("monitor") if state.exists() else None
    out["monitor"] = ("inactive (no delta_um read)" if "delta_um" not in ts
                      else "worse" if watch and watch.get("worse") else "not worse")
    out["worse_verdict"] = watch.get("worse") if watch else None
    write_text_atomic(directory / "summary.json", json.dumps(out, indent=2, allow_nan=False) + "\n")
    if counts.get("missed"):
        log.info("%d period(s) missed", counts["missed"])
    return out
