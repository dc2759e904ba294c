"""Acceptance checks of issue 13 on the default 2-D model: ``gatetherm reduce``, and
``gatetherm compensate --method rom`` on a paper condition and on a noisy hidden-effect file."""
import json

import numpy as np
import pytest
from scipy.signal import lsim

from gatetherm import cli
from gatetherm.studies.run.timeseries import read_timeseries, write_timeseries


@pytest.fixture(scope="module")
def reduced(tmp_path_factory):
    out = tmp_path_factory.mktemp("rom")
    assert cli.main(["reduce", "--dim", "2", "--out", str(out)]) == 0
    return out


def integrate(rom: dict, columns: dict, output: str = "delta_um") -> np.ndarray:
    """An output of rom.npz over a run's input columns by scipy's lsim (exact for inputs linear
    between samples), one pump mode at a time, the state carried over the switches: everything
    from the file alone (its inputs are plain columns here), nothing of gatetherm."""
    t = np.asarray(columns["time_s"], float)
    u = np.column_stack([columns[str(name)] for name in rom["inputs"]]) - rom["offsets"]
    row = list(rom["outputs"]).index(output)
    on = [np.asarray(columns[str(p)])[:-1] > 0.5 for p in rom["pumps"]]
    mode = ["_".join("on" if s else "off" for s in states) for states in zip(*on)] if on else [""] * (len(t) - 1)
    x, out = np.zeros(rom["C"].shape[1]), []
    starts = [0] + [k for k in range(1, len(t) - 1) if mode[k] != mode[k - 1]] + [len(t) - 1]
    for a, b in zip(starts[:-1], starts[1:]):
        sfx = f"_{mode[a]}" if mode[a] else ""
        sys = (rom[f"A{sfx}"], rom[f"B{sfx}"], rom["C"][row:row + 1], rom["D"][row:row + 1])
        _, y, X = lsim(sys, u[a:b + 1], t[a:b + 1] - t[a], X0=x, interp=True)
        y = np.atleast_1d(y) + rom["y0"][row]
        out += list(y if not out else y[1:])
        x = X[-1]
    return np.array(out)


def test_reduce_writes_the_specified_file_and_summary(reduced):
    with np.load(reduced / "rom.npz") as d:
        names = set(d.files)
        assert {"A_on", "B_on", "A_off", "B_off", "C", "D", "y0", "T0", "inputs", "offsets", "outputs"} <= names
        assert list(d["inputs"]) == ["oil_degC", "ambient_degC"] and list(d["offsets"]) == [20.0, 20.0]
        assert {"delta_um", "theta_A_degC", "theta_B_degC", "theta_C_degC"} <= set(d["outputs"])
        r = d["A_on"].shape[0]
        assert d["B_on"].shape == d["B_off"].shape == (r, 2) and d["C"].shape == (len(d["outputs"]), r)
    summary = json.loads((reduced / "summary.json").read_text())
    assert summary["states"] == r <= 40
    assert [k.split(":")[0] for k in summary["checks"]] == ["condition 1", "condition 2", "condition 3"]
    assert summary["max_delta_error_um"] == pytest.approx(0.06, abs=0.03)  # acceptance: ≤ 0.5
    assert all(v < 1.0 for v in summary["error_bound_bt"].values())


@pytest.mark.parametrize("number", [1, 2, 3])
def test_rom_reproduces_simulate(reduced, tmp_path, number):
    assert cli.main(["simulate", "--condition", str(number), "--no-pictures", "--fields-every", "600",
                     "--out", str(tmp_path)]) == 0
    ts = read_timeseries(tmp_path / "timeseries.csv")
    with np.load(reduced / "rom.npz") as d:
        rom = {k: d[k] for k in d.files}
    delta = integrate(rom, {k: ts[k] for k in ts.names})
    assert np.max(np.abs(delta - ts["delta_um"])) <= 0.5


def test_compensate_condition_2_with_the_rom(reduced):
    """The literal acceptance command, in the directory that holds the reduced model (reused by key)."""
    assert cli.main(["compensate", "--condition", "2", "--method", "rom", "--out", str(reduced)]) == 0
    s = json.loads((reduced / "summary.json").read_text())
    assert s["method"] == "rom" and s["rom_states"] <= 40
    assert s["residual_band_um"] <= 3.0 and s["updates"] <= 60


def test_compensate_noisy_hidden_effect_file_with_the_rom(reduced, tmp_path):
    assert cli.main(["simulate", "--condition", "1", "--effect", "joint_resistance:conductance=400",
                     "--no-pictures", "--fields-every", "600", "--out", str(tmp_path / "sim")]) == 0
    ts = read_timeseries(tmp_path / "sim" / "timeseries.csv")
    rng = np.random.default_rng(13)
    noisy = ts.with_columns(**{c: ts[c] + rng.normal(0, 0.05, len(ts)) for c in
                               ("theta_A_degC", "theta_B_degC", "theta_C_degC")},
                            delta_um=ts["delta_um"] + rng.normal(0, 0.1, len(ts)))
    write_timeseries(tmp_path / "noisy.csv", noisy)
    assert cli.main(["compensate", "--data", str(tmp_path / "noisy.csv"), "--method", "rom",
                     "--out", str(reduced)]) == 0
    s = json.loads((reduced / "summary.json").read_text())
    assert s["residual_band_um"] <= 5.0 and s["updates"] <= 60


def test_paper_method_stays_the_default_and_bad_rom_input(reduced, tmp_path, capsys):
    assert cli.main(["compensate", "--condition", "2", "--out", str(tmp_path), "--no-actuator"]) == 0
    s = json.loads((tmp_path / "summary.json").read_text())
    assert s["method"] == "paper" and s["k_source"] == "theory" and s["updates"] == 61
    capsys.readouterr()
    assert cli.main(["compensate", "--condition", "2", "--method", "rom", "--rom", str(tmp_path / "none.npz"),
                     "--out", str(tmp_path)]) == 2
    assert "none.npz: no such file" in capsys.readouterr().err
    assert cli.main(["compensate", "--condition", "2", "--method", "rom", "--rom", str(reduced / "rom.npz"),
                     "--sensors", "theta_A_degC,T_C1_degC,T_nowhere_degC", "--out", str(tmp_path)]) == 2
    assert "T_nowhere_degC" in capsys.readouterr().err
