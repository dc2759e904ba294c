"""CalculiX as an independent oracle: the exported deck, and (when ``ccx`` is installed)
δ between the probes computed by CalculiX against gatetherm's."""
from __future__ import annotations

import json
import shutil
import subprocess

import numpy as np
import pytest

from gatetherm.cli import main
from gatetherm.studies.run.ccx import read_dat, relative_from_dat


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    d = tmp_path_factory.mktemp("ccx")
    (d / "coarse.toml").write_text("[mesh]\nsize_3d = 0.03\n")
    assert main(["export", "ccx", "--condition", "1", "--time", "15", "--dim", "3", "--config",
                 str(d / "coarse.toml"), "--out", str(d)]) == 0
    return d


def test_deck_holds_mesh_materials_supports_temperatures_and_probe_prints(exported):
    text = (exported / "job.inp").read_text()
    nodes = text.split("*NODE\n")[1].split("*ELEMENT")[0].strip().splitlines()
    elements = [ln for block in text.split("*ELEMENT, TYPE=C3D4")[1:] for ln in block.split("*")[0].strip().splitlines()[1:]]
    temps = text.split("*TEMPERATURE\n")[1].split("*")[0].strip().splitlines()
    assert len(temps) == len(nodes) > 1000 and len(elements) > 3 * len(nodes)
    assert text.count("*MATERIAL") == 7 and "*EXPANSION, ZERO=20.0" in text
    assert "B_MOUNTING_FACE, 1, 1" in text and "B_MOUNTING_FACE, 3, 3" in text
    assert text.count("*NODE PRINT") == 16 and "P_F_L" in text and "P_F_R" in text
    g = json.loads((exported / "gatetherm.json").read_text())
    assert g["relative"]["delta"] == {"a": "P_F_L", "b": "P_F_R", "axis": 0} and g["relative_m"]["delta"] > 1e-5


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX (Debian calculix-ccx) is not installed")
def test_calculix_agrees_on_delta(exported):
    """ccx 2.20 on the same mesh, materials, supports and temperatures: δ between F_L and F_R
    within 0.5 % of gatetherm's (the same discretisation: agreement to ccx's printed digits)."""
    run = subprocess.run(["ccx", "job"], cwd=exported, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0 and "ERROR" not in run.stdout, run.stdout[-2000:]
    dat = (exported / "job.dat").read_text()
    g = json.loads((exported / "gatetherm.json").read_text())
    for name, ccx in relative_from_dat(dat, g).items():
        print(f"{name}: CalculiX {ccx * 1e6:.6f} um, gatetherm {g['relative_m'][name] * 1e6:.6f} um")
        assert ccx == pytest.approx(g["relative_m"][name], rel=5e-3)
        assert ccx == pytest.approx(g["relative_m"][name], rel=1e-5)  # and in fact to its printed digits
    assert np.isfinite(list(read_dat(dat).values())).all()
