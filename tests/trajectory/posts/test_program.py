"""Programs for the six dialects read back (issue 27 item 4).

Oracle: tests/program_parsers.py reads each program with the vendor's syntax and
recovers every target: joint values to the written precision, Cartesian poses to the
written precision (against robot.fk of the generating configuration, in the work
object), the tool and base frames; and, for Cartesian targets, the configuration
flags as a controller uses them: among every IK solution of the read pose (all turns
within the limits), those with the written flags are exactly the generating one
(KUKA S/T, ABB confdata, FANUC config with turn numbers) or share its branch
(Yaskawa RCONF, Staubli config, which carry no full turn information).
"""

import numpy as np
import pytest

from program_parsers import PARSERS
from robokin.spatial import invert
from robokin.trajectory.posts import post_names, render_program, write_program
from robokin.trajectory.posts.arm_config import (
    abb_confdata,
    arm_configuration,
    fanuc_config,
    kuka_status_turn,
    staubli_config,
    yaskawa_rconf,
)
from vendor_arms import CREATED, PointSet

DIALECTS = ["abb_rapid", "fanuc_tp", "kawasaki_as", "kuka_krl", "staubli_val3",
            "yaskawa_inform"]
PPD = (1000.0, 1200.0, 900.0, 700.0, 800.0, 500.0)  # pulses per degree (a test arm)


def test_the_builtin_dialects_are_registered():
    assert set(DIALECTS) <= set(post_names())


def _decimals(prog):
    return {"fanuc_tp": (3, 3), "staubli_val3": (3, 3)}.get(prog, (3, 4))


def _rotation_error(A, B):
    c = (np.trace(A[:3, :3].T @ B[:3, :3]) - 1) / 2
    return float(np.arccos(np.clip(c, -1, 1)))


def _written_flags(dialect, joints, back, below, turn_axes=(4, 5, 6)):
    if dialect == "kuka_krl":
        s, t = kuka_status_turn(joints, back, below)
        return {"S": int(s), "T": int(t)}
    if dialect == "abb_rapid":
        return {"confdata": abb_confdata(joints, back, below).tolist()}
    if dialect == "fanuc_tp":
        return {"config": fanuc_config(joints, back, below, turn_axes)[0]}
    if dialect == "yaskawa_inform":
        return {"rconf": yaskawa_rconf(joints, back, below).tolist()}
    if dialect == "staubli_val3":
        return dict(zip(("shoulder", "elbow", "wrist"), staubli_config(joints, back)[0]))
    return {}


def _branch(arm, profile, q):
    cfg = arm_configuration(arm, q, profile)
    return bool(cfg.behind_axis_1[0]), bool(cfg.behind_lower_arm[0])


def _candidates(arm, T_world):
    sols = arm.ik(T_world).expand_turns().keep_within_limits()
    return sols.q[sols.valid]


def _decode(dialect, arm, profile, T_world, flags):
    """Every IK solution of the pose whose flags are the written ones."""
    Q = _candidates(arm, T_world)
    cfg = arm_configuration(arm, Q, profile)
    keep = [q for q, j, b, e in zip(Q, cfg.joints_deg, cfg.behind_axis_1,
                                    cfg.behind_lower_arm)
            if _written_flags(dialect, j, b, e) == flags]
    return np.array(keep)


def _write_and_read(tmp_path, dialect, arm, motion, profile, **kw):
    pulses = kw.pop("pulses", False)
    options = {"pulses_per_degree": PPD} if dialect == "yaskawa_inform" and pulses else None
    prog = write_program(arm, motion, dialect, tmp_path, name="rk_test", profile=profile,
                         created=CREATED, options=options, **kw)
    assert all(p.is_file() for p in prog.files)
    extra = {"pulses_per_degree": PPD} if options else {}
    parsed = PARSERS[dialect](tmp_path, prog.name, **extra)
    return prog, parsed


@pytest.mark.parametrize("dialect", DIALECTS)
def test_sampled_trajectory_round_trip(tmp_path, dialect, arm, sampled, profiles):
    prof = profiles[dialect]
    prog, parsed = _write_and_read(tmp_path, dialect, arm, sampled, prof, tolerance=2e-3,
                                   pulses=True)
    assert [m.kind for m in parsed.moves] == ["joint"] * prog.moves
    q = np.array([m.joints for m in parsed.moves])
    want = np.degrees(prof.export(sampled.q))
    _, ad = _decimals(dialect)
    tol = 0.5 / np.array(PPD) if dialect == "yaskawa_inform" else 0.5 * 10.0 ** -ad
    # the targets are samples of the plan, in order, first and last included
    idx = [int(np.argmin(np.abs(want - row).max(axis=1))) for row in q]
    assert idx[0] == 0 and idx[-1] == len(sampled) - 1 and idx == sorted(idx)
    assert np.all(np.abs(q - want[idx]) <= tol + 1e-9)
    # decimated to 2e-3 rad: the joint polyline through them stays within it
    model = sampled.q
    for a, b in zip(idx[:-1], idx[1:]):
        s = (np.arange(a, b + 1) - a) / max(b - a, 1)
        chord = model[a] + s[:, None] * (model[b] - model[a])
        assert np.abs(model[a:b + 1] - chord).max() <= 2e-3 + 1e-12
    assert len(q) < len(sampled) / 4


@pytest.mark.parametrize("dialect", DIALECTS)
def test_process_path_round_trip(tmp_path, dialect, arm, seam, profiles):
    """A joint move to the start, then linear moves through the poses, in the work
    object, with the flags that select the generating branch."""
    result, wobj = seam
    prof = profiles[dialect]
    prog, parsed = _write_and_read(tmp_path, dialect, arm, result, prof, work_object=wobj,
                                   speed=0.025, zone=0.002)
    assert [m.kind for m in parsed.moves] == ["joint"] + ["linear"] * (len(result.q) - 1)
    ld, ad = _decimals(dialect)
    first = parsed.moves[0]
    want0 = np.degrees(prof.export(result.q[0]))
    if dialect == "yaskawa_inform":  # no pulse ratios: a Cartesian variable with RCONF
        assert first.joints is None and first.config["rconf"] == yaskawa_rconf(
            want0, *_branch(arm, prof, result.q[0])).tolist()
    else:
        np.testing.assert_allclose(first.joints, want0, atol=0.5 * 10.0 ** -ad + 1e-9)
    expected = invert(wobj) @ arm.fk(result.q)
    expected[:, :3, 3] *= 1000.0
    for k, move in enumerate(parsed.moves[1:], start=1):
        assert np.abs(move.pose[:3, 3] - expected[k, :3, 3]).max() <= 0.5 * 10.0 ** -ld + 1e-9
        assert _rotation_error(move.pose, expected[k]) <= np.radians(1.5 * 10.0 ** -ad) + 1e-9
        if dialect == "kawasaki_as":
            continue  # AS locations carry no configuration: the linear move keeps it
        in_wobj = move.pose.copy()
        in_wobj[:3, 3] /= 1000.0
        T_world = wobj @ in_wobj
        matches = _decode(dialect, arm, prof, T_world, move.config)
        assert len(matches), f"target {k + 1}: no IK solution has the written flags"
        hit = np.abs(matches - result.q[k]).max(axis=1) < 1e-4
        assert hit.any(), f"target {k + 1}: the generating configuration is not selected"
        if dialect in ("kuka_krl", "abb_rapid", "fanuc_tp"):
            assert len(matches) == 1
    if dialect in ("kuka_krl", "abb_rapid", "staubli_val3", "kawasaki_as"):
        tool = np.linalg.inv(arm.fk_all(result.q[0])[-1]) @ arm.fk(result.q[0])
        np.testing.assert_allclose(parsed.tool[:3, 3], tool[:3, 3] * 1000, atol=1e-3)
        np.testing.assert_allclose(parsed.base[:3, 3], wobj[:3, 3] * 1000, atol=1e-3)
        assert _rotation_error(parsed.base, wobj) < np.radians(1e-3)


@pytest.mark.parametrize("dialect", ["abb_rapid", "fanuc_tp", "kuka_krl", "staubli_val3",
                                     "yaskawa_inform"])
def test_point_set_as_cartesian_joint_moves(tmp_path, dialect, arm, profiles):
    """Points (process.order's result) written as Cartesian joint moves: each pose and
    its flags bring the controller to the configuration robokin chose."""
    prof = profiles[dialect]
    rng = np.random.default_rng(3)
    lo, hi = arm.limits[:, 0] * 0.6, arm.limits[:, 1] * 0.6
    q = rng.uniform(lo, hi, (6, 6))
    q[:, 4] = np.where(np.abs(q[:, 4]) < 0.2, 0.5, q[:, 4])  # away from the wrist singularity
    points = PointSet(q, np.arange(6))
    prog, parsed = _write_and_read(tmp_path, dialect, arm, points, prof, cartesian=True)
    assert [m.kind for m in parsed.moves] == ["joint"] * 6
    assert parsed.moves[1].pose is not None
    for k in range(1, 6):
        matches = _decode(dialect, arm, prof, arm.fk(q[k]), parsed.moves[k].config)
        assert (np.abs(matches - q[k]).max(axis=1) < 1e-3).any()
        if dialect in ("kuka_krl", "abb_rapid", "fanuc_tp"):
            assert len(matches) == 1


def test_robot_file_mapping_reaches_every_dialect(tmp_path):
    """The controller section's order, signs and zeros are applied (in degrees) to
    the joint values of every dialect."""
    import yaml

    import robokin

    doc = {k: v for k, v in robokin.load("ur5").meta["document"].items()
           if k != "controller"}
    doc["controller"] = {"name": "test cell", "signs": [-1, 1, 1, -1, 1, 1],
                         "offsets": [0, -90, 0, 0, 0, 180], "offset_unit": "deg"}
    f = tmp_path / "arm.yaml"
    f.write_text(yaml.safe_dump(doc, sort_keys=False))
    robot = robokin.load(f)
    q = np.array([[0.1, -1.2, 1.3, -1.5, -1.5, 0.2], [0.3, -1.0, 1.1, -1.4, -1.6, 0.5]])
    want = np.degrees(q) * [-1, 1, 1, -1, 1, 1] + [0, -90, 0, 0, 0, 180]
    for dialect in ("kuka_krl", "abb_rapid", "kawasaki_as", "staubli_val3"):
        out = tmp_path / dialect
        prog = write_program(robot, q, dialect, out, name="map", created=CREATED)
        got = np.array([m.joints for m in PARSERS[dialect](out, prog.name).moves])
        np.testing.assert_allclose(got, want, atol=1e-3)


def test_render_is_deterministic_and_write_matches_render(tmp_path, arm, sampled, profiles):
    a = render_program(arm, sampled, "kuka_krl", profile=profiles["kuka_krl"],
                       created=CREATED, name="same")
    b = render_program(arm, sampled, "kuka_krl", profile=profiles["kuka_krl"],
                       created=CREATED, name="same")
    assert a.texts == b.texts
    w = write_program(arm, sampled, "kuka_krl", tmp_path, profile=profiles["kuka_krl"],
                      created=CREATED, name="same")
    for path in w.files:
        assert path.read_bytes().decode("ascii") == a.texts[path.name]
