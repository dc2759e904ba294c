"""Every command's output directory is a transaction (issue 55), from one table: a previous
run's files in --out survive a refusal, SIGINT, SIGTERM and kill -9 of a rerun, whatever the
command, and no temporary is left (a kill -9 leaves only its hidden stage, which the next
command into the directory removes). The fault is injected where the run's stage has just been
made and holds a partly written file (every command), and, for the quick commands, after every
file was written and before the commit: the worst moments. The signals act on whole processes,
so those runs are subprocesses; the refusals run in-process."""
from __future__ import annotations

import hashlib
import importlib
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import gatetherm.outdir as od
from gatetherm import TEMP_PREFIX, InputError
from gatetherm.cli import main
from gatetherm.studies.run.timeseries import FORMAT, TimeSeries, write_timeseries

COARSE = "[mesh]\nsize = 0.03\nsize_3d = 0.04\n"
STUDY = '[study]\ncompute = ["coefficients"]\n[set]\n"mesh.size" = 0.03\n[grid]\n"geometry.l4" = [0.25, 0.3]\n'

#: command: (argv with {d} for the inputs' folder and {out} for --out, the module whose OUTPUTS
#: name its output set (of gatetherm.cli, or a dotted path: the API's module of the command), the
#: attribute, quick: also faulted after all files were written)
TABLE = {
    "run": ("run {d}/case.toml --no-pictures --out {out}", "gatetherm.api.jobs", "OUTPUTS", False),
    "simulate": ("simulate --condition 1 --config {d}/c.toml --no-pictures --out {out}",
                 "gatetherm.api.jobs", "OUTPUTS", False),
    "mesh": ("mesh --config {d}/c.toml --out {out}", "gatetherm.api.frame", "OUTPUTS", True),
    "export": ("export ccx --condition 1 --time 60 --dim 3 --config {d}/c.toml --out {out}",
               "gatetherm.api.export", "OUTPUTS", False),
    "reduce": ("reduce --config {d}/c.toml --states 4 --no-check --out {out}",
               "gatetherm.api.reduction", "OUTPUTS", False),
    "sensors": ("sensors --config {d}/c.toml --count 1 --loads 2 --states 4 --out {out}", "sensors", "OUTPUTS",
                False),
    "errormodel fit": ("errormodel fit --data {d}/data.csv --targets d_um --out {out}", "errormodel",
                       "FIT_OUTPUTS", True),
    "errormodel predict": ("errormodel predict {d}/model.json --data {d}/data.csv --out {out}", "errormodel",
                           "PREDICT_OUTPUTS", True),
    "compensate": ("compensate --model {d}/model.json --data {d}/data.csv --no-actuator --out {out}",
                   "compensate", "OUTPUTS", True),
    "diagnose": ("diagnose --data {d}/record.csv --config {d}/c.toml --out {out}", "diagnose", "OUTPUTS", False),
    "sweep": ("sweep {d}/study.toml --no-plots --out {out}", "sweep", "OUTPUTS", False),
    "report": ("report --data {d}/data.csv --out {out}", "report", "DRIFT", True),
}

DRIVER = """
import os, signal, sys
from pathlib import Path
import gatetherm.outdir as od
from gatetherm.cli import main
sig, point, argv = int(sys.argv[1]), sys.argv[2], sys.argv[3:]
signal.signal(signal.SIGINT, signal.default_int_handler)  # as on a terminal (a job started with '&' ignores it)
def fault(*args):
    if point == "started":
        Path(args[1], "partial.json").write_text('{"half": ')
    os.kill(os.getpid(), sig)
    raise SystemExit("the signal did not end the run")
if point == "started":
    real = od._stage
    od._stage = lambda out, stage: (real(out, stage), fault(out, stage))
else:
    od._refuse_staged_inputs = fault
sys.exit(main(argv))
"""


@pytest.fixture(scope="module")
def inputs(tmp_path_factory) -> Path:
    """The commands' input files: a coarse frame, a copy of the C-frame case, a machine's
    record for the error model (d_um = 2 theta_1 + noise) and its fitted model, a study."""
    d = tmp_path_factory.mktemp("inputs")
    (d / "c.toml").write_text(COARSE)
    (d / "study.toml").write_text(STUDY)
    example = Path(__file__).parents[1] / "validation" / "examples" / "c_frame"
    for f in example.iterdir():
        (d / f.name).write_bytes(f.read_bytes())
    rng = np.random.default_rng(0)
    t = 60.0 * np.arange(400)
    s1, s2 = 22 + np.cumsum(rng.normal(0, 0.05, t.size)), 22 + np.cumsum(rng.normal(0, 0.05, t.size))
    d_um = 2.0 * (s1 - s1[0]) + rng.normal(0, 0.05, t.size)
    write_timeseries(d / "data.csv", TimeSeries({"time_s": t, "s1_degC": s1, "s2_degC": s2, "d_um": d_um},
                                                 {"format": FORMAT}))
    write_timeseries(d / "record.csv", TimeSeries({"time_s": t, "oil_degC": 40 + 0 * t, "pump": 1 + 0 * t,
                                                   "delta_um": 0.01 * t / 60}, {"format": FORMAT}))
    assert main(["errormodel", "fit", "--data", str(d / "data.csv"), "--targets", "d_um", "--out", str(d)]) == 0
    return d


def argv(command: str, d: Path, out: Path) -> list[str]:
    return TABLE[command][0].format(d=d, out=out).split()


def previous_run(command: str, out: Path) -> dict[str, str]:
    """Fill ``out`` with a previous run's output set (each file naming itself) and a file of the
    user's; the digests of all."""
    _, module, attr, _ = TABLE[command]
    names = getattr(importlib.import_module(module if "." in module else f"gatetherm.cli.{module}"), attr)
    for name in (*names, "my_notes.txt"):
        p = out / name.replace("*", "old")
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(f"the previous run's {p.name}\n")
    return digests(out)


def digests(out: Path) -> dict[str, str]:
    """sha256 of every file in ``out`` but gatetherm's own (its lock, temporaries and stages)."""
    return {str(p.relative_to(out)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(out.rglob("*")) if p.is_file() and not left_by_gatetherm(p.relative_to(out))}


def left_by_gatetherm(rel: Path) -> bool:
    return any(part.startswith(TEMP_PREFIX) or part == od.LOCK for part in rel.parts)


def left(out: Path) -> list[str]:
    """gatetherm's own files and folders in ``out`` (the top of each)."""
    return sorted({next(str(q) for q in [*reversed(p.relative_to(out).parents), p.relative_to(out)]
                        if q.name and left_by_gatetherm(q))
                   for p in out.rglob("*") if left_by_gatetherm(p.relative_to(out))})


@pytest.mark.parametrize("command", TABLE)
def test_a_refused_rerun_keeps_the_previous_results(command, inputs, tmp_path, monkeypatch, capsys):
    out = tmp_path / "o"
    before = previous_run(command, out)
    real = od._stage

    def refuse(o, stage):
        real(o, stage)
        (stage / "partial.json").write_text('{"half": ')
        raise InputError("--data", "injected refusal", "none")

    monkeypatch.setattr(od, "_stage", refuse)
    assert main(argv(command, inputs, out)) == 2
    assert capsys.readouterr().err.splitlines() == ["gatetherm: error: --data: injected refusal; none"]
    assert digests(out) == before and left(out) == []


def _faults():
    """kill -9 of every command where its stage was just made; after all its files were written
    for the quick ones (slow but errormodel fit's); SIGTERM and SIGINT (one path through
    output_dir, whatever the command) for errormodel fit."""
    for command, row in TABLE.items():
        yield pytest.param(command, signal.SIGKILL, "started", id=f"{command}-kill-9-started")
        if row[3]:
            marks = () if command == "errormodel fit" else pytest.mark.slow
            yield pytest.param(command, signal.SIGKILL, "written", marks=marks, id=f"{command}-kill-9-written")
    for sig in (signal.SIGTERM, signal.SIGINT):
        for point in ("started", "written"):
            yield pytest.param("errormodel fit", sig, point, id=f"errormodel fit-{sig.name}-{point}")


@pytest.mark.parametrize("command, sig, point", list(_faults()))
def test_a_signalled_rerun_keeps_the_previous_results(command, sig, point, inputs, tmp_path):
    out = tmp_path / point
    before = previous_run(command, out)
    r = subprocess.run([sys.executable, "-c", DRIVER, str(int(sig)), point, *argv(command, inputs, out)],
                       capture_output=True, text=True, timeout=300)
    code = {signal.SIGKILL: -9, signal.SIGTERM: 143, signal.SIGINT: 130}[sig]
    assert r.returncode == code, (point, r.stderr[-2000:])
    assert digests(out) == before, point
    if sig == signal.SIGKILL:  # the hidden stage is left, and the lock (not held): the next run removes them
        assert len(left(out)) == 2 and left(out)[0].startswith(f"{TEMP_PREFIX}stage.") and od.LOCK in left(out)
        with od.output_dir(out):
            pass
        assert left(out) == [] and digests(out) == before
    else:
        assert left(out) == [] and r.stderr.endswith(("interrupted\n", "terminated\n"))


@pytest.mark.parametrize("command", [c for c, row in TABLE.items() if row[3]])
def test_a_finished_rerun_replaces_the_output_set(command, inputs, tmp_path, capsys):
    """The quick commands: the previous run's files are replaced, those this run does not write
    are removed, the user's own file is kept, nothing temporary is left."""
    out = tmp_path / "o"
    before = previous_run(command, out)
    assert main(argv(command, inputs, out)) == 0
    after = digests(out)
    assert after["my_notes.txt"] == before["my_notes.txt"] and left(out) == []
    assert not set(after.items()) & {(k, v) for k, v in before.items() if k != "my_notes.txt"}
