"""The voxel grid and the tool orientations of a reachability map (issue 16)."""

import math

import numpy as np
import pytest

from robokin.cell import VoxelGrid, tool_orientations
from robokin.exceptions import InputError


@pytest.mark.parametrize(("count", "rolls"), [(1, 1), (7, 1), (32, 1), (50, 4)])
def test_orientations_are_rotations_spread_over_the_sphere(count, rolls):
    R = tool_orientations(count, rolls)
    assert R.shape == (count * rolls, 3, 3)
    np.testing.assert_allclose(R @ np.swapaxes(R, -1, -2), np.broadcast_to(np.eye(3), R.shape),
                               atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-12)
    z = R[::rolls, :, 2]  # approach directions
    if count >= 32:
        # a Fibonacci spiral covers the sphere evenly: every direction has a
        # neighbour within twice the mean spacing, and none is duplicated
        cos = np.clip(z @ z.T, -1, 1) - 2 * np.eye(count)
        nearest = np.arccos(cos.max(axis=1))
        spacing = math.sqrt(4 * math.pi / count)
        assert nearest.max() < 2 * spacing and nearest.min() > 0.3 * spacing
        assert abs(z.mean(axis=0)).max() < 0.05  # no side of the sphere favoured
    # the rolls of one direction share its approach axis and turn about it evenly
    if rolls > 1:
        np.testing.assert_allclose(R[:rolls, :, 2], np.broadcast_to(R[0, :, 2], (rolls, 3)),
                                   atol=1e-12)
        x0, axis = R[0, :, 0], R[0, :, 2]
        xs = R[:rolls, :, 0]
        angles = np.arctan2(np.cross(x0, xs) @ axis, xs @ x0)  # turn of x about the axis
        np.testing.assert_allclose(np.sort(np.mod(angles, 2 * np.pi)),
                                   2 * np.pi * np.arange(rolls) / rolls, atol=1e-12)


@pytest.mark.parametrize("bad", [0, -3, 2.5, True, "8"])
def test_orientation_counts_must_be_positive_integers(bad):
    with pytest.raises(InputError, match="argument 'orientations'"):
        tool_orientations(bad)
    with pytest.raises(InputError, match="argument 'rolls'"):
        tool_orientations(4, bad)


def test_grid_covers_the_region_and_numbers_voxels_in_c_order():
    g = VoxelGrid.from_region([[0, -1, 0.5], [1, 1, 1.0]], 0.3)
    assert g.shape == (4, 7, 2) and g.size == 56
    np.testing.assert_allclose(g.bounds[0], [0, -1, 0.5])
    assert (g.bounds[1] >= [1, 1, 1.0]).all() and (g.bounds[1] < np.array([1, 1, 1]) + 0.3).all()
    c = g.centers()
    np.testing.assert_allclose(c[0], [0.15, -0.85, 0.65])
    np.testing.assert_allclose(c[1], [0.15, -0.85, 0.95])  # z varies fastest
    np.testing.assert_array_equal(g.voxel_of(c), np.arange(g.size))
    assert g.voxel_of([5.0, 0, 0]) == -1


def test_centres_do_not_depend_on_the_chunking():
    g = VoxelGrid.from_region([[-0.7, -0.3, 0.1], [0.9, 0.8, 1.3]], 0.037)
    whole = g.centers()
    for step in (1, 7, 1000):
        parts = np.concatenate([g.centers(a, min(a + step, g.size))
                                for a in range(0, g.size, step)])
        assert np.array_equal(parts, whole)


@pytest.mark.parametrize("voxel", [0, -0.05, math.nan, math.inf, "5"])
def test_a_voxel_must_be_a_positive_length(voxel):
    with pytest.raises(InputError, match="argument 'voxel'"):
        VoxelGrid.from_region([[0, 0, 0], [1, 1, 1]], voxel)


@pytest.mark.parametrize(("region", "match"), [
    ([[0, 0, 0], [1, 0, 1]], "is empty: its upper y"),
    ([[0, 0, 0], [-1, 1, 1]], "is empty: its upper x"),
    ([[0, 0, 0]], r"shape \(2, 3\)"),
    ([[0, 0, 0], [1, 1, math.nan]], "non-finite"),
    ("box", "expected"),
])
def test_a_region_must_be_a_non_empty_box(region, match):
    with pytest.raises(InputError, match=f"argument 'region'.*{match}"):
        VoxelGrid.from_region(region, 0.1)


def test_too_many_voxels_are_refused_before_any_work():
    with pytest.raises(InputError, match="argument 'voxel'.*more than 2\\*\\*40"):
        VoxelGrid.from_region([[0, 0, 0], [100, 100, 100]], 1e-5)


def test_voxel_of_needs_points_of_three_coordinates():
    g = VoxelGrid.from_region([[0, 0, 0], [1, 2, 3]], 1.0)
    np.testing.assert_array_equal(g.voxel_of([[0.5, 1.5, 2.5], [0.5, 0.5, 0.5], [5, 0, 0]]),
                                  [5, 0, -1])
    assert g.voxel_of([0.5, 0.5, 1.5]) == 1
    for bad, match in (([1, 2], r"got shape \(2,\)"), (0.5, r"got shape \(\)"),
                       (np.zeros((4, 2)), r"got shape \(4, 2\)"), ("ab", "got 'ab'")):
        with pytest.raises(InputError, match=rf"argument 'points': expected points "
                           rf"\(\.\.\., 3\) \[m\], {match}"):
            g.voxel_of(bad)
