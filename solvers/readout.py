"""The outputs of a heat state as linear read-outs (:class:`Readout`): sparse rows on the state for
temperatures at probes, fluid and hose temperatures and boundary means, and dense weight rows on the
temperature rise, from one adjoint elastic solve of all outputs, for displacements, relative
displacements and stresses at probes (:func:`build_readout`). The assembled model they read is
:mod:`gatetherm.solvers.model`."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from skfem import CellBasis

from gatetherm.solvers import p1
from gatetherm.solvers.elasticity import ElasticSystem
from gatetherm.solvers.fem import Field, element
from gatetherm.solvers.heat_assembly import boundary_terms
from gatetherm.solvers.helper import Pending
from gatetherm.solvers.loads import Terms
from gatetherm.solvers.problem import AXES, Problem
from gatetherm.solvers.stress import Recovery, recovery

Key = tuple
"""An output: ("T", probe), ("u", probe, axis), ("sigma", probe, component), ("relative", name),
("fluid", name), ("mean", name)."""


def boundary_mean(mesh, basis: CellBasis, name: str, thickness: Field) -> np.ndarray:
    """Weights giving the area-mean of a nodal field over a named boundary."""
    a = boundary_terms(mesh, name, basis.elem, 2 * basis.elem.maxdeg, thickness)[1]
    return a / a.sum()


@dataclass(frozen=True)
class Readout:
    """``y = L @ U + W @ (U_solid − T_ref) + R @ loads(env)``: the outputs :attr:`keys` of a
    heat state and the mechanical loads' values (:class:`~gatetherm.solvers.loads.Terms`)."""

    keys: tuple[Key, ...]
    L: sp.csr_matrix
    """Rows on the whole state (temperatures, °C)."""
    weights: Pending
    """:attr:`W`, solved beside the caller where the elastic solver runs in a helper process."""
    n_L: int
    """The first ``n_L`` keys are rows of ``L``, the rest rows of ``W``."""
    R: np.ndarray | None = None
    """Rows of ``W``'s outputs on the mechanical loads' values (None: no loads)."""
    terms: Terms | None = None

    @property
    def W(self) -> np.ndarray:
        """Rows on the solid's temperature rise (displacements in m, stresses in Pa)."""
        return self.weights.result()

    def __call__(self, U: np.ndarray, n_solid: int, T_ref: float, env=None) -> np.ndarray:
        y = self.L @ U
        if len(self.keys) == self.n_L:
            return y
        mech = self.R @ self.terms.at(env or {}) if self.R is not None else 0.0
        return np.concatenate([y, self.W @ (U[:n_solid] - T_ref) + mech])



def recovery_over(p: Problem, mesh, fields, simplices, elements, T_at=None) -> Recovery:
    """The stress projection over ``elements`` (None: all) of a problem's mesh; the temperature
    on the heat basis where there is a heat solve, else ``T_at``."""
    T_elem = element(p.dim, p.order) if p.heat else None
    return recovery(mesh, p.order, fields, p.dim, p.plane, T_elem, elements, T_at, simplices)



@dataclass(frozen=True)
class Rows:
    """The outputs of a displacement field: their keys, rows ``G`` on the displacement and
    rows ``GT`` (or None) on the temperature rise (a stress's thermal part)."""

    keys: list
    G: list
    GT: list


def mechanical_rows(problem: Problem, mesh, fields, el: ElasticSystem, simplices) -> Rows:
    """The relative displacements, displacements and stresses at probes, as rows."""
    keys, G, GT, recoveries = [], [], [], {}
    xyz = {pr.name: pr.xyz for pr in problem.probes}
    for r in problem.relative:
        keys.append(("relative", r.name))
        G.append(el.point_functional(xyz[r.a], r.axis) - el.point_functional(xyz[r.b], r.axis))
        GT.append(None)
    for pr in problem.probes:
        if "u" in pr.quantities:
            for c in range(problem.dim):
                keys.append(("u", pr.name, AXES[c]))
                G.append(el.point_functional(pr.xyz, c))
                GT.append(None)
        if "sigma" in pr.quantities:
            if pr.region not in recoveries:
                recoveries[pr.region] = recovery_over(problem, mesh, fields, simplices,
                                                  None if pr.region is None else mesh.subdomains[pr.region])
            for c, (gu, gT) in recoveries[pr.region].point(pr.xyz).items():
                keys.append(("sigma", pr.name, c))
                G.append(gu)
                GT.append(gT)
    return Rows(keys, G, GT)


def adjoint_weights(el: ElasticSystem, mech: Rows, n_T: int) -> Pending:
    """The rows of :attr:`Readout.W`, from one adjoint solve of all outputs (beside the caller
    where the elastic solver runs in a helper)."""
    if not mech.G:
        return Pending.of(np.zeros((0, n_T)))

    def add_thermal(W):
        for i, gT in enumerate(mech.GT):
            if gT is not None:
                W[i] += gT
        return W
    return el.weights_later(np.array(mech.G)).then(add_thermal)


def build_readout(model, mech: Rows, weights: Pending) -> Readout:
    """Sparse rows (temperatures) and the adjoint weight rows ``weights`` (mechanics) of every output of
    ``model`` (a :class:`~gatetherm.solvers.model.Model` without its read-out yet)."""
    p, heat = model.problem, model.heat
    keys, rows = [], []
    probes = [pr for pr in p.probes if "T" in pr.quantities]
    if probes:
        P = p1.probes(heat.basis, np.array([pr.xyz for pr in probes]).T)
        keys += [("T", pr.name) for pr in probes]
        rows.append(sp.hstack([P, sp.csr_matrix((len(probes), heat.n - heat.n_solid))]))
    for name, index in heat.lumped.items():
        keys.append(("fluid", name))
        rows.append(sp.csr_matrix(([1.0], ([0], [index])), shape=(1, heat.n)))
    for name, boundary in p.means:
        keys.append(("mean", name))
        w = boundary_mean(model.mesh, heat.basis, boundary, model.fields["thickness"])
        rows.append(sp.csr_matrix(np.r_[w, np.zeros(heat.n - heat.n_solid)][None, :]))
    L = sp.vstack(rows).tocsr() if rows else sp.csr_matrix((0, heat.n))
    R = np.array(mech.G) @ model.unit if mech.G and model.terms is not None else None
    return Readout(tuple(keys + mech.keys), L, weights, len(keys), R, model.terms)

