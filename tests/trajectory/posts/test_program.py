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
from hypothesis import given, settings
from hypothesis import strategies as st

from program_parsers import PARSERS
from robokin.exceptions import InputError
from robokin.spatial import invert
from robokin.trajectory.posts import (
    decimate,
    post_names,
    render_program,
    write_program,
)
from robokin.trajectory.posts.arm_config import (
    abb_confdata,
    arm_configuration,
    fanuc_config,
    kuka_status_turn,
    staubli_config,
    yaskawa_rconf,
)
from vendor_arms import CREATED, PROFILES, PathResult, PointSet

DIALECTS = ["abb_rapid", "fanuc_tp", "kawasaki_as", "kuka_krl", "staubli_val3",
            "yaskawa_inform"]
PPD = (1000.0, 1200.0, 900.0, 700.0, 800.0, 500.0)  # pulses per degree (a test arm)


def test_the_builtin_dialects_are_registered():
    assert set(DIALECTS) <= set(post_names())


def _assert_within(q, idx, tol):
    """Every sample within tol (per joint) of the polyline through q[idx]: measured
    by dense sampling of each chord (an independent check of the projection)."""
    for a, b in zip(idx[:-1], idx[1:]):
        s = np.linspace(0.0, 1.0, 2001)
        chord = q[a] + s[:, None] * (q[b] - q[a])
        dist = np.abs(q[a:b + 1, None, :] - chord[None]).max(axis=2).min(axis=1)
        assert dist.max() <= tol + 1e-3 * np.abs(q[b] - q[a]).max() + 1e-12


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
    _assert_within(sampled.q, idx, 2e-3)
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


# ------------------------------------------------------------------ writing safely
def test_files_are_never_replaced_without_force_and_all_or_none(tmp_path, arm, sampled):
    prof = PROFILES["kuka"]
    first = write_program(arm, sampled, "kuka_krl", tmp_path, name="p", profile=prof)
    before = {p: p.read_bytes() for p in first.files}
    with pytest.raises(InputError, match=r"p\.src exists; pass force=True \(--force\)"):
        write_program(arm, sampled.q[:50], "kuka_krl", tmp_path, name="p", profile=prof)
    assert {p: p.read_bytes() for p in first.files} == before
    again = write_program(arm, sampled.q[:50], "kuka_krl", tmp_path, name="p", profile=prof,
                          force=True)
    assert again.files == first.files and before != {p: p.read_bytes() for p in again.files}
    # one of the two files exists: neither is written
    (tmp_path / "q.dat").write_text("mine")
    with pytest.raises(InputError, match="q.dat exists"):
        write_program(arm, sampled, "kuka_krl", tmp_path, name="q", profile=prof)
    assert not (tmp_path / "q.src").exists() and (tmp_path / "q.dat").read_text() == "mine"


def test_out_dir_is_made_inside_an_existing_folder(tmp_path, arm):
    prog = write_program(arm, np.zeros((1, 6)), "abb_rapid", tmp_path / "new", name="m",
                         profile=PROFILES["abb"])
    assert prog.files == (tmp_path / "new" / "m.mod",)
    with pytest.raises(InputError, match="does not exist"):
        write_program(arm, np.zeros((1, 6)), "abb_rapid", tmp_path / "a" / "b", name="m")


def test_refusals(arm, seam, sampled):
    import robokin
    result, _ = seam
    with pytest.raises(InputError, match=r"not feasible \(waypoint 7: out of reach\)"):
        render_program(arm, PathResult(result.q, feasible=False,
                                       reason="waypoint 7: out of reach"), "kuka_krl")
    q = np.zeros((2, 6))
    q[1, 4] = np.radians(130)  # beyond A5's 120 deg
    with pytest.raises(InputError, match=r"target 2 is outside robot's joint limits"):
        render_program(arm, q, "kuka_krl")
    panda = robokin.load("panda")
    with pytest.raises(InputError, match="drive 6 revolute axes; panda has 7"):
        render_program(panda, np.zeros((1, 7)), "abb_rapid")
    bad = [({"joint_speed": 0}, "joint_speed"), ({"joint_speed": 1.5}, "joint_speed"),
           ({"speed": -1}, "speed"), ({"zone": float("nan")}, "zone"),
           ({"stride": 0}, "stride"), ({"stride": 2, "tolerance": 1e-3}, "stride")]
    for kw, arg in bad:
        with pytest.raises(InputError, match=arg):
            render_program(arm, sampled, "kuka_krl", **kw)
    with pytest.raises(InputError, match="tolerance.*use stride"):
        render_program(arm, result, "kuka_krl", tolerance=1e-3)
    with pytest.raises(InputError, match="expected a Trajectory"):
        render_program(arm, "path.csv", "kuka_krl")
    with pytest.raises(InputError, match="holds at most 5000"):
        render_program(arm, np.zeros((5001, 6)), "kuka_krl")


def test_robot_file_options_per_dialect(tmp_path):
    import yaml

    import robokin
    from robokin.exceptions import ModelError

    doc = {k: v for k, v in robokin.load("ur5").meta["document"].items()
           if k != "controller"}
    doc["controller"] = {"name": "cell 3", "posts": {"fanuc_tp": {"cnt": 100, "user_tool": 4}}}
    f = tmp_path / "arm.yaml"
    f.write_text(yaml.safe_dump(doc, sort_keys=False))
    robot = robokin.load(f)
    q = np.array([[0.1, -1.2, 1.3, -1.5, -1.5, 0.2]] * 3) + np.arange(3)[:, None] * 0.05
    text = render_program(robot, q, "fanuc_tp", name="a").texts["A.ls"]
    assert "CNT100" in text and "UTOOL_NUM=4 ;" in text
    # the call's options win
    text = render_program(robot, q, "fanuc_tp", name="a", options={"cnt": 10}).texts["A.ls"]
    assert "CNT10 " in text and "UTOOL_NUM=4 ;" in text
    doc["controller"]["posts"] = {"fanuc_tp": {"cnt": 300}}
    f.write_text(yaml.safe_dump(doc, sort_keys=False))
    with pytest.raises(ModelError, match=r"arm.yaml: controller.posts.fanuc_tp.cnt: expected an integer 0..100"):
        render_program(robokin.load(f), q, "fanuc_tp")
    doc["controller"]["posts"] = {"fanuk_tp": {}}
    f.write_text(yaml.safe_dump(doc, sort_keys=False))
    with pytest.raises(ModelError, match=r"controller.posts: unknown post processor"):
        render_program(robokin.load(f), q, "fanuc_tp")
    doc["controller"] = {"root": {"xyz_mm": [0, 0, 400], "rpy_deg": [0, 0, 180]}}
    f.write_text(yaml.safe_dump(doc, sort_keys=False))
    prof = robokin.trajectory.controllers.controller_profile(robokin.load(f))
    np.testing.assert_allclose(prof.frame("root")[:3, 3], [0, 0, 0.4])
    doc["controller"] = {"root": {"xyz": [0, 0, 400]}}
    f.write_text(yaml.safe_dump(doc, sort_keys=False))
    with pytest.raises(ModelError, match=r"controller.root: expected \{xyz_mm"):
        robokin.trajectory.controllers.controller_profile(robokin.load(f))


# ------------------------------------------------------------------ decimation
@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31), tol=st.sampled_from([0.0, 1e-9, 1e-3, 0.05, 1.0]))
def test_decimation_stays_within_tolerance(seed, tol):
    """Oracle: the polyline through the kept samples, checked at every sample."""
    rng = np.random.default_rng(seed)
    q = np.cumsum(rng.normal(0, 0.02, (rng.integers(2, 300), 6)), axis=0)
    keep = rng.integers(0, len(q), 3).tolist()
    idx = decimate(q, tol, keep=keep)
    assert idx[0] == 0 and idx[-1] == len(q) - 1 and set(keep) <= set(idx.tolist())
    assert np.all(np.diff(idx) > 0)
    _assert_within(q, idx, tol)
    # a straight line needs only its ends
    line = np.linspace(0, 1, 50)[:, None] * np.ones(6)
    assert decimate(line, 1e-9).tolist() == [0, 49]
