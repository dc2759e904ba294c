"""The docs against the code: every case-file key the readers accept is in docs/case-file.md
and every key documented there is accepted; the page's examples are the shipped files or
cases that load and solve to the closed forms the page states; docs/cli.md is what the
argument parsers make and docs/api.md what the public docstrings make, every public name documented;
nothing in the README is rewritten by the package."""
from __future__ import annotations

import math
import re
import tomllib
from pathlib import Path

import pytest

from gatetherm.studies.run import case as case_reader

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
HEADING = re.compile(r"^### `\[\[?([\w.]+)\]\]?`$")
FENCE = re.compile(r"^```[\w]*\n(.*?)^```$", re.S | re.M)
LABEL = re.compile(r"^(?://|#) (file|added to): (\S+)\n")


def documented_keys(text: str) -> dict[str, set[str]]:
    """{table: keys} of a reference page: each ``### `[TABLE]` `` heading and the backticked
    names in the first column of the rows under it (up to the next heading)."""
    out: dict[str, set[str]] = {}
    table = None
    for line in text.splitlines():
        m = HEADING.match(line)
        if m:
            table = m.group(1)
            out.setdefault(table, set())
        elif line.startswith("#"):
            table = None
        elif table and line.startswith("| `"):
            out[table] |= set(re.findall(r"`([^`]+)`", line.split("|")[1]))
    return out


def accepted_keys() -> dict[str, set[str]]:
    return {**{t: set(k) for t, k in case_reader.KEYS.items()}, **{t: {k} for t, k in case_reader.FREE.items()}}


def test_every_case_key_is_documented_and_every_documented_key_is_accepted():
    doc, code = documented_keys((DOCS / "case-file.md").read_text(encoding="utf-8")), accepted_keys()
    assert sorted(doc) == sorted(code), "tables: documented but not read, or read but not documented"
    for table in code:
        assert doc[table] == code[table], f"[{table}]: undocumented {code[table] - doc[table]}, " \
                                          f"not accepted {doc[table] - code[table]}"
    assert {t.split(".")[0] for t in code} == set(case_reader.SECTIONS)


def test_the_key_check_sees_a_missing_row():
    text = (DOCS / "case-file.md").read_text(encoding="utf-8").replace("| `hose_loss` |", "| hose_loss |")
    assert "hose_loss" not in documented_keys(text)["fluids.NAME"]


def examples() -> list[tuple[str, str, str]]:
    """(label, path, text) of every labelled code block of docs/case-file.md."""
    out = []
    for block in FENCE.findall((DOCS / "case-file.md").read_text(encoding="utf-8")):
        m = LABEL.match(block)
        if m:
            out.append((m.group(1), m.group(2), block[m.end():] if not m.group(2).startswith("validation/")
                        else block))
    return out


def test_examples_quoting_shipped_files_are_those_files():
    quoted = [(p, t) for label, p, t in examples() if label == "file" and p.startswith("validation/")]
    assert len(quoted) == 5
    for path, text in quoted:
        shipped = (ROOT / path).read_text(encoding="utf-8")
        assert text.split("\n", 1)[1] == shipped, path


@pytest.fixture(scope="module")
def written(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("docs")
    for label, path, text in examples():
        if label == "file" and not path.startswith("validation/"):
            (root / path).parent.mkdir(parents=True, exist_ok=True)
            (root / path).write_text(text, encoding="utf-8")
    return root


def _final(path: Path) -> dict:
    from gatetherm.api import run

    return run(case_reader.load_case(path)).summary()["probes"]


def test_assembly_example_is_the_series_resistance_closed_form():
    p = _final(ROOT / "validation/examples/joint/case.toml")
    q = 100.0 / (0.1 / 50 + 1 / 2000 + 0.1 / 15)
    assert p["a"]["T_degC"] == pytest.approx(100 - q * 0.05 / 50, rel=1e-9)   # 89.09 °C, as the page says
    assert p["b"]["T_degC"] == pytest.approx(q * 0.05 / 15, rel=1e-9)         # 36.36 °C
    assert round(100 - q * 0.05 / 50, 2) == 89.09 and round(q * 0.05 / 15, 2) == 36.36 and round(q) == 10909
    assert p["end"]["ux_um"] == pytest.approx(112.46, abs=0.01)   # the warm blocks lengthen, the pull adds ~1 µm


def test_axisymmetric_example_is_the_log_profile(written):
    T = _final(written / "sleeve/case.toml")["mid"]["T_degC"]
    exact = 80.0 - 60.0 * math.log(1.5) / math.log(2.0)
    assert T == pytest.approx(exact, rel=1e-4) and round(exact, 2) == 44.90
    assert T / exact - 1 == pytest.approx(0.0, abs=2e-6)


def _dotted(table: dict, prefix: str = "") -> dict:
    out = {}
    for k, v in table.items():
        out.update(_dotted(v, f"{prefix}{k}.") if isinstance(v, dict) else {f"{prefix}{k}": v})
    return out


def test_snippets_load_on_the_case_they_are_added_to():
    snippets = [(p, t) for label, p, t in examples() if label == "added to"]
    assert [p for p, _ in snippets] == ["validation/examples/c_frame/case.toml"]
    for path, text in snippets:
        case = case_reader.load_case(ROOT / path, overrides=_dotted(tomllib.loads(text)))
        assert case.actuator.preload_N == 580.0 and case.actuator.strategy == "reset"
        assert case.actuator.play_weights[1] == pytest.approx(0.125)


def test_cli_reference_is_what_the_parsers_make():
    from gatetherm.cli.reference import markdown

    assert (DOCS / "cli.md").read_text(encoding="utf-8") == markdown(), \
        "docs/cli.md is stale: python -m gatetherm.cli.reference > docs/cli.md"


def test_nothing_rewrites_the_readme():
    """The README holds no generated blocks and the report has no option to rewrite it."""
    from gatetherm.cli import build_parser

    assert "<!-- report:" not in (ROOT / "README.md").read_text(encoding="utf-8")
    assert "--readme" not in build_parser().format_help() + (DOCS / "cli.md").read_text(encoding="utf-8")


def test_api_reference_is_what_the_docstrings_make():
    from gatetherm.cli.api_reference import markdown

    assert (DOCS / "api.md").read_text(encoding="utf-8") == markdown(), \
        "docs/api.md is stale: python -m gatetherm.cli.api_reference > docs/api.md"


def test_every_public_name_is_documented_in_numpydoc():
    import inspect

    import gatetherm as gt
    from gatetherm.cli.api_reference import public

    text = (DOCS / "api.md").read_text(encoding="utf-8")
    names = public()
    assert len(names) == len(gt.API) + len(gt.plot.__all__) == 72
    for prefix, name, obj in names:
        assert f"### `{prefix}{name}" in text, name
        doc = inspect.getdoc(obj) or ""
        assert len(doc) > 40, f"{prefix}{name}: no docstring"
        if not inspect.isclass(obj) and inspect.signature(obj).parameters:
            assert "Parameters\n----------" in doc and "Returns\n-------" in doc, f"{prefix}{name}: not numpydoc"
