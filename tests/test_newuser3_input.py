"""A new user's gantry (newuser3): a probe on the surface off by round-off, messages naming the
file or option that lacks a column, a 2-D thickness in mm, the final paths a command prints."""
from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import pytest

from gatetherm import InputError
from gatetherm.geometry.nearest import nearest_on_body
from test_bad_case_input import t3

# ---- 1. probe coordinates on the boundary --------------------------------------------------------


def test_nearest_on_body_closed_form_2d_and_3d():
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    tri = np.array([[0, 1, 2], [0, 2, 3]])
    n = nearest_on_body(square, tri, [0.3, 1.0 + 2e-16])
    assert n.distance == pytest.approx(2e-16, abs=1e-16)  # band: round-off
    assert n.point == pytest.approx([0.3, 1.0], abs=1e-15)
    assert n.tolerance == pytest.approx(np.sqrt(2.0))  # the longest edge of the element, > 1 % of the diagonal
    n = nearest_on_body(square, tri, [2.0, 3.0])
    assert n.point == pytest.approx([1.0, 1.0]) and n.distance == pytest.approx(np.sqrt(5.0))
    cube = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    tet = np.array([[0, 1, 2, 3]])
    n = nearest_on_body(cube, tet, [1.0, 1.0, 1.0])  # above the face x + y + z = 1
    assert n.point == pytest.approx([1 / 3, 1 / 3, 1 / 3]) and n.distance == pytest.approx(2 / np.sqrt(3))
    n = nearest_on_body(cube, tet, [0.2, 0.3, -0.5])  # below the face z = 0
    assert n.point == pytest.approx([0.2, 0.3, 0.0]) and n.distance == pytest.approx(0.5)
    n = nearest_on_body(cube, tet, [-1.0, -1.0, 0.5])  # beside the edge x = y = 0
    assert n.point == pytest.approx([0.0, 0.0, 0.5]) and n.distance == pytest.approx(np.sqrt(2.0))


def test_probe_on_the_boundary_read_with_a_warning(tmp_path: Path, caplog):
    from gatetherm.studies.run.case import load_case

    path = t3(tmp_path, 'point = "target"', "point = [0.05, 0.010000001]")
    with caplog.at_level(logging.WARNING):
        case = load_case(path)
    (probe,) = case.problem.probes
    assert probe.xyz == pytest.approx((0.05, 0.01), abs=1e-9)
    assert "probes.target.point: [0.05, 0.010000001] lies 1e-09 m outside the mesh (within the tolerance 0.0112 m)" \
        in caplog.text
    assert "read at the nearest point on the body, [0.05, 0.01]" in caplog.text


def test_probe_far_from_the_body_refused_with_the_distance(tmp_path: Path):
    from gatetherm.studies.run.case import load_case

    path = t3(tmp_path, 'point = "target"', "point = [0.2, 0.005]")
    with pytest.raises(InputError) as e:
        load_case(path)
    assert "probes.target.point: [0.2, 0.005] lies outside the mesh, 0.1 m from the body (more than the " \
           "tolerance 0.0112 m); the nearest point on it is [0.1, 0.005]" in str(e.value)
