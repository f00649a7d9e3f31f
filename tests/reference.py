"""Independent reference implementations for the tests (plain numpy or a peer, no robokin)."""

from __future__ import annotations

import math

import numpy as np
import pytest


def dh_standard(rows, q):
    """Hand-written standard DH product: rows of (theta0, d, a, alpha, kind)."""
    T = np.eye(4)
    qi = iter(q)
    for theta, d, a, alpha, kind in rows:
        if kind == "r":
            theta = theta + next(qi)
        elif kind == "p":
            d = d + next(qi)
        ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
        A = np.array(
            [
                [ct, -st * ca, st * sa, a * ct],
                [st, ct * ca, -ct * sa, a * st],
                [0, sa, ca, d],
                [0, 0, 0, 1.0],
            ]
        )
        T = T @ A
    return T


def dh_modified(rows, q):
    """Hand-written modified (Craig) DH product: rows of (alpha_prev, a_prev, theta0, d, kind)."""
    T = np.eye(4)
    qi = iter(q)
    for alpha, a, theta, d, kind in rows:
        if kind == "r":
            theta = theta + next(qi)
        elif kind == "p":
            d = d + next(qi)
        ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
        A = np.array(
            [
                [ct, -st, 0, a],
                [st * ca, ct * ca, -sa, -sa * d],
                [st * sa, ct * sa, ca, ca * d],
                [0, 0, 0, 1.0],
            ]
        )
        T = T @ A
    return T


def random_q(robot, rng, size=()):
    """Random configurations inside the limits (unlimited angles drawn in +-pi)."""
    lim = np.where(
        np.isfinite(robot.limits), robot.limits, np.clip(robot.limits, -np.pi, np.pi)
    )
    return rng.uniform(
        lim[:, 0], lim[:, 1], size=tuple(np.atleast_1d(size)) + (robot.n,)
    )


def pose_errors(T, Tt):
    """Position distance [m] and rotation angle [rad] between poses (..., 4, 4)."""
    dp = np.linalg.norm(T[..., :3, 3] - Tt[..., :3, 3], axis=-1)
    R = np.swapaxes(T[..., :3, :3], -1, -2) @ Tt[..., :3, :3]
    c = np.clip((np.trace(R, axis1=-2, axis2=-1) - 1) / 2, -1, 1)
    s = np.linalg.norm(
        np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0],
                  R[..., 1, 0] - R[..., 0, 1]], -1), axis=-1) / 2
    return dp, np.arctan2(s, c)


def pin_fk(xml: str, frame: str, values: dict[str, float]) -> np.ndarray:
    """Pose (4, 4) of ``frame`` from pinocchio's own URDF parser (skips without it).

    ``values`` maps joint names to positions [rad, m]; continuous joints are given
    to pinocchio as (cos, sin).
    """
    pin = pytest.importorskip("pinocchio")
    model = pin.buildModelFromXML(xml)
    data = model.createData()
    q = pin.neutral(model)
    for name, v in values.items():
        j = model.joints[model.getJointId(name)]
        if j.nq == 1:
            q[j.idx_q] = v
        else:
            q[j.idx_q], q[j.idx_q + 1] = math.cos(v), math.sin(v)
    pin.framesForwardKinematics(model, data, q)
    return data.oMf[model.getFrameId(frame)].homogeneous


def iiwa14_srs():
    """An exact SRS arm with the KUKA LBR iiwa 14 R820's link lengths and ranges.

    Standard DH, flange frame: d_bs = 0.36, d_se = 0.42, d_ew = 0.40, d_wf = 0.126 m
    (Faria et al., Mechanism and Machine Theory 121, 2018, table 1); joint ranges
    +-170, 120, 170, 120, 170, 120, 175 deg (KUKA's iiwa specification). Every
    offset is zero: axes 1-3 meet in the shoulder, 5-7 in the wrist. (The same arm
    as ``kinematics/ik/test_fixed_properties.py``'s.)
    """
    import robokin

    table = [(-np.pi / 2, 0.36, 170), (np.pi / 2, 0.0, 120), (np.pi / 2, 0.42, 170),
             (-np.pi / 2, 0.0, 120), (-np.pi / 2, 0.40, 170), (np.pi / 2, 0.0, 120),
             (0.0, 0.126, 175)]
    rows = [{"a": 0.0, "alpha": alpha, "d": d, "theta": 0.0,
             "limits": [-np.radians(r), np.radians(r)], "name": f"a{i + 1}"}
            for i, (alpha, d, r) in enumerate(table)]
    return robokin.Robot.from_dh(rows, convention="standard", name="iiwa14_srs")


def ur5_on_a_track(length: float = 2.0):
    """A UR5 (standard DH, joints +-6.28 rad) on a linear track ``length`` [m] long.

    A 7-joint arm whose first joint is prismatic (along the base z axis), the
    parameter users pick for a robot on a rail; its revolute joints range over more
    than a turn.
    """
    import robokin

    ur5 = [(0.089159, 0.0, np.pi / 2), (0.0, -0.425, 0.0), (0.0, -0.39225, 0.0),
           (0.10915, 0.0, np.pi / 2), (0.09465, 0.0, -np.pi / 2), (0.0823, 0.0, 0.0)]
    rows = [{"a": 0.0, "alpha": -np.pi / 2, "d": 0.0, "theta": np.pi / 2,
             "joint": "prismatic", "limits": [0.0, length], "name": "track"}]
    rows += [{"a": a, "alpha": alpha, "d": d, "theta": 0.0, "limits": [-6.28, 6.28],
              "name": f"j{i + 1}"} for i, (d, a, alpha) in enumerate(ur5)]
    return robokin.Robot.from_dh(rows, convention="standard", name="ur5_track")


def rtb_iiwa14():
    """The rtb-data iiwa14 URDF (shoulder offset 0.44 mm: not exactly SRS; skipped
    without rtbdata)."""
    rtbdata = pytest.importorskip("rtbdata")
    from pathlib import Path

    import robokin

    urdf = (Path(rtbdata.__file__).parent
            / "xacro/kuka_description/kuka_lbr_iiwa/urdf/lbr_iiwa_14_r820.urdf")
    return robokin.Robot.from_urdf(str(urdf), geometry=False)


def offset_iiwa14(a2: float = 0.01):
    """:func:`iiwa14_srs` with a shoulder offset ``a2`` [m] (1 cm by default).

    Axes 1-3 no longer meet, so no joint held leaves a Pieper triple: joint 7 held
    goes to the general held-joint 6R solver (issue 29's general 7R case).
    """
    import robokin

    table = [(-np.pi / 2, 0.36, 170), (np.pi / 2, 0.0, 120), (np.pi / 2, 0.42, 170),
             (-np.pi / 2, 0.0, 120), (-np.pi / 2, 0.40, 170), (np.pi / 2, 0.0, 120),
             (0.0, 0.126, 175)]
    rows = [{"a": a2 if i == 1 else 0.0, "alpha": alpha, "d": d, "theta": 0.0,
             "limits": [-np.radians(r), np.radians(r)], "name": f"a{i + 1}"}
            for i, (alpha, d, r) in enumerate(table)]
    return robokin.Robot.from_dh(rows, convention="standard", name="offset_iiwa")


def random_7r(seed: int = 29):
    """A general 7R arm: a standard DH table drawn from ``seed``.

    a in [0.05, 0.3] m, d in [-0.3, 0.3] m, alpha uniform in (-pi, pi), every joint
    +-170 deg: no two axes meet or are parallel (generically), so no held joint has
    a closed form.
    """
    import robokin

    rng = np.random.default_rng(seed)
    rows = [{"a": float(rng.uniform(0.05, 0.3)), "alpha": float(rng.uniform(-np.pi, np.pi)),
             "d": float(rng.uniform(-0.3, 0.3)), "theta": 0.0,
             "limits": [-np.radians(170), np.radians(170)], "name": f"r{i + 1}"}
            for i in range(7)]
    return robokin.Robot.from_dh(rows, convention="standard", name=f"random7r_{seed}")


def kernel_copies() -> dict:
    """Every copy of the compiled kernels this CPU runs (name -> module): baseline,
    avx2+fma, avx512. Their rows can differ in the last bits."""
    import importlib

    from robokin import _native
    out = {"baseline": _native._base}
    if _native._base.cpu_has_avx2_fma():
        out["avx2+fma"] = importlib.import_module("robokin._native._avx2")
    if _native._base.cpu_has_avx512():
        out["avx512"] = importlib.import_module("robokin._native._avx512")
    return out


def assert_corner_listed(robot, sm, q0, t, slack=1e-12):
    """q0 is a corner of its branch at parameter t, listed (issue 29's one-point rule).

    Oracles: the branch b holding q0 at t (1e-6 rad, 2 pi wrapped) is outside the
    limits (``slack``) at t +- 1e-6, so q0 is a point alone; an interval of b at most
    1e-9 long holds t (1e-9; the swivel modulo 2 pi); b's row at that interval's start
    is inside every limit (``slack``) and reproduces FK(q0) to 1e-12.
    """
    T = robot.fk(q0)
    lo, hi = robot.limits[:, 0], robot.limits[:, 1]

    def gap(r):
        return np.abs((r - q0 + np.pi) % (2 * np.pi) - np.pi).max(axis=-1)

    def inside(r):
        return bool(np.all((r >= lo - slack) & (r <= hi + slack)))

    rows = sm.sample(t)
    b = int(np.nanargmin(gap(rows)))
    assert gap(rows[b]) < 1e-6, (t, rows)
    for d in (-1e-6, 1e-6):
        assert not inside(sm.sample(t + d)[b]), d  # not an interval with length
    iv = sm.intervals[sm.interval_branch == b]
    shifts = (-2 * np.pi, 0.0, 2 * np.pi) if sm.periodic else (0.0,)
    hit = np.concatenate([iv[(iv[:, 0] - 1e-9 <= t + s) & (t + s <= iv[:, 1] + 1e-9)]
                          for s in shifts])
    assert len(hit) == 1 and hit[0, 1] - hit[0, 0] <= 1e-9, (t, iv)
    row = sm.sample(hit[0, 0])[b]
    assert inside(row), row
    dp, dr = pose_errors(robot.fk(row), T)
    assert dp <= 1e-12 and dr <= 1e-12, (dp, dr)
