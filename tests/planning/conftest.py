"""Fixtures of the planning tests (helpers and the oracle: tests/planning_oracle.py)."""

from __future__ import annotations

import pytest

pytest.importorskip("coal")


@pytest.fixture(scope="session")
def l_mesh(tmp_path_factory):
    """A non-convex mesh file (an L of two boxes), its convex hull far from it."""
    trimesh = pytest.importorskip("trimesh")
    a = trimesh.creation.box(extents=[0.4, 0.08, 0.08])
    b = trimesh.creation.box(extents=[0.08, 0.4, 0.08])
    b.apply_translation([0.16, 0.16, 0.0])
    path = tmp_path_factory.mktemp("mesh") / "L.stl"
    trimesh.util.concatenate([a, b]).export(path)
    return path
