"""Reports (:mod:`gatetherm.api`): :func:`report`, every validation result on one page, and
:func:`drift_report`, the thermal drift report of one measured time series."""
from __future__ import annotations

import os
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

from gatetherm.validation.report.registry import SECTIONS

PUBLIC = ("DriftReport", "Report", "drift_report", "report")

PAGE = ("index.html", "validation.md")
"""What a report run replaces in its folder; the sections' folders (the cache) are kept."""
DRIFT = ("index.html", "drift.png")
"""What a drift report writes into its folder."""

SECTION_KEYS = tuple(s.key for s in SECTIONS)
"""The keys of the report's sections, in the page's order (``gatetherm.validation.report.registry``)."""


@dataclass(frozen=True)
class Report:
    """What :func:`report` returns (the page is written by then)."""

    results: dict
    """Section key -> its result (tables, figures, notes), or None (pending, or not computed)."""
    out: str
    """The folder of the page and the cache."""
    page: str | None = None
    """The results page written into a docs folder, if any."""
    seconds: float = 0.0
    """Wall time, s."""

    def summary(self) -> str:
        """What ``gatetherm report`` prints last: the files written and the time taken."""
        return (f"wrote {self.out}/index.html and validation.md" + (f" and {self.page}" if self.page else "")
                + f" in {self.seconds:.0f} s")


@dataclass(frozen=True)
class DriftReport:
    """What :func:`drift_report` returns (its page is written by then)."""

    result: object
    """The report result: tables, the figure, notes (duration, sampling, the largest drifts)."""
    out: str
    """The folder written."""

    @property
    def notes(self) -> tuple[str, ...]:
        """The notes of the page: duration and sampling, the largest drift of the displacements and
        temperatures (µm, K), and the standard's note last."""
        return tuple(self.result.notes)

    def summary(self) -> str:
        """What ``gatetherm report --data`` prints."""
        return "\n".join([f"wrote {self.out}/index.html and drift.png", *self.notes[:-1]])


def report(out: str | os.PathLike, *, full: bool = False, sections: Sequence[str] | None = None, workers: int = 1,
           docs: str | os.PathLike | None = None, on_section=None, on_progress=None) -> Report:
    """Compute (or reuse from ``out``) every section of the validation report and write
    ``out/index.html`` with its figures and ``out/validation.md`` (docs/validation.md says what
    each section is; CONTRIBUTING.md how to add one).

    Parameters
    ----------
    out : path
        Output folder, also the cache of the sections' results (kept across runs).
    full : bool
        Run every study in full (default: the stated subsets).
    sections : sequence of str, optional
        Keys of the sections to compute (others are shown if cached); default all.
    workers : int
        Worker processes for the sweeps.
    docs : path, optional
        A docs folder: also write ``docs/validation.md`` (a section not computed keeps its text there).
    on_section : callable, optional
        ``on_section(key, status, seconds)`` per section: ``computed``, ``cached`` (with its seconds),
        ``pending`` or ``skipped``.
    on_progress : callable, optional
        ``on_progress(i, n)`` after each section (``i`` up to ``n``, the sections).

    Returns
    -------
    Report
        The sections' results and ``.summary()``.

    Raises
    ------
    InputError
        An unknown section, a ``docs`` that is not a folder, an unreadable page there.
    """
    from gatetherm import InputError, write_text_atomic
    from gatetherm.checks import Range, whole_argument
    from gatetherm.files import read_text
    from gatetherm.outdir import output_dir
    from gatetherm.validation.report.build import build, code_digest
    from gatetherm.validation.report.markdown import results_markdown
    from gatetherm.validation.report.page import report_html

    t0 = time.perf_counter()
    whole_argument("workers", workers, Range(1, whole=True), "e.g. 1 or the CPU count")
    keys = [s.key for s in SECTIONS]
    if sections is not None:
        sections = [sections] if isinstance(sections, str) else list(sections)
        unknown = [k for k in sections if k not in keys]
        if unknown:
            raise InputError(f"sections {unknown[0]}", "is not a section of the report",
                             f"choose from {', '.join(keys)}")
    docs = Path(docs) if docs is not None else None
    if docs is not None and not docs.is_dir():
        raise InputError("docs", f"'{docs}' is not a folder", "give the docs folder of a checkout (docs)")
    page = docs / "validation.md" if docs is not None else None
    before = read_text(page, fix="delete it, or restore it from the checkout") if page and page.exists() else None
    done = []

    def tell(key, status, seconds):
        done.append(key)
        if on_section is not None:
            on_section(key, status, seconds)
        if on_progress is not None:
            on_progress(len(done), len(SECTIONS))

    with output_dir(out, PAGE) as stage:  # the sections' folders are the cache: kept
        results = build(Path(out), SECTIONS, full, workers, set(sections) if sections else None, tell)
        code = code_digest()
        write_text_atomic(stage / "index.html", report_html(SECTIONS, results, str(out), full, code))
        write_text_atomic(stage / "validation.md", results_markdown(SECTIONS, results, str(out), full, code))
    if page is not None:
        write_text_atomic(page, results_markdown(SECTIONS, results, "R", full, code, figures=False, previous=before))
    return Report(results, str(out), str(page) if page else None, time.perf_counter() - t0)


def drift_report(data: str | os.PathLike, out: str | os.PathLike) -> DriftReport:
    """The thermal drift report of one time series (docs/data-format.md): ``out/index.html`` with
    ``out/drift.png``, the drift of every displacement (µm) and temperature (K) from its start
    value, per channel and per input phase.

    Parameters
    ----------
    data : path
        The time-series file.
    out : path
        Output folder.

    Returns
    -------
    DriftReport
        ``.result`` (tables, notes) and ``.summary()``.

    Raises
    ------
    InputError
        A bad file or a record too short for a drift.
    """
    from gatetherm import write_text_atomic
    from gatetherm.outdir import output_dir
    from gatetherm.studies.run.timeseries import read_timeseries
    from gatetherm.validation.report.drift import check_record, compute
    from gatetherm.validation.report.page import drift_html

    ts = read_timeseries(data, required=("time_s",))
    check_record(ts, data)
    with output_dir(out, DRIFT, keep=(data,)) as stage:
        result = compute(ts, stage, Path(data).name)
        write_text_atomic(stage / "index.html", drift_html(result, data, f"gatetherm report --data {data} --out {out}"))
    return DriftReport(result, str(out))
