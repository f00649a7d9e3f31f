"""ROS 2 (issue 19, item 2): JointTrajectory YAML checked against rosbags' message
types, and JointState bags (MCAP and SQLite, written with rosbags) read back by
``compare``, joints matched by name."""

import json
import warnings

import numpy as np
import pytest
import yaml

import robokin
from robokin import trajectory
from robokin.exceptions import InputError, ModelError
from robokin.trajectory import io
from robokin.trajectory.ros2 import (
    joint_trajectory_message,
    read_bag_log,
    read_joint_trajectory,
    write_joint_trajectory,
)

rosbags = pytest.importorskip("rosbags")
from rosbags.rosbag2 import StoragePlugin, Writer  # noqa: E402
from rosbags.typesys import Stores, get_typestore  # noqa: E402

TS = get_typestore(Stores.ROS2_HUMBLE)


def message_from_dict(typename: str, value):
    """A rosbags message built strictly from a dict: unknown or missing fields fail."""
    _, fields = TS.fielddefs[typename]
    assert isinstance(value, dict) and set(value) == {f for f, _ in fields}, (
        typename, sorted(value), [f for f, _ in fields])
    kwargs = {}
    for name, (kind, spec) in fields:
        v = value[name]
        if kind.name == "NAME":
            kwargs[name] = message_from_dict(spec, v)
        elif kind.name == "SEQUENCE":
            (ekind, espec), _ = spec
            if ekind.name == "NAME":
                kwargs[name] = [message_from_dict(espec, x) for x in v]
            elif espec[0] == "string":
                assert all(isinstance(x, str) for x in v)
                kwargs[name] = list(v)
            else:
                kwargs[name] = np.asarray(v, dtype=np.dtype(espec[0]))
        else:
            base = spec[0]
            if base == "string":
                assert isinstance(v, str)
            else:
                assert isinstance(v, int) and not isinstance(v, bool)
                info = np.iinfo(np.dtype(base))
                assert info.min <= v <= info.max, (name, v)
            kwargs[name] = v
    return TS.types[typename](**kwargs)


def cdr_round_trip(typename: str, msg):
    return TS.deserialize_cdr(TS.serialize_cdr(msg, typename), typename)


@pytest.fixture
def ur5_traj():
    ur5 = robokin.load("ur5")
    q0 = np.radians([0, -90, 90, -90, -90, 0])
    q1 = q0 + np.radians([30, 20, -25, 10, 15, 40])
    return ur5, trajectory.quintic(q0, q1, 1.2, 0.004).replace(joint_names=ur5.joint_names)


def test_joint_trajectory_yaml_is_a_valid_message(ur5_traj, tmp_path):
    ur5, tr = ur5_traj
    from robokin.trajectory.controllers import controller_profile

    prof = controller_profile(ur5)
    path = write_joint_trajectory(tr, tmp_path / "jt.yaml", ur5.joint_names, profile=prof)
    doc = yaml.safe_load(path.read_text())
    msg = cdr_round_trip("trajectory_msgs/msg/JointTrajectory",
                         message_from_dict("trajectory_msgs/msg/JointTrajectory", doc))
    assert msg.joint_names == ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
                               "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"]
    assert len(msg.points) == len(tr)
    t = [p.time_from_start.sec + p.time_from_start.nanosec * 1e-9 for p in msg.points]
    np.testing.assert_allclose(t, tr.t - tr.t[0], atol=1e-9)
    np.testing.assert_array_equal(np.array([p.positions for p in msg.points]), tr.q)
    np.testing.assert_array_equal(np.array([p.velocities for p in msg.points]), tr.qd)
    np.testing.assert_array_equal(np.array([p.accelerations for p in msg.points]), tr.qdd)
    assert msg.header.stamp.sec == 0 and msg.header.stamp.nanosec == 0
    # and robokin reads it back to the model's joints
    back = read_joint_trajectory(path, joint_names=ur5.joint_names, profile=prof)
    np.testing.assert_array_equal(back.q, tr.q)
    np.testing.assert_allclose(back.t, tr.t, atol=1e-9)
    assert back.joint_names == ur5.joint_names


def test_profile_order_signs_offsets_and_names_apply_units_do_not(tmp_path, rng):
    tr = trajectory.quintic(rng.normal(size=3), rng.normal(size=3), 0.5, 0.01).replace(
        joint_names=("a", "b", "c"), is_revolute=[True, True, False])
    prof = io.ControllerProfile(name="ctl", order=(2, 0, 1), signs=(1, -1, 1),
                                offsets=(0.01, np.pi / 2, 0.0), angle_unit="deg",
                                length_unit="mm", names=("slide", "j1", "j2"))
    msg = joint_trajectory_message(tr, profile=prof)
    assert msg["joint_names"] == ["slide", "j1", "j2"]
    p0 = msg["points"][0]["positions"]
    assert p0 == pytest.approx([tr.q[0, 2] + 0.01, -tr.q[0, 0] + np.pi / 2, tr.q[0, 1]])
    path = write_joint_trajectory(tr, tmp_path / "g.yaml", profile=prof, action_goal=True,
                                  stride=7)
    doc = yaml.safe_load(path.read_text())
    assert list(doc) == ["trajectory"]
    msg = cdr_round_trip("trajectory_msgs/msg/JointTrajectory",
                         message_from_dict("trajectory_msgs/msg/JointTrajectory",
                                           doc["trajectory"]))
    assert len(msg.points) == len(range(0, len(tr), 7)) + 1  # the last one added
    back = read_joint_trajectory(path, joint_names=("a", "b", "c"), profile=prof,
                                 is_revolute=[True, True, False])
    keep = list(range(0, len(tr), 7)) + [len(tr) - 1]
    np.testing.assert_allclose(back.q, tr.q[keep], atol=1e-15)
    np.testing.assert_allclose(back.qd, tr.qd[keep], atol=1e-15)
    with pytest.raises(InputError, match="stride"):
        joint_trajectory_message(tr, stride=0)
    with pytest.raises(ModelError, match=r"joint_names .* do not match"):
        read_joint_trajectory(path, joint_names=("x", "y", "z"))


def state_msg(t_ns: int, names, positions):
    Time = TS.types["builtin_interfaces/msg/Time"]
    Header = TS.types["std_msgs/msg/Header"]
    JointState = TS.types["sensor_msgs/msg/JointState"]
    return JointState(header=Header(stamp=Time(sec=t_ns // 10**9, nanosec=t_ns % 10**9),
                                    frame_id=""),
                      name=list(names), position=np.asarray(positions, float),
                      velocity=np.zeros(0), effort=np.zeros(0))


def write_bag(path, storage, names, t, q, *, swap_every=2, extra=None, start_ns=None,
              header_t=None):
    """A bag of JointState messages; every ``swap_every``-th one lists joints reversed.

    Received 2 ms after their header stamps (``header_t``, default ``t``).
    """
    start = 1_700_000_000 * 10**9 if start_ns is None else start_ns
    with Writer(path, version=9, storage_plugin=storage) as w:
        js = w.add_connection("/joint_states", "sensor_msgs/msg/JointState", typestore=TS)
        other = w.add_connection("/rosout_count", "std_msgs/msg/Int32", typestore=TS)
        for k, (tk, qk) in enumerate(zip(t, q)):
            ns = start + int(round(tk * 1e9))
            head = ns if header_t is None else start + int(round(header_t[k] * 1e9))
            nm, pos = list(names), list(qk)
            if extra:
                nm, pos = nm + list(extra), pos + [0.0] * len(extra)
            if swap_every and k % swap_every == 1:
                nm, pos = nm[::-1], pos[::-1]
            w.write(js, ns + 2_000_000, TS.serialize_cdr(state_msg(head, nm, pos),
                                                        "sensor_msgs/msg/JointState"))
            w.write(other, ns, TS.serialize_cdr(TS.types["std_msgs/msg/Int32"](data=k),
                                               "std_msgs/msg/Int32"))
    return path


@pytest.fixture
def plan_and_run(tmp_path, rng):
    """A planned UR5 motion (CSV) and a 'real' run: offset, lagging, 125 Hz."""
    ur5 = robokin.load("ur5")
    q0 = np.radians([10, -80, 70, -60, -90, 5])
    plan = trajectory.quintic(q0, q0 + 0.4, 2.0, 0.004).replace(joint_names=ur5.joint_names)
    plan_csv = io.write_csv(plan, tmp_path / "plan.csv")
    t = np.arange(0, 2.0, 0.008)
    lag = 0.01
    q_real = np.stack([np.interp(t - lag, plan.t, plan.q[:, j]) for j in range(6)], -1)
    q_real += np.array([1e-3, 0, -2e-3, 0, 0, 5e-4]) + rng.normal(0, 1e-5, q_real.shape)
    return ur5, plan_csv, t, q_real


def run_cli(capsys, *args):
    from robokin.cli import main

    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("storage", [StoragePlugin.MCAP, StoragePlugin.SQLITE3])
def test_compare_reads_a_bag_like_a_csv_log(plan_and_run, tmp_path, capsys, storage):
    ur5, plan_csv, t, q = plan_and_run
    # the same run as a CSV log (joint columns in another order) and as a bag
    log = trajectory.Trajectory(t, q, np.zeros_like(q), np.zeros_like(q),
                                joint_names=ur5.joint_names)
    csv = io.write_csv(log, tmp_path / "log.csv",
                       profile=io.ControllerProfile(order=(5, 4, 3, 2, 1, 0)))
    bag = write_bag(tmp_path / "run", storage, ur5.joint_names, t, q)
    code, out_csv, _ = run_cli(capsys, "compare", str(plan_csv), str(csv), "--no-plot",
                               "--json")
    assert code == 0
    single = next(bag.glob("*.mcap" if storage == StoragePlugin.MCAP else "*.db3"))
    for source in (bag, single):  # the bag folder, or its one storage file
        code, out_bag, err = run_cli(capsys, "compare", str(plan_csv), str(source),
                                     "--topic", "/joint_states", "--no-plot", "--json")
        assert code == 0, err
        a, b = json.loads(out_csv)["joints"], json.loads(out_bag)["joints"]
        assert [r["joint"] for r in a] == [r["joint"] for r in b] == list(ur5.joint_names)
        for ra, rb in zip(a, b):
            for key in ("max", "rms", "mean"):
                assert rb[key] == pytest.approx(ra[key], rel=1e-9, abs=1e-9), (key, ra, rb)
    # every joint moves alike and lags alike: the offsets show in the mean errors
    rows = json.loads(out_bag)["joints"]
    assert rows[0]["mean"] - rows[2]["mean"] == pytest.approx(np.degrees(3e-3), abs=1e-3)
    assert rows[0]["mean"] - rows[1]["mean"] == pytest.approx(np.degrees(1e-3), abs=1e-3)


def test_swapped_joint_order_gives_the_same_answer(plan_and_run, tmp_path):
    ur5, plan_csv, t, q = plan_and_run
    plain = write_bag(tmp_path / "plain", StoragePlugin.MCAP, ur5.joint_names, t, q,
                      swap_every=0)
    swapped = write_bag(tmp_path / "swapped", StoragePlugin.SQLITE3, ur5.joint_names, t, q,
                        swap_every=2)
    a = read_bag_log(plain, joint_names=ur5.joint_names)
    b = read_bag_log(swapped, joint_names=ur5.joint_names)
    np.testing.assert_array_equal(a.q, b.q)
    np.testing.assert_array_equal(a.q, q)
    np.testing.assert_allclose(a.t, t, atol=1e-9)  # time 0 at the first message
    # the receive times (2 ms later, a constant) give the same times
    c = read_bag_log(swapped, joint_names=ur5.joint_names, stamp="receive")
    np.testing.assert_allclose(c.t, a.t, atol=1e-9)
    # the robot's order, whatever order the messages list
    rev = read_bag_log(plain, joint_names=ur5.joint_names[::-1])
    np.testing.assert_array_equal(rev.q, q[:, ::-1])


def test_missing_topic_or_joint_lists_what_exists(plan_and_run, tmp_path, capsys):
    ur5, plan_csv, t, q = plan_and_run
    bag = write_bag(tmp_path / "run", StoragePlugin.MCAP, ur5.joint_names, t, q)
    with pytest.raises(ModelError, match=r"no topic '/joint_state' in the bag; topics: "
                                         r"/joint_states \(sensor_msgs/msg/JointState\), "
                                         r"/rosout_count \(std_msgs/msg/Int32\)"):
        read_bag_log(bag, topic="/joint_state")
    with pytest.raises(ModelError, match="topic /rosout_count holds std_msgs/msg/Int32, "
                                         "not sensor_msgs/msg/JointState"):
        read_bag_log(bag, topic="/rosout_count")
    names = [*ur5.joint_names[:5], "wrist_3_joint"]
    with pytest.raises(ModelError, match=r"joint\(s\) \['wrist_3_joint'\] in no JointState "
                                         r"message on /joint_states; the messages name "
                                         r"\['shoulder_pan', "):
        read_bag_log(bag, joint_names=names)
    code, _, err = run_cli(capsys, "compare", str(plan_csv), str(bag), "--topic", "/js",
                           "--no-plot")
    assert code == 2 and len(err.splitlines()) == 1 and "topics: /joint_states" in err
    code, _, err = run_cli(capsys, "compare", str(plan_csv), str(plan_csv), "--topic",
                           "/js", "--no-plot")
    assert code == 2 and "--topic" in err and "ROS 2 bags" in err


def test_extra_joints_are_ignored_with_a_warning(plan_and_run, tmp_path):
    ur5, _, t, q = plan_and_run
    bag = write_bag(tmp_path / "run", StoragePlugin.MCAP, ur5.joint_names, t, q,
                    extra=["finger_left", "finger_right"])
    with pytest.warns(UserWarning, match=r"also names \['finger_left', 'finger_right'\]"):
        log = read_bag_log(bag, joint_names=ur5.joint_names)
    np.testing.assert_array_equal(log.q, q)


def test_bag_errors(tmp_path, plan_and_run):
    ur5, _, t, q = plan_and_run
    bad = tmp_path / "broken.mcap"
    bad.write_bytes(b"not an mcap file at all")
    with pytest.raises(ModelError, match=r"broken.mcap: not a readable ROS 2 bag"):
        read_bag_log(bad)
    with pytest.raises(ModelError, match="no such file"):
        read_bag_log(tmp_path / "nothing.mcap")
    # stamps going backwards are refused, naming the way out
    t_back = t.copy()
    t_back[10] = t_back[8]
    bag = write_bag(tmp_path / "back", StoragePlugin.MCAP, ur5.joint_names, t, q,
                    swap_every=0, header_t=t_back)
    with pytest.raises(ModelError, match=r"time goes backwards at message 10 .* "
                                         r"--stamp receive"):
        read_bag_log(bag)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        log = read_bag_log(bag, stamp="receive")  # the receive times increase
    np.testing.assert_allclose(log.t, t, atol=1e-9)
    with pytest.raises(InputError, match="stamp"):
        read_bag_log(bag, stamp="sent")
    with pytest.raises(ModelError, match="more than 5 messages"):
        read_bag_log(bag, max_messages=5)


def _sim_bag(path, names, t, q, heads_ns, recv_start=1_700_000_000 * 10**9):
    """JointState messages with the given header stamps [ns], received on the wall
    clock 2 ms after ``recv_start + t``."""
    with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as w:
        js = w.add_connection("/joint_states", "sensor_msgs/msg/JointState", typestore=TS)
        for tk, qk, hk in zip(t, q, heads_ns):
            w.write(js, recv_start + int(round(tk * 1e9)) + 2_000_000,
                    TS.serialize_cdr(state_msg(int(hk), names, qk),
                                     "sensor_msgs/msg/JointState"))
    return path


def test_a_bag_whose_first_stamp_is_zero_is_read(tmp_path, plan_and_run):
    """Issue 25: simulation time starts at 0.0; that stamp was read as "not stamped"
    (the wall-clock receive time, 1.7e9 s), so the next stamp (0.008 s) went
    "backwards" and the bag was refused. Oracle: the times written."""
    ur5, _, t, q = plan_and_run
    heads = np.round(t * 1e9).astype(np.int64)          # 0, 8 ms, 16 ms, ...
    assert heads[0] == 0
    bag = _sim_bag(tmp_path / "sim", ur5.joint_names, t, q, heads)
    log = read_bag_log(bag)
    np.testing.assert_allclose(log.t, t, atol=1e-12)
    np.testing.assert_array_equal(log.q, q)
    # real backwards time on that clock is still refused
    back = heads.copy()
    back[5] = back[3]
    with pytest.raises(ModelError, match="time goes backwards at message 5"):
        read_bag_log(_sim_bag(tmp_path / "back", ur5.joint_names, t, q, back))


def test_a_zero_stamp_on_the_bag_clock_is_not_stamped(tmp_path, plan_and_run):
    """Stamps on the wall clock with a few unstamped (zero) messages: those take
    their receive times, as before; all zero: the receive times."""
    ur5, _, t, q = plan_and_run
    start = 1_700_000_000 * 10**9
    heads = start + np.round(t * 1e9).astype(np.int64)
    heads[[0, 7]] = 0
    log = read_bag_log(_sim_bag(tmp_path / "wall", ur5.joint_names, t, q, heads))
    expect = t.copy()
    expect[[0, 7]] += 0.002                       # received 2 ms after the stamp
    np.testing.assert_allclose(log.t, expect - expect[0], atol=1e-9)
    none = read_bag_log(_sim_bag(tmp_path / "none", ur5.joint_names, t, q,
                                 np.zeros(len(t), np.int64)))
    np.testing.assert_allclose(none.t, t, atol=1e-9)


def test_aubo_i5_ros2_program_is_a_valid_message_with_the_driver_names():
    from robokin.trajectory.controllers import controller_program

    aubo = robokin.load("aubo_i5")
    tr = trajectory.quintic(np.zeros(6), np.full(6, 0.2), 0.3, 0.01).replace(
        joint_names=aubo.joint_names)
    prog = controller_program(aubo, tr, "ros2")
    doc = yaml.safe_load(prog.text)
    msg = cdr_round_trip("trajectory_msgs/msg/JointTrajectory",
                         message_from_dict("trajectory_msgs/msg/JointTrajectory", doc))
    assert msg.joint_names == ["shoulder_joint", "upperArm_joint", "foreArm_joint",
                               "wrist1_joint", "wrist2_joint", "wrist3_joint"]
    np.testing.assert_array_equal(np.array([p.positions for p in msg.points]), tr.q)
