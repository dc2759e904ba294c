"""A problem without a heat solve: its prescribed temperature field (:func:`prescribed_at`), the
displacement it causes (:func:`static_displacement`) and the nodal fields (:func:`static_fields`).
Each takes an assembled :class:`~gatetherm.solvers.model.Model`, whose
:meth:`~gatetherm.solvers.model.Model.static` gives its outputs."""
from __future__ import annotations

import numpy as np
from skfem import CellBasis, asm

from gatetherm.solvers.elasticity import moduli, thermal_load_at
from gatetherm.solvers.fem import Field


def static_displacement(model, env=None, loads: bool = True) -> np.ndarray:
    """The displacement (m) of a problem without a heat solve for the inputs ``env`` (only
    the prescribed temperature's if not ``loads``)."""
    p, el = model.problem, model.elastic
    u = el.from_load(prescribed_load(model)) if p.thermal else np.zeros(el.basis.N)
    return u + model.loads_displacement(env) if loads else u


def static_fields(model, env=None) -> dict[str, np.ndarray]:
    """Nodal temperature (°C, interpolated at the nodes; none without a temperature),
    displacement (m, 3 components) and stress (Pa) of a problem without a heat solve."""
    X = model.fmesh.points.T
    out = {"T": prescribed_at(model, X)} if model.problem.thermal else {}
    if model.elastic is not None:
        u_dofs = static_displacement(model, env)
        u = np.zeros((X.shape[1], 3))
        u[:, :model.dim] = u_dofs[model.elastic.basis.nodal_dofs].T
        out["u"] = u
        out.update({f"sigma_{k}" if k != "von_mises" else k: v for k, v in model.stress_field(u_dofs).items()})
    return out


def prescribed_at(model, X: np.ndarray) -> np.ndarray:
    """The prescribed temperature (°C) at points ``X`` (dim, n)."""
    p = model.problem
    if p.prescribed is not None:
        return np.broadcast_to(p.prescribed(dict(zip("xyz", X))), X.shape[1:]).astype(float)
    cells = model.mesh.element_finder()(*X)
    regions = {int(e): r for r, els in model.mesh.subdomains.items() for e in els}
    return np.array([p.prescribed_regions.get(regions.get(int(c)), 0.0) for c in cells])


def prescribed_rise(model):
    """``basis -> prescribed rise above T_ref`` at the basis's quadrature points."""
    p = model.problem

    def at(basis):
        if p.prescribed is not None:
            X = basis.global_coordinates().value
            return np.broadcast_to(p.prescribed(dict(zip("xyz", X))), X.shape[1:]) - p.T_ref
        per = Field.by_region(model.mesh, p.prescribed_regions, np.nan)
        return per.at(basis) - p.T_ref
    return at


def prescribed_load(model) -> np.ndarray:
    from gatetherm.solvers import axisym

    el, f, p = model.elastic, model.fields, model.problem
    vb = CellBasis(model.mesh, el.basis.elem, intorder=2 * p.order + p.axisymmetric)
    b = moduli(f["E"].values, f["nu"].values, f["alpha"].values, model.dim, p.plane)[2]
    return asm(axisym.thermal_load_at if p.axisymmetric else thermal_load_at, vb, b=Field(b).at(vb),
               t=f["thickness"].at(vb), T=prescribed_rise(model)(vb))
