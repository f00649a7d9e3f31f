# /// script
# requires-python = ">=3.10"
# dependencies = ["robokin[ros]"]
# ///
"""A ROS 2 bag of the pick cycle as a real arm would log it, for ``robokin compare``.

Reads ``plan.csv`` (the planned pick cycle of ``pick.yaml``), makes the run a
real arm would log from it (the servos 12 ms late, a few hundredths of a degree
off, 50 Hz, a little noise) and writes it as a ROS 2 bag: ``sensor_msgs/JointState``
messages on ``/joint_states`` in MCAP storage, written with rosbags (no ROS
install). ``run_bag/`` in this folder is what this script writes with its defaults
(``--out`` names another folder); ``robokin compare plan.csv run_bag`` reads it.

Requirements: robokin[ros] (rosbags).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import robokin
from robokin.trajectory.io import read_csv

HERE = Path(__file__).resolve().parent
LAG = 0.012  # [s] the servos follow the plan this late
OFFSET_DEG = np.array([0.02, -0.03, 0.01, 0.0, 0.04, -0.02])  # [deg] per joint
NOISE_DEG = 0.002  # [deg] encoder noise, standard deviation
RATE = 50.0  # [Hz] JointState messages
START_NS = 1_700_000_000 * 10**9  # the header stamp of the first message [ns]


def logged_run(plan_t: np.ndarray, plan_q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The logged run: times [s] at ``RATE`` and joint positions [rad], seeded."""
    t = np.arange(0.0, plan_t[-1], 1.0 / RATE)
    q = np.stack([np.interp(t - LAG, plan_t, plan_q[:, j])
                  for j in range(plan_q.shape[1])], axis=-1)
    rng = np.random.default_rng(7)
    q += np.radians(OFFSET_DEG) + rng.normal(0.0, np.radians(NOISE_DEG), q.shape)
    return t, q


def write_bag(folder: Path, names: tuple[str, ...], t: np.ndarray, q: np.ndarray) -> None:
    """Write ``/joint_states`` (sensor_msgs/msg/JointState) into a new MCAP bag folder."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    JointState = store.types["sensor_msgs/msg/JointState"]
    Header = store.types["std_msgs/msg/Header"]
    Time = store.types["builtin_interfaces/msg/Time"]
    with Writer(folder, version=9, storage_plugin=StoragePlugin.MCAP) as bag:
        topic = bag.add_connection("/joint_states", "sensor_msgs/msg/JointState",
                                   typestore=store)
        for tk, qk in zip(t, q):
            ns = START_NS + round(tk * 1e9)
            msg = JointState(
                header=Header(stamp=Time(sec=ns // 10**9, nanosec=ns % 10**9),
                              frame_id=""),
                name=list(names), position=qk, velocity=np.zeros(0),
                effort=np.zeros(0))
            # received 1 ms after its stamp
            bag.write(topic, ns + 1_000_000,
                      store.serialize_cdr(msg, "sensor_msgs/msg/JointState"))


def main() -> None:
    """Write the bag (``--out``, default ``run_bag`` in the current folder)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("run_bag"),
                        help="the bag folder to write (must not exist)")
    out = parser.parse_args().out
    robot = robokin.load(HERE / "arm.yaml")
    plan = read_csv(HERE / "plan.csv", joint_names=robot.joint_names,
                    is_revolute=robot.is_revolute)
    t, q = logged_run(plan.t, plan.q)
    write_bag(out, tuple(robot.joint_names), t, q)
    print(f"wrote {out}: {len(t)} JointState messages on /joint_states, "
          f"{t[-1]:.2f} s at {RATE:g} Hz")


if __name__ == "__main__":
    main()
