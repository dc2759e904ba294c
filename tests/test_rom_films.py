"""A reduced model of a case whose films follow the temperature (studies/run/reduce.py): each film
held at its law's mean over the case's own run, weighted by the wall's excess over the ambient
(solvers/convection.py, ``held_coefficient``), said with what it costs on that run."""
import shutil
from pathlib import Path

import numpy as np
import pytest

import gatetherm as gt
from gatetherm.solvers.convection import held_coefficient
from gatetherm.studies.run.reduce import check_run
from gatetherm.studies.run.scenario import run_scenario

SPINDLE = Path(__file__).resolve().parents[1] / "validation" / "examples" / "spindle_unit"
NOSE = ('film = { correlation = "rotating_cylinder", length = 0.065, speed = "n_spindle", reference = 40.0, '
        'minimum = 5.0 }')


def test_the_held_coefficient_weights_the_law_by_the_walls_excess():
    t, h = np.array([0.0, 1.0, 3.0]), np.array([1.0, 2.0, 3.0])
    # trapezoid weights 0.5, 1.5, 1.0; excess 0, 2, -1 (its size counts)
    assert held_coefficient(t, h, [0.0, 2.0, -1.0]) == pytest.approx((2 * 3.0 + 3 * 1.0) / 4.0, rel=1e-15)
    assert held_coefficient(t, h, np.zeros(3)) == pytest.approx((0.5 + 3.0 + 3.0) / 3.0, rel=1e-15)  # time mean
    assert held_coefficient([5.0], [7.0], [1.0]) == 7.0


def spindle(tmp_path, film=None) -> gt.Case:
    d = tmp_path / "spindle"
    shutil.copytree(SPINDLE, d, dirs_exist_ok=True)
    if film is not None:
        text = (d / "case.toml").read_text()
        assert NOSE in text
        (d / "case.toml").write_text(text.replace(NOSE, f"film = {film!r}"))
    return gt.load_case(d / "case.toml")


def test_a_correlation_film_is_held_at_its_runs_mean_and_the_cost_said(tmp_path):
    case = spindle(tmp_path)
    red = gt.reduce(case)
    print(f"spindle: nose held at {red.held['nose']:.2f} W/(m² K); {red.rom.notes[0]}")
    assert set(red.held) == {"nose"}
    assert red.held["nose"] == pytest.approx(124.44, abs=0.02)  # the law spans 5 ... 178 W/(m² K) over the run
    fe = run_scenario(case).result.columns
    err = check_run(red.rom, "own", fe).errors["delta_um"]
    assert err == pytest.approx(8.12, abs=0.02)  # µm of a 75.8-µm δ; held at the reference 40: 24.4 µm
    assert f"nose {red.held['nose']:.3g} W/(m² K) (the law 5 … 178 over the run); on that run delta_um is off the " \
           f"full model's by up to {err:.3g} µm (of 75.8 µm)" in red.rom.notes[0]
    assert red.rom.notes[0].startswith(f"{case.source}: the reduced model is linear: it holds each film")


@pytest.mark.slow
def test_the_held_coefficient_is_the_best_constant_of_a_grid(tmp_path):
    """The same case with the nose's film given as a number, reduced and run against the full model
    with the correlation: the held coefficient (about 124) is the best of the grid."""
    fe = run_scenario(spindle(tmp_path / "law")).result.columns
    errors = {}
    for h in (20.0, 40.0, 60.0, 80.0, 100.0, 124.0, 150.0):
        rom = gt.reduce(spindle(tmp_path / f"h{h:g}", h)).rom
        errors[h] = check_run(rom, "own", fe).errors["delta_um"]
        print(f"nose film {h:g} W/(m² K): max |δ_rom − δ_FE(law)| = {errors[h]:.2f} µm")
    assert min(errors, key=errors.get) == 124.0
    assert errors[124.0] == pytest.approx(8.08, abs=0.05) and errors[40.0] == pytest.approx(24.4, abs=0.1)


def test_the_note_is_kept_with_the_model_and_said_by_what_uses_it(tmp_path):
    """``rom.npz`` keeps the note; ``reduce`` prints it and a placement lists it first."""
    from gatetherm.studies.run.reduce import cached_rom

    case = spindle(tmp_path)
    first = cached_rom(case, 30, tmp_path)
    assert cached_rom(case, 30, tmp_path).notes == first.notes and len(first.notes) == 1
    done = gt.reduce_case(case, check_fe=False, out=tmp_path / "r")
    assert f"warning: {first.notes[0]}" in done.summary().splitlines()
    placed = gt.place_sensors(case, count=1)
    assert placed.notes[0] == first.notes[0]


def test_the_full_run_the_films_are_held_on_serves_the_check(tmp_path):
    """The case's own run, made to hold the films, is kept: checking the reduced model on that schedule
    runs the full model no second time."""
    from gatetherm.studies.run.reduce import build_rom, check
    from gatetherm.studies.run.scenario import ScenarioCache

    case, cache = spindle(tmp_path), ScenarioCache()
    rom = build_rom(case, 30, cache).rom
    assert cache.runs == 1
    [own] = check(case, rom, [case.schedule], cache)
    assert cache.runs == 1 and own.max_delta_error_um == pytest.approx(8.12, abs=0.02)
