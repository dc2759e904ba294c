"""The beam theory's two coefficients identified on the FE frame.

Two static load cases reproduce the theory's assumptions exactly in the
temperature field and leave the rest to the FE: (a) θ_A − θ_B = 1 K, linear
through the width of the tool-side column, zero mean, over the height l1;
(b) +1 K uniform on the tie bar(s). Then K_i = δ_a and K_C = −δ_b, read at the
column points E_L/E_R (the theory's assumption) and at the tips F_L/F_R.

The temperature is put on the quadrature points of the loaded region only, as
the theory does: a nodal field would also heat the nodes the region shares
with its neighbour, leaking the load one element layer into the adjacent
member (for a thin tie bar that heated sliver of column can dominate K_C, and
it vanishes only as O(element size)). Each load case costs one elastic solve.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from skfem import CellBasis, asm

from gatetherm.frame.problem import is_tie
from gatetherm.solvers.elasticity import moduli, thermal_load_at
from gatetherm.solvers.fem import Field
from gatetherm.solvers.model import Model


@dataclass(frozen=True)
class Coefficients:
    """K_i and K_C (m/K) at the column points E and at the tips F."""

    Ki_E: float
    Kc_E: float
    Ki_F: float
    Kc_F: float


def region_load(model: Model, temperature: Callable[[np.ndarray], np.ndarray],
                regions) -> np.ndarray:
    """Elastic load vector (N) of the temperature rise ``temperature(x)`` (K, x the
    quadrature-point coordinates ``(dim, elements, points)``) acting on ``regions`` only."""
    vb = CellBasis(model.mesh, model.elastic.basis.elem, intorder=4)
    f = model.fields
    b = moduli(f["E"].values, f["nu"].values, f["alpha"].values, model.dim, model.problem.plane)[2]
    on = Field.by_region(model.mesh, {r: 1.0 for r in regions}, 0.0).at(vb)
    T = on * temperature(vb.mapping.F(vb.X))
    return asm(thermal_load_at, vb, b=Field(b).at(vb), t=f["thickness"].at(vb), T=T)


def _read(model: Model, u: np.ndarray, a: str, b: str) -> float:
    pts = model.fmesh.points
    g = (model.elastic.point_functional(pts[model.fmesh.sensors[a]], 0)
         - model.elastic.point_functional(pts[model.fmesh.sensors[b]], 0))
    return float(g @ u)


def tip_coefficients_um(model: Model) -> tuple[float, float]:
    """(K_i, K_C) of ``model`` from the two load cases, read at the tips F, um/K."""
    c = fe_coefficients(model)
    return c.Ki_F * 1e6, c.Kc_F * 1e6


def fe_coefficients(model: Model) -> Coefficients:
    """K_i, K_C (m/K) of ``model`` from the two load cases."""
    p = model.config.frame
    ties = [r for r in model.fmesh.regions if is_tie(r)]
    ua = model.elastic.from_load(region_load(model, lambda X: (0.5 - X[0] / p.h) * (X[1] <= p.l1),
                                          ["column_L"]))
    ub = model.elastic.from_load(region_load(model, lambda X: np.ones(X.shape[1:]), ties))
    return Coefficients(_read(model, ua, "E_L", "E_R"), -_read(model, ub, "E_L", "E_R"),
                        _read(model, ua, "F_L", "F_R"), -_read(model, ub, "F_L", "F_R"))
