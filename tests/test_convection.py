"""Films from correlations (solvers/convection.py): each correlation's h against its formula at
three operating points, radiation against Stefan–Boltzmann, a steady block's energy balance with
temperature-dependent films, and a radiating plate's cooling against the ODE."""
from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import gatetherm as gt
from gatetherm import InputError
from gatetherm.solvers import convection as cv
from gatetherm.solvers.expr import Value
from gatetherm.solvers.heat import HeatSolver
from gatetherm.solvers.model import build

DATA = Path(__file__).resolve().parent / "data"
POINTS = [(45.0, 20.0, 0.3), (80.0, 25.0, 1.2), (21.0, 20.0, 0.05)]
"""(surface °C, ambient °C, length m)."""


def props(Tf):
    """Air by hand: ideal gas, Sutherland for μ and k."""
    T = Tf + 273.15
    mu = 1.716e-5 * (T / 273.15) ** 1.5 * (273.15 + 110.4) / (T + 110.4)
    k = 0.0241 * (T / 273.15) ** 1.5 * (273.15 + 194.0) / (T + 194.0)
    nu = mu / (101325.0 / (287.05 * T))
    return k, nu, mu * 1006.0 / k, 1.0 / T


def test_air_at_20_degC_is_the_tables():
    k, nu, pr, beta = cv.air(20.0)
    assert k == pytest.approx(0.025695, abs=1e-6)  # band: tables 0.0257 within 2 %
    assert nu == pytest.approx(1.5059e-5, abs=1e-9)  # band: tables 1.51e-5 within 2 %
    assert pr == pytest.approx(0.70995, abs=1e-5)  # band: tables 0.71 within 2 %
    assert abs(k / 0.0257 - 1) < 0.02 and abs(nu / 1.51e-5 - 1) < 0.02 and abs(pr / 0.71 - 1) < 0.02


@pytest.mark.parametrize("Ts, Ta, L", POINTS)
def test_natural_convection_is_its_formula(Ts, Ta, L):
    Tf, dT = 0.5 * (Ts + Ta), Ts - Ta
    k, nu, pr, beta = props(Tf)
    ra = 9.80665 * beta * dT * L ** 3 * pr / nu ** 2
    cc = (0.825 + 0.387 * ra ** (1 / 6) / (1 + (0.492 / pr) ** (9 / 16)) ** (8 / 27)) ** 2 * k / L
    assert cv.FilmLaw("vertical_plate", length=L)(Ts, Ta, {}) == pytest.approx(cc, rel=1e-9)
    up = (0.54 * ra ** 0.25 if ra <= 1e7 else 0.15 * ra ** (1 / 3)) * k / L
    assert cv.FilmLaw("horizontal_up", length=L)(Ts, Ta, {}) == pytest.approx(up, rel=1e-9)
    assert cv.FilmLaw("horizontal_down", length=L)(Ts, Ta, {}) == pytest.approx(0.52 * ra ** 0.2 * k / L, rel=1e-9)
    # a cold upper face is the hot-down case
    assert cv.FilmLaw("horizontal_up", length=L)(Ta - dT, Ta, {}) == pytest.approx(
        0.52 * (9.80665 / (0.5 * (2 * Ta - dT) + 273.15) * dT * L ** 3 * props(Ta - dT / 2)[2]
                / props(Ta - dT / 2)[1] ** 2) ** 0.2 * props(Ta - dT / 2)[0] / L, rel=1e-9)


@pytest.mark.parametrize("n, D", [(500.0, 0.08), (6000.0, 0.12), (24000.0, 0.05)])
def test_rotating_parts_are_their_formulas(n, D):
    Ts, Ta = 35.0, 20.0
    k, nu, pr, beta = props(27.5)
    w = 2 * math.pi * n / 60
    re = w * D ** 2 / nu
    law = cv.FilmLaw("rotating_cylinder", length=D, speed=Value.of("n"))
    assert law(Ts, Ta, {"n": n}) == pytest.approx(0.133 * re ** (2 / 3) * pr ** (1 / 3) * k / D, rel=1e-9)
    r = D / 2
    red = w * r ** 2 / nu
    disc = (0.36 * red ** 0.5 if red < 2.4e5 else 0.015 * red ** 0.8) * k / r
    law = cv.FilmLaw("rotating_disc", length=D, speed=Value.of("n"))
    assert law(Ts, Ta, {"n": -n}) == pytest.approx(disc, rel=1e-9)


@pytest.mark.parametrize("v, L", [(0.5, 0.3), (3.0, 0.8), (20.0, 1.5)])
def test_flow_along_a_plate_is_its_formula(v, L):
    k, nu, pr, beta = props(30.0)
    re = v * L / nu
    nu_l = 0.664 * re ** 0.5 if re <= 5e5 else 0.037 * re ** 0.8 - 871.0
    law = cv.FilmLaw("flat_plate", length=L, speed=Value(v))
    assert law(40.0, 20.0, {}) == pytest.approx(nu_l * pr ** (1 / 3) * k / L, rel=1e-9)


@pytest.mark.parametrize("Ts, Ta", [(60.0, 20.0), (300.0, 15.0), (5.0, 30.0)])
def test_linearised_radiation_exchanges_the_stefan_boltzmann_heat(Ts, Ta):
    h = cv.FilmLaw(h=4.0, emissivity=0.8)(Ts, Ta, {})
    q = 4.0 * (Ts - Ta) + 0.8 * cv.SIGMA * ((Ts + 273.15) ** 4 - (Ta + 273.15) ** 4)
    assert h * (Ts - Ta) == pytest.approx(q, rel=1e-12)


STEADY = """
[mesh]
file = "two_names.geo"
[materials.plate]
k = 15.0
thickness = 0.05
[sources.plate]
power = 150.0
[thermal.free]
film = {{ correlation = "vertical_plate", length = 1.0 }}
emissivity = 0.6
ambient = 20.0
[thermal.tank_wall]
film = {{ correlation = "horizontal_down", length = 0.5 }}
ambient = 20.0
[thermal.base]
film = 3.0
emissivity = 0.9
ambient = 20.0
[probes.corner]
point = "corner"
{time}"""


def _case(tmp_path, text):
    shutil.copy(DATA / "two_names.geo", tmp_path)
    (tmp_path / "c.toml").write_text(text)
    return gt.load_case(tmp_path / "c.toml")


def test_steady_block_with_correlation_films_balances_its_energy(tmp_path):
    """The source's 150 W leave through the three films at the coefficients of the final state."""
    case = _case(tmp_path, STEADY.format(time=""))
    model = build(case.problem, case.mesh)
    sys = model.heat
    U = HeatSolver(sys).steady({"t": 0.0})
    out = sum(v.h(U, {}) * (v.a @ U[:len(v.a)] - v.a.sum() * 20.0) for v in sys.varying)
    assert len(sys.varying) == 3
    err = abs(out / 150.0 - 1)
    print(f"energy balance {err:.2e}, hot spot {float(U.max()):.3f} °C")
    assert err < 1e-9  # band: < 1e-9
    assert float(U.max()) == pytest.approx(129.806, abs=0.01)  # the hot spot, °C


def test_radiating_plate_cools_as_the_ode(tmp_path):
    """A conductive plate radiating from its edges (ε = 1, no convection): uniform, it follows
    ρ c V dT/dt = −ε σ A (T⁴ − Ta⁴); Crank–Nicolson with Picard iterations per step."""
    text = STEADY.split("[sources.plate]")[0].replace("k = 15.0", "k = 1e6\nrho = 1.0\nc = 1e4") + \
        '[initial]\ntemperature = 200.0\n[thermal.free]\nfilm = 0.0\nemissivity = 1.0\nambient = 20.0\n' \
        '[thermal.tank_wall]\nfilm = 0.0\nemissivity = 1.0\nambient = 20.0\n' \
        '[thermal.base]\nfilm = 0.0\nemissivity = 1.0\nambient = 20.0\n[probes.corner]\npoint = "corner"\n' \
        '[time]\nend = 600.0\nstep = 10.0\noutput = 60.0\n'
    run = gt.run(_case(tmp_path, text))
    rate = 4 * 0.05 / (1e4 * 0.05)  # edge area / (ρ c V)
    ode = solve_ivp(lambda t, T: -rate * cv.SIGMA * ((T + 273.15) ** 4 - 293.15 ** 4), (0, 600), [200.0],
                    t_eval=run.time, rtol=1e-12, atol=1e-12)
    err = np.max(np.abs(run["T_corner_degC"] - ode.y[0]))
    print(f"radiating plate: {err:.4f} K off the ODE, fell {200 - run['T_corner_degC'][-1]:.1f} K")
    assert err == pytest.approx(0.0186, abs=0.002)  # K; band: < 0.05 K of a 155-K fall


def test_correlation_film_is_refused_by_the_reduced_model_and_bad_tables_are_one_line(tmp_path):
    case = _case(tmp_path, STEADY.format(time=""))
    with pytest.raises(InputError, match="film of 'free'.*reduced model"):
        from gatetherm.solvers.rom import linear_heat_model
        from gatetherm.studies.run.simulate import column
        linear_heat_model(build(case.problem, case.mesh), column)
    bad = STEADY.format(time="").replace('correlation = "vertical_plate", length = 1.0',
                                         'correlation = "vertical_plate", length = 1.0, speed = 3.0')
    with pytest.raises(InputError, match="thermal.free.film.speed"):
        _case(tmp_path, bad)
    bad = STEADY.format(time="").replace('correlation = "vertical_plate", length = 1.0',
                                         'correlation = "rotating_disc", length = 0.2, speed = "n"')
    with pytest.raises(InputError, match="thermal.free.film"):
        _case(tmp_path, bad)


def test_a_correlations_factor_scales_its_convective_part_and_is_a_diagnosis_parameter(tmp_path):
    """``factor`` multiplies the correlation before its floor; a diagnosis offers ``film_BOUNDARY`` as
    that factor, its reference scaled with it (a new user's nose film had no hypothesis)."""
    law = cv.FilmLaw("vertical_plate", length=1.0, emissivity=0.5, minimum=1.0)
    twice = cv.FilmLaw("vertical_plate", length=1.0, emissivity=0.5, minimum=1.0, factor=2.0)
    rad = float(cv.radiation(0.5, 60.0, 20.0))
    assert twice(60.0, 20.0, {}) - rad == pytest.approx(2 * (law(60.0, 20.0, {}) - rad), rel=1e-14)
    assert cv.FilmLaw("vertical_plate", length=1.0, minimum=50.0, factor=2.0)(60.0, 20.0, {}) == 50.0
    from gatetherm.studies.run.parameters import case_parameters

    case = _case(tmp_path, STEADY.format(time="").replace('length = 1.0 }', 'length = 1.0, factor = 1.5 }', 1))
    p = next(p for p in case_parameters(case) if p.name == "film_free")
    assert (p.param, p.value, p.lo, p.hi) == ("factor", 1.5, pytest.approx(0.6), pytest.approx(3.75))
    ref = next(f.h for f in case.problem.films if f.boundary == "free")
    moved = case.with_overrides(p.overrides(3.0))
    film = next(f for f in moved.problem.films if f.boundary == "free")
    assert film.law.factor == 3.0 and film.h == pytest.approx(2 * ref, rel=1e-12)
