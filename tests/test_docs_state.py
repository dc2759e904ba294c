"""Docs state what is: no path of any particular machine in the README, docs/ or the benchmark
results the report quotes, and docs/performance.md a page of current figures, not a diary."""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MACHINE_PATH = re.compile(r"(?<![\w.])/(?:work|root|home|Users|mnt|opt|srv)/[\w.-]+")
"""An absolute path into a particular machine's folders (``/tmp/…`` output folders are the
commands' own examples and allowed)."""


def texts():
    yield ROOT / "README.md"
    yield from sorted((ROOT / "docs").glob("*.md"))
    yield from sorted((ROOT / "benchmarks" / "results").glob("*.json"))


def test_no_machine_paths():
    found = [f"{p.relative_to(ROOT)}: {m.group(0)}" for p in texts() for m in MACHINE_PATH.finditer(p.read_text())]
    assert found == []


def test_pattern_catches_a_machine_path():
    assert MACHINE_PATH.search("--data /work/shared/data/x.csv") and MACHINE_PATH.search("`/home/ann/run`")
    assert not MACHINE_PATH.search("gatetherm run case.toml --out /tmp/gt/t4") and not MACHINE_PATH.search("a/work/b")


def test_performance_page_is_current():
    page = (ROOT / "docs" / "performance.md").read_text()
    assert len(page.splitlines()) <= 300
    assert not re.search(r"^#+ .*20\d\d-\d\d-\d\d", page, re.M), "dated sections go to the CHANGELOG"
