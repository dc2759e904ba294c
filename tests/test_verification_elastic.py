"""Verification of the thermoelastic solver: plane-stress constants by hand, exact
patch cases to round-off, manufactured-solution convergence orders, and a clamped
slender bar against beam theory. Material: FC300 (E = 1.2e11 Pa, ν = 0.26,
α = 1.05e-5 1/K). Observed orders are printed in the session summary."""
from __future__ import annotations

import numpy as np
import pytest
from skfem.models.elasticity import plane_stress as skfem_plane_stress

from gatetherm.solvers.elasticity import moduli
from gatetherm.solvers.material import lame, lame_plane_stress, thermal_stress_modulus
from gatetherm.validation.verification import (BLOCK, SPATIAL_ELASTIC, at_point, block, clamped_bar_tip,
                                               component_values, dofs_where, elastic_mms_error, free_expansion,
                                               linear_temperature, spatial_study, thermoelastic_solve)

E, NU, ALPHA = 1.2e11, 0.26, 1.05e-5
L, H, D = BLOCK  # test block, m


def test_plane_stress_constants():
    # By hand, E = 1.2e11 Pa, ν = 0.26:
    #   plane stress  λ* = Eν/(1−ν²) = 3.12e10/0.9324 = 3.3462033462e10 Pa
    #                 μ  = E/(2(1+ν)) = 1.2e11/2.52  = 4.7619047619e10 Pa
    #   3-D           λ  = Eν/((1+ν)(1−2ν)) = 3.12e10/0.6048 = 5.1587301587e10 Pa
    #   thermal stress modulus  Eα/(1−ν) = 1.26e6/0.74 = 1.7027027027e6 Pa/K (plane stress)
    #                           Eα/(1−2ν) = 1.26e6/0.48 = 2.625e6 Pa/K (3-D)
    #   and 2(λ* + μ) α = Eα/(1−ν): the plane-stress modulus follows from λ*, μ.
    lam_ps, mu = 3.3462033462033462e10, 4.7619047619047619e10
    assert lame_plane_stress(E, NU) == pytest.approx((lam_ps, mu), rel=1e-14)
    assert lame(E, NU) == pytest.approx((5.158730158730159e10, mu), rel=1e-14)
    assert thermal_stress_modulus(E, NU, ALPHA, 2) == pytest.approx(1.7027027027027027e6, rel=1e-14)
    assert thermal_stress_modulus(E, NU, ALPHA, 3) == pytest.approx(2.625e6, rel=1e-14)
    assert 2 * (lam_ps + mu) * ALPHA == pytest.approx(thermal_stress_modulus(E, NU, ALPHA, 2), rel=1e-14)
    assert moduli(E, NU, ALPHA, 2) == pytest.approx((lam_ps, mu, 1.7027027027027027e6), rel=1e-14)
    # scikit-fem 12.0.2 takes (E, ν) here (older releases took Lamé parameters): same values
    assert skfem_plane_stress(E, NU) == pytest.approx((lam_ps, mu), rel=1e-14)


@pytest.mark.parametrize("dim, order", [(2, 1), (2, 2), (3, 1), (3, 2)])
def test_free_expansion(dim, order):
    """Uniform ΔT on a block held only against rigid motion: u = α ΔT x exactly
    (the length grows by α ΔT L) and no stress, to round-off."""
    e = free_expansion(dim, order)
    assert e["u"] < 1e-10 and e["tip"] < 1e-10 and e["stress"] < 1e-10


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("T_order", [1, 2])
def test_linear_temperature_is_stress_free(dim, T_order):
    """A linear temperature field gives the compatible strain α T I, whose displacement is
    quadratic: P2 reproduces it, so the stress at the quadrature points vanishes."""
    e = linear_temperature(dim, T_order)
    assert e["stress"] < 1e-10
    # the strain really is α T I (not zero): u_x grows like α T x
    assert e["u_max"] > 0.5 * ALPHA * 10.0 * L


def _faces(mesh, x0):
    return mesh.facets_satisfying(lambda p: np.abs(p[0] - x0) < 1e-12, boundaries_only=True)


def test_uniaxial_tension_plane_stress():
    """Traction s on x = L, u_x = 0 on x = 0: ε_xx = s/E, ε_yy = −ν s/E (plane stress,
    σ_zz = 0) exactly with P1."""
    s, m = 1.0e7, block(2)
    def fixed(vb):
        return np.concatenate([dofs_where(vb, lambda x: np.abs(x[0]) < 1e-12, [0]),
                               dofs_where(vb, at_point([0.0, 0.0]), [1])])
    vb, U, sig = thermoelastic_solve(m, 1, 1, lambda x: np.zeros(x.shape[1]), fixed,
                                     traction=(_faces(m, L), [s, 0.0]))
    u, x = component_values(vb, U)
    np.testing.assert_allclose(u, [s / E * x[0], -NU * s / E * x[1]], rtol=0, atol=1e-10 * s / E * L)
    np.testing.assert_allclose(sig[0, 0], s, rtol=1e-10)
    assert np.abs(sig[1]).max() < 1e-10 * s


def test_restrained_bar_plane_stress():
    """Uniform ΔT, u_x = 0 on both ends, free in y: σ_xx = −E α ΔT = −3.78e7 Pa for
    ΔT = 30 K, σ_yy = 0 and ε_yy = (1 + ν) α ΔT (plane stress) exactly with P1."""
    dT, m = 30.0, block(2)
    def fixed(vb):
        return np.concatenate([dofs_where(vb, lambda x: (np.abs(x[0]) < 1e-12) | (np.abs(x[0] - L) < 1e-12), [0]),
                               dofs_where(vb, at_point([0.0, 0.0]), [1])])
    vb, U, sig = thermoelastic_solve(m, 1, 1, lambda x: np.full(x.shape[1], dT), fixed)
    np.testing.assert_allclose(sig[0, 0], -3.78e7, rtol=1e-10)
    assert np.abs(sig[1]).max() < 1e-10 * 3.78e7
    u, x = component_values(vb, U)
    np.testing.assert_allclose(u[1], (1 + NU) * ALPHA * dT * x[1], rtol=0, atol=1e-10 * ALPHA * dT * H)


SPATIAL = SPATIAL_ELASTIC  # label -> (dimension, element order, refinement levels)


@pytest.mark.parametrize("case", [pytest.param(k, id=k, marks=[pytest.mark.slow] if k.startswith("3-D") else [])
                                  for k in SPATIAL])
def test_spatial_order(case, record_order):
    """Manufactured displacement and temperature (body force by hand, traction face,
    module forms ``stiffness`` and ``thermal_load``; plane stress in 2-D): L2 order p + 1
    within ±0.2 from a least-squares fit."""
    dim, order, levels = SPATIAL[case]
    h, err, p = spatial_study(elastic_mms_error, dim, order, levels)
    record_order(f"elastic L2 {case}", p, order + 1)
    print(f"elastic {case}: h {h}, errors {err}, observed order {p:.3f}")
    assert np.all(np.diff(err) < 0)
    assert abs(p - (order + 1)) <= 0.2, f"observed {p:.3f}"


def test_clamped_bar_thermal_bending():
    """Bar 20 mm × 400 mm (L/h = 20), clamped on its mounting face, ΔT = 10 K across the
    width: tip deflection −α ΔT L²/(2h) = −4.2e-4 m within 1 % (P2, 4 × 80 cells:
    +0.23 %); the adjoint weight read-out equals the direct solve."""
    fe, theory, adjoint = clamped_bar_tip(L=0.4, h=0.02, dT=10.0, order=2, nx=4, ny=80)
    assert theory == pytest.approx(-4.2e-4, rel=1e-14)
    assert fe == pytest.approx(theory, rel=0.01)
    assert adjoint == pytest.approx(fe, rel=1e-9)
