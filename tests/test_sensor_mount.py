"""Sensors only where they can be mounted (issue 51): a case's ``[sensors] exclude`` names the
parts that rotate or move; sensor placement and the diagnosis' sensor faults leave them out, and
the placement says so. On the lathe headstock of tests/data (its spindle excluded)."""
import dataclasses
import shutil
from pathlib import Path

import numpy as np
import pytest

import gatetherm as gt
from gatetherm import InputError
from gatetherm.solvers.problem import Probe
from gatetherm.studies.diagnosis.hypotheses import sensor_pieces, unmounted
from gatetherm.studies.sensors.candidates import candidates, part_at, unmountable_nodes

DATA = Path(__file__).parent / "data"
FILES = ("headstock.toml", "headstock.geo", "headstock_schedule.csv")


@pytest.fixture(scope="module")
def headstock():
    return gt.load_case(DATA / "headstock.toml")


def _copy(tmp_path, old: str, new: str) -> Path:
    for f in FILES:
        shutil.copy(DATA / f, tmp_path / f)
    text = (DATA / "headstock.toml").read_text()
    assert old in text
    (tmp_path / "headstock.toml").write_text(text.replace(old, new))
    return tmp_path / "headstock.toml"


def test_the_key_is_read_and_a_wrong_name_is_one_line(headstock, tmp_path):
    assert headstock.unmountable == ("spindle",)
    path = _copy(tmp_path, 'exclude = ["spindle"]', 'exclude = ["spindel"]')
    with pytest.raises(InputError, match=r"sensors.*exclude.*'spindel' is not a region or boundary of the mesh") as e:
        gt.load_case(path)
    assert "\n" not in str(e.value) and "spindle" in str(e.value)  # the fix lists the names


def test_candidates_leave_out_every_node_of_the_spindle(headstock):
    """Every outer node of the spindle (its interfaces with the bearings included) is left out,
    and nothing else: 276 outer nodes, 63 of them the spindle's."""
    mesh = headstock.mesh
    every, kept = candidates(mesh), candidates(mesh, unmountable=headstock.unmountable)
    spindle = unmountable_nodes(mesh, ["spindle"])["spindle"]
    assert (len(every), len(kept), kept.excluded) == (276, 213, {"spindle": 63})
    assert not np.isin(kept.nodes, spindle).any()
    assert set(every.nodes) - set(kept.nodes) == set(every.nodes) & set(spindle)


def test_part_at_finds_regions_and_boundaries(headstock):
    m, names = headstock.mesh, ["spindle", "bearing_front", "feet_fixed"]
    assert part_at(m, names, (0.5, 0.36)) == "spindle"  # inside
    assert part_at(m, names, (0.72, 0.33)) == "spindle"  # the corner it shares with the front bearing
    assert part_at(m, names, (0.70, 0.31)) == "bearing_front"
    assert part_at(m, names, (0.05, 0.0)) == "feet_fixed"  # on a facet, not a node
    assert part_at(m, names, (0.45, 0.55)) is None and part_at(m, names, (0.5, 0.30)) is None


def test_the_diagnosis_tries_no_fault_of_a_thermocouple_on_the_spindle(headstock):
    p = headstock.problem
    case = dataclasses.replace(headstock, problem=dataclasses.replace(
        p, probes=(*p.probes, Probe("TS", (0.5, 0.36), ("T",)))))
    channels = ["T_TH_degC", "T_TS_degC", "delta_um"]
    assert unmounted(case, channels) == {"T_TS_degC": "spindle"}
    keys = {x.key for x in sensor_pieces(channels, case)}
    assert not any(k.endswith("@T_TS_degC") for k in keys)
    assert {"sensor:sensor_offset@T_TH_degC", "sensor:sensor_lag@T_TH_degC", "sensor:sensor_gain@delta_um"} <= keys
    mounted = dataclasses.replace(case, unmountable=())
    assert "sensor:sensor_offset@T_TS_degC" in {x.key for x in sensor_pieces(channels, mounted)}


def test_placement_puts_no_sensor_on_the_spindle(headstock):
    """A small placement (the reduced model about 3 s once pyMOR is loaded): no sensor on the spindle,
    and the summary (summary.json) lists it."""
    spindle = unmountable_nodes(headstock.mesh, ["spindle"])["spindle"]
    placed = gt.place_sensors(headstock, 2, loads=4, held_out_loads=2, states=12)
    assert len(placed.sensors) == 2 and not np.isin([s.node for s in placed.sensors], spindle).any()
    assert placed.summary()["excluded"] == {"spindle": 63, "feet_fixed": 7, "feet_sliding": 7}


def test_no_sensor_between_a_foot_and_the_bed(headstock):
    """The feet stand on the bed (one fixed, one sliding): the nodes between a foot and the bed are no
    candidates; those of its edges, on its free side too, are, named by that side; a face named as
    the candidates stays one."""
    from gatetherm.studies.sensors.candidates import boundary_names, seated_nodes
    from gatetherm.studies.sensors.place import supported_faces

    mesh, seats = headstock.mesh, supported_faces(headstock)
    assert seats == ("feet_fixed", "feet_sliding") and supported_faces(headstock, ("feet_fixed",)) == ("feet_sliding",)
    seated = seated_nodes(mesh, seats)
    for name in seats:
        face = np.unique(mesh.boundaries[name])
        edges = np.setdiff1d(face, seated[name])
        assert len(seated[name]) == len(face) - 2 and len(edges) == 2  # a 2-D foot: its two corners stay
        assert set(boundary_names(mesh, edges, seats)) == {"free"} and set(boundary_names(mesh, edges)) == {name}


@pytest.mark.slow
def test_placement_puts_no_sensor_on_the_spindle_and_says_so(headstock, tmp_path, capsys):
    """Without the key the best single sensor is a spindle node; with it none is, and the
    printout and summary.json list the exclusion."""
    from gatetherm.cli import main

    spindle = unmountable_nodes(headstock.mesh, ["spindle"])["spindle"]
    free = gt.place_sensors(dataclasses.replace(headstock, unmountable=()), 3, loads=6, held_out_loads=2, states=16)
    assert np.isin([s.node for s in free.sensors], spindle).any()  # what the key prevents
    placed = gt.place_sensors(headstock, 3, loads=6, held_out_loads=2, states=16)
    assert not np.isin([s.node for s in placed.sensors], spindle).any()
    assert placed.summary()["excluded"] == {"spindle": 63, "feet_fixed": 7, "feet_sliding": 7}
    assert placed.curve[-1].held_out_mae_um["delta_um"] == pytest.approx(0.101, abs=0.02)  # band: < 0.5 µm
    for f in FILES:
        shutil.copy(DATA / f, tmp_path / f)
    assert main(["sensors", "--case", str(tmp_path / "headstock.toml"), "--out", str(tmp_path / "s"), "--count", "2",
                 "--loads", "4", "--states", "12"]) == 0
    out = capsys.readouterr().out
    assert "excluded (cannot carry a sensor: [sensors] exclude, or a face a support holds): spindle (63 candidate " \
        "nodes left out), feet_fixed (7 candidate nodes left out), feet_sliding (7 candidate nodes left out)" in out
    assert "# none on spindle (63 candidate nodes), feet_fixed (7 candidate nodes), feet_sliding (7 candidate nodes) " \
        "(cannot carry a sensor: [sensors] exclude, or a face a support holds)" in (tmp_path / "s" / "sensors.toml"
                                                                                  ).read_text()


def test_the_axis_of_an_axisymmetric_section_is_no_surface():
    """The rotary table's section: its outline's facets on r = 0 lie inside the solid of revolution;
    the axis nodes that stay are on an end face."""
    from gatetherm.studies.sensors.candidates import outer_facets, surface_facets

    case = gt.load_case(Path(__file__).resolve().parents[1] / "validation" / "examples" / "rotary_table" / "case.toml")
    mesh = case.mesh
    plain = candidates(mesh, unmountable=case.unmountable)
    axis = candidates(mesh, unmountable=case.unmountable, axisymmetric=True)
    on_axis = np.abs(axis.xyz[:, 0]) < 1e-12
    assert (len(plain.nodes), len(axis.nodes), int(on_axis.sum())) == (55, 52, 2)
    assert len(outer_facets(mesh.cells)) - len(surface_facets(mesh, True)) == 7  # the axis' facets (table, bed)
    assert not np.any(np.all(np.abs(mesh.points[surface_facets(mesh, True), 0]) < 1e-12, axis=1))


def test_a_sensor_on_a_part_a_rotating_film_bounds_is_noted(tmp_path):
    """The spindle unit without its [sensors] exclude: the placement notes the sensors on its shaft."""
    src = Path(__file__).resolve().parents[1] / "validation" / "examples" / "spindle_unit"
    shutil.copytree(src, tmp_path / "s")
    text = (tmp_path / "s" / "case.toml").read_text()
    (tmp_path / "s" / "case.toml").write_text(text.replace('exclude = ["shaft"]', "exclude = []"))
    placed = gt.place_sensors(gt.load_case(tmp_path / "s" / "case.toml"), count=3)
    shaft = [n for n in placed.notes if "lies on region 'shaft'" in n]
    assert [n.split()[0] for n in shaft] == ["S1", "S3"]
    assert shaft[0] == ("S1 lies on region 'shaft', which the rotating_cylinder film of 'nose' bounds: if it rotates, "
                        "no thermocouple can go there; name it in [sensors] exclude")
    assert not any("lies on region" in n for n in gt.place_sensors(gt.load_case(src / "case.toml"), count=3).notes)
