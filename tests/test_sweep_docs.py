"""docs/sweep.md against the study-file reader, as tests/test_docs.py holds docs/case-file.md:
every table and key the reader accepts is documented and every documented one is accepted;
the page's case example loads beside a case file and plans its points (every swept key read
by the case reader)."""
from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from gatetherm import InputError
from gatetherm.studies.sweeps import studyfile

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "sweep.md"
C_FRAME = ROOT / "validation" / "examples" / "c_frame"


def documented() -> dict[str, set[str]]:
    from test_docs import documented_keys

    return documented_keys(PAGE.read_text(encoding="utf-8"))


def test_every_study_key_is_documented_and_every_documented_key_is_read():
    doc = documented()
    code = {**{t: set(k) for t, k in studyfile.KEYS.items()}, **{t: {k} for t, k in studyfile.FREE.items()}}
    assert list(doc) == list(studyfile.TABLES) == ["study", "set", "grid", "plot"]
    assert doc == code


def test_the_key_check_sees_a_key_the_reader_refuses():
    """A documented key the reader does not know would be refused by it, with the known keys."""
    with pytest.raises(InputError, match=r"^study\.cases: unknown key.*known keys: name, case"):
        studyfile.parse_study({"study": {"cases": "x.toml"}, "grid": {"a": [1]}}, "s.toml", case="x.toml")


def example() -> str:
    [block] = [b for b in PAGE.read_text(encoding="utf-8").split("```toml\n")[1:] if b.startswith("# file: study.toml")]
    return block.split("```")[0]


def test_the_case_example_loads_and_plans_beside_a_case(tmp_path):
    """The example, beside a copy of the C-frame's case: 3 × 2 points, each key read by the case
    reader (a misspelt key would stop the plan with the reader's line), the plot's columns known."""
    from gatetherm.studies.sweeps.sweep import plan

    shutil.copytree(C_FRAME, tmp_path, dirs_exist_ok=True)
    (tmp_path / "study.toml").write_text(example())
    study = studyfile.load_study(tmp_path / "study.toml")
    assert study.name == "films and spindle losses" and study.case == str(tmp_path / "case.toml")
    assert dict(study.fixed) == {"time.end": 7200.0} and study.compute == ("run",)
    assert [k for k, _ in study.grid] == ["thermal.free.film", "materials.spindle.alpha"]
    assert [(p.x, p.y, p.hue) for p in study.plots] == [("thermal.free.film", "delta_final_um",
                                                         "materials.spindle.alpha")]
    tasks = plan(study)
    assert [dict(t.overrides) for t in tasks][:2] == [
        {"time.end": 7200.0, "thermal.free.film": 6.0, "materials.spindle.alpha": 1.15e-5},
        {"time.end": 7200.0, "thermal.free.film": 6.0, "materials.spindle.alpha": 1.25e-5}]
    assert len({t.key for t in tasks}) == 6
    assert {"delta_final_um", "drift_x_max_um", "swing_um"} <= set(study.columns)
    (tmp_path / "study.toml").write_text(example().replace("materials.spindle.alpha", "materials.spindle.alfa"))
    with pytest.raises(InputError, match="alfa"):
        plan(studyfile.load_study(tmp_path / "study.toml"))
