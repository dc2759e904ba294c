"""The beam theory's two coefficients identified on the FE frame.

Two static load cases reproduce the theory's assumptions exactly in the
temperature field and leave the rest to the FE: (a) θ_A − θ_B = 1 K, linear
through the width of the tool-side column, zero mean, over the height l1;
(b) +1 K uniform on the tie bar(s). Then K_i = δ_a and K_C = −δ_b, read at the
column points E_L/E_R (the theory's assumption) and at the tips F_L/F_R.
Since the displacement outputs are fixed weight vectors on the temperature,
each load case costs one dot product.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from skfem import CellBasis, LinearForm, asm
from skfem.helpers import div

from solvers.elasticity import moduli
from solvers.fem import Field
from solvers.model import FrameModel, is_tie, region_fields


def _dofs_of(model: FrameModel, regions) -> np.ndarray:
    basis, mesh = model.heat.basis, model.mesh
    elems = np.concatenate([mesh.subdomains[r] for r in regions])
    return np.unique(basis.element_dofs[:, elems])


def gradient_case(model: FrameModel) -> np.ndarray:
    """Load case (a): temperature rise (K) on the heat DOFs."""
    p = model.config.frame
    x, y = model.heat.basis.doflocs[0], model.heat.basis.doflocs[1]
    dofs = _dofs_of(model, ["column_L"])
    dofs = dofs[y[dofs] <= p.l1 + 1e-12]
    T = np.zeros(model.heat.basis.N)
    T[dofs] = 0.5 - x[dofs] / p.h
    return T


def tie_case(model: FrameModel) -> np.ndarray:
    """Load case (b): +1 K on every tie-bar region."""
    T = np.zeros(model.heat.basis.N)
    T[_dofs_of(model, [r for r in model.fmesh.regions if is_tie(r)])] = 1.0
    return T


@dataclass(frozen=True)
class Coefficients:
    """K_i and K_C (m/K) at the column points E and at the tips F."""

    Ki_E: float
    Kc_E: float
    Ki_F: float
    Kc_F: float


def fe_coefficients(model: FrameModel) -> Coefficients:
    """K_i, K_C of ``model`` from the two load cases."""
    a, b = gradient_case(model), tie_case(model)
    wE, wF = model.weights["delta_E"], model.weights["delta"]
    return Coefficients(float(wE @ a), float(-(wE @ b)), float(wF @ a), float(-(wF @ b)))


# --- Element-exact load cases ---------------------------------------------------------
# The nodal load cases above set every DOF of the loaded region, including the nodes it
# shares with its neighbours, so the load leaks one element layer into the adjacent
# member. For a thin tie bar (large beta) that heated sliver of column bends the column
# and can dominate K_C (it vanishes only as O(element size)). The variants below put the
# temperature on the quadrature points of the loaded region only, as the theory does,
# at the price of one elastic solve per load case instead of a dot product.

@LinearForm
def _thermal_rhs(v, w):
    return w.t * w.b * w.T * div(v)


def region_load(model: FrameModel, temperature: Callable[[np.ndarray], np.ndarray],
                regions) -> np.ndarray:
    """Elastic load vector (N) of the temperature rise ``temperature(x)`` (K, x the
    quadrature-point coordinates ``(dim, elements, points)``) acting on ``regions`` only."""
    vb = CellBasis(model.mesh, model.elastic.basis.elem, intorder=4)
    f = region_fields(model.config, model.fmesh, model.mesh)
    b = moduli(f["E"].values, f["nu"].values, f["alpha"].values, model.dim)[2]
    on = Field.by_region(model.mesh, {r: 1.0 for r in regions}, 0.0).at(vb)
    T = on * temperature(vb.mapping.F(vb.X))
    return asm(_thermal_rhs, vb, b=Field(b).at(vb), t=f["thickness"].at(vb), T=T)


def _read(model: FrameModel, u: np.ndarray, a: str, b: str) -> float:
    pts = model.fmesh.points
    g = (model.elastic.point_functional(pts[model.fmesh.sensors[a]], 0)
         - model.elastic.point_functional(pts[model.fmesh.sensors[b]], 0))
    return float(g @ u)


def _displacement(model: FrameModel, load: np.ndarray) -> np.ndarray:
    el = model.elastic
    u = np.zeros(el.basis.N)
    u[el.free] = el.solve(load[el.free])
    return u


def exact_coefficients(model: FrameModel) -> Coefficients:
    """K_i, K_C (m/K) of ``model`` from the load cases applied element-exactly:
    (a) on the quadrature points of column_L at heights <= l1, (b) on the tie-bar regions."""
    p = model.config.frame
    ties = [r for r in model.fmesh.regions if is_tie(r)]
    ua = _displacement(model, region_load(model, lambda X: (0.5 - X[0] / p.h) * (X[1] <= p.l1),
                                          ["column_L"]))
    ub = _displacement(model, region_load(model, lambda X: np.ones(X.shape[1:]), ties))
    return Coefficients(_read(model, ua, "E_L", "E_R"), -_read(model, ub, "E_L", "E_R"),
                        _read(model, ua, "F_L", "F_R"), -_read(model, ub, "F_L", "F_R"))
