# /// script
# requires-python = ">=3.10"
# dependencies = ["robokin[collision]"]
# ///
"""A weld seam on a part in the press cell, followed over every IK branch, as KRL and RAPID.

The press cell (``collision/scenes/press.yaml``) gets a part on the table to the
robot's left, a bracket 160 x 120 x 40 mm, and the AUBO-i5 a welding torch instead
of the gripper. The seam is the fillet along the bracket's edge nearest the robot,
where its side meets the table: 140 mm, a pose every 5 mm, the torch 45 degrees
between the two faces. The torch is round, so it may turn about its own axis:
``robokin.process.follow`` searches every IK branch and every 5 degrees of that
turn, clear of the table, the part and the press, for the motion with the least
joint travel. The result is written as a KUKA KRL program (``seam.src`` and
``seam.dat``) and an ABB RAPID module (``seam.mod``), the tool and the work object
(the bracket's frame) declared, and read back: every Cartesian target is checked
against the seam. ``seam_diagnostics.png`` and ``seam.html`` show every seam pose
green (reachable) or red (not) along the path and in 3D.

Requirements: robokin[collision] (coal, for the scene).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

import robokin
from robokin import collision, process
from robokin.model import geometry
from robokin.spatial import invert, pose_from_xyz_rpy, rotx
from robokin.trajectory.posts import write_program
from robokin.viz.html import write_html

PART_SIZE = np.array([0.16, 0.12, 0.04])  # [m] the bracket
PART_CENTRE = np.array([0.0, 0.69, 0.32])  # [m] on the table top (z = 0.30 m)
STEP = 0.005  # [m] between seam poses
TILT = math.radians(45.0)  # torch between the side face and the table
STICK_OUT = 0.02  # [m] from the nozzle to the TCP (the wire's free end)


def press_cell_with_part() -> collision.Scene:
    """The press cell, the bracket on the table and a torch on the robot."""
    scene = collision.Scene.load(collision.scene_path("press"))
    scene.add_box("bracket", PART_SIZE.tolist(), pose_from_xyz_rpy(PART_CENTRE, [0, 0, 0]))
    # the torch: a neck and a nozzle along the tool z axis, the TCP beyond it
    length = 0.25  # [m] mount to TCP
    neck = geometry.capsule(0.025, 0.12, pose_from_xyz_rpy([0, 0, 0.07], [0, 0, 0]))
    nozzle = geometry.capsule(0.011, 0.07, pose_from_xyz_rpy(
        [0, 0, length - STICK_OUT - 0.035 - 0.011], [0, 0, 0]))
    scene.set_tool([neck, nozzle], tcp=pose_from_xyz_rpy([0, 0, length], [0, 0, 0]),
                   name="torch")
    return scene


def seam_poses() -> tuple[np.ndarray, np.ndarray]:
    """The seam's TCP poses (N, 4, 4) [m] in the world, and the bracket's frame."""
    x0, y_edge, z_table = PART_CENTRE[0] - PART_SIZE[0] / 2 + 0.01, \
        PART_CENTRE[1] - PART_SIZE[1] / 2, 0.30
    xs = np.arange(0.0, 0.14 + 1e-9, STEP) + x0
    # tool z points into the corner: down and toward +y, 45 deg from vertical
    R = rotx(math.pi + TILT)[:3, :3]
    poses = np.tile(np.eye(4), (len(xs), 1, 1))
    poses[:, :3, :3] = R
    poses[:, :3, 3] = np.stack([xs, np.full_like(xs, y_edge), np.full_like(xs, z_table)], -1)
    part_frame = pose_from_xyz_rpy(PART_CENTRE - PART_SIZE / 2 * [1, 1, 1], [0, 0, 0])
    return poses, part_frame


def read_krl_targets(src_dat: tuple[str, str]) -> np.ndarray:
    """The E6POS targets of a KRL .dat: X Y Z [mm] per LIN target."""
    dat = src_dat[1]
    return np.array([[float(v) for v in m.groups()] for m in re.finditer(
        r"DECL E6POS XP\d+=\{X (\S+),Y (\S+),Z (\S+),", dat)])


def main(out_dir: Path = Path("robokin-examples") / "weld_seam") -> None:
    """Follow the seam, write KRL and RAPID into ``out_dir``, read them back."""
    run(out_dir)


def run(out_dir: Path) -> process.FollowResult:
    """What :func:`main` does, returning the motion along the seam (for the tests)."""
    scene = press_cell_with_part()
    robot = robokin.load(scene.robot_name or "aubo_i5")
    placed = scene.attach(robot)
    poses, part_frame = seam_poses()
    res = process.follow(robot, poses, free_axis="z", free_range=(-math.pi, math.pi),
                         max_step=math.radians(10.0), scene=scene, clearance=0.001)
    print(f"{len(poses)} seam poses: {'feasible' if res.feasible else res.reason}; "
          f"joint travel {math.degrees(res.travel):.1f} deg, largest step "
          f"{math.degrees(res.max_step):.2f} deg")
    out_dir.mkdir(parents=True, exist_ok=True)
    # where the seam is reachable (green) or not (red), as a plot and in 3D
    process.plot_follow(res, robot=placed, path=out_dir / "seam_diagnostics.png",
                        overwrite=True)
    write_html(out_dir / "seam.html", placed, np.nan_to_num(res.q),
               scene=process.path_markers(res, scene=scene), dt=0.05)
    if not res.feasible:
        raise SystemExit(f"no motion along the seam: {res.reason}")
    turn = np.degrees(res.free_angle)
    print(f"torch turned between {turn.min():.0f} and {turn.max():.0f} deg about its axis")

    krl = write_program(placed, res, "kuka_krl", out_dir, name="seam", force=True,
                        speed=0.008, zone=0.0005, work_object=part_frame)
    rapid = write_program(placed, res, "abb_rapid", out_dir, name="seam", force=True,
                          speed=0.008, zone=0.0005, work_object=part_frame)
    for prog in (krl, rapid):
        print(f"wrote {', '.join(p.name for p in prog.files)}: {prog.describe()}")
        for note in prog.notes:
            print(f"  note: {note}")

    # read the KRL targets back: the seam in the bracket's frame, to the micrometre
    want = (invert(part_frame) @ poses)[1:, :3, 3] * 1000.0  # [mm]
    got = read_krl_targets((krl.texts["seam.src"], krl.texts["seam.dat"]))
    print(f"KRL LIN targets on the seam within {np.abs(got - want).max() * 1000:.2f} um")
    moves = re.findall(r"^\s*(MoveL|MoveAbsJ) ", rapid.texts["seam.mod"], re.M)
    print(f"RAPID: {moves.count('MoveAbsJ')} MoveAbsJ, {moves.count('MoveL')} MoveL")
    print(f"wrote {out_dir / 'seam_diagnostics.png'} and {out_dir / 'seam.html'}")
    return res


if __name__ == "__main__":
    main()
