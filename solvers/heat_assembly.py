"""Assembly of the heat system of a :class:`~gatetherm.solvers.problem.Problem`
(:func:`assemble_heat`): the weak form of :mod:`gatetherm.solvers.heat_system` on a mesh, the
lumped fluids and hoses bordering the solid's matrices (:func:`bordered`), the films' boundary
terms (:func:`boundary_terms`)."""
from __future__ import annotations

import logging

import numpy as np
import scipy.sparse as sp
from skfem import CellBasis, FacetBasis, asm

from gatetherm.solvers import p1
from gatetherm.solvers.convection import VaryingFilm
from gatetherm.solvers.expr import Value
from gatetherm.solvers.fem import Field, dof_basis, element
from gatetherm.solvers.heat_system import HeatSystem, Load, Pumped, capacity, conduction, film, film_load
from gatetherm.solvers.moving import moving_load

log = logging.getLogger(__name__)


def boundary_terms(mesh, name: str, e, q: int, thickness: Field) -> tuple[sp.csr_matrix, np.ndarray]:
    """``(∫ t u v, ∫ t v)`` over the named boundary (``t`` the 2-D thickness of the element
    beside each facet): a film of unit coefficient and its load. Linear elements in numpy
    (:func:`~gatetherm.solvers.p1.facet_terms`), others by scikit-fem's facet basis."""
    facets = mesh.boundaries[name]
    if e.maxdeg == 1:
        t = thickness.values[mesh.f2t[0, facets]] if np.ptp(thickness.values) else np.full(len(facets),
                                                                                           thickness.values[0])
        return p1.facet_terms(mesh.p.T, mesh.facets[:, facets].T, t, mesh.nvertices)
    fb = FacetBasis(mesh, e, facets=facets, intorder=q)
    tf = thickness.at(fb)
    return asm(film, fb, h=1.0, t=tf), asm(film_load, fb, h=1.0, t=tf)


def bordered(A: sp.spmatrix, d) -> sp.csr_matrix:
    """``[[A, 0], [0, diag(d)]]`` (CSR, no entry where ``d`` is 0): ``A``'s arrays extended, not
    made anew through triplets as ``sp.block_diag`` makes them."""
    A, d = A.tocsr(), np.asarray(d, dtype=float)
    n, on = A.shape[0], np.flatnonzero(d)
    indptr = np.r_[A.indptr, A.indptr[-1] + np.cumsum(d != 0)].astype(A.indptr.dtype)
    if not on.size:  # the same entries: A's arrays shared
        return sp.csr_matrix((A.data, A.indices, indptr), shape=(n + len(d),) * 2)
    return sp.csr_matrix((np.r_[A.data, d[on]], np.r_[A.indices, n + on].astype(A.indices.dtype), indptr),
                         shape=(n + len(d),) * 2)


def assemble_heat(mesh, problem, fields: dict[str, Field], intorder: int | None = None,
                  simplices: p1.Simplices | None = None) -> HeatSystem:
    """Assemble the heat system of ``problem`` (a :class:`~gatetherm.solvers.problem.Problem`)
    on a scikit-fem ``mesh`` with its named boundaries and subdomains; ``fields`` holds the
    element-wise ``k``, ``rho_c`` and ``thickness``. Linear elements use ``simplices``
    (:func:`~gatetherm.solvers.p1.simplices` of the mesh, found if not given)."""
    order = problem.order
    e = element(mesh.dim(), order)
    q = intorder or 2 * order
    th = fields["thickness"]
    s = None
    if order == 1 and problem.plane != "axisymmetric":  # the same matrices, vectorised (solvers/p1.py)
        s = simplices or p1.simplices(mesh)
        M = s.pattern.scalar(p1.mass, s.G, s.vol, fields["rho_c"].values * th.values)
        K = s.pattern.scalar(p1.conduction, s.G, s.vol, fields["k"].values * th.values)
        basis = dof_basis(mesh, e)
    else:
        basis = CellBasis(mesh, e, intorder=q)
        M = asm(capacity, basis, rc=fields["rho_c"].at(basis), t=th.at(basis))
        K = asm(conduction, basis, k=fields["k"].at(basis), t=th.at(basis))

    if problem.contacts:  # thermal contact layers (on a mesh cut open along them)
        from gatetherm.solvers.contact import conductances

        Kc = conductances(basis, mesh, problem.contacts, th)
        K = K if Kc is None else K + Kc

    def cells():  # a basis with quadrature, made only where a volume integral needs it
        return CellBasis(mesh, e, intorder=q) if order == 1 else basis

    loads: list[tuple[np.ndarray, Value, str]] = []
    varying = []
    for fl in problem.films:
        A_f, a_f = boundary_terms(mesh, fl.boundary, e, q, th)
        K = K + fl.h * A_f
        loads.append((fl.h * a_f, fl.ambient, "film"))
        if fl.law is not None:
            varying.append(VaryingFilm(fl.boundary, A_f.tocsr(), a_f, fl.h, fl.law, fl.ambient))
    for fx in problem.fluxes:
        loads.append((boundary_terms(mesh, fx.boundary, e, q, th)[1], fx.value, "flux"))
    if problem.faces is not None and mesh.dim() == 2:
        cb = cells()
        K = K + asm(film, cb, h=problem.faces.h, t=2.0)
        loads.append((asm(film_load, cb, h=problem.faces.h, t=2.0), problem.faces.ambient, "faces"))
    source_loads, moving = _sources(mesh, basis, problem, e, q, th, cells)
    loads += source_loads
    n_solid = basis.N
    caps, losses, lumped, couplings = _lumped(mesh, problem, e, q, th, n_solid)
    n = n_solid + len(caps)
    pumped = _pumped(problem, couplings, lumped, n)
    M, K0 = bordered(M, caps), bordered(K, [ua for ua, _ in losses])  # K0: the hoses' losses on its border
    loads = [Load(np.r_[v, np.zeros(len(caps))], value, kind) for v, value, kind in loads]
    for k, (ua, ambient) in enumerate(losses):
        if ua:
            v = np.zeros(n)
            v[n_solid + k] = ua
            loads.append(Load(v, ambient, "hose"))
    fixed = tuple((basis.get_dofs(mesh.boundaries[c.boundary]).all(), c.value) for c in problem.fixed)
    log.info("heat system: %d unknowns (P%d), %d fixed", n, order, len(np.unique(np.concatenate(
        [d for d, _ in fixed]))) if fixed else 0)
    return HeatSystem(basis, M, K0, tuple(pumped), tuple(loads), fixed, n_solid, lumped, problem.T0, s,
                      tuple(varying), tuple(moving))


def _sources(mesh, basis, problem, e, q, th, cells) -> tuple[list, list]:
    """The sources' load vectors (with their power densities) and the moving ones' loads;
    ``cells()`` is a basis with quadrature for the volume integrals."""
    loads, moving = [], []
    for src in problem.sources:
        if src.on_boundary:  # a power on a surface: ∫ t v over the boundary, normalised to it
            vec = boundary_terms(mesh, src.region, e, q, th)[1]
        else:
            cb = cells()
            on = Field.by_region(mesh, {src.region: 1.0}, 0.0)
            vec = asm(film_load, cb, h=on.at(cb), t=th.at(cb))
        if src.position is not None:
            moving.append(moving_load(mesh, basis, src, vec, problem.order))
        elif src.on_boundary:
            loads.append((vec / vec.sum(), src.density, "source"))
        else:
            loads.append((vec * src.per if src.per != 1.0 else vec, src.density, "source"))
    return loads, moving


def _lumped(mesh, problem, e, q, th, n_solid: int) -> tuple[list, list, dict, list]:
    """The fluids' lumped unknowns after the solid's (a tank, and its hose where it has one):
    their capacities, losses ``(UA, ambient)``, numbers by name, and each tank's wall terms."""
    caps, losses, lumped, couplings = [], [], {}, []
    for fluid in problem.fluids:
        lumped[fluid.name] = n_solid + len(caps)
        caps.append(fluid.capacity)
        losses.append((0.0, None))
        couplings.append(boundary_terms(mesh, fluid.boundary, e, q, th))
        if fluid.hose_capacity > 0:
            lumped[fluid.hose_name or f"{fluid.name}_hose"] = n_solid + len(caps)
            caps.append(fluid.hose_capacity)
            losses.append((fluid.hose_loss, fluid.ambient))
    return caps, losses, lumped, couplings


def _pumped(problem, couplings, lumped: dict, n: int) -> list[Pumped]:
    """Each fluid's wall exchange and pumped flow, on all ``n`` unknowns."""
    pumped = []
    for fluid, (A_ww, c) in zip(problem.fluids, couplings):
        o = lumped[fluid.name]
        i = lumped.get(fluid.hose_name or f"{fluid.name}_hose", o) if fluid.hose_capacity > 0 else o
        A, idx = A_ww.tocoo(), np.flatnonzero(c)
        oo = np.full(len(idx), o)
        wall = sp.csr_matrix((np.r_[A.data, -c[idx], -c[idx], c.sum()],
                              (np.r_[A.row, idx, oo, o], np.r_[A.col, oo, idx, o])), shape=(n, n))
        flow = sp.csr_matrix(([1.0, -1.0, 1.0], ([o, o, i], [o, i, i])), shape=(n, n))
        pumped.append(Pumped(wall, fluid.film_on, fluid.film_off, flow, fluid.conductance, i,
                             fluid.pump, fluid.supply))
        log.info("heat system: fluid %s on %s, wall area %.4g m²", fluid.name, fluid.boundary, c.sum())
    return pumped
