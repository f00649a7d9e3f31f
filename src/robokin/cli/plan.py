"""``robokin plan``: a collision-free motion in a scene, planned, smoothed and retimed.

::

    robokin plan press --start pick_approach --goal press_approach --out run
    robokin plan cell.yaml --deg --mm --clearance 5 --start 0 -90 90 0 90 0
        --goal-pose 500 0 400 180 0 0      # (one command)

``--start`` and ``--goal`` take a joint configuration (as many values as the robot
has joints) or the name of a scene pose that gives one (``q:``); ``--goal-pose``
takes a TCP pose ``x y z roll pitch yaw`` in the world or a scene pose's name, and
every IK solution inside the joint limits is a goal. Values are radians and metres
unless ``--deg`` / ``--mm``; ``--clearance`` is in millimetres (as ``robokin
check``'s).

Writes into ``--out`` the time-optimal trajectory (``plan.csv``: time and joints,
every step between samples proven collision-free) and its joint plot
(``plan.png``), all or none; existing files are replaced only with ``--force``.
Exit code 1 when no path is found (the reason is printed), 2 for bad input.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from robokin.cli.common import (
    NUMERIC_ARGS,
    DomainFailure,
    json_text,
    scene_file,
    scene_robot,
)
from robokin.cli.options import DegFlag, JsonFlag, MmFlag, NoPlotFlag
from robokin.cli.output import FormatOption, resolve_format

if TYPE_CHECKING:
    import numpy as np

    from robokin.collision.scene import Scene
    from robokin.planning import Planner, PlanResult
    from robokin.robot import Robot
    from robokin.trajectory.samples import Trajectory

__all__ = ["commands", "plan_command"]

commands = typer.Typer()

#: The files ``robokin plan`` writes into ``--out``.
OUTPUTS = ("plan.csv", "plan.png")
#: The options behind the arguments of Planner.plan and Planner.trajectory.
_OPTIONS = {"time_limit": "--time-limit", "seed": "--seed", "planner": "--planner",
            "dt": "--dt", "goal": "--goal-pose", "start": "--start"}


def _numbers(text: str) -> list[float] | None:
    try:
        return [float(v) for v in text.replace(",", " ").split()]
    except ValueError:
        return None


def _configuration(text: str, option: str, robot: Robot, scene: Scene, deg: bool,
                   mm: bool) -> np.ndarray:
    """N joint values (in the CLI units) or the name of a scene pose with ``q``."""
    import numpy as np

    from robokin.exceptions import InputError

    vals = _numbers(text)
    if vals is None:
        if text in scene.pose_joints:
            return np.asarray(scene.pose_joints[text], dtype=float)
        named = [k for k in scene.poses if k in scene.pose_joints]
        raise InputError(option, f"expected {robot.n} joint values or the name of a scene "
                         f"pose with joints; got {text!r} (scene poses with joints: "
                         f"{named})")
    if len(vals) != robot.n:
        raise InputError(option, f"expected {robot.n} joint values, got {len(vals)}")
    a = math.pi / 180.0 if deg else 1.0
    length = 1e-3 if mm else 1.0
    return np.where(robot.is_revolute, np.array(vals) * a, np.array(vals) * length)


def _pose(text: str, scene: Scene, deg: bool, mm: bool) -> np.ndarray:
    """``x y z roll pitch yaw`` (CLI units) or a scene pose's name -> (4, 4)."""
    import numpy as np

    from robokin.exceptions import InputError
    from robokin.spatial import pose_from_xyz_rpy

    vals = _numbers(text)
    if vals is None:
        if text in scene.poses:
            return scene.poses[text]
        raise InputError("--goal-pose", f"expected x y z roll pitch yaw or a scene pose "
                         f"name; got {text!r} (scene poses: {list(scene.poses)})")
    if len(vals) != 6 or not all(math.isfinite(v) for v in vals):
        raise InputError("--goal-pose", f"expected 6 finite numbers x y z roll pitch yaw, "
                         f"got {len(vals)}")
    length = 1e-3 if mm else 1.0
    a = math.pi / 180.0 if deg else 1.0
    return pose_from_xyz_rpy(np.array(vals[:3]) * length, np.array(vals[3:]) * a)


def _scene_and_robot(scene_arg: Path, robot_arg: str | None) -> tuple[Scene, Robot, Path]:
    import robokin
    from robokin import collision

    path = scene_file(scene_arg)
    sc = collision.Scene.load(path)
    return sc, robokin.load(scene_robot(sc, robot_arg)), path


def _check_out(out: Path, names: list[str], force: bool) -> None:
    """Refuse an --out that is a file, or outputs that exist (without --force)."""
    from robokin.exceptions import InputError

    if out.exists() and not out.is_dir():
        raise InputError("--out", f"{out} exists and is not a folder")
    taken = [n for n in names if (out / n).exists()]
    if taken and not force:
        raise InputError("--out", f"{out / taken[0]} exists; pass --force to replace it "
                         "(or choose another --out)")


@commands.command("plan", context_settings=NUMERIC_ARGS)
def plan_command(
    scene: Annotated[Path, typer.Argument(help="Scene file (YAML), or a bundled name.")],
    start: Annotated[str, typer.Option(
        "--start", help="Start: q1 ... qn, or a scene pose name with joints.")],
    goal: Annotated[str | None, typer.Option(
        "--goal", help="Goal configuration: q1 ... qn, or a scene pose name.")] = None,
    goal_pose: Annotated[str | None, typer.Option(
        "--goal-pose", help="Goal TCP pose: x y z roll pitch yaw in the world, or a "
        "scene pose name (every IK branch is a goal).")] = None,
    robot: Annotated[str | None, typer.Option(
        "--robot", help="Built-in name or robot file (default: the scene's).")] = None,
    deg: DegFlag = False,
    mm: MmFlag = False,
    clearance: Annotated[float, typer.Option(
        help="Distance kept from the scene \\[mm].")] = 0.0,
    time_limit: Annotated[float, typer.Option(
        "--time-limit", help="Planning time limit \\[s].")] = 1.0,
    seed: Annotated[int, typer.Option(help="Random seed (same seed, same path).")] = 0,
    planner: Annotated[str, typer.Option(
        help="rrtconnect (compiled) or ompl:<name> (robokin[plan]).")] = "rrtconnect",
    dt: Annotated[float, typer.Option("--dt", help="Sampling period \\[s].")] = 0.005,
    out: Annotated[Path, typer.Option("--out", help="Output folder.")] = Path(
        "robokin-plan"),
    no_plot: NoPlotFlag = False,
    force: Annotated[bool, typer.Option(
        "--force", help="Replace plan.csv / plan.png left by an earlier run.")] = False,
    as_json: JsonFlag = False,
    output_format: FormatOption = None,
) -> None:
    """Plan a collision-free motion from --start to --goal (or --goal-pose); retime it.

    Exit code 1 when no path is found within the time limit (the reason is printed).
    """
    from robokin import planning
    from robokin.exceptions import InputError
    from robokin.io.atomic import check_distinct, staged_outputs
    from robokin.trajectory.io import write_csv

    fmt = resolve_format(output_format, as_json)
    if (goal is None) == (goal_pose is None):
        raise InputError("--goal", "give exactly one of --goal and --goal-pose")
    if not math.isfinite(clearance) or clearance < 0:
        raise InputError("--clearance", f"expected a number >= 0 [mm], got {clearance}")
    sc, rob, scene_path = _scene_and_robot(scene, robot)
    names = [OUTPUTS[0]] + ([] if no_plot else [OUTPUTS[1]])
    check_distinct([(out / n, "--out") for n in names],
                   [(scene_path, "SCENE"), (rob.path, "--robot")])
    _check_out(out, names, force)
    q0 = _configuration(start, "--start", rob, sc, deg, mm)
    target = (_configuration(goal, "--goal", rob, sc, deg, mm) if goal is not None
              else _pose(str(goal_pose), sc, deg, mm))
    pl = planning.Planner(rob, sc)
    try:
        res = pl.plan(q0, target, time_limit=time_limit, seed=seed, planner=planner,
                      clearance=clearance * 1e-3)
        if not res.success:
            raise DomainFailure(f"no path: {res.reason}")
        traj = pl.trajectory(res, clearance=clearance * 1e-3, dt=dt)
    except InputError as exc:  # name the option, not the function argument
        option = _OPTIONS.get(exc.argument)
        if option is None:
            raise
        raise InputError(option, exc.reason) from None
    out.mkdir(parents=True, exist_ok=True)
    targets = [(out / n, "--out", force) for n in names]
    with staged_outputs(targets, how="pass --force (or choose another --out)") as staged:
        write_csv(traj, staged[0], pl.robot.joint_names)
        if not no_plot:
            from robokin.viz.plots import plot_joints

            plot_joints(traj, path=staged[1],
                        title=f"{rob.name}: planned in {sc.name}"[:200])
    files = [str(out / n) for n in names]
    _report(res, traj, pl, files, fmt)


def _report(res: PlanResult, traj: Trajectory, pl: Planner, files: list[str],
            fmt: str) -> None:
    """Print what was planned and written (text or ``--json``)."""
    import numpy as np

    rev = pl.robot.is_revolute
    scale = np.where(rev, 180.0 / math.pi, 1000.0)
    goal = (np.asarray(res.goal) * scale).round(4).tolist()
    doc = {"robot": pl.robot.name, "scene": pl.scene.name, "planner": res.planner,
           "planning_time_s": res.time, "waypoints": int(res.q.shape[0]),
           "path_length": res.length, "duration_s": traj.duration,
           "samples": len(traj), "goal_deg_mm": goal, "goal_index": res.goal_index,
           "goals": int(res.goals.shape[0]), "files": files}
    if fmt == "json":
        print(json_text(doc))
        return
    from robokin.cli.output import say

    which = "" if res.goal_index is None else \
        f"; goal {res.goal_index + 1} of {res.goals.shape[0]}"
    say(f"{pl.robot.name} in {pl.scene.name}: path found by {res.planner} in "
        f"{res.time * 1e3:.1f} ms ({res.q.shape[0]} waypoints, joint-space length "
        f"{res.length:.3f}{which})", fmt)
    say(f"time-optimal trajectory: {traj.duration:.3f} s, {len(traj)} samples, every "
        "step proven collision-free", fmt)
    say("goal [deg, mm]: " + " ".join(f"{v:g}" for v in goal), fmt)
    say("wrote " + ", ".join(files), fmt)
