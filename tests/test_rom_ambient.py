"""Films to a constant ambient are a loss (issue 51): a reduced model of a case whose room is a
number, not a schedule column, on a machine that is neither the paper's frame nor the C-frame (a
lathe headstock section, tests/data/headstock.*)."""
import shutil
from pathlib import Path

import numpy as np
import pytest

import gatetherm as gt
from gatetherm import InputError
from gatetherm.solvers.rom import Input

DATA = Path(__file__).parent / "data"
FILES = ("headstock.toml", "headstock.geo", "headstock_schedule.csv")


@pytest.fixture(scope="module")
def headstock():
    return gt.load_case(DATA / "headstock.toml")


@pytest.fixture(scope="module")
def reduced(headstock):
    return gt.reduce(headstock, 20)


def test_a_constant_room_is_a_constant_input(headstock, reduced):
    """The films' and faces' 20.0 °C is an input (offset T0) and the room; the reduced model's
    steady state for the room 1 K warmer (no source) is the body uniformly 1 K warmer: every
    temperature output reads T0 + 1 (closed form; the static responses are in the basis)."""
    rom = reduced.rom
    assert rom.inputs[rom.room] == Input("20.0", 20.0)
    assert [u.offset for u in rom.inputs].count(20.0) == 1  # sources: offset 0
    mode = rom.modes[-1]
    x = np.linalg.solve(-rom.A[mode], rom.B[mode][:, rom.room])
    y = rom.C @ x + rom.D[:, rom.room] + rom.y0
    temps = [i for i, n in enumerate(rom.outputs) if n.endswith("_degC")]
    assert np.max(np.abs(y[temps] - 21.0)) < 1e-8  # closed form: 21.0 °C exactly


def test_reduced_delta_within_half_a_micrometre_on_an_unseen_schedule(headstock, reduced, tmp_path):
    """Checked against the full FE run of a duty cycle the case's file does not hold (40 % speed
    1.5 h, full speed 1.5 h, stopped 1 h): δ within 0.5 µm."""
    rows = ["# format: gatetherm-timeseries/1", "time_s,speed"]
    rows += [f"{t},{0.4 if t < 5400 else 1.0 if t < 10800 else 0.0}" for t in range(0, 14401, 300)]
    (tmp_path / "other.csv").write_text("\n".join(rows) + "\n")
    other = gt.schedule_file(tmp_path / "other.csv", headstock)
    run = gt.run(headstock, other)
    (check,) = gt.check_rom(headstock, reduced.rom, [other])
    assert float(np.ptp(run["delta_um"])) == pytest.approx(5.524, abs=0.05)  # the drift it follows, µm
    assert check.max_delta_error_um == pytest.approx(0.0141, abs=0.005)  # band: < 0.5 µm


def test_a_truly_isolated_case_is_still_refused(tmp_path):
    """No film, no faces, no fixed temperature: the body only heats up; reduce refuses it."""
    for f in FILES:
        shutil.copy(DATA / f, tmp_path / f)
    text = (DATA / "headstock.toml").read_text()
    cut = text[text.index("[thermal.free]"):text.index("[sources.bearing_front]")]
    (tmp_path / "headstock.toml").write_text(text.replace(cut, ""))
    case = gt.load_case(tmp_path / "headstock.toml")
    assert not case.problem.films and case.problem.faces is None
    with pytest.raises(InputError, match="loses no heat to an ambient or a fixed temperature"):
        gt.reduce(case, 20)
