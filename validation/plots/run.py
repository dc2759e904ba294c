"""Pictures of one run: the paper's Figs. 10–13 analogues and the deformed frame."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from gatetherm import atomic_path  # noqa: E402
from gatetherm.validation.plots import save  # noqa: E402


def _pump_shading(ax, t_min, pump) -> None:
    on = np.asarray(pump) > 0.5
    edges = np.flatnonzero(np.diff(np.r_[0, on.astype(int), 0]))
    for a, b in zip(edges[::2], edges[1::2]):
        ax.axvspan(t_min[a], t_min[min(b, len(t_min) - 1)], color="0.92", lw=0)


def plot_oil(cols: dict, path, title: str) -> None:
    """Fig. 10 analogue: supply oil, tank oil and tank-wall temperature."""
    t = cols["time_s"] / 60.0
    fig, ax = plt.subplots(figsize=(7, 4))
    _pump_shading(ax, t, cols["pump"])
    ax.plot(t, cols["oil_degC"], label="supply oil")
    if "T_tank_oil_degC" in cols:
        ax.plot(t, cols["T_tank_oil_degC"], label="oil in tank")
        ax.plot(t, cols["T_tank_wall_degC"], label="tank wall (mean)")
    ax.set(xlabel="time [min]", ylabel="temperature [°C]", title=f"{title}\n(grey: pump on)")
    ax.legend()
    ax.grid(alpha=0.3)
    save(fig, path, tight=False)


def plot_response(cols: dict, path, title: str) -> None:
    """Figs. 11–13 analogue: θ_A, θ_B, θ_C rises and δ against time."""
    t = cols["time_s"] / 60.0
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    _pump_shading(a1, t, cols["pump"])
    for key, lab in (("theta_A_degC", "θ_A"), ("theta_B_degC", "θ_B"), ("theta_C_degC", "θ_C")):
        a1.plot(t, cols[key] - cols[key][0], label=lab)
    a1.set(ylabel="temperature rise [K]", title=f"{title}\n(grey: pump on)")
    a1.legend()
    a1.grid(alpha=0.3)
    _pump_shading(a2, t, cols["pump"])
    a2.plot(t, cols["delta_um"], "k", label="δ at tool/workpiece tips")
    if "delta_E_um" in cols:
        a2.plot(t, cols["delta_E_um"], "k--", lw=0.8, label="δ at E_L/E_R (beam theory point)")
    a2.axhline(0, color="0.5", lw=0.5)
    a2.set(xlabel="time [min]", ylabel="δ [µm] (+ = approach)")
    a2.legend()
    a2.grid(alpha=0.3)
    save(fig, path, tight=False)


def render_deformed(grid, path, title: str, scale: float) -> None:
    """Temperature on the frame deformed by ``scale`` × displacement (pyvista, off screen).

    ``grid`` is a pyvista mesh with point arrays ``T`` (°C) and ``u`` (m, 3 components).
    """
    import pyvista as pv
    from vtkmodules.vtkCommonCore import vtkLogger

    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_ERROR)  # no X display: VTK falls back quietly
    pv.OFF_SCREEN = True
    warped = grid.warp_by_vector("u", factor=scale)
    p = pv.Plotter(off_screen=True, window_size=(900, 700))
    p.add_mesh(warped, scalars="T", cmap="inferno", show_edges=False,
               scalar_bar_args={"title": "T [°C]"})
    p.add_mesh(grid.outline(), color="grey")
    p.add_text(f"{title}\ndisplacement magnified ×{scale:.0f}", font_size=10)
    if grid.bounds[5] - grid.bounds[4] < 1e-12:
        p.view_xy()
    else:  # y is up; seen from behind and above, so the tool side stays on the left
        p.view_vector((0.35, 0.45, 1.0), viewup=(0.0, 1.0, 0.0))
    with atomic_path(path) as tmp:
        p.screenshot(str(tmp))
    p.close()


def picture_time(figs: dict) -> float:
    """When ``deformed.png`` of :func:`plot_run` shows the frame (s): the first peak of δ, else 1 h."""
    return (figs["first_peak_min"] or 60.0) * 60.0


def plot_run(run, figs: dict, out, title: str, solved: dict | None = None) -> None:
    """``oil_temperatures.png`` (Fig. 10), ``response.png`` (Figs. 11–13) and ``deformed.png``
    (at :func:`picture_time`) of a :class:`~gatetherm.studies.run.scenario.ScenarioRun`
    whose kept states include that time; ``solved``: displacements of kept states, by time,
    if solved already."""
    from pathlib import Path

    from gatetherm.studies.run.output import deformed_grid

    out = Path(out)
    plot_oil(run.columns, out / "oil_temperatures.png", title)
    plot_response(run.columns, out / "response.png", title)
    t, grid = deformed_grid(run, picture_time(figs), solved)
    umax = float(np.abs(grid["u"]).max()) or 1.0
    scale = float(10 ** np.floor(np.log10(0.08 * max(grid.bounds[1] - grid.bounds[0], 1e-9) / umax)))
    render_deformed(grid, out / "deformed.png", f"{title}, t = {t / 60:.0f} min", scale)


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


def plot_case(run, out, title: str, solved: dict | None = None) -> None:
    """``channels.png`` (transient runs) and ``deformed.png`` (the last state, when the case
    has elasticity) of a case run; ``solved`` as for :func:`plot_run`."""
    from pathlib import Path

    from gatetherm.studies.run.output import deformed_grid

    out = Path(out)
    if len(run.columns["time_s"]) > 1:
        plot_channels(run.columns, out / "channels.png", title)
    if run.model.elastic is None:
        return
    t, grid = deformed_grid(run, float(run.columns["time_s"][-1]), solved)
    umax = float(np.abs(grid["u"]).max()) or 1.0
    scale = float(10 ** np.floor(np.log10(0.08 * max(grid.bounds[1] - grid.bounds[0], 1e-9) / umax)))
    render_deformed(grid, out / "deformed.png", f"{title}, t = {t / 3600:.3g} h", scale)
