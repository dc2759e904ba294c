"""Pictures of one run: the paper's Figs. 10–13 analogues and the deformed frame."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from gatetherm.validation.plots import save  # noqa: E402


def pump_phases(t, on) -> list[tuple[float, float]]:
    """(start, end) of the runs of ``on`` (booleans at the times ``t``): the last sample of a
    phase ends it at the next sample."""
    on = np.asarray(on, bool)
    edges = np.flatnonzero(np.diff(np.r_[0, on.astype(int), 0]))
    return [(t[a], t[min(b, len(t) - 1)]) for a, b in zip(edges[::2], edges[1::2])]


def shade(ax, t, on, label: str = "pump on") -> None:
    """Grey bands where ``on``; the first band carries ``label`` for the legend."""
    for k, (a, b) in enumerate(pump_phases(t, on)):
        ax.axvspan(a, b, color="0.9", lw=0, label=label if k == 0 else None, zorder=0)


def plot_oil(cols: dict, path, title: str) -> None:
    """Fig. 10 analogue: supply oil, tank oil and tank-wall temperature."""
    t = cols["time_s"] / 60.0
    fig, ax = plt.subplots(figsize=(7, 4))
    shade(ax, t, cols["pump"] > 0.5)
    ax.plot(t, cols["oil_degC"], label="supply oil")
    if "T_tank_oil_degC" in cols:
        ax.plot(t, cols["T_tank_oil_degC"], label="oil in tank")
        ax.plot(t, cols["T_tank_wall_degC"], label="tank wall (mean)")
    ax.set(xlabel="time [min]", ylabel="temperature [°C]", title=title)
    ax.legend()
    ax.grid(alpha=0.3)
    save(fig, path, tight=True)


def plot_response(cols: dict, path, title: str) -> None:
    """Figs. 11–13 analogue: θ_A, θ_B, θ_C rises and δ against time, pump phases shaded."""
    plot_responses({"": cols}, path, title)


def plot_responses(runs: dict, path, title: str) -> None:
    """Figs. 11–13 analogue for one or more runs of the same schedule ({label: columns}: solid
    lines for the first, dashed for the second, …): θ_A, θ_B, θ_C rises and δ against time,
    pump phases shaded."""
    first = next(iter(runs.values()))
    t0 = first["time_s"] / 60.0
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7.5, 6.5), sharex=True)
    for ax in (a1, a2):
        if "pump" in first:
            shade(ax, t0, first["pump"] > 0.5)
    for k, (name, cols) in enumerate(runs.items()):
        t, ls, tag = cols["time_s"] / 60.0, ("-", "--", ":")[k % 3], f" {name}" if name else ""
        for i, (key, lab) in enumerate((("theta_A_degC", "θ_A"), ("theta_B_degC", "θ_B"), ("theta_C_degC", "θ_C"))):
            a1.plot(t, cols[key] - cols[key][0], ls=ls, color=f"C{i}", label=lab + tag)
        a2.plot(t, cols["delta_um"], ls=ls, color="k", label="δ at the tips F" + tag)
        if "delta_E_um" in cols and k == 0:
            a2.plot(t, cols["delta_E_um"], ls=":", color="0.4", lw=0.9, label="δ at E (beam theory point)" + tag)
    a1.set(ylabel="temperature rise [K]", title=title)
    a2.axhline(0, color="0.5", lw=0.5)
    a2.set(xlabel="time [min]", ylabel="δ [µm] (+ = approach)")
    for ax in (a1, a2):
        ax.legend(fontsize="small", ncol=2 if len(runs) > 1 else 1)
        ax.grid(alpha=0.3)
    save(fig, path, tight=True)


def render_deformed(grid, path, title: str, scale: float) -> None:
    """Temperature on the frame deformed by ``scale`` × displacement, the undeformed outline
    in grey (pyvista, off screen), framed by matplotlib with a labelled colour bar.

    ``grid`` is a pyvista mesh with point arrays ``T`` (°C) and ``u`` (m, 3 components);
    without ``T`` (a purely mechanical case) the colours show the displacement's magnitude.
    """
    import pyvista as pv
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize
    from vtkmodules.vtkCommonCore import vtkLogger

    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_ERROR)  # no X display: VTK falls back quietly
    pv.OFF_SCREEN = True
    thermal = "T" in grid.point_data
    if not thermal:
        grid["|u| [µm]"] = 1e6 * np.linalg.norm(np.asarray(grid["u"]), axis=1)
    name = "T" if thermal else "|u| [µm]"
    T = np.asarray(grid[name])
    clim = (float(T.min()), float(T.max()) if T.max() > T.min() else float(T.min()) + 1.0)
    flat = grid.bounds[5] - grid.bounds[4] < 1e-12
    outline = grid.extract_surface(algorithm="dataset_surface").extract_feature_edges(feature_angle=30.0, boundary_edges=flat,
                                                           feature_edges=not flat, manifold_edges=False,
                                                           non_manifold_edges=False)
    p = pv.Plotter(off_screen=True, window_size=(1600, 1200))
    p.set_background("white")
    p.add_mesh(grid.warp_by_vector("u", factor=scale), scalars=name, cmap=CMAP, clim=clim, show_scalar_bar=False)
    p.add_mesh(outline, color="#8c8c8c", line_width=2)
    if flat:
        p.view_xy()
    else:  # y is up; seen from behind and above, so the tool side stays on the left
        p.view_vector((0.35, 0.45, 1.0), viewup=(0.0, 1.0, 0.0))
    img = _trim(p.screenshot(return_img=True))
    p.close()
    fig, ax = plt.subplots(figsize=(7.5, 6.0))
    ax.imshow(img, interpolation="lanczos")
    ax.set_axis_off()
    bar = fig.colorbar(ScalarMappable(Normalize(*clim), CMAP), ax=ax, fraction=0.04, pad=0.02, shrink=0.85)
    bar.set_label("temperature T [°C]" if thermal else "displacement |u| [µm]")
    ax.set_title(f"{title}\ndisplacement magnified ×{scale:.0f}; grey: undeformed edges", fontsize="medium")
    save(fig, path, tight=True)


CMAP = "coolwarm"
"""Colour map of temperature on the frame (no black end: every part of the frame stays visible)."""


def _trim(img: np.ndarray, pad: int = 12) -> np.ndarray:
    """The image cropped to its non-white content plus ``pad`` pixels."""
    ink = np.flatnonzero(img.min(axis=2).min(axis=1) < 250), np.flatnonzero(img.min(axis=2).min(axis=0) < 250)
    if not len(ink[0]):
        return img
    (r0, r1), (c0, c1) = (ink[0][[0, -1]], ink[1][[0, -1]])
    return img[max(r0 - pad, 0):r1 + pad + 1, max(c0 - pad, 0):c1 + pad + 1]


def draw_deformed(run, t: float, path, title, solved: dict | None = None) -> float:
    """The kept state of ``run`` nearest ``t`` (s) drawn by :func:`render_deformed`, magnified so
    that the largest displacement shows as about 8 % of the frame's width (a power of ten);
    ``title``: text or a function of the time drawn; ``solved`` as for :func:`plot_run`;
    returns the time drawn, s."""
    from gatetherm.studies.run.output import deformed_grid

    t, grid = deformed_grid(run, t, solved)
    umax = float(np.abs(grid["u"]).max()) or 1.0
    scale = float(10 ** np.floor(np.log10(0.08 * max(grid.bounds[1] - grid.bounds[0], 1e-9) / umax)))
    render_deformed(grid, path, title(t) if callable(title) else title, scale)
    return t


def picture_time(figs: dict) -> float:
    """When ``deformed.png`` of :func:`plot_run` shows the frame (s): the first peak of δ, else 1 h."""
    return (figs["first_peak_min"] or 60.0) * 60.0


def plot_run(run, figs: dict, out, title: str, solved: dict | None = None) -> None:
    """``oil_temperatures.png`` (Fig. 10), ``response.png`` (Figs. 11–13) and ``deformed.png``
    (at :func:`picture_time`) of a :class:`~gatetherm.studies.run.scenario.ScenarioRun`
    whose kept states include that time; ``solved``: displacements of kept states, by time,
    if solved already."""
    from pathlib import Path

    out = Path(out)
    plot_oil(run.columns, out / "oil_temperatures.png", title)
    plot_response(run.columns, out / "response.png", title)
    draw_deformed(run, picture_time(figs), out / "deformed.png", lambda t: f"{title}, t = {t / 60:.0f} min", solved)


def plot_channels(cols: dict, path, title: str) -> None:
    """Every temperature (°C) and displacement (µm) column of a run against time."""
    t = cols["time_s"] / 3600.0
    temps = [k for k in cols if k.endswith("_degC")]
    disp = [k for k in cols if k.endswith("_um")]
    fig, axes = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    for ax, keys, label in ((axes[0], temps, "temperature [°C]"), (axes[1], disp, "displacement [µm]")):
        for k in keys:
            ax.plot(t, cols[k], label=k)
        ax.set(ylabel=label)
        ax.grid(alpha=0.3)
        if keys:
            ax.legend(fontsize="small", ncol=2)
    axes[0].set_title(title)
    axes[1].set(xlabel="time [h]")
    save(fig, path, tight=False)


def write_pictures(run, out, title: str, picture_s: float | None, solved: dict | None = None) -> list[str]:
    """The pictures of a run (a :class:`~gatetherm.studies.run.scenario.ScenarioRun`) into ``out``,
    by what the case has: ``channels.png`` (every channel of a transient run), ``response.png``
    (θ_A, θ_B, θ_C and δ: Figs. 11–13), ``oil_temperatures.png`` (a fluid's supply, volume and wall:
    Fig. 10) and ``deformed.png`` (the state kept nearest ``picture_s``); returns the names written."""
    from pathlib import Path

    out, cols, written = Path(out), run.columns, []
    transient = len(cols["time_s"]) > 1
    if transient:
        plot_channels(cols, out / "channels.png", title)
        written.append("channels.png")
    if transient and all(k in cols for k in ("theta_A_degC", "theta_B_degC", "theta_C_degC", "delta_um")):
        plot_response(cols, out / "response.png", title)
        written.append("response.png")
    if transient and "oil_degC" in cols and "pump" in cols:
        plot_oil(cols, out / "oil_temperatures.png", title)
        written.append("oil_temperatures.png")
    if picture_s is not None and run.model.elastic is not None:
        draw_deformed(run, picture_s, out / "deformed.png", lambda t: f"{title}, t = {t / 60:.0f} min", solved)
        written.append("deformed.png")
    return written


def plot_case(run, out, title: str, solved: dict | None = None) -> None:
    """``channels.png`` (transient runs) and ``deformed.png`` (the last state, when the case
    has elasticity) of a case run; ``solved`` as for :func:`plot_run`."""
    from pathlib import Path

    out = Path(out)
    if len(run.columns["time_s"]) > 1:
        plot_channels(run.columns, out / "channels.png", title)
    if run.model.elastic is not None:
        draw_deformed(run, float(run.columns["time_s"][-1]), out / "deformed.png",
                      lambda t: f"{title}, t = {t / 3600:.3g} h", solved)
