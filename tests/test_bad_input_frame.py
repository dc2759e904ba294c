"""The third audit of the paper frame's commands and the files they read (issue 55, part A:
cases the earlier audits had not shown). One test per class it found, at the boundary where the
input is read: a TOML file nested thousands deep (tomllib's recursion) and an effect given twice
on the command line are each one line naming the file or the option and the fix."""
from __future__ import annotations

import pytest

from gatetherm import InputError
from gatetherm.cli import main
from gatetherm.files import MAX_TOML_DEPTH, parse_toml

COARSE = "[mesh]\nsize = 0.03\nsize_3d = 0.04\n"


def refused(capsys, code: int, argv, *needles: str) -> str:
    """Run the command; assert exit ``code``, exactly one line on stderr holding every needle."""
    got = main([str(a) for a in argv])
    err = capsys.readouterr().err
    assert got == code, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for needle in needles:
        assert needle in err, err
    return err


DEEP = {
    "arrays": "[effects]\nx = " + "[" * 3000 + "]" * 3000 + "\n",
    "inline tables": "a = " + "{b = " * 500 + "1" + "}" * 500 + "\n",
    "tables": "[" + ".".join(f"t{i}" for i in range(MAX_TOML_DEPTH + 1)) + "]\nx = 1\n",
}


@pytest.mark.parametrize("body", DEEP.values(), ids=DEEP)
def test_a_toml_file_nested_too_deep_is_one_line(tmp_path, capsys, body):
    """Arrays 3 000 deep ended in tomllib's RecursionError (a traceback); every TOML reader
    (model, study, case, map, solver files) goes through one parser that refuses them."""
    cfg = tmp_path / "deep.toml"
    cfg.write_text(body)
    refused(capsys, 2, ["simulate", "--condition", "1", "--config", cfg, "--out", tmp_path / "o"],
            f"gatetherm: error: {cfg}: nested deeper than {MAX_TOML_DEPTH} levels; fix the model file's syntax")
    study = tmp_path / "study.toml"
    study.write_text('[study]\ncompute = ["coefficients"]\n' + body)
    refused(capsys, 2, ["sweep", study, "--out", tmp_path / "o"], f"{study}: nested deeper than {MAX_TOML_DEPTH} levels")
    assert not (tmp_path / "o").exists()


def test_a_toml_file_at_the_depth_limit_is_read():
    doc = parse_toml("x = " + "[" * (MAX_TOML_DEPTH - 1) + "1" + "]" * (MAX_TOML_DEPTH - 1) + "\n", "f.toml")
    assert isinstance(doc["x"], list)
    with pytest.raises(InputError, match="not valid TOML"):
        parse_toml("[mesh\n", "f.toml")


def test_an_effect_given_twice_is_refused(tmp_path, capsys):
    """--effect piezo_heat:power=1 --effect piezo_heat=2 ran with 2 W without a word."""
    cfg = tmp_path / "c.toml"
    cfg.write_text(COARSE)
    refused(capsys, 2, ["simulate", "--condition", "1", "--config", cfg, "--no-pictures", "--out", tmp_path / "o",
                        "--effect", "piezo_heat:power=1", "--effect", "piezo_heat=2"],
            "gatetherm: error: --effect: piezo_heat is given more than once; give each effect once")
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("body, needle", [
    ("[mesh]\nsize = 50.0\n", "mesh.size: 50 m is larger than the whole frame (0.85 m); lengths are in m; "
                             "choose an element size below 0.085 m"),
    ("[mesh]\nsize_3d = 2.0\n", "mesh.size_3d: 2 m is larger than the whole frame"),
    ("[geometry]\ndepth = 1e20\n", "geometry.depth: got 1e+20, must be a number in (0, 100] m"),
], ids=["size 50 m", "3-D size 2 m", "depth 1e20"])
def test_a_frame_size_no_machine_has_is_refused_naming_the_model_file(tmp_path, capsys, body, needle):
    """[mesh] size = 50 meshed the frame with 69 elements (first peak 3 µm instead of 48 µm), and
    a 2-D depth of 1e20 m gave a swing of 1e-12 µm, both without a word."""
    cfg = tmp_path / "c.toml"
    cfg.write_text(body)
    dim = "3" if "3d" in body else "2"
    refused(capsys, 2, ["mesh", "--dim", dim, "--config", cfg, "--out", tmp_path / "o"], f"gatetherm: error: {cfg}: {needle}")
    assert not (tmp_path / "o").exists()


# ---- compensate: options its method does not read, coefficients no machine has ----------------------

REC = "# format: gatetherm-timeseries/1\ntime_s,theta_A_degC,theta_B_degC,theta_C_degC,delta_um\n" + "".join(
    f"{60 * i},{20 + 0.1 * i},{20 + 0.05 * i},{20 + 0.01 * i},{0.3 * i}\n" for i in range(20))


@pytest.mark.parametrize("extra, needle", [
    (["--Ki", "2", "--Kc", "1", "--target", "delta_um"],
     "--target: is read by --model MODEL.json only: --method paper would ignore it"),
    (["--Ki", "2", "--Kc", "1", "--correction"], "--correction: is read by --model MODEL.json only"),
    (["--rom", "x.npz"], "--rom: is read by --method rom only: --method paper would ignore it; drop --rom"),
    (["--method", "mlr", "--states", "5"], "--states: is read by --method rom only: --method mlr would ignore it"),
    (["--updates", "fixed"], "--updates: is read by --method rom only"),
    (["--method", "rom", "--Ki", "1", "--Kc", "2"], "--Ki: is read by --method paper only: --method rom would ignore it"),
    (["--Ki", "1e308", "--Kc", "1"], "--Ki/--Kc: got 1e+308, 1, must be within ±1e+06 um/K"),
], ids=["target", "correction", "rom file", "states with mlr", "updates", "Ki with rom", "Ki 1e308"])
def test_compensate_refuses_an_option_its_method_would_ignore(tmp_path, capsys, extra, needle):
    """--target and --correction without --model, rom's options with paper or mlr, --Ki with rom:
    each ran without a word; --Ki 1e308 overflowed into a 'report it' error after the run."""
    data = tmp_path / "d.csv"
    data.write_text(REC)
    refused(capsys, 2, ["compensate", "--data", data, "--out", tmp_path / "o", *extra], f"gatetherm: error: {needle}")
    assert not (tmp_path / "o").exists()


def test_the_library_refuses_a_setting_its_method_would_ignore(tmp_path):
    import gatetherm as gt
    from gatetherm.studies.run.timeseries import read_timeseries

    (tmp_path / "r.csv").write_text(REC)
    with pytest.raises(InputError, match="--Ki: is read by --method paper only: --method mlr would ignore it"):
        gt.compensate(read_timeseries(tmp_path / "r.csv", required=("time_s",)), None, "mlr", Ki=1.0, Kc=1.0)


# ---- time-series files and the beam command ------------------------------------------------------

def test_a_field_too_long_for_the_csv_reader_is_one_line(tmp_path, capsys):
    """A 10-MB field ended in _csv.Error (a traceback); a long number is shown shortened."""
    cfg = tmp_path / "c.toml"
    cfg.write_text(COARSE)
    head = "# format: gatetherm-timeseries/1\ntime_s,oil_degC,pump\n0,40,1\n3600,40,0\n"
    sched = tmp_path / "s.csv"
    sched.write_text(head + "1" * 200_000 + "\n")
    refused(capsys, 2, ["simulate", "--schedule", sched, "--config", cfg, "--out", tmp_path / "o"],
            f"{sched}, line 5: not CSV (field larger than field limit (131072)); give one number per field")
    sched.write_text(head + "7200," + "9" * 100_000 + ",1\n")
    err = refused(capsys, 2, ["simulate", "--schedule", sched, "--config", cfg, "--out", tmp_path / "o"],
                  "column oil_degC: non-numeric value '" + "9" * 36 + "...; write")
    assert len(err) < 400, err


def test_beam_takes_an_infinite_beta_as_documented(capsys):
    """'inf = no tie bar' (its help) was refused by the API's boundary check as not finite."""
    import math

    import gatetherm as gt

    assert main(["beam", "--l-over-l4", "2", "--beta", "inf", "--json"]) == 0
    assert capsys.readouterr().out.strip() == '{"Ki_norm": 1.0, "Kc_norm": 0.0}'
    assert (gt.beam_normalised(2, math.inf).ki_norm, gt.beam_normalised(2, math.inf).kc_norm) == (1.0, 0.0)
    with pytest.raises(InputError, match="beta: got nan"):
        gt.beam_normalised(2, math.nan)


@pytest.mark.parametrize("option, value", [("--effects", ""), ("--effects", ","), ("--parameters", " , "),
                                           ("--uncertain", ",")])
def test_a_diagnose_list_naming_nothing_is_refused(tmp_path, capsys, option, value):
    """--effects "" ran as if no --effects were given (all effects), without a word."""
    data = tmp_path / "d.csv"
    data.write_text(REC)
    refused(capsys, 2, ["diagnose", "--data", data, option, value, "--out", tmp_path / "o"],
            f"gatetherm: error: {option}: {value!r} names nothing; give names separated by commas, or '{option} none'")
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("edit, needle", [
    ('[grid]\n' + "".join(f'"geometry.{k}" = [{", ".join(str(0.1 + 0.001 * i) for i in range(40))}]\n'
                         for k in ("l4", "l_C", "h")),
     "grid: 40 x 40 x 40 = 64000 points, more than the budget of 10000; sweep fewer values, or split the study"),
    ('compute = []\n[grid]\n"geometry.l4" = [0.25, 0.3]\n', "study.compute: expected a non-empty list, got []"),
    ('compute = 3\n[grid]\n"geometry.l4" = [0.25, 0.3]\n', "study.compute: expected a non-empty list, got 3"),
    ('name = 12\n[grid]\n"geometry.l4" = [0.25, 0.3]\n', "study.name: expected a string, got 12"),
], ids=["64000 points", "compute nothing", "compute 3", "name 12"])
def test_a_study_file_beyond_a_budget_or_computing_nothing_is_refused(tmp_path, capsys, edit, needle):
    """40^4 points planned for more than 180 s with no output (no progress); compute = [] ran
    and computed nothing, compute = 3 was a TypeError, a number as the name was taken."""
    study = tmp_path / "s.toml"
    study.write_text("[study]\n" + edit)
    refused(capsys, 2, ["sweep", study, "--no-plots", "--out", tmp_path / "o"], f"gatetherm: error: {study}: {needle}")
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("study", ["hidden-effects", "compound", "case-diagnosis"])
def test_a_negative_seed_of_a_validation_study_is_one_line(tmp_path, capsys, study):
    """validate hidden-effects --seed -1 ended in numpy's ValueError (a traceback) after its setup."""
    refused(capsys, 2, ["validate", study, "--seed", "-1", "--out", tmp_path / "o"],
            f"gatetherm validate {study}: error: argument --seed: got -1, must be a whole number in [0, 4.29497e+09]")
    assert not (tmp_path / "o").exists()


DEFERRED = """
import os, signal, sys
held = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})  # as gatetherm.cli does first
from gatetherm.api import start_libraries
start_libraries()
signal.pthread_sigmask(signal.SIG_SETMASK, held)
import gatetherm.api.run  # a task's modules, imported when first used
from gatetherm.solvers.cholesky import _others_block, _signals_deferred
got = []
signal.signal(signal.SIGTERM, lambda n, f: got.append(n))
assert _others_block({signal.SIGINT, signal.SIGTERM})
with _signals_deferred():
    os.kill(os.getpid(), signal.SIGTERM)
    inside = list(got)
print(inside, got)
"""


def test_a_sigterm_during_metis_waits_for_it_to_return():
    """SIGTERM while METIS ordered (GKlib traps it with a longjmp) left a run waiting on malloc's
    lock for ever (1 in 12 tries) or ended it in a traceback; the command line starts the
    libraries' threads with the signals blocked, so that the main thread can defer them."""
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-c", DEFERRED], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[] [15]"


@pytest.mark.parametrize("value", ["4_0", "４０", "infinity", "0x28"])
def test_a_number_only_python_reads_is_refused_in_a_data_file(tmp_path, capsys, value):
    """'4_0' was read as 40 (Python's float takes underscores and other scripts' digits)."""
    cfg = tmp_path / "c.toml"
    cfg.write_text(COARSE)
    sched = tmp_path / "s.csv"
    sched.write_text(f"# format: gatetherm-timeseries/1\ntime_s,oil_degC,pump\n0,40,1\n3600,{value},0\n7200,40,1\n")
    refused(capsys, 2, ["simulate", "--schedule", sched, "--config", cfg, "--out", tmp_path / "o"],
            f"{sched}, line 4 (data row 2), column oil_degC: non-numeric value '{value}'; write a decimal number")


def test_a_model_files_sensors_that_disagree_with_its_terms_are_refused(tmp_path, capsys):
    """'sensors': 'theta_A_degC' (a string, or any list other than the terms' sensors) was read
    without a word: the field is derived from the terms and nothing checked it."""
    import json

    import math

    data = tmp_path / "d.csv"
    data.write_text("# format: gatetherm-timeseries/1\ntime_s,theta_A_degC,theta_B_degC,delta_um\n" + "".join(
        f"{60 * i},{20 + math.sin(i / 10):.4f},{20 + math.cos(i / 7):.4f},{3 * math.sin(i / 10) - 2 * math.cos(i / 7):.4f}\n"
        for i in range(200)))
    assert main(["errormodel", "fit", "--data", str(data), "--targets", "delta_um", "--out", str(tmp_path / "m")]) == 0
    capsys.readouterr()
    model = json.loads((tmp_path / "m" / "model.json").read_text())
    sensors = model["targets"]["delta_um"]["sensors"]
    model["targets"]["delta_um"]["sensors"] = sensors[0]
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(model))
    refused(capsys, 2, ["errormodel", "predict", bad, "--data", data, "--out", tmp_path / "o"],
            f"gatetherm: error: {bad}: targets.delta_um.sensors: lists ", "but its terms read")


def test_a_short_write_names_the_file(tmp_path):
    """On a nearly full disk numpy's tofile (meshio's .msh) raised OSError('7488 requested and
    4579 written'), and the command's one line named neither the file nor the cause."""
    from gatetherm import atomic_path

    target = tmp_path / "mesh.msh"
    with pytest.raises(OSError) as info:
        with atomic_path(target):
            raise OSError("7488 requested and 4579 written")
    assert (info.value.filename, info.value.strerror) == (
        str(target), "cannot write it all (7488 requested and 4579 written; is the disk full?)")
    assert list(tmp_path.iterdir()) == []
