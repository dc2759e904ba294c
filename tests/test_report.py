"""The validation report: the section cache (a rerun recomputes nothing, a changed input
recomputes its section only, a default run reuses a full result but not the other way),
the page and its links, the Markdown results page, the thermal drift report and the XDMF time
series of a run. The browser check is a slow test."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from gatetherm.cli import main
from gatetherm.studies.run.timeseries import TimeSeries, write_timeseries
from gatetherm.validation.report import build as b
from gatetherm.validation.report import drift
from gatetherm.validation.report.browser import static_check
from gatetherm.validation.report.page import report_html
from gatetherm.validation.report.registry import SECTIONS, Section
from gatetherm.validation.report.result import Figure, Result, table


def _png(path):
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(1, 1))
    ax.plot([0, 1])
    fig.savefig(path)
    plt.close(fig)


@pytest.fixture
def registry(tmp_path):
    """Two computing sections (one with a data file, one with a full scope) and a pending one;
    ``calls`` lists the computations."""
    calls, data = [], tmp_path / "input.txt"
    data.write_text("1")

    def make(key):
        def compute(ctx):
            calls.append(key)
            _png(ctx.work / f"{key}.png")
            return Result(tables=(table(f"table {key}", ("n",), [(str(ctx.scope["n"]),)]),),
                          figures=(Figure(f"{key}.png", f"figure {key}"),))
        return compute

    sections = (Section("a", "A", make("a"), subset={"n": 1}, inputs=(str(data),)),
                Section("b", "B", make("b"), subset={"n": 2}, full={"n": 3}, about="n = 2 instead of 3"),
                Section("c", "C", pending="a later issue"))
    return sections, calls, data


def test_a_rerun_with_nothing_changed_recomputes_nothing(tmp_path, registry):
    sections, calls, _ = registry
    seen = []
    first = b.build(tmp_path / "R", sections, on_section=lambda *a: seen.append(a[:2]))
    assert calls == ["a", "b"] and first["c"] is None
    assert seen == [("a", "computed"), ("b", "computed"), ("c", "pending")]
    again = b.build(tmp_path / "R", sections, on_section=lambda *a: seen.append(a[:2]))
    assert calls == ["a", "b"] and seen[3:] == [("a", "cached"), ("b", "cached"), ("c", "pending")]
    assert again["a"].stamp == first["a"].stamp and (tmp_path / "R/sections/a/a.png").is_file()
    assert not list((tmp_path / "R/sections").glob(".*"))  # no work folders left behind


def test_a_changed_input_recomputes_that_section_only(tmp_path, registry):
    sections, calls, data = registry
    b.build(tmp_path / "R", sections)
    data.write_text("2")
    (tmp_path / "R/sections/.a-0123456789abcdef").mkdir()  # an unfinished run of another digest
    b.build(tmp_path / "R", sections)
    assert calls == ["a", "b", "a"] and not list((tmp_path / "R/sections").glob(".*"))


def test_changed_code_recomputes_everything(tmp_path, registry, monkeypatch):
    sections, calls, _ = registry
    b.build(tmp_path / "R", sections)
    monkeypatch.setattr(b, "code_digest", lambda: "another version of the code")
    b.build(tmp_path / "R", sections)
    assert calls == ["a", "b", "a", "b"]


def test_a_full_result_serves_the_default_run_but_not_the_reverse(tmp_path, registry):
    sections, calls, _ = registry
    b.build(tmp_path / "R", sections)                       # subset
    full = b.build(tmp_path / "R", sections, full=True)     # b has a full scope: recomputed; a has none
    assert calls == ["a", "b", "b"] and full["b"].tables[0].rows == (("3",),)
    assert full["a"].stamp["full"] and full["b"].stamp["full"]
    default = b.build(tmp_path / "R", sections)              # the full b is accepted
    assert calls == ["a", "b", "b"] and default["b"].tables[0].rows == (("3",),)


def test_only_computes_the_named_sections(tmp_path, registry):
    sections, calls, _ = registry
    res = b.build(tmp_path / "R", sections, only={"b"})
    assert calls == ["b"] and res["a"] is None
    res = b.build(tmp_path / "R", sections, full=True, only={"a"})  # b's subset result stays on the page
    assert calls == ["b", "a"] and res["b"].tables[0].rows == (("2",),) and not res["b"].stamp["full"]


def test_code_digest_covers_the_numerics_not_the_presentation():
    files = b.source_files()
    assert "gatetherm/solvers/heat.py" in files and "gatetherm/validation/report/sections/paper.py" in files
    assert "gatetherm/cli/report.py" not in files and "gatetherm/validation/report/page.py" not in files
    assert len(b.code_digest()) == 64


def test_every_registered_section_can_be_found():
    """Each compute function of the shipped registry exists; pending ones say what brings them."""
    import importlib

    for s in SECTIONS:
        if s.pending:
            assert not s.compute
            continue
        module, name = s.compute.split(":")
        assert callable(getattr(importlib.import_module(f"gatetherm.validation.report.sections.{module}"), name))
        assert b.input_files(s.inputs) or not s.inputs, s.key


def test_the_page_links_resolve_and_captions_name_the_command(tmp_path, registry):
    sections, _, _ = registry
    res = b.build(tmp_path / "R", sections)
    text = report_html(sections, res, "R", False, b.code_digest())
    (tmp_path / "R/index.html").write_text(text)
    c = static_check(tmp_path / "R/index.html")
    assert c.problems == [] and c.images == 2 and c.links >= 5
    assert "gatetherm report --out R --section b" in text and "Not in this build: a later issue" in text
    assert "subset: n = 2 instead of 3" in text and "<script" not in text


def test_the_markdown_page_has_every_table_and_says_what_it_shows(tmp_path, registry):
    """The results page: each section's scope (subset or full), tables with their captions,
    the command that regenerates it; figures linked in R, named in a docs copy."""
    from gatetherm.validation.report.markdown import results_markdown

    sections, _, _ = registry
    res = b.build(tmp_path / "R", sections)
    text = results_markdown(sections, res, "R", False, b.code_digest())
    assert "| n |\n| --- |\n| 1 |\n\n*Table 1.* table a." in text and "*Table 2.* table b." in text
    assert "- [B](#b) (subset)" in text and "- [A](#a) (full study)" in text and "(not in this build)" in text
    assert "a subset (n = 2 instead of 3; `--full` runs the whole study)" in text
    assert "Regenerate: `gatetherm report --out R --section b`" in text and "Not in this build: a later issue." in text
    assert "![figure a](sections/a/a.png)" in text
    docs = results_markdown(sections, res, "R", False, b.code_digest(), figures=False)
    assert "](sections/" not in docs and "Figures (on the HTML page): figure a." in docs


def test_a_section_not_computed_keeps_its_text_from_the_page_before(tmp_path, registry):
    """``--section b --docs DIR``: section a stands as on the page before (its tables numbered again),
    not as "not computed"."""
    from gatetherm.validation.report.markdown import results_markdown

    sections, _, _ = registry
    res = b.build(tmp_path / "R", sections)
    first = results_markdown(sections, res, "R", False, "code", figures=False)
    only_b = {**res, "a": None}
    assert "Not computed for the current code" in results_markdown(sections, only_b, "R", False, "code", False)
    page = results_markdown(sections, only_b, "R", False, "code", False, first.replace("*Table 1.*", "*Table 7.*"))
    assert page.splitlines()[3:] == first.splitlines()[3:] and "*Table 1.* table a." in page
    assert "The sections this run did not compute are those of the page before" in page.splitlines()[2]


def test_speed_section_shows_the_benchmark_files_as_they_are(tmp_path, monkeypatch):
    """Absent files are "not measured yet"; a result file is one table of its columns and rows,
    captioned with its command, machine and date, its notes under it; a file that is not a
    table is said to be one; the digest follows the files (absent, then present)."""
    from gatetherm.validation.report.registry import BENCHMARK_FILES, Context, section
    from gatetherm.validation.report.sections import speed

    monkeypatch.setattr(speed, "BENCHMARKS", tmp_path)
    res = speed.compute(Context(tmp_path, {}, 1))
    assert res.tables == () and len(res.notes) == len(BENCHMARK_FILES) and all("not measured yet" in n for n in res.notes)
    assert "`python benchmarks/peer.py --rounds 3` writes it" in res.notes[0]
    (tmp_path / "peer.json").write_text(json.dumps(
        {"date": "2026-11-26", "machine": "2 cores", "command": "python benchmarks/peer.py --rounds 3",
         "columns": ["case", "gatetherm s", "ratio"], "rows": [["3-D heat", 1.23456, 0.5], ["3-D elastic", 2, None]],
         "notes": ["median of 3 rounds"]}))
    (tmp_path / "scaling.json").write_text("[1, 2]")
    res = speed.compute(Context(tmp_path, {}, 1))
    (t,), notes = res.tables, res.notes
    assert t.columns == ("case", "gatetherm s", "ratio") and t.rows == (("3-D heat", "1.235", "0.5"),
                                                                        ("3-D elastic", "2", "—"))
    assert t.title == "peer.json: measured by `python benchmarks/peer.py --rounds 3` on 2 cores, 2026-11-26"
    assert t.note == "median of 3 rounds" and len(notes) == len(BENCHMARK_FILES) - 1
    assert notes[0].startswith("`benchmarks/results/scaling.json` is not a benchmark table (AttributeError: ")
    assert notes[0].endswith("rerun `python benchmarks/scaling.py`.")
    monkeypatch.setattr(b, "input_files", lambda patterns: {p: tmp_path / Path(p).name for p in patterns})
    with_files = b.digest(section("speed"), {}, "code")
    (tmp_path / "peer.json").unlink()
    assert b.digest(section("speed"), {}, "code") != with_files


def _drift_series() -> TimeSeries:
    """20 min at 1 min: the pump on for 10 min; δ rises from 1 to 4 µm, then falls to 2; one
    thermocouple warms by 0.5 K per minute until 10 min, then holds; a sample of it is missing."""
    t = np.arange(21) * 60.0
    on = (t < 600).astype(float)
    delta = np.where(t <= 600, 1.0 + 3.0 * t / 600, 4.0 - 2.0 * (t - 600) / 600)
    temp = 20.0 + 0.5 * np.minimum(t, 600) / 60
    temp[5] = np.nan
    return TimeSeries({"time_s": t, "oil_degC": 20 + 5 * on, "pump": on, "delta_um": delta, "T_A_degC": temp})


def test_drift_numbers():
    ts = _drift_series()
    ch = drift.channels(ts)
    assert ch.displacement == ("delta_um",) and ch.temperature == ("T_A_degC",) and ch.inputs == ("oil_degC", "pump")
    r = drift.channel_row(ts, "delta_um")
    assert r["max |drift|"] == pytest.approx(3.0) and r["at [min]"] == 10 and r["drift at end"] == pytest.approx(1.0)
    assert r["range"] == pytest.approx(3.0)
    t = drift.channel_row(ts, "T_A_degC")
    assert t["max |drift|"] == pytest.approx(5.0) and t["missing"] == 1
    ph = drift.phase_rows(ts, ch, *drift.phase_signal(ts, ch))
    assert [(p["phase"], p["from [min]"], p["to [min]"]) for p in ph] == [("pump on", 0, 10), ("not pump on", 10, 20)]
    assert ph[0]["delta_um: change"] == pytest.approx(3.0) and ph[1]["delta_um: change"] == pytest.approx(-2.0)


def test_drift_report_command(tmp_path, capsys):
    write_timeseries(tmp_path / "run.csv", _drift_series())
    assert main(["report", "--data", str(tmp_path / "run.csv"), "--out", str(tmp_path / "D")]) == 0
    out = capsys.readouterr().out
    assert "Test duration 20.0 min, 21 samples, sampling interval 60 s" in out
    assert "Largest drift over the whole test, displacement: 3 µm (delta_um, at 10 min)" in out
    assert out.index("δ (delta_um, the tool against the workpiece): largest drift 3 µm at 10 min, drift at the end "
                     "1 µm, range 3 µm.") < out.index("Largest drift")
    assert static_check(tmp_path / "D/index.html").problems == []
    assert "ISO 230-3" in (tmp_path / "D/index.html").read_text()


def test_drift_report_of_a_bad_file_is_one_line(tmp_path, capsys):
    (tmp_path / "bad.csv").write_text("t,x\n0,1\n")
    assert main(["report", "--data", str(tmp_path / "bad.csv"), "--out", str(tmp_path / "D")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "time_s" in err


def test_xdmf_of_simulate_opens_in_pyvista_with_every_step_and_array(tmp_path):
    """``gatetherm simulate`` writes fields/fields.xdmf: one mesh, a step per field time (every
    hour of the 5-h run), each with temperature, displacement and stress; read back through
    meshio's TimeSeriesReader into pyvista."""
    import meshio
    import pyvista as pv

    (tmp_path / "coarse.toml").write_text("[mesh]\nsize = 0.02\n")
    assert main(["simulate", "--condition", "1", "--config", str(tmp_path / "coarse.toml"), "--out",
                 str(tmp_path / "s"), "--no-pictures"]) == 0
    vtu = meshio.read(tmp_path / "s/fields/fields_0060min.vtu")
    with meshio.xdmf.TimeSeriesReader(tmp_path / "s/fields/fields.xdmf") as reader:
        points, cells = reader.read_points_cells()
        steps = [reader.read_data(k) for k in range(reader.num_steps)]
    assert [t for t, _, _ in steps] == [0.0, 3600.0, 7200.0, 10800.0, 14400.0, 18000.0]
    for t, point_data, cell_data in steps:
        grid = pv.from_meshio(meshio.Mesh(points, cells, point_data=point_data, cell_data=cell_data))
        assert grid.n_points == len(vtu.points) and grid.n_cells == len(cells[0].data)
        assert {"T", "u", "sigma_xx", "sigma_yy", "sigma_xy", "von_mises"} <= set(grid.point_data)
        assert grid.point_data["u"].shape == (grid.n_points, 3) and "region" in grid.cell_data
    t, hour, _ = steps[1]
    np.testing.assert_allclose(hour["T"], vtu.point_data["T"], rtol=1e-12)
    assert np.ptp(steps[0][1]["T"]) == 0.0 and np.ptp(hour["T"]) > 1.0  # uniform start, then heated


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("chromium") is None, reason="Debian chromium is not installed")
def test_browser_renders_the_report(tmp_path):
    """Two real sections into a page; headless Chromium shows every image with no console
    message, and the screenshot is written; a page with a missing image fails."""
    from gatetherm.validation.report.browser import browser_check

    assert main(["report", "--out", str(tmp_path / "R"), "--section", "nafems", "c-frame", "--workers", "1"]) == 0
    good = browser_check(tmp_path / "R/index.html", tmp_path / "shot.png")
    assert good.problems == [] and good.rendered_images == good.images == 3 and good.screenshot.stat().st_size > 1e4
    (tmp_path / "R/sections/c-frame/drift.png").unlink()
    bad = browser_check(tmp_path / "R/index.html", tmp_path / "shot2.png")
    assert "browser: image 'sections/c-frame/drift.png' did not load" in bad.problems
    summary = json.loads((tmp_path / "R/sections/nafems/result.json").read_text())["stamp"]
    assert summary["full"] and summary["digest"]


@pytest.mark.slow
def test_rom_section_is_the_rom_study(tmp_path):
    """The report's ROM tables are the rows of ``gatetherm validate rom``'s own table
    (rom_study.md, the same run), its figures written; the reduced model is within 0.1 µm of
    the FE run."""
    from gatetherm.validation.report.registry import Context
    from gatetherm.validation.report.sections import rom

    res = rom.compute(Context(tmp_path, {"dims": [2], "conditions": [1], "effects": ["joint_resistance"]}, 1))
    checks, study = res.tables
    md = (tmp_path / "rom_study.md").read_text()
    for t in (checks, study):
        assert "\n".join("| " + " | ".join(r) + " |" for r in t.rows) in md
    assert [r[:3] for r in study.rows] == [("model", "1", "2-D FE"), ("measured", "1", study.rows[1][2])]
    assert float(checks.rows[0][2]) < 0.1 and all((tmp_path / f.file).stat().st_size > 1e4 for f in res.figures)


def test_report_writes_the_results_page_into_out_and_docs(tmp_path, monkeypatch, capsys):
    """``report`` writes ``R/validation.md`` beside ``R/index.html``; ``--docs DIR`` also
    ``DIR/validation.md`` (commands naming ``R``, no figure links); nothing else is touched."""
    from gatetherm.cli import main
    from gatetherm.validation.report.sections import speed

    monkeypatch.setattr(speed, "BENCHMARKS", tmp_path)
    (tmp_path / "peer.json").write_text(json.dumps({"date": "2026-11-26", "machine": "m", "command": "c",
                                                    "columns": ["job", "s"], "rows": [["x", 1.5]], "notes": []}))
    docs = tmp_path / "docs"
    docs.mkdir()
    (docs / "other.md").write_text("kept")
    out = tmp_path / "R"
    assert main(["report", "--section", "speed", "--out", str(out), "--docs", str(docs)]) == 0
    page, copy = (out / "validation.md").read_text(), (docs / "validation.md").read_text()
    assert "| x | 1.5 |" in page and "| x | 1.5 |" in copy and "peer.json: measured by `c` on m, 2026-11-26." in copy
    assert f"gatetherm report --out {out} --section speed" in page and "gatetherm report --out R --section speed" in copy
    assert sorted(p.name for p in docs.iterdir()) == ["other.md", "validation.md"]
    assert f"and {docs / 'validation.md'}" in capsys.readouterr().out
