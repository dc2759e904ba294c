"""Shared fixtures: coarse frame meshes, and the observed convergence orders that the
verification tests record and the terminal summary prints."""
from __future__ import annotations

import pytest

from gatetherm.geometry.build import build_mesh
from gatetherm.geometry.frame import FrameParams, MeshParams
from gatetherm.solvers.frame import ModelConfig

COARSE = MeshParams(size=0.02, size_3d=0.02)
"""Mesh density of the shared frame fixtures (about 1.6k triangles / 24k tetrahedra)."""
FIXED = FrameParams(h=0.12, column_height=0.53, l=0.50, l4=0.25, A_C=2.4e-3, tank_wall=0.015, tank_width=0.05)
"""A fixed frame (not the calibrated defaults), so that hand values in tests stay valid."""

FIXED_MODEL = ModelConfig(frame=FIXED, mesh=COARSE)
"""The model whose mesh the fixtures :func:`frame_2d`, :func:`frame_3d` are (a matching pair)."""

_ORDERS = pytest.StashKey[list]()


@pytest.fixture(scope="session")
def frame_2d():
    """The :data:`FIXED` frame meshed in 2-D at :data:`COARSE`."""
    return build_mesh(FIXED, 2, COARSE)


@pytest.fixture(scope="session")
def frame_3d():
    """The :data:`FIXED` frame meshed in 3-D at :data:`COARSE`."""
    return build_mesh(FIXED, 3, COARSE)


@pytest.fixture
def record_order(request, record_property):
    """``record_order(label, observed, expected)``: keep an observed convergence order
    for the session summary and the junit properties."""
    def record(label: str, observed: float, expected: float) -> None:
        request.config.stash.setdefault(_ORDERS, []).append(
            (request.node.nodeid, label, observed, expected))
        record_property(f"order[{label}]", f"{observed:.3f}")
    return record


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    orders = config.stash.get(_ORDERS, [])
    if orders:
        terminalreporter.section("observed convergence orders")
        for nodeid, label, observed, expected in orders:
            terminalreporter.write_line(f"{label:<46} {observed:6.3f}  (expected {expected:g})"
                                        f"   {nodeid.split('::')[0]}")
