"""The time-series file format: exact round trip and one-line errors naming the row."""
import logging
import math

import numpy as np
import pytest

from gatetherm import InputError
from gatetherm.studies.run.timeseries import (FORMAT, INPUT_COLUMNS, OUTPUT_COLUMNS, TimeSeries, read_timeseries,
                                rises, validate_complete, write_timeseries)

HEADER = "time_s,oil_degC,pump,theta_A_degC,theta_B_degC,theta_C_degC,delta_um"


def _write(tmp_path, body, name="run.csv"):
    path = tmp_path / name
    path.write_text(body, encoding="utf-8")
    return path


def _series():
    n = 301  # 5 h at 1 min, times need more than 6 significant digits
    t = np.arange(n) * 60.0 + 0.25
    rng = np.random.default_rng(3)
    cols = {
        "delta_um": rng.normal(size=n) * 17.3,  # columns in a non-standard order
        "time_s": t,
        "pump": (np.arange(n) // 60 % 2 == 0).astype(float),
        "oil_degC": 40.0 + rng.normal(size=n) / 3,
        "theta_A_degC": 20 + np.linspace(0, 14.123456789, n),
        "theta_B_degC": 20 + np.linspace(0, 3, n) ** 0.5,
        "theta_C_degC": 20 + np.linspace(0, 1e-7, n),
        "T_leg_degC": np.full(n, 21.5),
        "mystery": rng.normal(size=n) * 1e-12,
    }
    cols["delta_um"][[0, 17, 300]] = np.nan
    cols["mystery"][5] = np.nan
    return TimeSeries(cols, {"format": FORMAT, "condition": "2", "source": "rig 3: bay 1"})


def test_round_trip_is_exact(tmp_path):
    ts = _series()
    path = tmp_path / "out" / "run.csv"
    write_timeseries(path, ts)
    back = read_timeseries(path)
    assert back.names == ts.names
    assert back.metadata == ts.metadata
    for name in ts.names:
        np.testing.assert_array_equal(back[name], ts[name])  # NaN == NaN here
    text = path.read_text().splitlines()
    assert text[0] == f"# format: {FORMAT}"
    assert text[3] == ",".join(ts.names)
    assert text[4].startswith(",") and ",1," in text[4]  # NaN is an empty field, pump an integer
    assert [p.name for p in path.parent.iterdir()] == ["run.csv"]  # no temp file left


def test_format_line_added_and_unknown_columns_logged(tmp_path, caplog):
    ts = TimeSeries({"time_s": [0, 60], "extra": [1.5, math.nan]}, {"condition": "1"})
    path = tmp_path / "x.csv"
    write_timeseries(path, ts)
    with caplog.at_level(logging.INFO):
        back = read_timeseries(path, required=("time_s",))
    assert back.metadata == {"format": FORMAT, "condition": "1"}
    assert "extra" in caplog.text
    np.testing.assert_array_equal(back["extra"], [1.5, math.nan])


def test_api():
    ts = _series()
    assert ts.time_s is ts["time_s"]
    assert len(ts) == 301 and "mystery" in ts
    sub = ts.slice(slice(10, 20))
    assert len(sub) == 10 and sub.time_s[0] == 600.25 and sub.names == ts.names
    assert len(ts.slice(ts["pump"] == 1)) == 180
    new = ts.with_columns(delta_um=np.zeros(301), u_piezo_um=np.ones(301))
    assert new.names == ts.names + ("u_piezo_um",) and new is not ts
    assert np.isnan(ts["delta_um"][0]) and new["delta_um"][0] == 0  # original untouched
    with pytest.raises(ValueError):
        ts["delta_um"][1] = 0.0  # columns are read-only
    np.testing.assert_allclose(rises(ts, "theta_A_degC")[[0, -1]], [0, 14.123456789], atol=1e-12)
    assert INPUT_COLUMNS + OUTPUT_COLUMNS == ("time_s", "oil_degC", "pump", "theta_A_degC",
                                              "theta_B_degC", "theta_C_degC", "delta_um")


def test_validate_complete_names_first_missing_row():
    ts = _series()
    validate_complete(ts, ["time_s", "theta_A_degC"])
    with pytest.raises(InputError) as err:
        validate_complete(ts.slice(slice(1, None)), ["mystery", "delta_um"], source="run.csv")
    assert str(err.value) == ("run.csv: data row 5 (time_s = 300.25), column mystery: value missing; "
                              "this analysis needs every sample; fill or remove the row")


@pytest.mark.parametrize("body, expected", [
    ("# condition: 1\ntime_s,oil_degC,pump,theta_A_degC,theta_B_degC,theta_C_degC\n0,40,1,20,20,20\n",
     "{p}, line 2: missing required column 'delta_um'; add it to the header (required: time_s, "
     "oil_degC, pump, theta_A_degC, theta_B_degC, theta_C_degC, delta_um)"),
    (f"{HEADER}\n0,40,1,20,20,20,0\n60,40,1,20.5,abc,20,1\n",
     "{p}, line 3 (data row 2), column theta_B_degC: non-numeric value 'abc'; "
     "write a decimal number, or leave the field empty for a missing sample"),
    (f"{HEADER}\n0,40,1,20,20,20,0\n60,40,1,20,20,20,nan\n",
     "{p}, line 3 (data row 2), column delta_um: non-numeric value 'nan'; "
     "write a decimal number, or leave the field empty for a missing sample"),
    (f"# format: {FORMAT}\n{HEADER}\n0,40,1,20,20,20,0\n60,40,1,20,20,20,0\n120,40,1,20,20,20,0\n"
     "120,40,1,20,20,20,0\n",
     "{p}, line 6 (data row 4), column time_s: time 120 s is not after the previous 120 s; "
     "times must strictly increase; sort the rows or remove the duplicate"),
    (f"{HEADER}\n0,40,1,20,20,20,0\n60,40,0.5,20,20,20,0\n",
     "{p}, line 3 (data row 2), column pump: value 0.5 is not 0 or 1; write 1 (on) or 0 (off)"),
    (f"{HEADER}\n0,40,1,20,20,20,0\n,40,1,20,20,20,0\n",
     "{p}, line 3 (data row 2), column time_s: time missing; every row needs a time"),
    (f"{HEADER}\n0,40,1,20,20,20\n",
     "{p}, line 2 (data row 1): 6 fields for 7 columns; "
     "give one field per column (empty for a missing sample)"),
    ("# format: gatetherm-timeseries/2\n" + HEADER + "\n0,40,1,20,20,20,0\n",
     "{p}: metadata format: unsupported 'gatetherm-timeseries/2'; expected 'gatetherm-timeseries/1'"),
    (HEADER + "\n", "{p}: no data rows; add at least one sample after the header"),
])
def test_read_errors_are_one_line(tmp_path, body, expected):
    path = _write(tmp_path, body)
    with pytest.raises(InputError) as err:
        read_timeseries(path)
    assert str(err.value) == expected.format(p=path)
    assert "\n" not in str(err.value)


def test_missing_values_and_blank_lines_read_as_nan(tmp_path):
    path = _write(tmp_path, f"# a comment without key\n\n{HEADER}\n0,40,1,20,20,20,0\n60, ,1,,20,20,1.5\n\n")
    ts = read_timeseries(path)
    assert ts.metadata == {}
    np.testing.assert_array_equal(ts["oil_degC"], [40, math.nan])
    np.testing.assert_array_equal(ts["delta_um"], [0, 1.5])


def test_a_celsius_column_in_kelvins_is_read_with_a_word(tmp_path, caplog):
    """A room written in kelvins in a schedule or a record (the third audit: ``amb_degC = 293``
    was read without a word, unlike the same number in a case file)."""
    import logging

    from gatetherm.studies.run.timeseries import read_timeseries

    (tmp_path / "s.csv").write_text("time_s,amb_degC,t1_degC\n0,293.15,20\n60,293.65,21\n")
    with caplog.at_level(logging.WARNING):
        read_timeseries(tmp_path / "s.csv", required=("time_s",))
    assert "column amb_degC: every value lies in 253-373, a machine's surroundings in kelvins" in caplog.text
    assert "t1_degC" not in caplog.text
