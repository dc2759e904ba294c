"""Mechanical loads in a reduced model: a constant load (gravity) is the outputs' constant part,
a load that follows the schedule (a cutting force) an input read out directly; the reduced δ then
follows FE's, sag and force included (issue 51: a column under gravity was 5.09 µm off, its sag).
On the lathe headstock of tests/data, which is neither shipped machine."""
import shutil
from pathlib import Path

import numpy as np
import pytest

import gatetherm as gt

DATA = Path(__file__).parent / "data"
LOADS = """
[gravity]
acceleration = [0, -9.81]

[loads.nose]
force = [0, "-3000 * speed"]
"""


@pytest.fixture(scope="module")
def loaded(tmp_path_factory):
    folder = tmp_path_factory.mktemp("loaded")
    for f in ("headstock.toml", "headstock.geo", "headstock_schedule.csv"):
        shutil.copy(DATA / f, folder / f)
    text = (DATA / "headstock.toml").read_text()
    (folder / "headstock.toml").write_text(text.replace("[time]", LOADS + "\n[time]", 1))
    return gt.load_case(folder / "headstock.toml")


def test_the_loads_are_in_the_reduced_delta(loaded):
    run = gt.run(loaded)
    reduced = gt.reduce(loaded, 20)
    rom = reduced.rom
    assert "-3000 * speed" in [u.text for u in rom.inputs]  # the force: an input, read out directly
    (check,) = gt.check_rom(loaded, rom, [loaded.schedule])
    sag = float(run["delta_um"][0])  # at t = 0, before any heat: gravity and the force alone
    assert sag == pytest.approx(-22.968, abs=0.01)  # the nose sags under its weight and the force
    assert check.max_delta_error_um == pytest.approx(0.0133, abs=0.005)  # band: < 0.5 µm (22.98 µm before)
