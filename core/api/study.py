"""Parametric studies (:mod:`gatetherm.api`): :func:`sweep` runs a study file's grid of points
(docs/sweep.md) and writes its table and plots."""
from __future__ import annotations

import dataclasses
import json
import os
from dataclasses import dataclass
from pathlib import Path

from gatetherm.checks import Range

PUBLIC = ("SweepResult", "sweep")  # offered as gt.NAME (gatetherm.api finds them here)

_WORKERS = Range(1, whole=True)
OUTPUTS = ("table.csv", "study.json", "*_vs_*.png")
"""What a sweep writes into its output directory besides the point files (kept: a rerun resumes
from them); a rerun replaces all of it."""


@dataclass(frozen=True)
class SweepResult:
    """What :func:`sweep` returns: the study, its table and the points that failed."""

    study: object
    """The study file read (:class:`gatetherm.studies.sweeps.studyfile.Study`)."""
    columns: tuple[str, ...]
    """The table's columns (the parameters, then the results with their units in the names)."""
    rows: tuple[dict, ...]
    """One row per point; ``status`` is ``done``, ``skipped`` (the frame cannot be built) or ``failed``."""
    failed: tuple = ()
    """``(task, exception)`` per point that raised; a rerun retries them."""
    plots: bool = True
    """Whether :meth:`write` draws the study's ``[[plot]]`` tables."""
    written: tuple[str, ...] = ()
    """The plot files written, in order."""
    files: tuple[str, ...] = ()
    """The study file (kept by :meth:`write`: never overwritten)."""

    @property
    def skipped(self) -> int:
        """Points whose frame cannot be built."""
        return sum(r["status"] == "skipped" for r in self.rows)

    def _write_into(self, out: Path, final: Path) -> tuple[str, ...]:
        from gatetherm import write_text_atomic
        from gatetherm.studies.sweeps.runner import write_table

        s = self.study
        write_table(out / "table.csv", list(self.columns), list(self.rows))
        write_text_atomic(out / "study.json", json.dumps(
            {"name": s.name, "dim": s.dim, "config": s.case or s.base.source, "compute": list(s.compute),
             "set": dict(s.fixed), "grid": {k: list(v) for k, v in s.grid}}, indent=2) + "\n")
        written = []
        if self.plots and s.plots:
            from gatetherm.validation.plots import save
            from gatetherm.validation.plots.sweep import plot_xy

            for spec in s.plots:
                path = out / f"{spec.y}_vs_{spec.x}{'_by_' + spec.hue if spec.hue else ''}.png".replace("/", "_")
                others = [k for k, _ in s.grid if k not in (spec.x, spec.hue)]
                save(plot_xy(list(self.rows), spec.x, spec.y, spec.hue, s.name, lines_by=others), path)
                written.append(str(final / path.name))  # the final file, not the stage's
        return tuple(written)

    def write(self, out: str | os.PathLike) -> tuple[str, ...]:
        """Write ``out/table.csv``, ``out/study.json`` and the plots (replacing the previous ones
        only on success); returns the plot files."""
        from gatetherm.outdir import output_dir

        with output_dir(out, OUTPUTS, keep=self.files) as st:
            return self._write_into(st, Path(out))

    def summary(self, out: str | os.PathLike) -> str:
        """What ``gatetherm sweep`` prints: the points done, skipped and failed, and the plots written."""
        n = len(self.rows)
        lines = [f"wrote {Path(out) / 'table.csv'}: {n} points, {n - self.skipped - len(self.failed)} done, "
                 f"{self.skipped} skipped (frame cannot be built), {len(self.failed)} failed"]
        return "\n".join(lines + [f"wrote {p}" for p in self.written])

    def raise_failed(self) -> None:
        """Raise :class:`~gatetherm.studies.sweeps.runner.PointsFailed` (one line: how many, why
        the first three) if a point failed."""
        from gatetherm.studies.sweeps.runner import PointsFailed

        if self.failed:
            raise PointsFailed(list(self.failed), len(self.rows))


def sweep(study: str | os.PathLike, out: str | os.PathLike, *, workers: int = 1, scheduler: str | None = None,
          plots: bool = True, on_progress=None) -> SweepResult:
    """Run every point of a study file's grid (docs/sweep.md) into ``out`` and write its table and plots.

    The finished points are stored one file each under ``out/points/`` as they end, so a stopped
    sweep resumes where it left off; the table, ``study.json`` and the plots then replace the
    previous run's (a transaction: :func:`gatetherm.outdir.output_dir`). A point that raises is
    recorded as ``failed`` and retried by a rerun.

    Parameters
    ----------
    study : path
        The study file (``[study]``, ``[set]``, ``[grid]``, ``[[plot]]``).
    out : path
        Output directory (also the point store).
    workers : int
        Local worker processes (1: in this process).
    scheduler : str, optional
        Address of an existing Dask cluster, e.g. ``tcp://10.0.0.5:8786``.
    plots : bool
        Draw the study's ``[[plot]]`` tables.
    on_progress : callable, optional
        ``on_progress(i, n)`` as points finish (``i`` up to ``n``).

    Returns
    -------
    SweepResult
        ``.rows`` and ``.columns`` of the table, ``.failed``; ``.summary(out)``; ``.raise_failed()``.

    Raises
    ------
    InputError
        A bad study file (naming the file and key).
    """
    from gatetherm import InputError
    from gatetherm.checks import whole_argument
    from gatetherm.outdir import output_dir
    from gatetherm.studies.sweeps.runner import PointStore, run_studies
    from gatetherm.frame.sweeppoint import FRAME
    from gatetherm.studies.sweeps.studyfile import load_study
    from gatetherm.studies.sweeps.sweep import plan, table

    whole_argument("workers", workers, _WORKERS, "e.g. 1 (in this process) or the CPU count")
    s = load_study(study, FRAME)  # the frame's side of a study of the frame
    try:
        tasks = plan(s)
    except InputError as err:
        raise err.at(str(study)) from None
    with output_dir(out, OUTPUTS, keep=(str(study),)) as stage:
        (records,), failed = run_studies([(tasks, PointStore(Path(out)))], workers, scheduler, on_progress)
        columns, rows = table(tasks, records, s.columns)
        result = SweepResult(s, tuple(columns), tuple(rows), tuple(failed), plots, (), (str(study),))
        written = result._write_into(stage, Path(out))
    return dataclasses.replace(result, written=written)
