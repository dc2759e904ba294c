"""Library plots: ``gt.plot`` draws what the run holds on the Axes it is given (or a new pyplot
figure's) and returns them; the snippet of gt.plot's docstring leaves a notebook's matplotlib
backend as it was; pyvista's global off-screen switch is not touched; the pictures are written by
one writer."""
from __future__ import annotations

import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from matplotlib.figure import Figure

import gatetherm as gt
from gatetherm import InputError
from gatetherm.validation.plots import save
from gatetherm.validation.plots.field import Surface, boundary_edges, surface_of

ROOT = Path(__file__).resolve().parents[1]
CASE = ROOT / "validation" / "examples" / "c_frame" / "case.toml"


def axes(n: int = 1, **kw):
    """Axes of a bare figure: what a test hands to a plot."""
    return Figure().subplots(n, 1, **kw)


@pytest.fixture(scope="module")
def cframe():
    return gt.run(gt.load_case(CASE))


def test_the_documented_snippet_keeps_the_svg_backend(tmp_path):
    """The snippet in a fresh interpreter with ``MPLBACKEND=svg``: the plots made without ``ax=``
    are pyplot figures (they show in a notebook), and the backend is still svg afterwards."""
    snippet = textwrap.dedent(f"""
        import io
        import gatetherm as gt
        case = gt.load_case({str(CASE)!r})
        run = gt.run(case)
        ax = gt.plot.series(run, "delta_um")
        bx = gt.plot.field(run, "T", t=run.time[-1])
        gt.plot.response(run)
        import matplotlib, matplotlib.pyplot as plt
        ax.figure.savefig(io.BytesIO(), format="svg")
        print(matplotlib.get_backend(), plt.get_fignums(), ax.figure is plt.figure(1), bx.figure is plt.figure(2))
    """)
    env = {**os.environ, "MPLBACKEND": "svg"}
    out = subprocess.run([sys.executable, "-c", snippet], env=env, cwd=tmp_path, capture_output=True, text=True,
                         timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split("\n")[-2] == "svg [1, 2, 3] True True"


def test_series_draws_the_columns(cframe):
    ax = gt.plot.series(cframe, "delta_um", "drift_x_um", ax=axes())
    assert [line.get_label() for line in ax.lines] == ["delta_um", "drift_x_um"]
    assert np.array_equal(ax.lines[0].get_ydata(), cframe["delta_um"])
    assert np.array_equal(ax.lines[1].get_xdata(), cframe.time / 3600.0)
    assert ax.get_ylabel() == "displacement [µm]"


def test_channels_and_response(cframe):
    top, bottom = gt.plot.channels(cframe, axes=axes(2))
    temps = [k for k in cframe.columns if k.endswith("_degC")]
    assert [line.get_label() for line in top.lines] == temps
    assert [line.get_label() for line in bottom.lines] == [k for k in cframe.columns if k.endswith("_um")]
    assert np.array_equal(top.lines[-1].get_ydata(), cframe[temps[-1]])
    a1, a2 = gt.plot.response(cframe, axes=axes(2))
    theta = cframe["theta_B_degC"]
    assert np.array_equal(a1.lines[1].get_ydata(), theta - theta[0])  # the rise of θ_B
    assert np.array_equal(a2.lines[0].get_ydata(), cframe["delta_um"]) and not a1.patches  # no pump: no shading


def test_fluids_of_the_frame():
    """The paper frame's tank: supply, oil and wall (mean), one grey band per pump phase."""
    from conftest import fixed_condition

    case, schedule = fixed_condition(150)  # pump on for the first hour, off, on again at 2 h
    run = gt.run(case, schedule, keep=())
    ax = gt.plot.fluids(run, ax=axes())
    assert [line.get_label() for line in ax.lines] == ["supply", "tank oil", "tank wall (mean)"]
    assert np.array_equal(ax.lines[1].get_ydata(), run["T_tank_oil_degC"])
    assert len(ax.patches) == 2 and ax.patches[0].get_label() == "pump on"


def test_field_in_2d_is_the_nodal_field(cframe):
    ax = gt.plot.field(cframe, "T", ax=axes())
    mesh = ax.collections[0]
    assert np.array_equal(mesh.get_array(), cframe.field("T"))
    assert ax.get_title() == "C-frame machining centre, t = 6 h"
    u = gt.plot.field(cframe, "u", t=3600.0, ax=axes()).collections[0].get_array()
    assert np.allclose(u, 1e6 * np.linalg.norm(cframe.field("u", 3600.0), axis=1), rtol=1e-15, atol=0)
    with pytest.raises(InputError, match="no state kept at 30 s"):
        gt.plot.field(cframe, "T", t=30.0)


def test_field_in_3d_is_a_surface_picture_and_leaves_pyvista_on_screen(tmp_path):
    import pyvista as pv

    from test_assembly_mesh import BOX, CASE_GROUPS  # a 1 x 2 x 3 m box, one face at 100 °C, a film elsewhere

    (tmp_path / "box.geo").write_text(BOX)
    (tmp_path / "case.toml").write_text(CASE_GROUPS)
    run = gt.run(gt.load_case(tmp_path / "case.toml"))
    before = pv.OFF_SCREEN
    ax = gt.plot.field(run, "T", ax=axes())
    assert pv.OFF_SCREEN is before
    T = run.field("T")
    image, = ax.images
    assert image.get_array().shape[2] in (3, 4) and min(image.get_array().shape[:2]) > 300
    bar = ax.figure.axes[-1]  # the colour bar over the field's range
    assert bar.get_ylim() == pytest.approx((T.min(), T.max()), rel=1e-12)
    assert T.max() == pytest.approx(100.0, abs=1e-9)  # the hot face


def test_the_surface_of_a_mesh_is_closed_and_faces_out():
    """The surface of a tetrahedral box, each triangle turned outward: the divergence theorem
    gives the box's volume from it (one triangle turned in would take twice its share off), and
    its nodes are scikit-fem's boundary nodes."""
    from skfem import MeshTet

    mesh = MeshTet.init_tensor(np.linspace(0, 1, 5), np.linspace(0, 2, 4), np.linspace(0, 3, 6))
    s = surface_of(mesh)
    a, b, c = (s.points[s.triangles[:, k]] for k in range(3))
    assert np.einsum("ij,ij->", a, np.cross(b - a, c - a)) / 6 == pytest.approx(6.0, rel=1e-13)
    assert np.array_equal(s.nodes, mesh.boundary_nodes()) and len(s.triangles) == 2 * 2 * (12 + 20 + 15)


def test_a_3d_deformed_picture_from_the_surface_is_the_one_from_the_volume(tmp_path):
    """The 3-D deformed picture drawn from the body's :class:`Surface` (what a painting process is
    sent: a fraction of the mesh) and from the whole mesh, as before: the same
    pixels but for the shading's rounding: one level on under 0.5 % of them (826 of 1 228 800),
    more on at most ten (2: an edge's rasterisation)."""
    import dataclasses

    import matplotlib.image

    from conftest import fixed_case
    from gatetherm.studies.run.output import nearest_state, nodal_fields
    from gatetherm.frame.conditions import condition_schedule
    from gatetherm.validation.plots.field import deformed, render_deformed

    sched = condition_schedule(1)
    run = gt.run(fixed_case(3), dataclasses.replace(sched, times=sched.times[:16])).scenario
    surface, fields, title, scale = deformed(run, 900.0, "t")
    assert isinstance(surface, Surface) and len(surface.nodes) < len(run.model.fmesh.points)
    whole = nodal_fields(run.model, nearest_state(run, 900.0)[1], stress=False)
    for name, (mesh, f) in {"surface": (surface, fields), "volume": (run.model.fmesh, whole)}.items():
        save(render_deformed(mesh, f, title, scale, ax=axes()), tmp_path / f"{name}.png")
    a, b = (np.round(255 * matplotlib.image.imread(tmp_path / f"{n}.png")) for n in ("surface", "volume"))
    assert a.shape == b.shape
    d = np.abs(a - b).max(axis=-1)
    assert np.count_nonzero(d > 1) <= 10 and np.count_nonzero(d) < 0.005 * d.size, (d.max(), np.count_nonzero(d))


def test_deformed_picture(cframe, tmp_path):
    """In 2-D a tripcolor of T on the nodes moved by scale × u, the undeformed outline in grey."""
    ax = gt.plot.deformed(cframe, ax=axes())
    assert "t = 6 h" in ax.get_title()
    scale = float(re.search(r"magnified ×(\d+)", ax.get_title())[1])
    colours, outline = ax.collections
    xy, u = cframe.case.mesh.points[:, :2], cframe.field("u")[:, :2]
    moved = colours._triangulation
    assert np.allclose(np.c_[moved.x, moved.y], xy + scale * u, rtol=0, atol=1e-12)
    assert np.array_equal(colours.get_array(), cframe.field("T"))
    mesh = cframe.scenario.model.heat.basis.mesh
    facets = np.sort(mesh.facets[:, mesh.boundary_facets()].T, axis=1)  # scikit-fem's own boundary
    edges = boundary_edges(np.asarray(cframe.case.mesh.cells)[:, :3])
    assert np.array_equal(edges, facets[np.lexsort(facets.T[::-1])])
    assert len(outline.get_segments()) == len(edges) == 313
    save(ax, tmp_path / "d.png")
    assert (tmp_path / "d.png").stat().st_size > 10_000


def test_save_writes_matplotlibs_pixels(tmp_path):
    """The PNG holds the pixels of matplotlib's own, opaque or not (only its compression differs)."""
    from PIL import Image

    fig = Figure(figsize=(2.3, 1.7))
    fig.subplots().plot([0, 1], [0, 2], label="a")
    for alpha in (1.0, 0.0):
        fig.patch.set_alpha(alpha)
        save(fig, tmp_path / "ours.png", dpi=60, tight=False)
        fig.savefig(tmp_path / "theirs.png", format="png", dpi=60)
        ours, theirs = Image.open(tmp_path / "ours.png"), Image.open(tmp_path / "theirs.png")
        assert (ours.mode, ours.size) == (theirs.mode, theirs.size) == ("RGBA", (138, 102))
        assert np.array_equal(np.asarray(ours), np.asarray(theirs))
        assert (np.asarray(ours)[..., 3] == 255).all() == (alpha == 1.0)


def _labels(ax) -> list[str]:
    return [line.get_label() for line in ax.lines if not line.get_label().startswith("_")]


def test_compensation(cframe):
    """The paper's method with the C-frame's actuator: four panels, the stroke named as the piezo
    model's, R_i and R_C, every axis with its unit."""
    comp = gt.compensate(cframe, method="paper")
    ax = gt.plot.compensation(comp, axes=axes(4))
    assert np.array_equal(ax[0].lines[0].get_ydata(), cframe["delta_um"])
    assert np.array_equal(ax[2].lines[0].get_ydata(), comp.loop.delta_comp_um)
    assert np.array_equal(ax[2].lines[1].get_ydata(), comp.loop.stroke_um)
    assert _labels(ax[2]) == ["compensated δ", "actuator stroke (piezo model)"] and _labels(ax[3]) == ["R_i", "R_C"]
    assert [a.get_ylabel() for a in ax] == ["δ [µm]", "δ − δ_et [µm]", "compensated δ [µm]",
                                            "correction factor [1]"]
    assert ax[3].get_xlabel() == "time [h]" and ax[0].get_title() == comp.label


def test_compensation_without_actuator_or_factors_draws_neither(cframe):
    """mlr without an actuator (the rom and errormodel methods have no R_i, R_C either): three
    panels, the fourth given removed; no stroke, no actuator named, no empty R panel."""
    comp = gt.compensate(cframe, method="mlr", actuator=None)
    given = axes(4)
    ax = gt.plot.compensation(comp, axes=given)
    assert len(ax) == 3 and len(given[0].figure.axes) == 3
    assert _labels(ax[2]) == ["compensated δ"]
    text = " ".join(label for a in ax for label in (*_labels(a), a.get_ylabel(), a.get_title()))
    assert "piezo" not in text and "actuator" not in text and "R_i" not in text and "cutting" not in text
    assert all(a.get_ylabel().endswith("[µm]") for a in ax) and ax[2].get_xlabel() == "time [h]"


def test_response_names_the_cases_own_signals(cframe):
    """The C-frame's δ is the table top against the tool along y; θ_A … its probes: no "tips F"."""
    a1, a2 = gt.plot.response(cframe, axes=axes(2))
    assert _labels(a2) == ["δ = u_y(table_top) − u_y(tool)"]
    assert _labels(a1) == ["θ_A (probe TF)", "θ_B (probe TB)", "θ_C (probe TS)"]
    assert a1.get_ylabel() == "temperature rise [K]" and a2.get_ylabel() == "δ [µm] (+ = approach)"


def test_a_steady_picture_is_titled_steady_state(tmp_path):
    """A steady thermoelastic bar (no [time]): its pictures say so, not "t = 0"."""
    from test_order_check import free_bar

    from gatetherm.validation.plots.run import state_title

    run = gt.run(free_bar(tmp_path, 40.0))
    assert gt.plot.deformed(run, ax=axes()).get_title().startswith("case, steady state\ndisplacement magnified")
    assert gt.plot.field(run, "T", ax=axes()).get_title() == "case, steady state"
    assert state_title("lathe", None) == "lathe, steady state" and state_title("lathe", 1800.0) == "lathe, t = 30 min"


def test_drift_inputs_have_their_units_and_no_empty_panel():
    """A pump alone: on the panel's own axis, labelled 1 = on; a spindle's power in W beside a
    room temperature; no inputs: no empty 0-1 panel, the time axis on the temperatures'."""
    from gatetherm.validation.plots.drift import plot_drift

    t = np.arange(0.0, 7200.0, 60.0)
    d, T = {"delta_um": np.sin(t / 900)}, {"T_bed_degC": np.cos(t / 900)}
    ax = plot_drift(t, d, T, {"pump": (t > 1800).astype(float)}, None, "lathe", axes=axes(3))
    assert ax[2].get_ylabel() == "pump [1 = on, 0 = off]" and len(ax[2].figure.axes) == 3
    ax = plot_drift(t, d, T, {"ambient_degC": 20 + 0 * t, "spindle_W": 60 + 0 * t}, None, "lathe", axes=axes(3))
    assert ax[2].get_ylabel() == "input temperature [°C]" and ax[2].figure.axes[-1].get_ylabel() == "spindle_W [W]"
    ax = plot_drift(t, d, T, {}, None, "lathe", axes=axes(3))
    assert not ax[2].get_visible() and ax[1].get_xlabel() == "time [min]"
    assert [a.get_ylabel() for a in ax[:2]] == ["displacement drift [µm]", "temperature drift [K]"]


def test_sweep_axes_carry_their_units():
    """A case study's swept film and its result: both axes with units, the hue's legend too."""
    rows = [{"thermal.free.film": f, "materials.spindle.alpha": a, "delta_final_um": f * a * 1e5}
            for f in (6.0, 10.0) for a in (1.15e-5, 1.25e-5)]
    ax = gt.plot.sweep(rows, "thermal.free.film", "delta_final_um", "materials.spindle.alpha", ax=axes())
    assert ax.get_xlabel() == "thermal.free.film [W/(m² K)]" and ax.get_ylabel() == "delta_final_um [µm]"
    assert _labels(ax) == ["materials.spindle.alpha = 1.15e-05 1/K", "materials.spindle.alpha = 1.25e-05 1/K"]
    from gatetherm.validation.plots.labels import axis_label

    assert [axis_label(k) for k in ("sources.spindle.power", "effect.heat_source@arm", "swing_um", "Ki_F_fe",
                                    "derived.beta", "geometry.l4", "mesh.parameters.h")] == [
        "sources.spindle.power [W]", "effect.heat_source@arm [W]", "swing_um [µm]", "Ki_F_fe [µm/K]",
        "derived.beta [1]", "geometry.l4 [m]", "mesh.parameters.h"]


def test_prediction(cframe):
    from gatetherm.studies.errormodel.fit import FitParams, fit_error_model
    from gatetherm.studies.errormodel.model import predict

    model = fit_error_model(cframe.columns, ["delta_um"], ["theta_A_degC", "theta_B_degC", "theta_C_degC"],
                            params=FitParams(form="static"))
    (left, right), = gt.plot.prediction(model, cframe, axes=Figure().subplots(1, 2))
    measured, predicted = left.lines
    assert np.array_equal(measured.get_ydata(), cframe["delta_um"])
    assert np.array_equal(predicted.get_ydata(), predict(model, cframe.columns)["delta_um"])
    assert np.array_equal(right.lines[0].get_ydata(), cframe["delta_um"] - predicted.get_ydata())
    assert len(left.patches) == 1  # the fitting span


def test_residuals():
    """A diagnosis' residuals (a stand-in with the fields the plot reads; ``gatetherm diagnose``
    draws a real one in tests/test_discrepancy.py)."""
    from gatetherm.studies.diagnosis.locate import Phase

    t = np.arange(0.0, 5 * 3600.0 + 1, 60.0)
    r = {"delta_um": np.where(t > 3 * 3600.0, 1.0, 0.0) + 0.01 * np.sin(t), "theta_A_degC": 0.01 * np.cos(t)}
    diag = SimpleNamespace(time_s=t, channels=tuple(r), residual_before=r, train_end_s=3 * 3600.0,
                           phases=(Phase("heating", 0.0, 3600.0), Phase("pump off", 3600.0, t[-1], True)))
    ax = gt.plot.residuals(diag, axes=axes(2))
    assert ax.shape == (2, 1)
    lines = {line.get_label(): line.get_ydata() for line in ax[0, 0].lines}
    assert np.array_equal(lines["measured − model"], r["delta_um"])
    assert ax[0, 0].get_ylabel() == "δ (µm)" and ax[1, 0].get_ylabel() == "θ_A (K)"
    significant = lines["significant"]  # the step of 1 µm after 3 h stands out, the noise does not
    assert np.isfinite(significant[t > 3.5 * 3600.0]).all() and np.isnan(significant[t < 2.5 * 3600.0]).all()


def test_sweep_from_rows_and_from_the_table(tmp_path):
    from gatetherm.studies.sweeps.runner import write_table

    rows = [{"film": f, "h": h, "delta_um": 10 * f + h} for h in (1, 2) for f in (3.0, 1.0, 2.0)]
    ax = gt.plot.sweep(rows, "film", "delta_um", hue="h", ax=axes())
    assert [line.get_label() for line in ax.lines] == ["h = 1", "h = 2"]
    assert list(ax.lines[1].get_xdata()) == [1.0, 2.0, 3.0] and list(ax.lines[1].get_ydata()) == [12.0, 22.0, 32.0]
    write_table(tmp_path / "table.csv", ["film", "h", "delta_um"], rows)
    again = gt.plot.sweep(tmp_path / "table.csv", "film", "delta_um", hue="h", ax=axes())
    assert [list(line.get_ydata()) for line in again.lines] == [list(line.get_ydata()) for line in ax.lines]


def test_every_plot_of_gt_plot_is_tested():
    tested = {n.removeprefix("test_") for n in globals() if n.startswith("test_")}
    names = set(gt.plot.__all__) - {"save", "Painter"}  # the painter: tests/test_painter.py
    assert all(any(n in t for t in tested) for n in names), names


def test_sensor_curve_and_sensors_draw_a_placement():
    """The C-frame meshed coarse, 2 sensors from 3 loads: the curve has a held-out and a
    leave-one-load-out line per target (and the case's TF, TB, TS star); the machine picture marks
    the chosen points and the case's thermocouples."""
    case = gt.load_case(CASE, mesh_factor=3.0)
    p = gt.place_sensors(case, 2, loads=3, held_out_loads=1, states=8)
    ax = gt.plot.sensor_curve(p, ax=axes())
    targets = list(p.curve[0].held_out_mae_um)
    assert [line.get_label() for line in ax.lines][:2] == [f"{targets[0]}, held-out loads",
                                                           f"{targets[0]}, leave one training load out"]
    assert list(ax.lines[0].get_ydata()) == [c.held_out_mae_um[targets[0]] for c in p.curve]
    bx = gt.plot.sensors(p, case, ax=axes())
    marked = {t.get_text(): t.xy for t in bx.texts}
    assert {s.name: s.xyz for s in p.sensors}.items() <= marked.items()
    assert {"TF", "TB", "TS"} <= set(marked)
