"""Workspace sampling: bounds against hand-derived reach, voxel volume, plots, CLI."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import robokin
from robokin.exceptions import InputError
from robokin.kinematics.workspace import (
    random_joints,
    sample_workspace,
    voxel_volume,
)
from robokin.viz.plots import plot_cross_section, save_workspace_plots

# SCARA (robot file / its paper): x = c2 cos q1 + c3 cos(q1 + q2), z = c1 + c4 + l4.
C1, C2, C3, C4 = 0.400, 0.325, 0.275, -0.150
# UR5 published DH lengths [m].
UR5_D1, UR5_A2, UR5_A3 = 0.089159, 0.425, 0.39225
UR5_D4, UR5_D5, UR5_D6 = 0.10915, 0.09465, 0.0823


def _scara_hand_bounds() -> np.ndarray:
    """Dense grid of the SCARA's planar formula over its joint limits."""
    q1 = np.radians(np.linspace(-150, 150, 1201))[:, None]
    q2 = np.radians(np.linspace(-145, 145, 1161))[None, :]
    x = C2 * np.cos(q1) + C3 * np.cos(q1 + q2)
    y = C2 * np.sin(q1) + C3 * np.sin(q1 + q2)
    return np.array([[x.min(), y.min(), C1 + C4], [x.max(), y.max(), C1 + C4 + 0.2]])


def _ur5_reach() -> float:
    """Farthest tool point from the shoulder (0, 0, d1).

    Joints 2-4 are parallel: the upper arm and forearm (a2 + a3) stretch in the
    arm plane; d5 lies in that plane, d6 is perpendicular to d5 at an angle beta
    out of the plane, and d4 is the lateral offset along the parallel axes:
    R(beta)^2 = (a2 + a3 + sqrt(d5^2 + (d6 sin beta)^2))^2 + (d4 + d6 cos beta)^2.
    """
    beta = np.linspace(0.0, np.pi, 200001)
    inplane = UR5_A2 + UR5_A3 + np.sqrt(UR5_D5**2 + (UR5_D6 * np.sin(beta)) ** 2)
    lateral = UR5_D4 + UR5_D6 * np.cos(beta)
    return float(np.sqrt(inplane**2 + lateral**2).max())


def test_scara_bounds_match_the_planar_formula():
    ws = sample_workspace(robokin.load("scara"), 200_000, rng=np.random.default_rng(3))
    ref = _scara_hand_bounds()
    # Never outside the true set; within a few mm of it with 200k samples.
    assert np.all(ws.bounds[0] >= ref[0] - 1e-9)
    assert np.all(ws.bounds[1] <= ref[1] + 1e-9)
    np.testing.assert_allclose(ws.bounds, ref, atol=5e-3)
    # Reach is the sum of the two link lengths, exactly the stretched arm.
    assert ws.bounds[1, 0] == pytest.approx(C2 + C3, abs=1e-3)
    radial = np.hypot(ws.points[:, 0], ws.points[:, 1])
    assert radial.max() <= C2 + C3 + 1e-12
    # The elbow limit (145 deg) leaves a hole around the shaft.
    r_min = math.sqrt(C2**2 + C3**2 + 2 * C2 * C3 * math.cos(math.radians(145)))
    assert radial.min() >= r_min - 1e-12
    assert radial.min() == pytest.approx(r_min, abs=5e-3)


def test_ur5_bounds_within_link_length_sum_and_reach():
    robot = robokin.load("ur5")
    ws = sample_workspace(robot, 300_000, rng=np.random.default_rng(5))
    shoulder = np.array([0.0, 0.0, UR5_D1])
    dist = np.linalg.norm(ws.points - shoulder, axis=1)
    link_sum = UR5_A2 + UR5_A3 + UR5_D4 + UR5_D5 + UR5_D6
    reach = _ur5_reach()
    assert 0.949 < reach < link_sum
    assert dist.max() <= reach + 1e-9
    assert dist.max() >= 0.97 * reach
    # All joints turn fully: the bounds are (nearly) a sphere of radius `reach`.
    np.testing.assert_allclose(ws.bounds[1, :2], [reach, reach], rtol=0.04)
    np.testing.assert_allclose(ws.bounds[0, :2], [-reach, -reach], rtol=0.04)
    assert ws.bounds[1, 2] <= UR5_D1 + reach + 1e-9
    assert ws.bounds[1, 2] == pytest.approx(UR5_D1 + reach, rel=0.04)
    assert np.all(np.abs(ws.bounds) <= UR5_D1 + link_sum)


def test_voxel_volume_of_a_cartesian_gantry_is_its_box():
    # Three orthogonal prismatic axes: the workspace is a 0.5 x 0.3 x 0.2 m box.
    rows = [
        {
            "joint": "prismatic",
            "a": 0,
            "alpha": -math.pi / 2,
            "d": 0,
            "theta": 0,
            "limits": [0.0, 0.5],
        },
        {
            "joint": "prismatic",
            "a": 0,
            "alpha": -math.pi / 2,
            "d": 0,
            "theta": -math.pi / 2,
            "limits": [0.0, 0.3],
        },
        {
            "joint": "prismatic",
            "a": 0,
            "alpha": 0,
            "d": 0,
            "theta": 0,
            "limits": [0.0, 0.2],
        },
    ]
    robot = robokin.Robot.from_dh(rows, name="gantry")
    ws = sample_workspace(robot, 400_000, rng=np.random.default_rng(0), voxel_size=0.02)
    np.testing.assert_allclose(np.sort(ws.extent), [0.2, 0.3, 0.5], atol=2e-3)
    assert ws.volume == pytest.approx(0.5 * 0.3 * 0.2, rel=0.03)


def test_voxel_volume_counts_distinct_cells():
    pts = np.array([[0.0, 0, 0], [0.05, 0.05, 0.05], [0.15, 0, 0], [0.0, 0, 0.25]])
    vol, n = voxel_volume(pts, 0.1)
    assert n == 3
    assert vol == pytest.approx(3e-3)
    with pytest.raises(InputError, match="voxel_size"):
        voxel_volume(pts, 0.0)


def test_random_joints_stay_inside_limits(rng):
    lim = np.array([[-1.0, 2.0], [0.0, 0.1]])
    q = random_joints(rng, lim, 10_000)
    assert q.shape == (10_000, 2)
    assert np.all(q >= lim[:, 0]) and np.all(q <= lim[:, 1])
    assert q[:, 0].min() < -0.99 and q[:, 0].max() > 1.99
    with pytest.raises(InputError, match="finite limits"):
        random_joints(rng, [[0, np.inf]], 3)


def test_manipulability_subset_matches_jacobian():
    robot = robokin.load("ur5")
    ws = sample_workspace(
        robot,
        5_000,
        rng=np.random.default_rng(1),
        keep_q=True,
        manipulability_samples=200,
    )
    assert ws.manipulability.shape == (200,)
    q = ws.q[ws.manipulability_index]
    J = robot.jacobian(q)
    ref = np.sqrt(np.abs(np.linalg.det(J @ np.swapaxes(J, -1, -2))))
    np.testing.assert_allclose(ws.manipulability, ref, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(
        robot.fk(q)[:, :3, 3], ws.points[ws.manipulability_index]
    )


def test_progress_and_errors():
    robot = robokin.load("scara")
    calls = []
    sample_workspace(robot, 1000, chunk=300, progress=lambda d, t: calls.append((d, t)))
    assert calls == [(300, 1000), (600, 1000), (900, 1000), (1000, 1000)]
    with pytest.raises(InputError, match="n_samples"):
        sample_workspace(robot, 0)
    slider = robokin.Robot.from_dh(
        [
            {
                "joint": "prismatic",
                "a": 0,
                "alpha": 0,
                "d": 0,
                "theta": 0,
                "name": "slide",
            }
        ]
    )
    with pytest.raises(InputError, match="slide"):
        sample_workspace(slider, 10)


def test_plots_written(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    ws = sample_workspace(robokin.load("scara"), 20_000, rng=np.random.default_rng(2))
    paths = save_workspace_plots(ws, tmp_path)
    assert [p.name for p in paths] == [
        "scara_workspace_xy.png",
        "scara_workspace_xz.png",
    ]
    for p in paths:
        assert p.stat().st_size > 10_000
    ax = plot_cross_section(ws, "xz", color_by="density")
    assert ax.get_xlabel() == "x [m]" and ax.get_ylabel() == "z [m]"
    with pytest.raises(InputError, match="plane"):
        plot_cross_section(ws, "zz")


def test_cli_workspace(tmp_path):
    from robokin.cli import main

    rc = main(
        ["workspace", "scara", "--samples", "20000", "--out", str(tmp_path), "--json"]
    )
    assert rc == 0
    summary = json.loads((tmp_path / "scara_workspace.json").read_text())
    assert summary["samples"] == 20000
    assert summary["bounds_max_m"][2] == pytest.approx(C1 + C4 + 0.2, abs=2e-3)
    assert (tmp_path / "scara_workspace_xy.png").is_file()


def test_voxel_volume_is_exact_when_the_grid_overflows_an_int64_index():
    # 2**22 cells per axis (more than 2**62 in all): the old packed fallback
    # (x * 2**42 + y * 2**21 + z) mapped (0, 1, 0) and (0, 0, 2**21) together.
    h = 1e-3
    pts = np.array([[0, 1, 0], [0, 0, 2**21], [2**22, 2**22, 2**22], [0, 1, 0.5]])
    vol, n = voxel_volume((pts + 0.5) * h, h)
    assert n == 3
    assert vol == pytest.approx(3 * h**3)
    for bad in (float("nan"), float("inf"), -1.0):
        with pytest.raises(InputError, match="voxel_size"):
            voxel_volume(pts, bad)


def test_cli_workspace_rejects_bad_voxel_and_a_file_as_out_before_sampling(
    tmp_path, capsys
):
    from robokin.cli import main

    assert main(["workspace", "scara", "-n", "10", "--voxel", "-1"]) == 2
    assert "--voxel" in capsys.readouterr().err
    f = tmp_path / "notes.txt"
    f.write_text("mine")
    assert main(["workspace", "scara", "-n", "10", "--out", str(f)]) == 2
    assert "--out" in capsys.readouterr().err and f.read_text() == "mine"
    ws = sample_workspace(robokin.load("scara"), 10, manipulability_samples=0)
    with pytest.raises(InputError, match="out_dir"):
        save_workspace_plots(ws, f)
