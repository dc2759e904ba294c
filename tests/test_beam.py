"""Beam theory (paper section 3.1): closed forms, branches, limits, findings, CLI, plots."""
from __future__ import annotations

import json
import warnings

import numpy as np
import pytest
from scipy.optimize import brentq, minimize_scalar

from gatetherm import InputError
from gatetherm.frame import beam
from gatetherm.frame.beam import BeamModel, coefficients, delta, normalised, tie_force

BETAS = (0.01, 0.03, 0.1, 0.3, 1.0)

# FC300-like column and tie bar of the same material; l1 = l/2 (the paper's normalisation).
E, I, ALPHA = 1.2e11, 2.0e-4, 1.1e-5
L, H, L_C = 0.8, 0.3, 1.3


def same_material(a, b, l1=None, **kw) -> BeamModel:
    """Model with l/l4 = a and eq (26) beta = b (A_C solved from beta)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    with np.errstate(divide="ignore"):
        a_c = 3.0 * I * L_C / (b * L**3)
    fields = dict(l=L, l1=L / 2 if l1 is None else l1, l4=L / a, h=H, EI=E * I, alpha=ALPHA,
                  l_C=L_C, A_C=a_c, E_C=E, alpha_C=ALPHA)
    return BeamModel(**{**fields, **kw})


# Hand example, middle branch l1 <= l4 <= l, different materials:
#   k_m = 3 EI / l4^3 = 3*2e6/0.125 = 4.8e7 N/m,  k_C = A_C E_C / l_C = 6e-4*2e11/1 = 1.2e8 N/m
#   k_m/k_C = 0.4,  D = 2.4
#   K_i = alpha/(2h) [l1(2l-l1) - l1(3l-l4)(2l4-l1)/(l4 D)]
#       = 1e-5/0.5 * [0.4*1.6 - 0.4*2.5*0.6/(0.5*2.4)] = 2e-5 * (0.64 - 0.5) = 2.8e-6 m/K
#   K_C = (3l-l4)/(l4 D) l_C alpha_C = 2.5/1.2 * 1 * 1.2e-5 = 2.5e-5 m/K
#   dtheta_AB = 3 K, theta_C = 0.5 K:
#   P = [l1(2l4-l1) alpha dtheta/(2h) + alpha_C theta_C l_C] / (1/k_C + 2/k_m)
#     = [0.4*0.6*1e-5*3/0.5 + 1.2e-5*0.5] / (1/1.2e8 + 1/2.4e7) = 2.04e-5 / 5e-8 = 408 N
#   delta = 3*2.8e-6 - 0.5*2.5e-5 = -4.1e-6 m;  M_h = EI alpha dtheta / h = 2e6*1e-5*3/0.25 = 240 N m
HAND = BeamModel(l=1.0, l1=0.4, l4=0.5, h=0.25, EI=2e6, alpha=1e-5,
                 l_C=1.0, A_C=6e-4, E_C=2e11, alpha_C=1.2e-5)


def test_hand_values():
    k_i, k_c = coefficients(HAND)
    assert k_i == pytest.approx(2.8e-6, rel=1e-13)
    assert k_c == pytest.approx(2.5e-5, rel=1e-13)
    assert tie_force(HAND, 3.0, 0.5) == pytest.approx(408.0, rel=1e-13)
    assert delta(HAND, 3.0, 0.5) == pytest.approx(-4.1e-6, rel=1e-12)
    assert beam.thermal_moment(2e6, 1e-5, 3.0, 0.25) == pytest.approx(240.0, rel=1e-15)
    # normalised, a = 2, beta = 0.1: D = 2.8, Ki = 1 - 4*5/(3*4*2.8) = 17/42, Kc = 5/2.8 = 25/14
    # a = 0.5, beta = 1: D = 2.125, Ki = 1 - 0.5*2.5*3.5/(3*2.125) = 16/51, Kc = 0.25*2.5/2.125 = 5/17
    np.testing.assert_allclose(normalised([2.0, 0.5], [0.1, 1.0]),
                               [[17 / 42, 16 / 51], [25 / 14, 5 / 17]], rtol=1e-15)


def test_general_reproduces_normalised():
    a = np.union1d(np.linspace(0.2, 6.0, 233), [1.0, 2.0])[:, None]
    b = np.array(BETAS)[None, :]
    m = same_material(a, b)
    np.testing.assert_allclose(beam.beta(I, L_C, m.A_C, L), np.broadcast_to(b, m.A_C.shape), rtol=1e-14)
    np.testing.assert_allclose(beam.k_m(m.EI, m.l4) / beam.k_C(m.l_C, m.A_C, m.E_C), b * a**3, rtol=1e-13)
    k_i, k_c = coefficients(m)
    ki_n, kc_n = normalised(a, b)
    assert k_i.shape == k_c.shape == (a.size, len(BETAS))
    # atol: Ki crosses zero for beta = 0.01, where only absolute round-off is meaningful
    np.testing.assert_allclose(k_i / beam.ki_scale(ALPHA, L, H), ki_n, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(k_c / beam.kc_scale(ALPHA, L_C), kc_n, rtol=1e-12)
    back = beam.denormalise(ki_n, kc_n, ALPHA, L, H, L_C)
    np.testing.assert_allclose(back[0], k_i, rtol=1e-12, atol=1e-14 * beam.ki_scale(ALPHA, L, H))
    np.testing.assert_allclose(back[1], k_c, rtol=1e-12)


def test_branch_formulas_equal_at_the_joints():
    l, l1 = np.array([1.0, 0.8, 2.3]), np.array([0.5, 0.37, 1.1])
    (x22, x23, _), _ = beam._branch_terms(l, l1, l1)  # l4 = l1
    np.testing.assert_allclose(x22, x23, rtol=1e-15)
    (_, x23, x24), (r22, r24) = beam._branch_terms(l, l1, l)  # l4 = l
    np.testing.assert_allclose(x23, x24, rtol=1e-15)
    np.testing.assert_allclose(r22, r24, rtol=1e-15)
    # dyadic lengths: bit-for-bit equal
    (x22, x23, _), _ = beam._branch_terms(1.0, 0.5, 0.5)
    (_, y23, y24), (r22, r24) = beam._branch_terms(1.0, 0.5, 1.0)
    assert (x22, y23, r22) == (x23, y24, r24)
    for a_joint, (i, j) in ((2.0, (0, 1)), (1.0, (1, 2))):
        br = beam._normalised_branches(a_joint, np.array(BETAS))
        np.testing.assert_array_equal(br[i][0], br[j][0])
        np.testing.assert_array_equal(br[i][1], br[j][1])


@pytest.mark.parametrize("eps", [1e-7, 1e-9])
def test_branches_continuous_either_side(eps):
    b = np.array(BETAS)
    # compared in normalised units (values O(1)), absolutely: Ki_norm(1) = beta/(beta+2) is small
    for a_joint in (1.0, 2.0):  # l4 = l and l4 = l1 = l/2
        sides = [same_material(a_joint * (1 + s * eps), b) for s in (-1, 1)]
        general = [np.array(coefficients(m)) / np.array([[beam.ki_scale(ALPHA, L, H)],
                                                        [beam.kc_scale(ALPHA, L_C)]]) for m in sides]
        norm = [np.array(normalised(a_joint * (1 + s * eps), b)) for s in (-1, 1)]
        for lo, hi in (general, norm):
            np.testing.assert_allclose(lo, hi, rtol=0, atol=20 * eps)
    # general model with l1 != l/2 and different materials, around l4 = l1 and l4 = l
    for l4 in (0.3, 1.0):
        ms = [BeamModel(l=1.0, l1=0.3, l4=l4 * (1 + s * eps), h=0.2, EI=3e6, alpha=1.1e-5, l_C=1.2,
                        A_C=4e-4, E_C=2.1e11, alpha_C=1.2e-5) for s in (-1, 1)]
        np.testing.assert_allclose(coefficients(ms[0]), coefficients(ms[1]), rtol=20 * eps)


def test_no_tie_bar_exact():
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no division-by-zero warnings
        m = BeamModel(l=1.0, l1=np.array([0.3, 0.5, 1.0]), l4=np.array([0.2, 0.7, 1.5]), h=0.2,
                      EI=3e6, alpha=1.1e-5, l_C=1.2, A_C=0.0, E_C=2.1e11, alpha_C=1.2e-5)
        k_i, k_c = coefficients(m)
        np.testing.assert_array_equal(k_c, 0.0)
        np.testing.assert_array_equal(k_i, 1.1e-5 * m.l1 * (2 * 1.0 - m.l1) / (2 * 0.2))
        np.testing.assert_array_equal(tie_force(m, 4.0, 2.0), 0.0)
        assert beam.beta(I, L_C, 0.0, L) == np.inf
        np.testing.assert_array_equal(normalised([0.3, 1.5, 3.0], np.inf), [[1, 1, 1], [0, 0, 0]])


def test_far_tie_bar_limits():
    ratio = 10.0 ** np.arange(2, 7)  # l4 / l
    m = same_material(1 / ratio, 0.1)
    k_i, k_c = coefficients(m)
    assert np.all(np.diff(k_c) < 0) and k_c[-1] < 1e-16
    # errors of the asymptotes shrink like l/l4: K_C -> (3 l^2/(2 l4^2)) l_C alpha_C since D -> 2,
    # K_i -> alpha l1 (2l - l1)/(2h) (no tie bar); normalised: Kc_norm -> 1.5/ratio^2, Ki_norm -> 1
    ki_n, kc_n = normalised(1 / ratio, 0.1)
    for value, limit, bound in ((k_c * ratio**2 / (L_C * ALPHA), 1.5, 1.0),
                                (k_i / (ALPHA * (L / 2) * (1.5 * L) / (2 * H)), 1.0, 3.0),
                                (kc_n * ratio**2, 1.5, 1.0), (ki_n, 1.0, 3.0)):
        assert np.all(np.abs(value - limit) * ratio < bound)


def _ki(b):
    return lambda a: float(normalised(a, b)[0])


def test_ki_near_zero_between_0p7_and_1p3():
    # Ki_norm = 0 on 1 <= a <= 2 <=> (4 - 3a)(a - 1) = 3 beta a^4: roots only in (1, 4/3), and they
    # exist only for beta <= beta* = max of (4-3a)(a-1)/(3a^4), at a* = (21 - sqrt 57)/12.
    a_star = (21 - np.sqrt(57)) / 12
    beta_star = (4 - 3 * a_star) * (a_star - 1) / (3 * a_star**4)
    assert beta_star == pytest.approx(0.0162698, abs=1e-7)
    assert _ki(0.99 * beta_star)(a_star) < 0 < _ki(1.01 * beta_star)(a_star)
    minima = {}
    for b in (0.01, 0.03, 0.1):
        res = minimize_scalar(_ki(b), bounds=(0.7, 1.3), method="bounded", options={"xatol": 1e-10})
        minima[b] = (res.x, res.fun)
        assert 0.7 < res.x < 1.3 and _ki(b)(0.7) > res.fun < _ki(b)(1.3)
        assert abs(res.fun) < 0.05 and _ki(b)(0.2) > 0.5 and _ki(b)(6.0) > 0.5
    # beta = 0.01 < beta*: Ki_norm really crosses zero, twice, inside (0.7, 1.3)
    roots = [brentq(_ki(0.01), 0.7, minima[0.01][0], xtol=1e-14),
             brentq(_ki(0.01), minima[0.01][0], 1.3, xtol=1e-14)]
    np.testing.assert_allclose(roots, [1.0398333571759666, 1.2342671865726837], rtol=1e-11)
    for r in roots:
        assert (4 - 3 * r) * (r - 1) == pytest.approx(3 * 0.01 * r**4, rel=1e-11)
    # beta = 0.03, 0.1 > beta*: only a positive minimum ("near zero", as the paper says)
    np.testing.assert_allclose([minima[b][1] for b in (0.01, 0.03, 0.1)],
                               [-0.0044538244450, 0.0091717791227, 0.0474507861790], rtol=1e-8)
    np.testing.assert_allclose([minima[b][0] for b in (0.01, 0.03, 0.1)],
                               [1.1329952891, 1.0972935361, 1.0149404759], rtol=1e-7)


def test_kc_single_maximum_moves_out_as_beta_drops():
    a = np.geomspace(1e-3, 40.0, 40001)
    peaks = []
    for b in BETAS:
        kc = normalised(a, b)[1]
        assert kc[0] < 1e-5 and np.count_nonzero(np.diff(np.sign(np.diff(kc)))) == 1
        # on a >= 1, dKc/da = 0 <=> 2 beta a^3 - beta a^2 - 2 = 0, and there Kc = 1/(beta a^2) = a - 1/2
        a_max = brentq(lambda x: 2 * b * x**3 - b * x**2 - 2, 1.0, 50.0, xtol=1e-14)
        assert a[np.argmax(kc)] == pytest.approx(a_max, rel=3e-4)
        np.testing.assert_allclose(normalised(a_max, b)[1], [a_max - 0.5, 1 / (b * a_max**2)], rtol=1e-13)
        peaks.append((a_max, a_max - 0.5))
    np.testing.assert_allclose(np.array(peaks)[:, 0],
                               [4.8143831076, 3.3938929601, 2.3346552731, 1.6804273491, 1.1974293369],
                               rtol=1e-9)
    assert np.all(np.diff(np.array(peaks), axis=0) < 0)  # smaller beta: larger, further out


def _frame_fe(m: BeamModel, dtheta_AB: float, theta_C: float) -> tuple[float, float]:
    """Reference: Hermite-cubic FE of the two clamped columns plus a bar spring at l4.

    Nodal values are exact for Euler-Bernoulli beams with nodes at l1, l4 and l. The
    thermal curvature enters as the consistent load M_h * [0, -1, 0, 1] per heated element.
    Unknowns per column: (v, v') at each node, v positive towards the other column.
    Returns (P, delta) with P the compressive bar force.
    """
    z = np.unique([0.0, m.l1, m.l4, m.l])
    n = z.size
    K, f = np.zeros((4 * n, 4 * n)), np.zeros(4 * n)
    m_h = beam.thermal_moment(m.EI, m.alpha, dtheta_AB, m.h)
    for col in (0, 1):
        for e in range(n - 1):
            le = z[e + 1] - z[e]
            c, s = 6 * le, 2 * le**2
            ke = m.EI / le**3 * np.array([[12, c, -12, c], [c, 2 * s, -c, s],
                                          [-12, -c, 12, -c], [c, s, -c, 2 * s]])
            dofs = 2 * n * col + 2 * e + np.arange(4)
            K[np.ix_(dofs, dofs)] += ke
            if col == 0 and z[e + 1] <= m.l1:
                f[dofs] += m_h * np.array([0.0, -1.0, 0.0, 1.0])
    i4 = 2 * int(np.searchsorted(z, m.l4))
    bar = [i4, 2 * n + i4]
    kc, stretch = beam.k_C(m.l_C, m.A_C, m.E_C), m.alpha_C * theta_C * m.l_C
    K[np.ix_(bar, bar)] += kc
    f[bar] -= kc * stretch
    free = np.setdiff1d(np.arange(4 * n), [0, 1, 2 * n, 2 * n + 1])
    u = np.zeros(4 * n)
    u[free] = np.linalg.solve(K[np.ix_(free, free)], f[free])
    il = 2 * int(np.searchsorted(z, m.l))
    return kc * (u[bar[0]] + u[bar[1]] + stretch), u[il] + u[2 * n + il]


@pytest.mark.parametrize("l1, l4, a_c", [(0.6, 0.4, 5e-4), (0.6, 0.55, 5e-4), (0.6, 0.6, 5e-4),
                                         (0.3, 0.7, 2e-4), (0.3, 1.0, 8e-4), (0.5, 1.4, 5e-4),
                                         (0.5, 0.8, 0.0)])
def test_against_direct_compatibility_solve(l1, l4, a_c):
    m = BeamModel(l=1.0, l1=l1, l4=l4, h=0.2, EI=3e6, alpha=1.1e-5, l_C=1.2, A_C=a_c,
                  E_C=2.1e11, alpha_C=1.7e-5)
    for dth, th_c in ((2.0, 0.0), (0.0, 1.5), (3.0, -0.7)):
        p_fe, d_fe = _frame_fe(m, dth, th_c)
        assert tie_force(m, dth, th_c) == pytest.approx(p_fe, rel=1e-9, abs=1e-9)
        assert delta(m, dth, th_c) == pytest.approx(d_fe, rel=1e-9, abs=1e-18)


@pytest.mark.parametrize("field, value", [("l", 0.0), ("h", -1.0), ("A_C", -1e-4), ("l1", 2.0),
                                          ("alpha", np.nan)])
def test_model_rejects_bad_fields(field, value):
    fields = dict(l=1.0, l1=0.5, l4=0.5, h=0.2, EI=3e6, alpha=1e-5, l_C=1.0, A_C=1e-4,
                  E_C=2e11, alpha_C=1e-5)
    with pytest.raises(InputError, match=f"^{field}: "):
        BeamModel(**{**fields, field: value})


@pytest.fixture
def cli(monkeypatch):
    """``studies.cli`` with only the beam command, independent of the other command modules."""
    from gatetherm import cli

    assert "beam" in cli.COMMAND_MODULES
    monkeypatch.setattr(cli, "COMMAND_MODULES", ("beam",))
    return cli


def test_cli_json_and_text(cli, capsys):
    assert cli.main(["beam", "--l-over-l4", "2", "--beta", "0.1", "--json"]) == 0
    out = capsys.readouterr().out
    assert json.loads(out) == pytest.approx({"Ki_norm": 17 / 42, "Kc_norm": 25 / 14}, rel=1e-15)
    assert out.count("\n") == 1
    assert cli.main(["beam", "--l-over-l4", "0.5", "--beta", "1"]) == 0
    out = capsys.readouterr().out.strip()
    assert "\n" not in out and "0.313725" in out and "0.294118" in out


@pytest.mark.parametrize("args, option", [(["--l-over-l4", "0", "--beta", "0.1"], "--l-over-l4"),
                                          (["--l-over-l4", "-1", "--beta", "0.1"], "--l-over-l4"),
                                          (["--l-over-l4", "1", "--beta", "-0.1"], "--beta"),
                                          (["--l-over-l4", "1", "--beta", "nan"], "--beta")])
def test_cli_bad_input(cli, capsys, args, option):
    assert cli.main(["beam", *args]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.startswith(f"gatetherm: error: {option}: ") and captured.err.count("\n") == 1


def test_plots_written(tmp_path):
    from gatetherm.validation.plots import save
    from gatetherm.validation.plots.beam import plot_ki_kc

    a = np.linspace(0.5, 5.0, 200)
    theory = {b: normalised(a, b) for b in BETAS}
    fa = np.array([0.8, 1.5, 3.0])
    fe = {b: (fa, *(v * 1.03 for v in normalised(fa, b))) for b in (0.01, 0.1)}
    for tag, fe_data in (("theory", None), ("fe", fe)):
        pk, pc = tmp_path / f"{tag}_ki.png", tmp_path / f"{tag}_kc.png"
        ki, kc = plot_ki_kc(a, theory, fe_data)
        # a theory line per beta, FE markers per beta with FE data, the zero line and the legend's keys
        assert len(ki.lines) == len(BETAS) + len(fe_data or {}) + 1 + (2 if fe_data else 1)
        assert ki.lines[0].get_ydata() == pytest.approx(theory[min(BETAS)][0])
        save(ki, pk)
        save(kc, pc)
        for p in (pk, pc):
            assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and p.stat().st_size > 10_000
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fe_kc.png", "fe_ki.png", "theory_kc.png",
                                                         "theory_ki.png"]  # no temp files left
