"""Material constants and the small constitutive functions built on them."""
from __future__ import annotations

from dataclasses import dataclass

from gatetherm.checks import POSITIVE, Range, admissible


@admissible(E=POSITIVE, nu=Range(0.0, 0.5, hi_open=True), alpha=Range(-1e-4, 1e-3), k=POSITIVE,
            rho=POSITIVE, c=POSITIVE)
@dataclass(frozen=True)
class Material:
    """An isotropic, linear thermoelastic solid.

    The defaults are grey cast iron JIS FC300 (≈ ASTM A48 class 45, EN-GJL-300):
    E and ν from JIS G 5501 commentary and the ASM Handbook Vol. 1 "Gray Iron"
    tables (class 40–45: E = 110–138 GPa, ν = 0.26); α, k, ρ, c from the same
    tables at 20–100 °C (α = 10.5 µm/(m K), k = 48 W/(m K), ρ = 7250 kg/m³,
    c = 510 J/(kg K)).
    """

    E: float = 1.2e11
    """Young's modulus, Pa."""
    nu: float = 0.26
    """Poisson's ratio, 1."""
    alpha: float = 1.05e-5
    """Linear thermal expansion coefficient, 1/K."""
    k: float = 48.0
    """Thermal conductivity, W/(m K)."""
    rho: float = 7250.0
    """Density, kg/m³."""
    c: float = 510.0
    """Specific heat capacity, J/(kg K)."""


FC300 = Material()


def diffusivity(m: Material) -> float:
    """Thermal diffusivity k/(ρc), m²/s."""
    return m.k / (m.rho * m.c)


def lame(E: float, nu: float) -> tuple[float, float]:
    """3-D Lamé parameters (λ, μ), Pa."""
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


def lame_plane_stress(E: float, nu: float) -> tuple[float, float]:
    """Plane-stress Lamé parameters (λ*, μ) = (Eν/(1−ν²), E/(2(1+ν))), Pa."""
    return E * nu / (1 - nu ** 2), E / (2 * (1 + nu))


def thermal_stress_modulus(E: float, nu: float, alpha: float, dim: int) -> float:
    """Stress per kelvin of a fully restrained uniform heating, Pa/K:
    E α/(1−2ν) in 3-D, E α/(1−ν) in plane stress."""
    return E * alpha / (1 - 2 * nu) if dim == 3 else E * alpha / (1 - nu)
