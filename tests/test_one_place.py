"""Each of the usual additions goes to one place (CONTRIBUTING.md, "Where a change goes"): a dummy
heat-source kind, compensation method, output format and command, each added in its one place
only, is found everywhere it belongs (the case reader, the API, the command line's choices, the
generated references whose tests then ask for the docs)."""
from __future__ import annotations

import dataclasses
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

import gatetherm as gt
from gatetherm.solvers import elements
from gatetherm.studies.control import method as methods
from gatetherm.studies.run import case_sources, formats

DATA = Path(__file__).resolve().parent / "data"
DOCS = Path(__file__).resolve().parents[1] / "docs"
BLOCK = """[mesh]
file = "two_names.geo"
[materials.plate]
k = 50.0
rho = 7800.0
c = 460.0
thickness = 0.1
[sources.plate]
kind = "heater"
watts = 12.5
[probes.corner]
point = "corner"
[time]
end = 120.0
step = 60.0
"""


@pytest.fixture
def heater(monkeypatch):
    """A heat-source kind registered in its one place, :data:`gatetherm.solvers.elements.KINDS`."""
    kind = elements.ElementKind("heater", ("watts",), lambda t, text: text("watts", "W"), order=60)
    monkeypatch.setitem(elements.KINDS, "heater", kind)
    return kind


def test_a_heat_source_kind_is_one_entry(heater, tmp_path):
    """Its keys are the case file's, a case heats at its loss, an unknown kind names it, and the
    docs check asks for its row (docs/case-file.md)."""
    from tests.test_docs import documented_keys

    assert case_sources.ELEMENT_KEYS["heater"] == ("watts",) and "watts" in case_sources.KEYS["sources.REGION"]
    shutil.copy(DATA / "two_names.geo", tmp_path)
    (tmp_path / "c.toml").write_text(BLOCK)
    run = gt.run(gt.load_case(tmp_path / "c.toml"))
    assert run["P_plate_W"].tolist() == [12.5] * 3  # the kind's loss, W, at every sample
    (tmp_path / "c.toml").write_text(BLOCK.replace('"heater"', '"gear"'))
    with pytest.raises(gt.InputError, match="motor, heater"):
        gt.load_case(tmp_path / "c.toml")
    documented = documented_keys((DOCS / "case-file.md").read_text(encoding="utf-8"))["sources.REGION"]
    assert "watts" not in documented  # test_docs' key check fails until the row is written


def doubled(job: methods.Job) -> methods.Batch:
    """The paper's batch form under another name, for the test."""
    from gatetherm.studies.control.method import paper

    return dataclasses.replace(paper.batch(job), head="doubled")


class Holding:
    """A stepper that never corrects (the test's)."""

    def __init__(self, setup):
        self.setup = setup


@pytest.fixture
def doubled_method(monkeypatch):
    """A compensation method registered in its one place, :func:`gatetherm.studies.control.method.register`."""
    methods.names()  # the shipped ones found first
    m = methods.Method("doubled", doubled, lambda setup: (Holding(setup), "holding"), order=25, summary="a test's")
    monkeypatch.setitem(methods._METHODS, "doubled", m)
    return m


def test_a_compensation_method_is_one_object(doubled_method):
    """The API's and both commands' choices offer it, the batch form runs it, ``live`` builds its
    stepper, and the command-line reference (docs/cli.md, checked by test_docs) lists it."""
    import gatetherm.api as api
    from gatetherm.api.live import _stepper
    from gatetherm.cli.reference import markdown
    from gatetherm.studies.control.compensator import CompensatorParams
    from gatetherm.studies.control.methods import METHODS, Settings, compensate
    from gatetherm.studies.run.timeseries import TimeSeries

    assert METHODS == ("paper", "mlr", "doubled", "rom", "errormodel") == api.METHODS
    assert api.COMPENSATION_METHODS == api.STEPWISE_METHODS == ("paper", "mlr", "doubled", "rom")
    k = np.arange(120.0)
    dth, thc = 5 * (1 - np.exp(-k / 5)), 0.1 * k
    ts = TimeSeries({"time_s": 60 * k, "theta_A_degC": 20 + dth, "theta_B_degC": np.full(k.size, 20.0),
                     "theta_C_degC": 20 + thc, "delta_um": 2.4 * dth - 0.8 * thc})
    ours, paper = (compensate(ts, None, Settings(m, Ki=2.0, Kc=1.0, force=True)) for m in ("doubled", "paper"))
    assert ours.summary["method"] == "doubled" and ours.head == "doubled"
    np.testing.assert_array_equal(ours.loop.delta_comp_um, paper.loop.delta_comp_um)
    stepper, label = _stepper(object(), "doubled", None, None, CompensatorParams(), 30, None, None)
    assert isinstance(stepper, Holding) and label == "holding"
    page = markdown()
    assert "`paper` \\| `mlr` \\| `doubled` \\| `rom`" in page and "doubled: a test's" in page


def export_state(case, schedule, t, title, on_step=None):
    """The dummy format's writer (this module): a one-line deck."""
    return f"{title}\n", {"element": "none", "nodes": 0, "relative_m": {"gap": 1e-6}, "time_s": t}


def test_an_output_format_is_one_writer_and_one_entry(heater, monkeypatch, tmp_path, capsys):
    """``gt.export_case(format=)`` writes it, ``gatetherm export`` offers and runs it, and the
    reference lists it."""
    from gatetherm.cli import main
    from gatetherm.cli.reference import markdown

    fmt = formats.Format("plain", "Plain", "a text file", __name__, "deck.txt", "cat deck.txt")
    monkeypatch.setitem(formats.FORMATS, "plain", fmt)
    shutil.copy(DATA / "two_names.geo", tmp_path)
    (tmp_path / "c.toml").write_text(BLOCK)
    res = gt.export_case(tmp_path / "c.toml", time=60.0, format="plain", out=tmp_path / "a")
    assert (tmp_path / "a/deck.txt").read_text() == "gatetherm " + str(tmp_path / "c.toml") + ", t = 1 min\n"
    assert res.summary().splitlines() == [f"wrote {tmp_path / 'a'}/deck.txt (none, 0 nodes) and gatetherm.json; "
                                          f"run: cd {tmp_path / 'a'} && cat deck.txt", "gatetherm gap: 1 um"]
    assert main(["export", "plain", str(tmp_path / "c.toml"), "--time", "1", "--out", str(tmp_path / "b")]) == 0
    assert sorted(p.name for p in (tmp_path / "b").iterdir()) == ["deck.txt", "gatetherm.json"]
    assert "gatetherm gap: 1 um" in capsys.readouterr().out
    assert "(ccx: CalculiX input deck, plain: a text file)" in markdown()  # test_docs: regenerate docs/cli.md


API_MODULE = '''PUBLIC = ("hello",)


def hello(name: str) -> str:
    """Greet ``name`` (a test's task).

    Parameters
    ----------
    name : str
        Whom.

    Returns
    -------
    str
    """
    return f"hello, {name}"
'''
CLI_MODULE = '''ORDER = 15


def register(sub) -> None:
    p = sub.add_parser("hello", help="greet (a test's command)", description="Greet.")
    p.add_argument("name", help="whom")
    p.set_defaults(func=run)


def run(args) -> int:
    import gatetherm.api as gt

    print(gt.hello(args.name))
    return 0
'''


def test_a_command_is_its_task_module_and_its_command_module(monkeypatch, tmp_path, capsys):
    """``core/api/hello.py`` and ``core/cli/hello.py`` (here in a folder of their own, on the packages'
    paths) are found: the API offers ``gt.hello`` (and ``gatetherm.API`` its name), ``gatetherm hello``
    runs it, in its ``ORDER``, and both references list it (test_docs then asks to regenerate them)."""
    import gatetherm.api as api
    import gatetherm.cli as cli
    from gatetherm.cli.api_reference import markdown as api_page
    from gatetherm.cli.reference import markdown as cli_page

    for side, text in (("api", API_MODULE), ("cli", CLI_MODULE)):
        (tmp_path / side).mkdir()
        (tmp_path / side / "hello.py").write_text(text)
    monkeypatch.setattr(api, "__path__", [*api.__path__, str(tmp_path / "api")])
    monkeypatch.setattr(cli, "__path__", [*cli.__path__, str(tmp_path / "cli")])
    try:
        where = gt._api_modules([*api.__path__])
        assert sorted(where) == sorted([*gt.API, "hello"]) and where["hello"] == "hello"
        assert "hello" in gt._api([*api.__path__])
        monkeypatch.setattr(api, "_WHERE", where)
        monkeypatch.setattr(api, "__all__", sorted(where))
        monkeypatch.setattr(cli, "COMMAND_MODULES", cli._commands())
        assert cli.COMMAND_MODULES[:3] == ("run", "hello", "mesh")
        assert cli.main(["hello", "world"]) == 0 and capsys.readouterr().out == "hello, world\n"
        assert api.hello.__checked__ and "hello" in dir(api)  # imported on first use, its arguments checked
        assert "## `gatetherm hello`" in cli_page() and "### `gt.hello(name: str) -> str`" in api_page()
    finally:
        monkeypatch.undo()
        for package in (api, cli):
            vars(package).pop("hello", None)  # the submodule the import set
            sys.modules.pop(f"{package.__name__}.hello", None)
