"""Pictures on the mesh: a nodal field and the deformed frame (a tripcolor in 2-D, a pyvista
surface picture in 3-D). pyvista renders off screen into an image (its own plotter's setting:
``pyvista.OFF_SCREEN`` is left as it was), which matplotlib frames with a labelled colour bar."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gatetherm.validation.plots import figure

CMAP = "coolwarm"
"""Colour map of temperature on the frame (no black end: every part of the frame stays visible)."""


def scalar(name: str, values) -> tuple[np.ndarray, str]:
    """(values drawn, colour-bar label) of the nodal field ``name`` as
    :meth:`gatetherm.api.Run.field` gives it: T in °C, |u| in µm, stresses in MPa."""
    values = np.asarray(values, dtype=float)
    if name == "T":
        return values, "temperature T [°C]"
    if name == "u":
        return 1e6 * np.linalg.norm(values, axis=1), "displacement |u| [µm]"
    return 1e-6 * values, f"{name} [MPa]"


def _limits(v) -> tuple[float, float]:
    return float(v.min()), float(v.max()) if v.max() > v.min() else float(v.min()) + 1.0


def plot_field(fmesh, name: str, values, title: str = "", ax=None):
    """The nodal field ``name`` (``values`` at the nodes of ``fmesh``, a
    :class:`~gatetherm.geometry.mesh.FrameMesh`): in 2-D a tripcolor on the mesh (x, y in m),
    in 3-D a picture of the body's surface (pyvista). Returns the Axes."""
    v, label = scalar(name, values)
    if fmesh.dim == 3:
        surface = _surface(fmesh, {name: v})
        return frame_image(screenshot(surface, name, _limits(v), surface), _limits(v), label, title, ax)
    ax = figure((7.5, 6.0)) if ax is None else ax
    _tripcolor(ax, np.asarray(fmesh.points, dtype=float)[:, :2], np.asarray(fmesh.cells)[:, :3], v, label)
    ax.set(xlabel="x [m]", ylabel="y [m]", title=title)
    return ax


def screenshot(surface, name: str, clim, outline_of) -> np.ndarray:
    """An off-screen pyvista image of the point array ``name`` on the body's ``surface`` (colours
    over ``clim``), seen from behind and above with y up (the tool side on the left), with the
    feature edges of the surface ``outline_of`` in grey, cropped to its content."""
    import pyvista as pv
    from vtkmodules.vtkCommonCore import vtkLogger

    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_ERROR)  # no X display: VTK falls back quietly
    outline = outline_of.extract_feature_edges(feature_angle=30.0, boundary_edges=False, feature_edges=True,
                                               manifold_edges=False, non_manifold_edges=False)
    p = pv.Plotter(off_screen=True, window_size=(1600, 1200))
    try:
        p.set_background("white")
        p.add_mesh(surface, scalars=name, cmap=CMAP, clim=clim, show_scalar_bar=False)
        p.add_mesh(outline, color="#8c8c8c", line_width=2)
        p.view_vector((0.35, 0.45, 1.0), viewup=(0.0, 1.0, 0.0))
        return _trim(p.screenshot(return_img=True))
    finally:
        p.close()


def warm_surface() -> None:
    """Import pyvista and render a small body off screen, as :func:`screenshot` does: the part
    of a 3-D picture's time that is not its own (the import, the first rendering's set-up),
    done ahead by :meth:`~gatetherm.validation.plots.painter.Painter.prepare`."""
    import pyvista as pv

    body = pv.Cube().triangulate()
    body["v"] = body.points[:, 0]
    screenshot(body, "v", (0.0, 1.0), body)


def frame_image(img: np.ndarray, clim, label: str, title: str, ax=None):
    """``img`` on ``ax`` (axes off) with a colour bar of :data:`CMAP` over ``clim`` labelled
    ``label``. Returns the Axes."""
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    ax = figure((7.5, 6.0)) if ax is None else ax
    ax.imshow(img, interpolation="antialiased")  # lanczos: 0.46 s against 0.19 s in savefig (3-D deformed)
    ax.set_axis_off()
    _colour_bar(ax, ScalarMappable(Normalize(*clim), CMAP), label)
    ax.set_title(title, fontsize="medium")
    return ax


def render_deformed(fmesh, fields: dict, title: str, scale: float, ax=None):
    """Temperature on the frame deformed by ``scale`` × displacement, the undeformed outline
    in grey, with a labelled colour bar; returns the Axes. A 2-D mesh is drawn by matplotlib
    (a tripcolor), a 3-D body by pyvista off screen and framed on ``ax``.

    ``fields`` are nodal arrays of ``fmesh`` (a :class:`~gatetherm.geometry.mesh.FrameMesh`, or a
    3-D body's :class:`Surface`):
    ``T`` (°C) and ``u`` (m, 3 components); without ``T`` (a purely mechanical case) the
    colours show the displacement's magnitude.
    """
    name, label = ("T", "temperature T [°C]") if "T" in fields else ("|u| [µm]", "displacement |u| [µm]")
    values = fields["T"] if "T" in fields else scalar("u", fields["u"])[0]
    clim = _limits(np.asarray(values))
    title = f"{title}\ndisplacement magnified ×{scale:.0f}; grey: undeformed edges"
    if fmesh.dim == 3:
        surface = _surface(fmesh, {name: values, "u": fields["u"]})
        return frame_image(screenshot(surface.warp_by_vector("u", factor=scale), name, clim, surface), clim, label,
                           title, ax)
    from matplotlib.collections import LineCollection

    ax = figure((7.5, 6.0)) if ax is None else ax
    tri = np.asarray(fmesh.cells)[:, :3]
    xy = np.asarray(fmesh.points, dtype=float)[:, :2]
    _tripcolor(ax, xy + scale * fields["u"][:, :2], tri, values, label, vmin=clim[0], vmax=clim[1])
    ax.add_collection(LineCollection(xy[boundary_edges(tri)], colors="#8c8c8c", linewidths=1.2))
    ax.set_axis_off()
    ax.set_title(title, fontsize="medium")
    return ax


def boundary_edges(tri: np.ndarray) -> np.ndarray:
    """The edges (pairs of node indices) that belong to one triangle of ``tri`` only."""
    from gatetherm.geometry.mesh import facet_keys

    n = int(tri.max()) + 1 if len(tri) else 1
    key, count = np.unique(facet_keys(tri[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), n), return_counts=True)
    once = key[count == 1]
    return np.column_stack((once // n, once % n))


@dataclass(frozen=True)
class Surface:
    """The boundary triangles of a 3-D body: what its picture draws, a fraction of the mesh (no
    tetrahedra, the surface's nodes only), so that a painting process is sent and handles that only."""

    points: np.ndarray
    """(n, 3) coordinates of the surface's nodes, m."""
    triangles: np.ndarray
    """(m, 3) node indices into :attr:`points`."""
    nodes: np.ndarray
    """(n,) the mesh nodes that :attr:`points` are: a nodal field's values on the surface are ``values[nodes]``."""
    dim: int = 3


def surface_of(mesh) -> Surface:
    """The :class:`Surface` of a scikit-fem tetrahedral mesh: its facets that one element has,
    each turned to face out of it (as VTK's surface of the cells: feature edges are found by
    the normals)."""
    t2f = mesh.t2f.ravel()
    at = np.flatnonzero(np.bincount(t2f, minlength=mesh.facets.shape[1])[t2f] == 1)  # (local facet, element)
    element = at % mesh.t.shape[1]
    tri = mesh.facets[:, t2f[at]].T
    p = mesh.p.T
    inner = p[mesh.t[:, element].sum(axis=0) - tri.sum(axis=1)]  # the element's node off the facet
    a, b, c = p[tri[:, 0]], p[tri[:, 1]], p[tri[:, 2]]
    inward = np.einsum("ij,ij->i", np.cross(b - a, c - a), inner - a) > 0
    tri[inward] = tri[inward][:, ::-1]
    nodes, inverse = np.unique(tri, return_inverse=True)
    return Surface(np.ascontiguousarray(p[nodes]), inverse.reshape(tri.shape), nodes)


def _surface(fmesh, point_data: dict):
    """The pyvista surface of the 3-D body of ``fmesh`` (a FrameMesh or its :class:`Surface`)
    with the nodal arrays ``point_data``."""
    import pyvista as pv

    from gatetherm.studies.run.output import volume_grid

    if not isinstance(fmesh, Surface):
        return volume_grid(fmesh, point_data).extract_surface(algorithm="dataset_surface")
    tri = fmesh.triangles
    body = pv.PolyData(fmesh.points, np.column_stack([np.full(len(tri), 3), tri]).ravel())
    for name, values in point_data.items():
        body.point_data[name] = values
    return body


def _tripcolor(ax, xy: np.ndarray, tri: np.ndarray, values, label: str, **limits) -> None:
    """``values`` at the nodes ``xy`` of the triangles ``tri``, Gouraud-shaded, equal axes, with a colour bar."""
    _colour_bar(ax, ax.tripcolor(*xy.T, tri, values, shading="gouraud", cmap=CMAP, **limits), label)
    ax.set_aspect("equal")


def _colour_bar(ax, mappable, label: str) -> None:
    ax.figure.colorbar(mappable, ax=ax, fraction=0.04, pad=0.02, shrink=0.85).set_label(label)


def _trim(img: np.ndarray, pad: int = 12) -> np.ndarray:
    """The image cropped to its non-white content plus ``pad`` pixels."""
    ink = np.flatnonzero(img.min(axis=2).min(axis=1) < 250), np.flatnonzero(img.min(axis=2).min(axis=0) < 250)
    if not len(ink[0]):
        return img
    (r0, r1), (c0, c1) = (ink[0][[0, -1]], ink[1][[0, -1]])
    return img[max(r0 - pad, 0):r1 + pad + 1, max(c0 - pad, 0):c1 + pad + 1]


def deformed(run, t: float, title, solved: dict | None = None) -> tuple:
    """The arguments of :func:`render_deformed` (``fmesh, fields, title, scale``) for the kept
    state of ``run`` (a :class:`~gatetherm.studies.run.scenario.ScenarioRun`) nearest ``t`` (s),
    magnified so that the largest displacement shows as about 8 % of the frame's width (a power
    of ten); ``title``: text or a function of the time drawn; ``solved``: displacements of kept
    states, by time, if solved already."""
    from gatetherm.studies.run.output import nearest_state, nodal_fields

    t, U = nearest_state(run, t)
    fmesh = run.model.fmesh
    fields = nodal_fields(run.model, U, stress=False, u_dofs=(solved or {}).get(t), env=run.result.envs.get(t))
    x = np.asarray(fmesh.points)[:, 0]
    umax = float(np.abs(fields["u"]).max()) or 1.0
    scale = float(10 ** np.floor(np.log10(0.08 * max(x.max() - x.min(), 1e-9) / umax)))
    if fmesh.dim == 3:  # the body's surface is what is drawn
        fmesh = surface_of(run.model.mesh)
        fields = {k: np.asarray(v)[fmesh.nodes] for k, v in fields.items()}
    return fmesh, fields, title(t) if callable(title) else title, scale


def draw_deformed(run, t: float, title, solved: dict | None = None, ax=None):
    """The kept state of ``run`` nearest ``t`` (s) drawn by :func:`render_deformed` (see
    :func:`deformed`). Returns the Axes."""
    return render_deformed(*deformed(run, t, title, solved), ax=ax)
