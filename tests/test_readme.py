"""The README: short (at most 250 lines), its Python quick start runs as it stands and prints
what the README says it prints, its picture is the one that block draws, its set-up test command
is the one CI runs, and every file it links to exists."""
from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")


def test_short():
    assert len(README.splitlines()) <= 250


def test_setup_commands_are_the_ones_ci_runs():
    setup = re.search(r"## Set up.*?```sh\n(.*?)```", README, re.S).group(1).splitlines()
    assert setup == ["python -m pip install . && gatetherm simulate --condition 1 --out run-c1",
                     'python -m pip install ".[test]" && python -m pytest']
    ci = (ROOT / ".ci/run").read_text(encoding="utf-8").splitlines()[-1]
    assert ci == setup[1].replace("pip install ", "pip install -q ")   # the same command, quietly


def test_quick_start_runs_as_it_stands_and_draws_the_readme_picture(tmp_path):
    block, = re.findall(r"```python\n(.*?)```", README, re.S)
    assert 8 <= len(block.splitlines()) <= 12
    done = subprocess.run([sys.executable, "-c", block], cwd=tmp_path, capture_output=True, text=True, timeout=600,
                          env={**os.environ, "MPLBACKEND": "Agg"})
    assert done.returncode == 0, done.stderr[-2000:]
    for line in done.stdout.splitlines():
        assert f"`{line}`" in README, f"the README does not quote what the quick start prints: {line}"
    assert done.stdout.splitlines() == ["first peak of delta: 40.2 um at 30 min",
                                        "beam theory: K_i = 4.80 um/K, K_C = 2.61 um/K"]
    import matplotlib.image

    assert "(docs/images/quickstart.png)" in README
    new, old = (matplotlib.image.imread(p) for p in (tmp_path / "quickstart.png", ROOT / "docs/images/quickstart.png"))
    assert new.shape == old.shape and np.abs(new - old).mean() < 2e-3, "docs/images/quickstart.png is stale"


def links(text: str) -> set[str]:
    return set(re.findall(r"\]\(([^)#:]+)(?:#[^)]*)?\)", text))


def test_every_linked_file_exists():
    assert {"docs/validation.md", "docs/case-file.md", "LICENSE", "CONTRIBUTING.md"} <= links(README)
    pages = [ROOT / "README.md", ROOT / "CONTRIBUTING.md", ROOT / "examples/README.md", *sorted((ROOT / "docs").glob("*.md"))]
    for page in pages:
        found = {(page.parent / link).resolve() for link in links(page.read_text(encoding="utf-8"))}
        missing = {p.relative_to(ROOT).as_posix() for p in found if not p.exists()}
        assert not missing, f"{page.relative_to(ROOT)} links to missing files: {sorted(missing)}"
