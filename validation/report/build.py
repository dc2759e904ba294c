"""Compute each section or reuse its cached result.

A section's result is kept in ``DIR/sections/KEY/result.json`` beside its figures, stamped
with a digest of everything it was made from: the section's key and scope, gatetherm's
version, the *code digest* (SHA-256 of every source file of the installed package, except
the modules that only reuse and present results: the CLI, this module and the report's page,
Markdown and browser modules), the bytes of the data files the section names and the version line of the
external programs it runs. A result whose digest matches is reused; anything else is
recomputed. A default run also accepts a ``--full`` result of the same code and inputs, and a
section left out by ``--section`` is shown from either.

A section is computed in ``DIR/sections/.KEY-DIGEST`` and renamed into place when it has
finished, so an interrupted run leaves the last good result; a sweep study that is
interrupted resumes from the points stored there when the run is repeated.
"""
from __future__ import annotations

import dataclasses
import datetime
import functools
import hashlib
import importlib
import json
import logging
import os
import shutil
import subprocess
import time
from pathlib import Path

from gatetherm import __version__
from gatetherm.validation.report.registry import Context, Section
from gatetherm.validation.report.result import Result, dump, load

log = logging.getLogger(__name__)

PACKAGES = ("gatetherm", "gatetherm.geometry", "gatetherm.solvers", "gatetherm.studies", "gatetherm.validation")
PRESENTATION = ("gatetherm/cli/", "gatetherm/validation/report/build.py", "gatetherm/validation/report/page.py",
                "gatetherm/validation/report/markdown.py", "gatetherm/validation/report/browser.py")
"""Source files left out of the code digest: they decide what to reuse and format results, they
do not make them."""


def source_files() -> dict[str, Path]:
    """The package's Python sources by their name inside the package (``gatetherm/…``)."""
    out: dict[str, Path] = {}
    for pkg in PACKAGES:
        for d in importlib.import_module(pkg).__path__:
            for p in sorted(Path(d).rglob("*.py")):
                name = "/".join((*pkg.split("."), *p.relative_to(d).parts))
                if not name.startswith(PRESENTATION):
                    out.setdefault(name, p)
    return out


def code_digest() -> str:
    h = hashlib.sha256(__version__.encode())
    for name, path in sorted(source_files().items()):
        h.update(name.encode() + b"\0" + path.read_bytes() + b"\0")
    return h.hexdigest()


def input_files(patterns) -> dict[str, Path]:
    """``package:glob`` patterns (or absolute paths) -> {package:relative path (or the path): file}."""
    out = {}
    for pattern in patterns:
        if Path(pattern).is_absolute():
            out[pattern] = Path(pattern)
            continue
        pkg, glob = pattern.split(":", 1)
        for d in importlib.import_module(pkg).__path__:
            for p in sorted(Path(d).glob(glob)):
                if p.is_file():
                    out.setdefault(f"{pkg}:{p.relative_to(d).as_posix()}", p)
    return out


@functools.cache
def tool_version(name: str) -> str:
    """The first line a program prints for ``-v``, or "absent"."""
    exe = shutil.which(name)
    if not exe:
        return "absent"
    try:
        run = subprocess.run([exe, "-v"], capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.SubprocessError) as err:
        return f"{exe}: {err}"
    lines = [ln.strip() for ln in (run.stdout + run.stderr).splitlines() if ln.strip()]
    return f"{exe}: {lines[0] if lines else 'no version'}"


def digest(section: Section, scope: dict, code: str) -> str:
    files = {k: hashlib.sha256(p.read_bytes()).hexdigest() if p.is_file() else "absent"
             for k, p in input_files(section.inputs).items()}
    payload = {"section": section.key, "scope": scope, "version": __version__, "code": code, "inputs": files,
               "tools": {t: tool_version(t) for t in section.tools}}
    return hashlib.sha256(json.dumps(payload, sort_keys=True).encode()).hexdigest()[:16]


def cached(out: Path, key: str) -> Result | None:
    path = Path(out) / "sections" / key / "result.json"
    try:
        return load(path)
    except (OSError, ValueError, KeyError, TypeError):
        return None


def compute(section: Section, scope: dict, stamp: dict, out: Path, workers: int) -> Result:
    """Run the section's compute function in a folder of its own and move it into place."""
    base = Path(out) / "sections"
    work = base / f".{section.key}-{stamp['digest']}"
    work.mkdir(parents=True, exist_ok=True)
    fn = section.compute
    if isinstance(fn, str):
        module, name = fn.split(":")
        fn = getattr(importlib.import_module(f"gatetherm.validation.report.sections.{module}"), name)
    load_avg, t0 = os.getloadavg()[0], time.perf_counter()
    res = fn(Context(work, scope, workers))
    missing = [f for f in [f.file for f in res.figures] + [f for f, _ in res.files] if not (work / f).is_file()]
    if missing:
        raise RuntimeError(f"section {section.key} did not write {', '.join(missing)}")
    stamp = {**stamp, "seconds": round(time.perf_counter() - t0, 1), "load": round(load_avg, 1),
             "cpus": os.cpu_count(), "date": datetime.datetime.now().astimezone().isoformat(timespec="seconds")}
    res = dataclasses.replace(res, stamp=stamp)
    dump(res, work / "result.json")
    final, old = base / section.key, base / f".{section.key}-old"
    shutil.rmtree(old, ignore_errors=True)
    if final.exists():
        final.rename(old)
    work.rename(final)
    for stale in base.glob(f".{section.key}-*"):  # the old result and unfinished runs of other digests
        shutil.rmtree(stale, ignore_errors=True)
    return res


def build(out: Path, sections, full: bool = False, workers: int = 1, only=None, on_section=None) -> dict:
    """Compute or reuse every section (of ``only``, if given); returns {key: Result or None}
    for all ``sections`` (None: pending, or not computed for this code and ``only`` left it
    out). ``on_section(key, status, seconds)`` reports each: "computed", "cached", "pending",
    "skipped"."""
    code = code_digest()
    results = {}
    for s in sections:
        if not s.compute:
            results[s.key] = None
            _tell(on_section, s.key, "pending", 0.0)
            continue
        scope = s.scope(full)
        want = digest(s, scope, code)
        wanted = only is None or s.key in only
        accept = {want} if s.full is None or (full and wanted) else {digest(s, s.scope(f), code) for f in (0, 1)}
        old = cached(out, s.key)
        if old is not None and old.stamp.get("digest") in accept:
            results[s.key] = old
            _tell(on_section, s.key, "cached", old.stamp.get("seconds", 0.0))
        elif wanted:
            stamp = {"digest": want, "version": __version__, "code": code[:12], "scope": scope,
                     "full": full or s.full is None}
            log.info("computing section %s", s.key)
            results[s.key] = compute(s, scope, stamp, out, workers)
            _tell(on_section, s.key, "computed", results[s.key].stamp["seconds"])
        else:
            results[s.key] = None
            _tell(on_section, s.key, "skipped", 0.0)
    return results


def _tell(on_section, key, status, seconds) -> None:
    if on_section:
        on_section(key, status, seconds)
