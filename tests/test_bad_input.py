"""Bad input, as a new user meets it (issue 11): refused in one line on stderr naming the file,
the key (or row and column) and the admissible range, exit code 2 (input) or 1 (I/O), never
a traceback, never exit 0. Valid files in their many shapes still run. In-process, through
the command's ``main``; signals, kills and real I/O failures are in test_faults.py."""
from __future__ import annotations

import dataclasses
import errno
import json
import math
import os
import re
import typing
from pathlib import Path

import numpy as np
import pytest

from gatetherm import InputError
from gatetherm.checks import ranges
from gatetherm.outdir import LOCK, output_dir
from gatetherm.cli import main
from gatetherm.frame.config import SCHEMA, parse_config
from gatetherm.studies.run.timeseries import read_timeseries
from gatetherm.studies.sweeps import evaluate as sweep_evaluate
from test_compensator import HAND

COARSE = "[mesh]\nsize = 0.02\nsize_3d = 0.03\n"
SCHEDULE = "# format: gatetherm-timeseries/1\ntime_s,oil_degC,pump\n0,40,1\n3600,40,0\n7200,40,1\n"
DATA = "".join(line for line in HAND.splitlines(keepends=True) if not line.startswith("# note"))
"""A format line, the header and six rows a minute apart: delta = 2 (theta_A - theta_B) - theta_C."""


def refused(capsys, code: int, argv, *needles: str) -> str:
    """Run the command; assert exit ``code``, exactly one line on stderr holding every needle."""
    got = main([str(a) for a in argv])
    err = capsys.readouterr().err
    assert got == code, err
    assert err.count("\n") == 1 and err.endswith("\n") and "Traceback" not in err, err
    for needle in needles:
        assert needle in err, err
    return err


def _write(path, body: str | bytes):
    path.write_bytes(body if isinstance(body, bytes) else body.encode())
    return path


# ---- model files -------------------------------------------------------------------------------

MODEL_FILES = {
    "h inf": ("[geometry]\nh = inf\n", "geometry.h: got inf, must be a number in (0, 100] m"),
    "depth inf": ("[geometry]\ndepth = inf\n", "geometry.depth: got inf, must be a number in (0, 100] m"),
    "depth in mm": ("[geometry]\ndepth = 120\n", "geometry.depth: got 120, must be a number in (0, 100] m"),
    "tie bar deeper than the column": ("[geometry]\nA_C = 0.01\n",
                                       "geometry.A_C: tie-bar depth A_C/t_C = 0.25 m exceeds the column depth"),
    "h_oil_on nan": ("[thermal]\nh_oil_on = nan\n", "thermal.h_oil_on: got nan, must be a finite number >= 0"),
    "h_air < 0": ("[thermal]\nh_air = -8\n", "thermal.h_air: got -8, must be a finite number >= 0"),
    "flow_rate < 0": ("[thermal]\nflow_rate = -3e-5\n", "thermal.flow_rate: got -3e-05, must be a finite number >= 0"),
    "T0 below absolute zero": ("[thermal]\nT0 = -300\n",
                               "thermal.T0: got -300, must be a number in (-273.15, 1000] °C"),
    "tie-bar E = 0": ("[material.tie_bar]\nE = 0\n", "material.tie_bar.E: got 0, must be a finite number > 0"),
    "E < 0": ("[material]\nE = -1.2e11\n", "material.E: got -1.2e+11, must be a finite number > 0"),
    "k = -48": ("[material]\nk = -48\n", "material.k: got -48, must be a finite number > 0"),
    "k = 0": ("[material]\nk = 0\n", "material.k: got 0, must be a finite number > 0"),
    "rho = 0": ("[material]\nrho = 0\n", "material.rho: got 0, must be a finite number > 0"),
    "nu = 0.7": ("[material]\nnu = 0.7\n", "material.nu: got 0.7, must be a number in [0, 0.5)"),
    "alpha nan": ("[material]\nalpha = nan\n", "material.alpha: got nan, must be a number in [-0.0001, 0.001]"),
    "alpha inf": ("[material]\nalpha = inf\n", "material.alpha: got inf"),
    "alpha in um/(m K)": ("[material]\nalpha = 10.5\n", "material.alpha: got 10.5"),
    "tau_heat = 0": ("[supply]\ntau_heat = 0\n", "supply.tau_heat: got 0, must be a finite number > 0"),
    "T_room nan": ("[supply]\nT_room = nan\n", "supply.T_room: got nan, must be a number in (-273.15, 1000] °C"),
    "mesh size inf": ("[mesh]\nsize = inf\n", "mesh.size: got inf, must be a finite number > 0"),
    "order 1.5": ("[model]\norder = 1.5\n", "model.order: expected a whole number, got 1.5"),
    "order 3": ("[model]\norder = 3\n", "model.order: got 3, must be 1 or 2"),
    "order inf": ("[model]\norder = inf\n", "model.order: expected a whole number, got inf"),
    "theta below CN": ("[model.scheme]\ntheta = 0.2\n", "model.scheme.theta: got 0.2, must be a number in [0.5, 1]"),
    "restart 0": ("[model.scheme]\nrestart = 0\n", "model.scheme.restart: got 0, must be a whole number in [1, 1000]"),
    "joint conductance 0": ("[model]\njoint_conductance = 0\n", "model.joint_conductance: got 0"),
    "a string": ('[thermal]\nh_air = "high"\n', "thermal.h_air: expected a number, got 'high'"),
    "unknown key": ("[geometry]\nheight = 1\n", "geometry.height: unknown key"),
    "effect nan": ("[effects]\npiezo_heat = {power = nan}\n", "effects.piezo_heat.power"),
    "latin-1 degree sign in a comment": (b"# oil at 40 \xb0C\n[mesh]\nsize = 0.02\n",
                                         "bad.toml, line 1: byte 0xb0 is not UTF-8 text; save it as UTF-8"),
    "binary": (b"\x89PNG\r\n\x1a\n\x00\x00", "bad.toml, line 3: holds a NUL byte: a binary file, not text"),
    "latin-1 key": (b"[geometry]\nl\xe4nge = 1\n", "bad.toml, line 2: byte 0xe4 is not UTF-8 text"),
    "NUL bytes": (b"[mesh]\x00\x00\n", "bad.toml, line 1: holds a NUL byte"),
    "not TOML": ("[mesh\nsize = 1\n", "not valid TOML"),
}


@pytest.mark.parametrize("body, needle", MODEL_FILES.values(), ids=MODEL_FILES)
def test_model_file_values_refused_where_read(tmp_path, capsys, body, needle):
    cfg = _write(tmp_path / "bad.toml", body)
    refused(capsys, 2, ["simulate", "--condition", "1", "--config", cfg, "--out", tmp_path / "o"], str(cfg), needle)
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("make, needle", [
    (lambda d: d, "--config: 'DIR' is a directory; give a TOML model file"),
    (lambda d: d / "nope.toml", "--config: no such file 'DIR/nope.toml'"),
    (lambda d: os.mkfifo(d / "fifo") or d / "fifo", "--config: 'DIR/fifo' is not a regular file"),
], ids=["directory", "missing", "fifo"])
def test_model_file_paths(tmp_path, capsys, make, needle):
    path = make(tmp_path)
    refused(capsys, 2, ["mesh", "--config", path, "--out", tmp_path / "o"], needle.replace("DIR", str(tmp_path)))


def test_model_file_with_bom_and_crlf_is_read(tmp_path):
    """As a Windows editor writes it."""
    cfg = _write(tmp_path / "m.toml", b"\xef\xbb\xbf# model\r\n[geometry]\r\nl4 = 0.3\r\n")
    from gatetherm.frame.config import load_config

    assert load_config(cfg).model.frame.l4 == 0.3


def _sections():
    for sec in SCHEMA:
        for name, rng in ranges(sec.cls).items():
            if sec.keys is None or name in sec.keys:
                yield sec, name, rng


def _doc(section: str, key: str, value) -> dict:
    doc: dict = {key: value}
    for part in reversed(section.split(".")):
        doc = {part: doc}
    return doc


@pytest.mark.parametrize("sec, name, rng", list(_sections()), ids=[f"{s.name}.{n}" for s, n, _ in _sections()])
def test_every_parameter_refuses_nan_and_values_out_of_its_range(sec, name, rng):
    """Each declared range, read through the model-file reader: nan, inf and the first values
    outside either end are refused in one line naming the key."""
    bad = [math.nan, math.inf, -math.inf]
    bad += [rng.lo if rng.lo_open else rng.lo - 1] if np.isfinite(rng.lo) else []
    bad += [rng.hi if rng.hi_open else rng.hi + 1] if np.isfinite(rng.hi) else []
    for value in bad:
        with pytest.raises(InputError) as err:
            parse_config(_doc(sec.name, name, value))
        assert str(err.value).startswith(f"{sec.name}.{name}: "), err.value
        assert "\n" not in str(err.value)


def test_every_number_of_the_model_file_has_a_range():
    """A field added to a model-file section without an admissible range fails here."""
    for sec in SCHEMA:
        hints = typing.get_type_hints(sec.cls)
        for f in dataclasses.fields(sec.cls):
            numeric = hints[f.name] in (float, int, float | None)
            if numeric and (sec.keys is None or f.name in sec.keys):
                assert f.name in ranges(sec.cls), f"{sec.name}.{f.name} has no admissible range"


def test_a_mesh_that_cannot_fit_in_memory_is_refused_before_gmsh(tmp_path, capsys, monkeypatch):
    import gmsh

    monkeypatch.setattr(gmsh, "initialize", lambda *a, **k: pytest.fail("gmsh ran"))
    cfg = _write(tmp_path / "fine.toml", "[mesh]\nsize = 1e-6\n")
    refused(capsys, 2, ["mesh", "--config", cfg, "--out", tmp_path / "o"],
            f"gatetherm: error: {cfg}: mesh.size: 1e-06 m gives about 8e+11 triangles", "raise it to at least")
    assert not (tmp_path / "o").exists()



@pytest.mark.parametrize("value", ["x", "0", "-2", "1.5"])
def test_a_bad_blas_thread_count_is_refused(tmp_path, capsys, monkeypatch, value):
    monkeypatch.setenv("GATETHERM_BLAS_THREADS", value)
    refused(capsys, 2, ["mesh", "--out", tmp_path / "o"],
            f"gatetherm: error: environment variable GATETHERM_BLAS_THREADS: got {value!r}",
            "or unset it")
    assert not (tmp_path / "o").exists()

# ---- schedules and data files ------------------------------------------------------------------

def _sched(old: str, new: str) -> bytes:
    return SCHEDULE.replace(old, new).encode()


SCHEDULES = {
    "latin-1": (SCHEDULE.replace("# format", "# oil at 40 °C\n# format").encode("latin-1"),
                "s.csv, line 1: byte 0xb0 is not UTF-8 text; save it as UTF-8 (a spreadsheet's 'CSV UTF-8')"),
    "0xff in a cell": (_sched("3600,40,0", "3600,4\xff0,0").replace(b"\xc3\xbf", b"\xff"),
                       "s.csv, line 4: byte 0xff is not UTF-8 text"),
    "binary": (bytes(range(256)) * 8, "s.csv, line 1: holds a NUL byte"),
    "oil at 1e6 degC": (_sched("3600,40,0", "3600,1e6,0"),
                        "line 4 (data row 2), column oil_degC: got 1e+06, must be a number in (-273.15, 1000] °C"),
    "oil below absolute zero": (_sched("3600,40,0", "3600,-300,0"), "column oil_degC: got -300"),
    "ambient nan": (_sched("time_s,oil_degC,pump\n0,40,1", "time_s,oil_degC,pump,ambient_degC\n0,40,1,nan")
                    .replace(b"3600,40,0", b"3600,40,0,20").replace(b"7200,40,1", b"7200,40,1,20"),
                    "column ambient_degC: non-numeric value 'nan'"),
    "one row": (_sched("3600,40,0\n7200,40,1\n", ""), "the schedule spans 0 s, less than one 60-s step"),
    "time 1e300": (_sched("7200,", "1e300,"), "column time_s: got 1e+300, must be a number in [-1e+10, 1e+10] s"),
    "thirty years": (_sched("7200,", "1e9,"), "column time_s: 1e+09 s are 16666666 steps of 60 s, more than 1000000"),
    "pump 2": (_sched("3600,40,0", "3600,40,2"), "column pump: value 2 is not 0 or 1"),
    "time backwards": (_sched("3600,", "9000,"), "column time_s: time 7200 s is not after the previous 9000 s"),
    "no oil column": (_sched("oil_degC", "oil"), "column oil_degC: missing: the case reads it"),
    "empty": (b"", "no header row"),
    "header only": (_sched("0,40,1\n3600,40,0\n7200,40,1\n", ""), "no data rows"),
}


@pytest.mark.parametrize("body, needle", SCHEDULES.values(), ids=SCHEDULES)
def test_schedule_files(tmp_path, capsys, body, needle):
    sched = _write(tmp_path / "s.csv", body)
    refused(capsys, 2, ["simulate", "--schedule", sched, "--out", tmp_path / "o"], needle)
    assert not (tmp_path / "o").exists()


def _with_column(text: str, name: str, value: str) -> str:
    head, header, *rows = text.splitlines()
    return "\n".join([head, f"{header},{name}", *(f"{r},{value}" for r in rows)]) + "\n"


@pytest.mark.parametrize("edit, needle", [
    (lambda s: s.replace("180,40,1,29,21.5,23,12", "180,40,1,29,21.5,23,1e300"),
     "line 6 (data row 4), column delta_um: got 1e+300, must be a number in [-1e+06, 1e+06] µm"),
    (lambda s: _with_column(s, "delta_pred_um", "1"), "column delta_pred_um: compensate writes a column of this name"),
    (lambda s: s.replace("60,40,1,23,", "60,40,1,-280,"), "column theta_A_degC: got -280"),
    (lambda s: s.encode("utf-16"), "d.csv: is UTF-16 text; save it as UTF-8 (a spreadsheet's 'CSV UTF-8')"),
], ids=["delta 1e300", "an input column delta_pred_um", "theta below absolute zero", "UTF-16"])
def test_compensate_data_files(tmp_path, capsys, edit, needle):
    data = _write(tmp_path / "d.csv", edit(DATA))
    refused(capsys, 2, ["compensate", "--data", data, "--Ki", 2, "--Kc", 1, "--out", tmp_path / "o"], needle)
    assert not (tmp_path / "o").exists()


def test_valid_files_in_many_shapes_still_run(tmp_path, capsys):
    """CRLF line ends and a BOM (a spreadsheet), columns reordered, extra columns (kept),
    irregular sampling and empty cells as missing samples."""
    rows = [line.split(",") for line in DATA.splitlines()[1:]]
    order = [6, 0, 3, 4, 5, 2, 1]  # delta_um first, time_s second, ...
    lines = [",".join([rows[0][i] for i in order] + ["rig_note", "T_spindle_degC"])]
    for k, r in enumerate(rows[1:]):
        r = list(r)
        r[0] = str(int(r[0]) + (7 if k % 2 else 0))  # irregular sampling
        lines.append(",".join([r[i] for i in order] + [str(k), "" if k == 2 else "21.5"]))  # a missing sample
    data = _write(tmp_path / "d.csv", "\ufeff# rig: 3\r\n" + "\r\n".join(lines) + "\r\n")
    assert main(["compensate", "--data", str(data), "--Ki", "2", "--Kc", "1", "--no-actuator",
                 "--out", str(tmp_path / "o")]) == 0, capsys.readouterr().err
    out = read_timeseries(tmp_path / "o" / "compensated.csv")
    assert out.names[:9] == ("delta_um", "time_s", "theta_A_degC", "theta_B_degC", "theta_C_degC", "pump",
                             "oil_degC", "rig_note", "T_spindle_degC")
    assert np.isnan(out["T_spindle_degC"][2]) and out.metadata["rig"] == "3"
    assert json.loads((tmp_path / "o" / "summary.json").read_text())["resampled"]
    sched = "\r\n".join(["\ufefftime_s,pump,note,oil_degC", "0,1,11,40", "90,1,12,", "3700,0,13,41", "7200,1,14,40"])
    _write(tmp_path / "s.csv", sched + "\r\n")
    cfg = _write(tmp_path / "c.toml", COARSE)
    assert main(["simulate", "--schedule", str(tmp_path / "s.csv"), "--config", str(cfg), "--no-pictures",
                 "--out", str(tmp_path / "r")]) == 0, capsys.readouterr().err
    ts = read_timeseries(tmp_path / "r" / "timeseries.csv")
    assert ts.time_s[-1] == 7200.0 and ts["oil_degC"][1] == pytest.approx(40.0 + 60 / 3700, rel=1e-12)


# ---- command-line arguments --------------------------------------------------------------------

@pytest.mark.parametrize("argv, needle", [
    (["simulate", "--condition", "1", "--fields-every", "-5"],
     "argument --fields-every: got -5, must be a finite number > 0"),
    (["simulate", "--condition", "1", "--fields-every", "nan"], "argument --fields-every: got nan"),
    (["simulate", "--condition", "x"], "argument --condition: invalid int value: 'x'"),
    (["simulate", "--condition", "1", "--dim", "4"], "argument --dim: invalid choice: 4"),
    (["simulate", "--condition", "1", "--schedule", "s.csv"], "not allowed with argument"),
    (["simulate", "--condition", "1", "--colour", "red"], "unrecognized arguments: --colour red"),
    (["simulate", "--condition", "1", "--out"], "argument --out: expected one argument"),
    (["sweep", "s.toml", "--workers", "0"], "argument --workers: got 0, must be a whole number >= 1"),
    (["sweep", "s.toml", "--workers", "1.5"], "argument --workers: expected a whole number, got '1.5'"),
    (["validate"], "argument TARGET: invalid choice"),
    (["validate", "calibrate", "--evals", "0"], "argument --evals: got 0"),
    (["validate", "hidden-effects", "--conditions", "1,x"], "argument --conditions: got '1,x'"),
    (["validate", "hidden-effects", "--mesh-size", "-1"], "argument --mesh-size: got -1"),
    (["diagnose", "--data", "d.csv", "--mesh-size", "0"], "argument --mesh-size: got 0"),
    (["frobnicate"], "argument COMMAND: invalid choice: 'frobnicate'"),
])
def test_argument_errors_are_one_line(tmp_path, capsys, argv, needle):
    err = refused(capsys, 2, [*argv, *(["--out", tmp_path / "o"] if argv[-1] != "--out" else [])], needle)
    assert "usage:" not in err and err.startswith("gatetherm") and "--help" in err
    assert not (tmp_path / "o").exists()


def test_no_command_prints_the_help_and_exits_2(capsys):
    assert main([]) == 2
    io_ = capsys.readouterr()
    assert io_.out.startswith("usage: gatetherm") and "simulate" in io_.out and io_.err == ""
    assert main(["simulate", "--help"]) == 0
    assert "--fields-every" in capsys.readouterr().out


# ---- output directories ------------------------------------------------------------------------

@pytest.mark.parametrize("where, needle", [
    (lambda d: _write(d / "afile", "x"), "--out: 'DIR/afile' exists and is not a directory"),
    (lambda d: _write(d / "afile", "x") / "sub",
     "--out: 'DIR/afile/sub' lies below 'DIR/afile', which is not a directory"),
], ids=["a file", "below a file"])
def test_out_is_checked_before_the_run(tmp_path, capsys, monkeypatch, where, needle):
    from gatetherm.studies.run import scenario

    monkeypatch.setattr(scenario, "run_scenario", lambda *a, **k: pytest.fail("the run started"))
    refused(capsys, 2, ["simulate", "--condition", "1", "--out", where(tmp_path)], needle.replace("DIR", str(tmp_path)))
    assert (tmp_path / "afile").read_text() == "x"


def test_a_second_run_into_a_locked_directory_is_refused(tmp_path, capsys):
    out = tmp_path / "o"
    with output_dir(out) as stage:
        (stage / "timeseries.csv").write_text("the first run's\n")
        refused(capsys, 1, ["simulate", "--condition", "1", "--out", out],
                f"gatetherm: error: {out}: another gatetherm run (pid {os.getpid()}) is writing into this directory")
        assert (stage / "timeseries.csv").read_text() == "the first run's\n"
    assert sorted(p.name for p in out.iterdir()) == ["timeseries.csv"]  # committed; the lock is gone


def test_an_interrupted_run_leaves_no_temporary(tmp_path):
    """A writer cut short (a terminated worker) leaves its temporary; the run's output
    directory removes it and the stage as the interruption passes, and keeps the files a
    command keeps across runs (a sweep's points, written into the directory itself)."""
    from gatetherm import _new_temporary

    out = tmp_path / "o"
    with pytest.raises(KeyboardInterrupt), output_dir(out) as stage:
        (stage / "table.csv").write_text("never committed")
        (out / "points").mkdir()
        (out / "points" / "a.json").write_text("{}")
        _new_temporary(out / "points" / "b.json")
        raise KeyboardInterrupt
    assert sorted(str(p.relative_to(out)) for p in out.rglob("*")) == ["points", "points/a.json"]


def test_unwritable_output_and_unreadable_input(tmp_path, capsys, monkeypatch):
    """A read-only output directory (exit 1, before the run) and a model file without read
    permission (exit 2). Root is not bound by file permissions: there the file system's
    refusals are made at the os level."""
    ro, secret = tmp_path / "ro", _write(tmp_path / "secret.toml", COARSE)
    ro.mkdir()
    if os.geteuid() == 0:
        def refuse(real, code, where):
            def call(path, *args, **kwargs):
                if Path(path).parent == where:
                    raise OSError(code, os.strerror(code), str(path))
                return real(path, *args, **kwargs)
            return call
        monkeypatch.setattr(os, "open", refuse(os.open, errno.EROFS, ro))  # creating files in ro
        monkeypatch.setattr(os, "mkdir", refuse(os.mkdir, errno.EROFS, ro))
        monkeypatch.setattr(Path, "read_bytes", refuse(Path.read_bytes, errno.EACCES, tmp_path))
        problem = os.strerror(errno.EROFS)
    else:
        ro.chmod(0o555)
        secret.chmod(0)
        problem = os.strerror(errno.EACCES)
    try:
        for out in (ro, ro / "new"):
            refused(capsys, 1, ["simulate", "--condition", "1", "--out", out],
                    f"gatetherm: error: {out}: cannot write into this directory ({problem})")
        refused(capsys, 2, ["simulate", "--condition", "1", "--config", secret, "--out", tmp_path / "o"],
                f"gatetherm: error: --config: cannot read '{secret}' (Permission denied); check its permissions")
    finally:
        ro.chmod(0o755)
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("umask, mode", [(0o022, 0o644), (0o077, 0o600), (0o002, 0o664)])
def test_files_get_the_umask_permissions(tmp_path, capsys, umask, mode):
    cfg = _write(tmp_path / "c.toml", COARSE)
    old = os.umask(umask)
    try:
        assert main(["mesh", "--config", str(cfg), "--out", str(tmp_path / "o")]) == 0
    finally:
        os.umask(old)
    assert {oct(p.stat().st_mode & 0o777) for p in (tmp_path / "o").iterdir()} == {oct(mode)}


def test_a_rerun_replaces_the_whole_output_set(tmp_path, capsys):
    """Stale field files of an earlier run with more fields, and the temporaries of a killed
    run, are gone after a rerun; other files are left alone."""
    cfg = _write(tmp_path / "c.toml", COARSE)
    run = ["simulate", "--condition", "1", "--config", str(cfg), "--no-pictures", "--out"]
    assert main([*run, str(tmp_path / "fresh")]) == 0
    assert main([*run, str(tmp_path / "o"), "--fields-every", "30"]) == 0
    assert len(list((tmp_path / "o" / "fields").glob("*.vtu"))) == 11
    for stale in ("fields/.gatetherm-tmp.fields_0042min.0badf00d.vtu", ".gatetherm-tmp.summary.deadbeef.json",
                  "response.png", LOCK):
        _write(tmp_path / "o" / stale, "stale")
    _write(tmp_path / "o" / "my_notes.txt", "mine")
    assert main([*run, str(tmp_path / "o")]) == 0

    def files(d):
        return sorted(str(p.relative_to(d)) for p in d.rglob("*") if p.is_file())
    assert files(tmp_path / "o") == sorted(files(tmp_path / "fresh") + ["my_notes.txt"])


def test_a_run_never_overwrites_its_input_files(tmp_path):
    """diagnose --config DIR/model.toml --out DIR would write a new DIR/model.toml over the
    model file it read: refused in one line before anything is removed. An input that is
    not among the files the command writes is kept while the previous run's files go."""
    _write(tmp_path / "model.toml", "[geometry]\n")
    _write(tmp_path / "report.md", "old")
    with pytest.raises(InputError, match=f"would overwrite its input '{tmp_path / 'model.toml'}'"):
        with output_dir(tmp_path, ("model.toml", "report.md"), keep=(str(tmp_path / "model.toml"), None)):
            pass
    assert sorted(p.name for p in tmp_path.iterdir()) == ["model.toml", "report.md"]
    with output_dir(tmp_path, ("report.md",), keep=(str(tmp_path / "model.toml"),)):
        pass
    assert sorted(p.name for p in tmp_path.iterdir()) == ["model.toml"]


def test_disk_full_ends_in_one_line_and_leaves_nothing(tmp_path, capsys, monkeypatch):
    """The disk fills while the fields are written: exit 1, one line naming the file (its
    name in --out, not the stage's); nothing of the failed run is left (the directory it
    created is removed again), so no partial file under a final name and no temporary."""
    from gatetherm.studies.run import output

    def full(path, *args, **kwargs):
        with open(path, "wb") as fh:
            fh.write(b"<VTKFile partial")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(output, "write_vtu", full)
    cfg = _write(tmp_path / "c.toml", COARSE)
    out = tmp_path / "o"
    refused(capsys, 1, ["simulate", "--condition", "1", "--config", cfg, "--no-pictures", "--out", out],
            f"gatetherm: error: {out}/fields/fields_0000min.vtu: No space left on device")
    assert not out.exists()


# ---- sweeps ------------------------------------------------------------------------------------

STUDY = """[study]
name = "two"
compute = ["coefficients"]
[set]
"mesh.size" = 0.03
[grid]
"geometry.l4" = [0.25, 0.3]
"""


@pytest.mark.parametrize("edit, needle", [
    (lambda s: s.replace("[0.25, 0.3]", "[0.25, 0.3]\n\"material.E\" = [0, 1.2e11]").encode(),
     "study.toml: material.E: got 0, must be a finite number > 0"),
    (lambda s: s.replace('"mesh.size" = 0.03', '"mesh.size" = 1e-6').encode(), "study.toml: mesh.size: 1e-06 m gives"),
    (lambda s: s.replace('"mesh.size" = 0.03', "condition = 1.5").encode(),
     "study.toml: condition: expected a whole number, got 1.5"),
    (lambda s: s.replace('"mesh.size" = 0.03', '"thermal.h_oil_on" = nan').encode(), "thermal.h_oil_on: got nan"),
    (lambda s: ("# ° \n" + s).encode("latin-1"), "study.toml, line 1: byte 0xb0 is not UTF-8 text"),
    (lambda s: s.replace("[study]\n", "study = 3\n[x]\n").encode(), "study.toml: study: expected a [study] table"),
    (lambda s: s.replace("[study]\n", '[study]\nconfig = "nope.toml"\n').encode(),
     "study.toml: study.config: no such file"),
], ids=["E = 0", "mesh too fine", "condition 1.5", "nan", "latin-1", "study not a table", "missing config"])
def test_study_files(tmp_path, capsys, edit, needle):
    study = _write(tmp_path / "study.toml", edit(STUDY))
    refused(capsys, 2, ["sweep", study, "--workers", "1", "--out", tmp_path / "o"], needle)
    assert not (tmp_path / "o").exists()


def _fake_evaluate(task):
    """A point in no time: the store and the table, not the numbers, are under test."""
    return {"key": task.key, "params": dict(task.params), "status": "ok", "note": "",
            "results": {"nodes": 7, "Ki_E_fe": dict(task.params)["geometry.l4"]}, "seconds": 0.0,
            "version": "x", "scheme": "y"}


def test_corrupted_point_files_of_any_shape_are_recomputed(tmp_path, caplog, monkeypatch):
    calls = []
    monkeypatch.setattr(sweep_evaluate, "evaluate", lambda t: calls.append(t.key) or _fake_evaluate(t))
    study = _write(tmp_path / "study.toml", STUDY.replace("[0.25, 0.3]", "[0.2, 0.25, 0.3, 0.35, 0.4, 0.45]"))
    argv = ["sweep", str(study), "--workers", "1", "--out", str(tmp_path / "o")]
    assert main(argv) == 0
    table = (tmp_path / "o" / "table.csv").read_bytes()
    points = sorted((tmp_path / "o" / "points").glob("*.json"))
    shapes = [lambda k: "{}", lambda k: f'{{"key": "{k}", "status": "ok", "note": "", "results": "oops"}}',
              lambda k: points[2].read_text()[:40], lambda k: bytes(range(256)), lambda k: "[1, 2]",
              lambda k: f'{{"key": "{k}", "status": "ok", "note": "", "results": {{"x": "1"}}}}']
    for path, shape in zip(points, shapes):
        _write(path, shape(path.stem))
    calls.clear()
    caplog.clear()
    assert main(argv) == 0
    assert sorted(calls) == sorted(p.stem for p in points)
    assert sum("cannot be used" in r.getMessage() and r.levelname == "WARNING" for r in caplog.records) == 6
    assert (tmp_path / "o" / "table.csv").read_bytes() == table


def test_a_failed_point_is_one_line_naming_the_field(tmp_path, capsys, monkeypatch):
    def evaluate(task):
        if dict(task.params)["geometry.l4"] == 0.3:
            raise InputError("thermal.h_air", "got -1, must be a finite number >= 0")
        return _fake_evaluate(task)

    monkeypatch.setattr(sweep_evaluate, "evaluate", evaluate)
    study = _write(tmp_path / "study.toml", STUDY)
    refused(capsys, 1, ["sweep", study, "--workers", "1", "--out", tmp_path / "o"],
            "gatetherm: error: 1 of 2 points failed (point {'geometry.l4': 0.3}: thermal.h_air: got -1")
    assert [row.split(",")[1] for row in (tmp_path / "o" / "table.csv").read_text().splitlines()[1:]] == \
        ["ok", "pending"]


# ---- error-model files, leakage, non-finite numbers (issue 55) ---------------------------------

def _record(path: Path) -> Path:
    """A machine's record: d_um = 2 theta_1 + noise, two sensors, 400 samples a minute apart."""
    from gatetherm.studies.run.timeseries import FORMAT, TimeSeries, write_timeseries

    rng = np.random.default_rng(0)
    t = 60.0 * np.arange(400)
    s1, s2 = 22 + np.cumsum(rng.normal(0, 0.05, t.size)), 22 + np.cumsum(rng.normal(0, 0.05, t.size))
    write_timeseries(path, TimeSeries({"time_s": t, "s1_degC": s1, "s2_degC": s2, "rpm": 0 * t,
                                       "d_um": 2.0 * (s1 - s1[0]) + rng.normal(0, 0.05, t.size)}, {"format": "x"}))
    return path


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    d = tmp_path_factory.mktemp("fitted")
    data = _record(d / "data.csv")
    assert main(["errormodel", "fit", "--data", str(data), "--targets", "d_um", "--out", str(d)]) == 0
    return data, json.loads((d / "model.json").read_text())


@pytest.mark.parametrize("option", ["--candidates", "--inputs"])
def test_a_target_is_never_read_by_its_own_model(tmp_path, capsys, fitted, option):
    """The leak of issue 55: d_um predicted from itself (held-out error 1e-15) is refused before
    the data file is read, and the library refuses it too."""
    from gatetherm.studies.errormodel.fit import fit_error_model
    from gatetherm.studies.run.timeseries import read_timeseries

    data, _ = fitted
    refused(capsys, 2, ["errormodel", "fit", "--data", tmp_path / "none.csv", "--targets", "d_um", option,
                        "d_um,s1_degC", "--out", tmp_path / "o"],
            f"gatetherm: error: {option} d_um: is a target (--targets): a model cannot read the column it predicts; "
            f"drop d_um from {option}")
    kwargs = {"candidates": ["s1_degC", "d_um"]} if option == "--candidates" else {"inputs": ["d_um"]}
    with pytest.raises(InputError, match="d_um: is a target"):
        fit_error_model(read_timeseries(data, required=("time_s",)), ["d_um"], **kwargs)
    assert not (tmp_path / "o").exists()


def _coefficient(model: dict, text: str) -> str:
    """The model file with its first coefficient written as ``text``."""
    return re.sub(r'"coefficient": [^,}]+', f'"coefficient": {text}', json.dumps(model), count=1)


@pytest.mark.parametrize("edit, needle", [
    (lambda d: {**d, "targets": {}}, "model.json: targets: must be a non-empty table of the targets' models"),
    (lambda d: _coefficient(d, "NaN"), "holds NaN, not a finite"),
    (lambda d: _coefficient(d, "1e999"), "holds 1e999, not a fin"),
    (lambda d: _coefficient(d, '"nan"'),
     "model.json: targets.d_um.terms[0].coefficient: must be a number within ±1e+09"),
    (lambda d: _coefficient(d, "1" * 400),
     "holds the integer 111111111111... of 400 digits"),
    (lambda d: "[" * 100_000 + "]" * 100_000, "model.json: nested deeper than 32 levels"),
    (lambda d: {**d, "targets": {"d_um": {**d["targets"]["d_um"], "terms": [
        {"kind": "sensor", "column": "d_um", "coefficient": 1.0}]}}, "reference_degC": {"d_um": 0.0}},
     "model.json: targets.d_um.terms[0].column: reads the target d_um itself: a model cannot read the column"),
], ids=["no targets", "NaN", "1e999", "'nan'", "400 digits", "nested 100000 deep", "reads its target"])
def test_error_model_files_are_refused_in_one_line(tmp_path, capsys, fitted, edit, needle):
    data, model = fitted
    text = edit(model)
    path = _write(tmp_path / "model.json", text if isinstance(text, str) else json.dumps(text))
    refused(capsys, 2, ["errormodel", "predict", path, "--data", data, "--out", tmp_path / "o"], needle)
    assert not (tmp_path / "o").exists()


def test_json_writers_name_a_non_finite_quantity(tmp_path):
    from gatetherm.checks import NonFiniteError, json_text
    from gatetherm.studies.run.output import write_json

    with pytest.raises(NonFiniteError, match=r"^summary.json: probes.tip\[1\]: is nan, not a finite number; "
                                             "nothing was written"):
        write_json(tmp_path / "summary.json", {"probes": {"tip": [1.0, float("nan")]}})
    assert json_text({"a": [1.5, None]}, "x.json") == '{"a": [1.5, null]}\n'
    assert not list(tmp_path.iterdir())


def test_fit_with_differences_on_the_shipped_record_writes_finite_numbers(tmp_path, capsys):
    """errormodel fit --differences gave ``ValueError: Out of range float values ...: inf``: a
    forward step whose every addition made the model singular (a difference of two sensors
    already in it) was put on the path with an infinite error. Such additions are skipped."""
    data = _record(tmp_path / "data.csv")
    assert main(["errormodel", "fit", "--data", str(data), "--targets", "d_um", "--differences",
                 "--out", str(tmp_path / "o")]) == 0
    model = json.loads((tmp_path / "o" / "model.json").read_text())
    errors = [s["cv_mae_um"] for s in model["targets"]["d_um"]["selection"]]
    assert all(map(math.isfinite, errors)) and min(errors) == pytest.approx(0.088, abs=0.01)  # noise-scored (ROBUST): 0.04 plain


# ---- gmsh's reading of a case is quiet (issue 55) ----------------------------------------------

PLATE_GEO = """SetFactory("OpenCASCADE");
Rectangle(1) = {0, 0, 0, 1, 1};
Physical Surface("plate") = {1};
Physical Curve("edge") = {1};
"""
PLATE_CASE = '[mesh]\nfile = "a.geo"\nsize = SIZE\n[materials.plate]\nk = 50.0\n[thermal.edge]\ntemperature = 100.0\n'


@pytest.mark.parametrize("script, needle", [
    ('Error(StrCat("leak: ", GetEnv("GT_SECRET")));\n',
     "a.geo: gmsh cannot read it (gmsh's message is not repeated: it names no line; open the file in gmsh to read it)"),
    ('Printf(StrCat("leak: ", GetEnv("GT_SECRET")));\nError("stop");\n', "gmsh's message is not repeated"),
    ('x = GT_SECRET_IS_hunter2 + ;\n', "a.geo: gmsh cannot read it (a.geo, line 5: Unknown variable); check the file"),
    ('Error(StrCat("leak: ", GetString("GT_SECRET")));\n', "gmsh's message is not repeated"),
], ids=["Error of GetEnv", "Printf of GetEnv", "a syntax error quoting the text", "GetString"])
def test_a_geo_never_echoes_the_environment_or_its_own_text(tmp_path, capsys, monkeypatch, script, needle):
    """A .geo's messages are not repeated beyond the file name and line; the script's process
    has no environment to read (GetEnv gives ''), also in the -v log."""
    monkeypatch.setenv("GT_SECRET", "hunter2")
    _write(tmp_path / "a.geo", PLATE_GEO + script)
    case = _write(tmp_path / "case.toml", PLATE_CASE.replace("SIZE", "0.25"))
    err = refused(capsys, 2, ["-v", "run", case, "--out", tmp_path / "o"], needle)
    assert "hunter2" not in err and "leak" not in err


def test_the_child_reading_a_geo_has_no_environment(tmp_path, monkeypatch):
    """The script writes what GetEnv gives into a Physical name, which comes back in the mesh:
    empty, for a variable set in gatetherm's environment."""
    from gatetherm.geometry.gmshfile import MeshSpec, mesh_geometry

    monkeypatch.setenv("GT_SECRET", "hunter2")
    monkeypatch.setenv("OMP_NUM_THREADS", "1")
    geo = PLATE_GEO.replace('"edge"', 'StrCat("e", GetEnv("GT_SECRET"), GetEnv("OMP_NUM_THREADS"))')
    fm = mesh_geometry(MeshSpec(_write(tmp_path / "a.geo", geo), size=0.25))
    assert sorted(fm.boundaries) == ["e1"]


@pytest.mark.parametrize("size, needle", [
    ("1e-300", "mesh.size: 1e-300 m gives more triangles than can be counted, more than the budget of 5e+07 "
               "elements; give a size of about a tenth of the smallest part"),
    ("1e-4", "mesh.size: 0.0001 m gives about 2.3e+08 triangles, more than the budget of 5e+07 elements; raise it "
             "to at least 0.00021 m"),
], ids=["1e-300", "1e-4"])
def test_an_element_size_beyond_the_element_budget_is_refused(tmp_path, capsys, monkeypatch, size, needle):
    """[mesh] size = 1e-300 gave ZeroDivisionError in gmsh's process; every size whose estimate
    exceeds the budget is refused in one line before gmsh meshes (memory set ample here)."""
    from gatetherm.geometry import sizing

    monkeypatch.setattr(sizing, "memory_bytes", lambda: 1e15)
    _write(tmp_path / "a.geo", PLATE_GEO)
    case = _write(tmp_path / "case.toml", PLATE_CASE.replace("SIZE", size))
    refused(capsys, 2, ["run", case, "--out", tmp_path / "o"], needle)
    assert not (tmp_path / "o").exists()


# ---- the older audit's and the newest commands' arguments (issue 55) ----------------------------

@pytest.mark.parametrize("argv, needle", [
    (["sensors", "--seed", "-1"], "gatetherm sensors: error: argument --seed: got -1, must be a whole number in [0, "),
    (["sensors", "--exclude=0,0,nan,1"], "gatetherm: error: --exclude: got nan, must be a finite number"),
    (["sensors", "--range", "spindle_W=0:1e300"],
     "gatetherm: error: --range spindle_W: got 1e+300, must be a number in [-1e+09, 1e+09]"),
    (["sensors", "--range", "spindle_W=5:1"], "gatetherm: error: --range spindle_W=5:1: its low end is above its high"),
    (["simulate", "--condition", "0"], "gatetherm: error: --condition: no condition 0; choose one of 1, 2, 3"),
    (["export", "ccx", "--condition", "0"], "gatetherm: error: --condition: no condition 0"),
    (["compensate", "--model", "m.json", "--data", "d.csv", "--method", "rom"],
     "gatetherm: error: --model/--method: --model replays a fitted error model: --method rom would be ignored"),
], ids=["seed -1", "exclude nan", "range 1e300", "range reversed", "simulate condition 0", "export condition 0",
        "model with method"])
def test_command_arguments_are_refused_in_one_line(tmp_path, capsys, argv, needle):
    refused(capsys, 2, [*argv, "--out", tmp_path / "o"], needle)
    assert not (tmp_path / "o").exists()


def test_a_case_diagnosis_study_of_an_unfit_case_is_one_line(tmp_path, capsys):
    """validate case-diagnosis --case t4.toml: AttributeError ('function' object has no
    attribute 'columns') deep in the study; a steady case without signals is refused at once."""
    t4 = Path(__file__).parents[1] / "validation" / "nafems" / "t4.toml"
    refused(capsys, 2, ["validate", "case-diagnosis", "--case", t4, "--out", tmp_path / "o"],
            f"gatetherm: error: --case {t4}: the study replays a transient case from its schedule file")
    assert not (tmp_path / "o").exists()


def test_gravity_out_of_range_names_gravity(tmp_path, capsys):
    """[gravity] of 1e300 ended in a message about a stress column; now the key is named."""
    example = Path(__file__).parents[1] / "validation" / "examples" / "c_frame"
    for f in example.iterdir():
        _write(tmp_path / f.name, f.read_bytes())
    case = _write(tmp_path / "case.toml", (example / "case.toml").read_text() + "\n[gravity]\nacceleration = [0, -1e300]\n")
    refused(capsys, 2, ["run", case, "--out", tmp_path / "o"],
            f"gatetherm: error: {case}: gravity.acceleration[2]: got -1e+300, must be a number in [-10000, 10000] m/s²")


def test_a_geometry_of_more_parts_than_the_budget_is_refused(tmp_path, capsys):
    """1 000 touching cubes gave no output in 300 s (fragmenting them); over the part budget
    a geometry is refused in one line before."""
    from gatetherm.geometry.gmshfile import MAX_PARTS

    n = MAX_PARTS + 1
    geo = 'SetFactory("OpenCASCADE");\nFor i In {1:%d}\n  Rectangle(i) = {2 * i, 0, 0, 1, 1};\nEndFor\n' % n
    _write(tmp_path / "a.geo", geo + 'Physical Surface("plate") = {1:%d};\nPhysical Curve("edge") = {1};\n' % n)
    case = _write(tmp_path / "case.toml", PLATE_CASE.replace("SIZE", "0.5"))
    refused(capsys, 2, ["run", case, "--out", tmp_path / "o"],
            f"a.geo: has {n} surfaces, more than the budget of {MAX_PARTS} parts")
