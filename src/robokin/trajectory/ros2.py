"""ROS 2 in and out: ``trajectory_msgs/msg/JointTrajectory`` YAML, ``JointState`` bags.

Out: :func:`joint_trajectory_yaml` / :func:`write_joint_trajectory` write a
trajectory as the YAML of a ``trajectory_msgs/msg/JointTrajectory`` message (the
form ``ros2 topic pub TOPIC trajectory_msgs/msg/JointTrajectory "$(cat FILE)"``
and ``rosidl_runtime_py.set_message_fields`` read), or, with
``action_goal=True``, of a ``control_msgs/action/FollowJointTrajectory`` goal
(``{trajectory: ...}``, for ``ros2 action send_goal``)::

    header: {stamp: {sec: 0, nanosec: 0}, frame_id: ''}
    joint_names: [shoulder_pan_joint, shoulder_lift_joint, ...]
    points:
    - positions: [0.0, -1.57, ...]        # [rad] or [m]
      velocities: [0.0, 0.0, ...]         # [rad/s] or [m/s]
      accelerations: [0.0, 0.0, ...]      # [rad/s^2] or [m/s^2]
      effort: []
      time_from_start: {sec: 0, nanosec: 5000000}

ROS messages are SI: a :class:`~robokin.trajectory.controller_profile.ControllerProfile`'s
joint order, signs, zero offsets and names apply, its units do not. A zero
header stamp tells the controller to start now. :func:`read_joint_trajectory`
reads the file back (a message or a goal).

In: :func:`read_bag_log` reads the ``sensor_msgs/msg/JointState`` messages of a
topic in a ROS 2 bag (a bag folder with ``metadata.yaml``, or one ``.mcap`` or
``.db3`` file; rosbags, the ``robokin[ros]`` extra, no ROS install) as a logged
run for :func:`robokin.trajectory.compare.compare`. Joints are matched by name
in each message (any order, as the CSV reader matches columns); messages
without all the requested joints are skipped, joints the robot does not have
are ignored with a warning naming them. Time is the header stamp (or the
bag's receive time, ``stamp="receive"``) and starts at 0 at the first message
used.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from robokin._text import short_repr
from robokin.exceptions import InputError, MissingExtraError, ModelError
from robokin.io.atomic import write_atomic
from robokin.io.text_files import MAX_CSV_BYTES
from robokin.trajectory.controller_profile import ControllerProfile
from robokin.trajectory.samples import Trajectory

__all__ = [
    "JOINT_STATE",
    "JOINT_TRAJECTORY",
    "MAX_BAG_MESSAGES",
    "joint_trajectory_message",
    "joint_trajectory_yaml",
    "read_bag_log",
    "read_joint_trajectory",
    "write_joint_trajectory",
]

JOINT_TRAJECTORY = "trajectory_msgs/msg/JointTrajectory"
JOINT_STATE = "sensor_msgs/msg/JointState"
#: Most messages :func:`read_bag_log` reads from one topic (an hour at 1 kHz is 3.6 M).
MAX_BAG_MESSAGES = 5_000_000
_GOAL_KEYS = ("trajectory", "multi_dof_trajectory", "path_tolerance",
              "component_path_tolerance", "goal_tolerance",
              "component_goal_tolerance", "goal_time_tolerance")


# ----------------------------------------------------------------- JointTrajectory
def _duration(ns: int) -> dict[str, int]:
    return {"sec": int(ns // 1_000_000_000), "nanosec": int(ns % 1_000_000_000)}


def _rows(traj: Trajectory, stride: int) -> np.ndarray:
    """Sample indices: every ``stride``-th, the last always included."""
    if isinstance(stride, bool) or not isinstance(stride, (int, np.integer)) or stride < 1:
        raise InputError("stride", f"expected an integer >= 1, got {short_repr(stride)}")
    idx = np.arange(0, len(traj), int(stride))
    if idx[-1] != len(traj) - 1:
        idx = np.append(idx, len(traj) - 1)
    return idx


def joint_trajectory_message(
    traj: Trajectory,
    joint_names: Sequence[str] | None = None,
    *,
    profile: ControllerProfile | None = None,
    stride: int = 1,
) -> dict[str, Any]:
    """The trajectory as a ``trajectory_msgs/msg/JointTrajectory`` (plain dict).

    Args:
        traj: A joint-space trajectory.
        joint_names: The robot's joint names (default ``traj.joint_names``);
            the profile's ``names`` replace them when it has some.
        profile: Joint order, signs, zero offsets and names of the controller
            (its units are not used: ROS messages are SI).
        stride: Keep every ``stride``-th sample (and the last): the controller
            interpolates between points with their velocities and accelerations.

    Returns:
        ``{"header", "joint_names", "points"}`` with lists of floats; times
        from the first sample, to the nanosecond.

    Raises:
        InputError: a trajectory in actuator space, a wrong number of names,
            a bad stride.
    """
    if traj.space != "joint":
        raise InputError("traj", "a JointTrajectory holds joint values: convert to "
                         "joint space")
    names = list(joint_names) if joint_names is not None else list(traj.names())
    if len(names) != traj.n:
        raise InputError("joint_names", f"expected {traj.n} names, got {len(names)}")
    prof = profile or ControllerProfile()
    cols = prof.column_names(names)
    if len(cols) != traj.n or len(set(cols)) != traj.n:
        raise InputError("profile", f"needs {traj.n} distinct joint names, got {cols}")
    idx = _rows(traj, stride)
    q = prof.export(traj.q[idx])
    qd = prof.export(traj.qd[idx], rates=True)
    qdd = prof.export(traj.qdd[idx], rates=True)
    ns = np.rint((traj.t[idx] - traj.t[0]) * 1e9).astype(np.int64)
    points = [{"positions": q[k].tolist(), "velocities": qd[k].tolist(),
               "accelerations": qdd[k].tolist(), "effort": [],
               "time_from_start": _duration(int(ns[k]))} for k in range(len(idx))]
    return {"header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""},
            "joint_names": [str(c) for c in cols], "points": points}


def joint_trajectory_yaml(
    traj: Trajectory,
    joint_names: Sequence[str] | None = None,
    *,
    profile: ControllerProfile | None = None,
    stride: int = 1,
    action_goal: bool = False,
) -> str:
    """The YAML text :func:`write_joint_trajectory` writes (arguments as there)."""
    import yaml

    msg = joint_trajectory_message(traj, joint_names, profile=profile, stride=stride)
    doc = {"trajectory": msg} if action_goal else msg
    kind = "control_msgs/action/FollowJointTrajectory goal" if action_goal \
        else JOINT_TRAJECTORY
    head = (f"# {kind}, written by robokin: {len(msg['points'])} points, "
            f"{traj.duration:.6g} s; positions [rad, m], SI\n")
    return head + yaml.safe_dump(doc, sort_keys=False, default_flow_style=None,
                                 width=100)


def write_joint_trajectory(
    traj: Trajectory,
    path: str | Path,
    joint_names: Sequence[str] | None = None,
    *,
    profile: ControllerProfile | None = None,
    stride: int = 1,
    action_goal: bool = False,
    overwrite: bool = False,
) -> Path:
    """Write the trajectory as ROS 2 ``JointTrajectory`` YAML (module docstring).

    Args:
        traj: A joint-space trajectory.
        path: The file (``.yaml``).
        joint_names: The robot's joint names (default ``traj.joint_names``).
        profile: Controller joint order, signs, offsets and names.
        stride: Keep every ``stride``-th sample (and the last).
        action_goal: Write a ``FollowJointTrajectory`` goal (``trajectory:``
            at the top) instead of a message.
        overwrite: Replace an existing file.

    Returns:
        The path written.

    Raises:
        InputError: as :func:`joint_trajectory_message`, or the file exists
            and ``overwrite`` is False.
    """
    text = joint_trajectory_yaml(traj, joint_names, profile=profile, stride=stride,
                                 action_goal=action_goal)
    return write_atomic(path, text, overwrite=overwrite)


def _float_list(value: Any, where: str, n: int | None, file: Path) -> list[float]:
    ok = isinstance(value, list) and all(
        isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
    if not ok or (n is not None and len(value) not in (0, n)):
        want = "numbers" if n is None else f"{n} numbers (or none)"
        raise ModelError(f"expected a list of {want}, got {short_repr(value)}",
                         file=file, field=where)
    return [float(v) for v in value]


def read_joint_trajectory(
    path: str | Path,
    *,
    joint_names: Sequence[str] | None = None,
    profile: ControllerProfile | None = None,
    is_revolute: npt.ArrayLike | None = None,
) -> Trajectory:
    """Read a ``JointTrajectory`` YAML (a message or a ``FollowJointTrajectory`` goal).

    Args:
        path: The file.
        joint_names: The robot's joint names: the message's are matched to
            them (any order; after undoing ``profile``'s names).
        profile: The controller profile the file was written with (undone).
        is_revolute: (n,) angle flags (default: all angles).

    Returns:
        A :class:`~robokin.trajectory.samples.Trajectory`, model order, SI;
        velocities and accelerations differentiated when the points have none.

    Raises:
        ModelError: not YAML, missing or malformed fields, names that do not
            match ``joint_names``, times that do not increase.
    """
    from robokin.io.yaml_reader import read_yaml_document

    path = Path(path)
    doc = read_yaml_document(path, max_bytes=MAX_CSV_BYTES).data
    if isinstance(doc, Mapping) and "trajectory" in doc and "points" not in doc:
        doc = doc["trajectory"]
    if not isinstance(doc, Mapping) or not isinstance(doc.get("points"), list) \
            or not doc["points"]:
        raise ModelError("expected a JointTrajectory: a mapping with 'joint_names' "
                         "and a non-empty list 'points'", file=path)
    names = doc.get("joint_names")
    if not isinstance(names, list) or not all(isinstance(x, str) for x in names):
        raise ModelError(f"expected a list of names, got {short_repr(names)}",
                         file=path, field="joint_names")
    n = len(names)
    t = np.empty(len(doc["points"]))
    cols: dict[str, list[list[float]]] = {"positions": [], "velocities": [],
                                          "accelerations": []}
    for k, p in enumerate(doc["points"]):
        where = f"points[{k}]"
        if not isinstance(p, Mapping):
            raise ModelError("expected a mapping", file=path, field=where)
        tfs = p.get("time_from_start", {})
        sec, nsec = (tfs.get("sec", 0), tfs.get("nanosec", 0)) \
            if isinstance(tfs, Mapping) else (None, None)
        if not all(isinstance(v, int) and not isinstance(v, bool) for v in (sec, nsec)):
            raise ModelError(f"expected {{sec: int, nanosec: int}}, got {short_repr(tfs)}",
                             file=path, field=f"{where}.time_from_start")
        t[k] = sec + nsec * 1e-9  # type: ignore[operator]  # checked ints
        for key, rows in cols.items():
            rows.append(_float_list(p.get(key, []), f"{where}.{key}", n, path))
        if len(cols["positions"][-1]) != n:
            raise ModelError(f"expected {n} positions", file=path,
                             field=f"{where}.positions")
    if np.any(np.diff(t) <= 0):
        k = int(np.flatnonzero(np.diff(t) <= 0)[0]) + 1
        raise ModelError("time_from_start does not increase", file=path,
                         field=f"points[{k}].time_from_start")
    order = _match_names(names, joint_names, profile, path)
    prof = profile or ControllerProfile()

    def model(key: str, rates: bool) -> np.ndarray | None:
        rows = cols[key]
        if any(len(r) == 0 for r in rows):
            return None
        return prof.undo(np.asarray(rows)[:, order], rates=rates)

    q = model("positions", False)
    if q is None:  # pragma: no cover - every point has n positions (checked above)
        raise ModelError("no positions", file=path)
    qd, qdd = model("velocities", True), model("accelerations", True)
    if qd is None:
        qd = np.gradient(q, t, axis=0) if len(t) > 1 else np.zeros_like(q)
    if qdd is None:
        qdd = np.gradient(qd, t, axis=0) if len(t) > 1 else np.zeros_like(q)
    model_names = list(joint_names) if joint_names is not None else \
        [names[i] for i in order]
    return Trajectory(t, q, qd, qdd, joint_names=tuple(model_names),
                      is_revolute=_flags(is_revolute),
                      via_times=np.array([t[0], t[-1]]))


def _flags(is_revolute: npt.ArrayLike | None) -> np.ndarray | None:
    return None if is_revolute is None else np.asarray(is_revolute, bool).reshape(-1)


def _match_names(names: list[str], joint_names: Sequence[str] | None,
                 profile: ControllerProfile | None, path: Path) -> list[int]:
    """Message column per controller column (the profile's names, or the model's)."""
    if joint_names is None:
        return list(range(len(names)))
    expected = (profile or ControllerProfile()).column_names(list(joint_names))
    if sorted(names) != sorted(expected):
        raise ModelError(f"joint_names {names} do not match the robot's {expected} "
                         "(any order)", file=path, field="joint_names")
    return [names.index(c) for c in expected]


# ------------------------------------------------------------------------ bags
def _rosbags() -> Any:
    try:
        from rosbags.highlevel import AnyReader
    except ImportError:
        raise MissingExtraError("rosbags", "ros") from None
    return AnyReader


def _bag_topics(reader: Any) -> str:
    topics = sorted((c.topic, c.msgtype) for c in reader.connections)
    shown = ", ".join(f"{t} ({m})" for t, m in dict(topics).items())
    return shown or "none"


def read_bag_log(
    path: str | Path,
    *,
    topic: str = "/joint_states",
    joint_names: Sequence[str] | None = None,
    is_revolute: npt.ArrayLike | None = None,
    stamp: Literal["header", "receive"] = "header",
    max_messages: int = MAX_BAG_MESSAGES,
) -> Trajectory:
    """Read a ROS 2 bag's ``sensor_msgs/msg/JointState`` topic as a logged run.

    Args:
        path: The bag: a folder with ``metadata.yaml``, or an ``.mcap`` or
            ``.db3`` file (rosbags, ``robokin[ros]``).
        topic: The JointState topic.
        joint_names: The robot's joint names, matched by name in every message
            (any order) and returned in this order. Default: the names of the
            first message, in its order.
        is_revolute: (n,) angle flags in the order of ``joint_names`` (default:
            all angles).
        stamp: ``"header"``: the messages' header stamps (a zero stamp is "not
            stamped", read as the receive time, when the stamps are on the bag's
            clock; on a clock of their own, such as simulation time starting at
            0.0, it is a time); ``"receive"``: the bag's receive times.
        max_messages: The most messages read from the topic.

    Returns:
        A :class:`~robokin.trajectory.samples.Trajectory` in SI, its time 0 at
        the first message used; velocities and accelerations differentiated.

    Raises:
        ModelError: not a readable bag; no such topic or not JointState
            (listing the topics); a joint in no message (listing the names the
            messages hold); time going backwards; too many messages.
        InputError: a bad ``stamp`` or ``max_messages``.
        MissingExtraError: rosbags is not installed.
    """
    if stamp not in ("header", "receive"):
        raise InputError("stamp", f"expected 'header' or 'receive', got {short_repr(stamp)}")
    if isinstance(max_messages, bool) or not isinstance(max_messages, int) \
            or max_messages < 1:
        raise InputError("max_messages", f"expected an integer >= 1, got "
                         f"{short_repr(max_messages)}")
    path = Path(path)
    if not path.exists():
        raise ModelError("no such file or folder", file=path)
    AnyReader = _rosbags()
    try:
        with AnyReader([path]) as reader:
            conns = [c for c in reader.connections if c.topic == topic]
            if not conns:
                raise ModelError(f"no topic {short_repr(topic)} in the bag; topics: "
                                 f"{_bag_topics(reader)}", file=path)
            wrong = [c.msgtype for c in conns if c.msgtype != JOINT_STATE]
            if wrong:
                raise ModelError(f"topic {topic} holds {wrong[0]}, not {JOINT_STATE}",
                                 file=path)
            rows = _joint_states(reader, conns, max_messages, path)
    except ModelError:
        raise
    except Exception as exc:  # rosbags' reader errors, sqlite, mcap, serde
        raise ModelError(f"not a readable ROS 2 bag: {type(exc).__name__}: "
                         f"{short_repr(str(exc), 200)}", file=path) from None
    return _log_from_states(rows, path, topic, joint_names, is_revolute, stamp)


def _joint_states(reader: Any, conns: list[Any], max_messages: int, path: Path
                  ) -> list[tuple[int, int, list[str], list[float]]]:
    """(receive ns, header ns, names, positions) of each message."""
    rows: list[tuple[int, int, list[str], list[float]]] = []
    for conn, t_recv, raw in reader.messages(connections=conns):
        if len(rows) >= max_messages:
            raise ModelError(f"more than {max_messages:,} messages on the topic; "
                             "pass max_messages= to read more", file=path)
        msg = reader.deserialize(raw, conn.msgtype)
        st = msg.header.stamp
        rows.append((int(t_recv), int(st.sec) * 1_000_000_000 + int(st.nanosec),
                     list(msg.name), np.asarray(msg.position, float).tolist()))
    return rows


#: Header stamps within this of their receive times [ns] are on the bag's clock.
_SAME_CLOCK_NS = 60 * 10**9


def _header_times(head: list[int], recv: list[int]) -> list[int]:
    """The header stamps as times [ns], a zero stamp read as its clock says.

    A zero stamp means "not stamped" (the receive time is used) when the other
    stamps are on the bag's clock (the median within a minute of their receive
    times), or when every stamp is zero; when they are on a clock of their own
    (simulation time, which starts at 0.0), zero is a time like any other.
    """
    stamped = [(h, r) for h, r in zip(head, recv) if h > 0]
    if not stamped:
        return list(recv)
    gaps = sorted(abs(h - r) for h, r in stamped)
    if gaps[len(gaps) // 2] > _SAME_CLOCK_NS:
        return list(head)
    return [h if h > 0 else r for h, r in zip(head, recv)]


def _log_from_states(rows: list[tuple[int, int, list[str], list[float]]], path: Path,
                     topic: str, joint_names: Sequence[str] | None,
                     is_revolute: npt.ArrayLike | None,
                     stamp: Literal["header", "receive"]) -> Trajectory:
    if not rows:
        raise ModelError(f"no messages on {topic}", file=path)
    seen: dict[str, None] = {}
    for _, _, names, _ in rows:
        seen.update(dict.fromkeys(names))
    wanted = list(joint_names) if joint_names is not None else list(rows[0][2])
    missing = [j for j in wanted if j not in seen]
    if missing:
        raise ModelError(f"joint(s) {missing} in no JointState message on {topic}; "
                         f"the messages name {list(seen)}; expected {wanted}", file=path)
    extra = [j for j in seen if j not in wanted]
    if extra:
        warnings.warn(f"{path}: {topic} also names {short_repr(extra, 200)}, joints "
                      "the robot does not have: ignored", UserWarning, stacklevel=3)
    recv, head, q = [], [], []
    for t_recv, t_head, names, pos in rows:
        if len(pos) != len(names):
            continue  # a message without positions for its names (velocity only)
        where = {nm: k for k, nm in enumerate(names)}
        if not all(j in where for j in wanted):
            continue
        recv.append(t_recv)
        head.append(t_head)
        q.append([pos[where[j]] for j in wanted])
    if not q:
        raise ModelError(f"no message on {topic} holds positions of all of {wanted}",
                         file=path)
    times = _header_times(head, recv) if stamp == "header" else recv
    ns = np.asarray(times, np.int64)
    step = np.diff(ns)
    if np.any(step < 0):
        k = int(np.flatnonzero(step < 0)[0]) + 1
        raise ModelError(f"time goes backwards at message {k} of {topic} "
                         f"({stamp} stamps); robokin refuses it rather than reorder"
                         + (" (try stamp='receive', CLI --stamp receive)"
                            if stamp == "header" else ""), file=path)
    keep = np.concatenate([[True], step > 0])
    t = (ns[keep] - ns[0]) * 1e-9
    qa = np.asarray(q)[keep]
    if not np.isfinite(qa).all():
        raise ModelError(f"a JointState position on {topic} is not finite", file=path)
    qd = np.gradient(qa, t, axis=0) if len(t) > 1 else np.zeros_like(qa)
    qdd = np.gradient(qd, t, axis=0) if len(t) > 1 else np.zeros_like(qa)
    return Trajectory(t, qa, qd, qdd, joint_names=tuple(wanted),
                      is_revolute=_flags(is_revolute), via_times=np.array([t[0], t[-1]]))
