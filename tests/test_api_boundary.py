"""Every public function checks its arguments' types where it is called, before any work
(gatetherm.api.boundary): a class of defects, not a list of cases (issue 55's audits found path
arguments going to ``os.fspath``, callbacks called only after the work, strings read letter by
letter where a list belongs)."""
from __future__ import annotations

import inspect
import math
import os
import typing
from pathlib import Path
from typing import Callable, Literal, Sequence

import pytest

import gatetherm as gt
import gatetherm.api as api
from gatetherm import InputError
from gatetherm.api.boundary import checked, describe, hint_of

FUNCTIONS = sorted(n for n in api.__all__ if inspect.isfunction(getattr(api, n)))


def unchecked(fn) -> list[str]:
    """The parameters of ``fn`` that neither an annotation nor a convention checks."""
    fn = inspect.unwrap(fn)
    hints = typing.get_type_hints(fn, include_extras=True)
    return [p.name for p in inspect.signature(fn).parameters.values()
            if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD) and hint_of(p, hints) is None]


@pytest.mark.parametrize("name", FUNCTIONS)
def test_every_public_function_checks_every_parameter(name):
    fn = getattr(api, name)
    assert getattr(fn, "__checked__", False), f"gt.{name} is not wrapped by gatetherm.api.boundary.checked"
    assert not unchecked(fn), f"gt.{name}: annotate {unchecked(fn)} (or follow a convention of CONVENTIONS)"
    assert getattr(gt, name) is fn  # the top-level name is the checked one


def test_the_walk_sees_an_unannotated_parameter():
    def f(case, out, on_done=None, n: int = 1):
        return case

    assert unchecked(f) == ["case"]  # out and on_done: by convention


@pytest.mark.parametrize("name", FUNCTIONS)
def test_a_wrong_type_is_refused_by_name_before_any_work(name):
    """Every required argument (or, with none, the first) an ``object()``: the first is named,
    and nothing ran."""
    fn = getattr(api, name)
    given = [p for p in inspect.signature(fn).parameters.values() if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]
    params = [p for p in given if p.default is p.empty] or given[:1]
    args = {p.name: object() for p in params}
    with pytest.raises(TypeError, match=rf"^{params[0].name}: got object <object object at 0x[0-9a-f]+>, expected "):
        fn(**args)


def test_the_audits_cases_are_named(tmp_path):
    """Cases of the third audit, each now one line naming the argument."""
    cases = [
        (lambda: gt.sweep(5, "o"), TypeError, "study: got int 5, expected a str or path"),
        (lambda: gt.report(5), TypeError, "out: got int 5, expected a str or path"),
        (lambda: gt.drift_report("em.csv", 5), TypeError, "out: got int 5, expected a str or path"),
        (lambda: gt.report("o", sections="paper"), TypeError, "sections: got str 'paper', expected a list of str or None"),
        (lambda: gt.report("o", sections=["beam"], on_section=5), TypeError, "on_section: got int 5, expected a function"),
        (lambda: gt.validate("beam", "o", on_line=5), TypeError, "on_line: got int 5, expected a function or None"),
        (lambda: gt.simulate(1, effects="coolant"), TypeError, "effects: got str 'coolant', expected a list of str"),
        (lambda: gt.compensate_run(condition=1, ideal="yes"), TypeError, "ideal: got str 'yes', expected a bool"),
        (lambda: gt.compensate_run(condition=1, interval_min=math.nan), InputError, "interval_min: got nan, must be a finite"),
        (lambda: gt.export_case(time="10"), TypeError, "time: got str '10', expected a number or None"),
    ]
    for call, kind, start in cases:
        with pytest.raises(kind) as info:
            call()
        assert str(info.value).startswith(start), str(info.value)
    assert not list(tmp_path.iterdir()) and not Path("o").exists()


def test_settings_are_checked_by_their_fields_types():
    """``**settings`` of place_sensors, compensate and diagnose: named and typed by their
    dataclass's fields (``states=6.5`` reached a slice)."""
    case = gt.gate_frame()
    with pytest.raises(InputError, match=r"^states: got 6.5, must be a whole number; give a whole number$"):
        gt.place_sensors(case, states=6.5)
    with pytest.raises(TypeError, match=r"^nope: is not a setting of diagnose; settings: "):
        gt.diagnose(case, "m.csv", nope=1)
    with pytest.raises(TypeError, match=r"^train_fraction: got str '0.5', expected a number$"):
        gt.diagnose(case, "m.csv", train_fraction="0.5")


def test_the_checker_on_each_kind_of_annotation():
    @checked
    def f(path: str | os.PathLike, names: Sequence[str] = (), n: int = 1, x: float = 1.0, y: float = math.inf,
          how: Literal["a", "b"] = "a", on_step: Callable | None = None, flag: bool = False):
        return path, names, n, x, y, how

    assert f(Path("p"), ["a"], 2.0, 1, math.inf, "b", print, True)[2] == 2.0  # a whole float counts as int
    for kwargs, kind, text in [
            ({"path": b"p"}, TypeError, "path: got bytes b'p', expected a str or path"),
            ({"names": "ab"}, TypeError, "names: got str 'ab', expected a list of str"),
            ({"names": ["a", 1]}, TypeError, "names: got list ['a', 1], expected a list of str"),
            ({"n": 2.5}, InputError, "n: got 2.5, must be a whole number"),
            ({"n": True}, TypeError, "n: got bool True, expected a whole number"),
            ({"x": math.nan}, InputError, "x: got nan, must be a finite number"),
            ({"x": math.inf}, InputError, "x: got inf, must be a finite number"),
            ({"how": "c"}, InputError, "how: got 'c'; choose one of 'a', 'b'"),
            ({"on_step": 5}, TypeError, "on_step: got int 5, expected a function or None"),
            ({"flag": "yes"}, TypeError, "flag: got str 'yes', expected a bool"),
            ({"nope": 1}, TypeError, "f: got an unexpected keyword argument 'nope'")]:
        with pytest.raises(kind) as info:
            f(**{"path": "p", **kwargs})
        assert str(info.value) == text or str(info.value).startswith(text), str(info.value)
    assert f("p", y=math.inf)[4] == math.inf  # an infinite default admits infinity
    assert describe(str | os.PathLike | None) == "a str or path or None"
