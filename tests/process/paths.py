"""Tool paths and arms for the process tests (small: each test runs in well under a
second)."""

from __future__ import annotations

import dataclasses

import numpy as np

import robokin
from robokin.spatial import rotx, rotz, trans

#: A comfortable UR5 / AUBO-i5 configuration the paths are built around [rad].
Q0 = np.array([0.3, -1.2, 1.5, -1.9, -1.4, 0.2])


def circle(robot, n=24, radius=0.08, tilt=0.4, q=Q0):
    """A circle of tool poses in a plane tilted by ``tilt`` about x, around FK(q)."""
    T0 = robot.fk(q)
    s = np.linspace(0.0, 2.0 * np.pi, n)
    local = trans(radius * np.cos(s) - radius, radius * np.sin(s), 0.0)
    return T0 @ rotx(tilt) @ local @ rotx(-tilt)


def spin(robot, turns, n, q=Q0):
    """The tool turning about its own z axis in place: ``turns`` turns in n poses."""
    return robot.fk(q) @ rotz(np.linspace(0.0, 2.0 * np.pi * turns, n))


def with_limits(robot, limits):
    """The robot with other joint limits (n, 2) [rad]."""
    joints = tuple(dataclasses.replace(j, limits=(float(a), float(b)))
                   for j, (a, b) in zip(robot.chain.joints, limits, strict=True))
    return robot.replace(chain=robot.chain.replace(joints=joints, coordinates=joints))


def panel_holes(robot_name, count, seed):
    """``count`` hole poses on a curved panel in front of the arm (tool z into it)."""
    rng = np.random.default_rng(seed)
    a = rng.uniform(-0.7, 0.7, count)
    z = rng.uniform(0.05, 0.45, count)
    T = np.zeros((count, 4, 4))
    T[:, 3, 3] = 1.0
    zax = np.stack([np.cos(a), np.sin(a), np.zeros(count)], axis=-1)
    xax = np.broadcast_to([0.0, 0.0, -1.0], zax.shape)
    T[:, :3, :3] = np.stack([xax, np.cross(zax, xax), zax], axis=-1)
    T[:, :3, 3] = np.stack([0.55 * np.cos(a), 0.55 * np.sin(a), z], axis=-1)
    return T


def load(name):
    """A built-in robot."""
    return robokin.load(name)
