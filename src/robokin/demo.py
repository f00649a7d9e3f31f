"""The main job: the AUBO-i5 loads a press (``robokin demo``).

It reproduces, on the built-in AUBO-i5 with a parallel gripper, the press-loading
study that motivated robokin: from its zero configuration the arm prepares to
grasp, grasps a workpiece from a fixture, moves to the press opening and places
the workpiece between the dies along a straight final approach, then retracts.

* Via points: zero -> pick approach -> pick -> (lift) pick approach -> press
  approach -> press place; quintic blends between joint via points, Cartesian
  straight lines where the gripper approaches, lifts, enters and retracts.
* Every via pose is solved in closed form (all solutions); the branch taken is the
  solution nearest the scene's taught configuration for that pose (as a
  controller stores a configuration flag with each waypoint), and lines follow
  the nearest closed-form solution sample by sample, so there are no branch flips.
* Sampled every 5 ms (about 25 s, about 5,000 samples), checked against the
  joint position, speed and acceleration limits and, link by link, against the
  press scene (collision and minimum distance, with subdivision between samples).
* The shortest cycle of the same path (:func:`robokin.trajectory.retime`, needs
  ``robokin[retime]``): under the AUBO-i5's limits from its robot file and under
  the demo's own caps, side by side with the planned 24 s; the retimed motion is
  checked against the press again.

Outputs in ``--out`` (default ``./robokin-demo``): ``trajectory.csv`` (time and
joints), ``waypoints.csv`` (the via points in degrees, for reading), the program
the AUBO-i5's controller profile names (``program.waypoints.csv``: every sample in
the controller's joint order and units, for AUBO's SDK waypoint calls; see
:mod:`robokin.trajectory.controllers`), ``joints.png``,
``tool_path.png`` (3D with projections), ``press_views.png`` (the tool path inside
the press, side and top views), ``distance.csv`` and ``distance.png`` (the closest
body pairs over time), ``animation.html`` (the
motion, self-contained), ``report.html`` (one page with all of it) and
``summary.json``. With ``sim=True`` (``robokin demo --sim``) the plan also runs in
MuJoCo: ``sim_*`` files and a "simulated run" section in the report. The command
exits 0 only when the plan is collision-free with at least the required clearance.

With ``place=True`` (``robokin demo --place``) it also asks where else the arm
could stand: robot bases on a 100 mm floor grid within 400 mm of the cell's base are
scored for the same motion (:func:`robokin.cell.place`: one continuous IK branch,
joint limits, clearance, manipulability) and ``placement.png`` maps the feasible
ones (``placement.csv`` lists them all); the cell's own base comes out feasible.

With ``plan=True`` (``robokin demo --plan``) robokin also plans the free moves
itself (:mod:`robokin.demo_plan`: the collision-free planner between the same
configurations, process lines and dwells kept, every move time-optimal under the
robot file's limits) and reports that cycle time next to the hand-made path's
(``planned_trajectory.csv``, a "planned by robokin" row and report section).
"""

from __future__ import annotations

import base64
import html
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from robokin.exceptions import InputError

if TYPE_CHECKING:
    from robokin.collision.report import CollisionReport
    from robokin.collision.scene import Scene
    from robokin.robot import Robot
    from robokin.trajectory.samples import Trajectory

__all__ = ["DemoResult", "plan_press_loading", "run_demo"]

# AUBO-i5 published joint speed limit (150 deg/s on joints 1-3, 180 on 4-6: the demo
# caps all six at 150); the acceleration cap is this demo's own choice for smooth
# motion, not a manufacturer figure (the robot file's rate_limits hold AUBO's).
V_MAX = math.radians(150.0)
A_MAX = math.radians(300.0)
DT = 0.005
MARKER = "summary.json"  # an output folder holding this was written by the demo

# (label, kind, target pose name, duration [s]); "joint" moves go to the closed-form
# solution nearest the scene's taught configuration, "line" moves are straight.
PLAN = (
    ("prepare to grasp", "joint", "pick_approach", 5.0),
    ("approach the part", "line", "pick", 2.5),
    ("close the gripper", "dwell", None, 1.0),
    ("lift the part", "line", "pick_approach", 2.5),
    ("move to the press", "joint", "press_approach", 6.0),
    ("enter the press", "line", "press_place", 3.0),
    ("release the part", "dwell", None, 1.0),
    ("retract", "line", "press_approach", 3.0),
)


@dataclass
class DemoResult:
    """What the demo computed (also written to ``summary.json``)."""

    ok: bool
    summary: dict[str, Any]
    files: dict[str, Path] = field(default_factory=dict)
    trajectory: Any = None
    report: CollisionReport | None = None


def plan_press_loading(
    robot: Robot, scene: Scene, *, dt: float = DT, progress: Any = None
) -> tuple[Any, list[dict[str, Any]]]:
    """Plan the press-loading motion.

    Args:
        robot: The AUBO-i5 as placed in the scene (``scene.attach(robot)``).
        scene: The press scene (its named poses and taught configurations).
        dt: Sampling period [s].
        progress: Optional ``progress(done, total)`` callable.

    Returns:
        The sampled :class:`~robokin.trajectory.Trajectory` and, per via pose, a
        record of the IK (number of solutions, the branch chosen).

    Raises:
        UnreachableError: a via pose has no solution inside the joint limits.
    """
    from robokin import trajectory
    from robokin.exceptions import UnreachableError

    q0 = np.zeros(robot.n)
    path = trajectory.PathBuilder(
        robot, q0, dt=dt, v_max=V_MAX, a_max=A_MAX, ik="analytic"
    )
    via: list[dict[str, Any]] = []
    for label, kind, pose, duration in PLAN:
        if pose is None:  # a dwell: no target
            path.dwell(duration, label=label)
            continue
        T = scene.tcp_pose(pose)
        if kind == "line":
            path.line(T, duration, label=label)
            via.append(
                {
                    "label": label,
                    "pose": pose,
                    "kind": "line",
                    "q_deg": np.degrees(path.q_end).round(4).tolist(),
                }
            )
            continue
        sols = robot.ik(T, q_near=path.q_end).keep_within_limits()
        hint = scene.pose_joints.get(pose, path.q_end)
        try:
            q = sols.nearest(hint)
        except UnreachableError as exc:
            raise UnreachableError(f"via point '{label}' ({pose}): {exc}") from None
        k = int(np.argmin(sols.distance(q)))
        branch = {name: int(v[k]) for name, v in sols.branches.items()}
        via.append(
            {
                "label": label,
                "pose": pose,
                "kind": "joint",
                "solutions": int(sols.count),
                "branch": branch,
                "q_deg": np.degrees(q).round(4).tolist(),
            }
        )
        path.joint(q, duration, label=label)
    traj = path.build(progress=progress)
    return traj, via


# Placement search (``--place``): candidate bases every PLACE_STEP within
# PLACE_SPAN of the cell's base in x and y; the task is the motion after the first
# move (from home, a configuration and not a task pose), every PLACE_EVERY-th sample.
PLACE_SPAN = 0.4  # [m]
PLACE_STEP = 0.1  # [m]
PLACE_EVERY = 10  # samples (50 ms)


def placement_task(traj: Any, every: int = PLACE_EVERY) -> np.ndarray:
    """The tool poses (N, 4, 4) [m] the arm must reach wherever it stands.

    The press-loading motion from the end of its first move (from home) on, every
    ``every``-th sample.
    """
    first = traj.via_times[1] if len(traj.via_times) > 1 else traj.t[0]
    return np.ascontiguousarray(traj.pose[traj.t >= first - 1e-9][::every])


def search_placement(bare: Any, scene: Any, traj: Any, *, clearance: float,
                     scheduler: Any = None, progress: Any = None) -> Any:
    """Score robot bases on a floor grid around the cell's base for the motion.

    Returns:
        A :class:`robokin.cell.Placement`; the cell's own base is a candidate.
    """
    from robokin import cell

    offsets = np.round(np.arange(-PLACE_SPAN, PLACE_SPAN + 1e-9, PLACE_STEP), 9)
    base = scene.base
    yaw = math.atan2(base[1, 0], base[0, 0])
    candidates = cell.base_grid(base[0, 3] + offsets, base[1, 3] + offsets, base[2, 3], yaw)
    return cell.place(bare, placement_task(traj), candidates, scene=scene,
                      clearance=clearance, scheduler=scheduler, progress=progress)


def _placement_summary(pl: Any, scene: Any) -> dict[str, Any]:
    own = int(np.argmin(np.linalg.norm(pl.candidates[:, :3, 3] - scene.base[:3, 3],
                                       axis=1)))
    return {**pl.summary(), "cell_base_feasible": bool(pl.feasible[own]),
            "cell_base_reason": str(pl.reason[own]),
            "cell_base_score": float(pl.score[own])}


def _cycle_times(robot: Any, bare: Any, scene: Any, traj: Any, clearance: float
                 ) -> dict[str, Any]:
    """The shortest cycle of the planned path, and the retimed motion's clearance.

    The minimum cycle time (dwells kept) under the robot file's limits and under the
    demo's caps; the retimed motion is checked against the press again.
    """
    from robokin import collision
    from robokin.exceptions import MissingExtraError
    from robokin.trajectory import retime

    try:
        fast = retime(robot, traj)
        capped = retime(robot, traj, v_max=V_MAX, a_max=A_MAX)
    except MissingExtraError as exc:
        return {"planned_s": round(traj.duration, 3), "note": str(exc)}
    rep = collision.check(bare, scene, fast, clearance=clearance)
    return {"planned_s": round(traj.duration, 3),
            "minimum_s": round(fast.duration, 3),
            "minimum_demo_caps_s": round(capped.duration, 3),
            "retimed_collides": bool(rep.collides),
            "retimed_min_clearance_mm": round(float(rep.min_distance) * 1000.0, 3)}


def _check_out_dir(out: Path, force: bool) -> None:
    if out.exists() and not out.is_dir():
        raise InputError("out", f"{out} exists and is not a folder")
    if (
        out.is_dir()
        and any(out.iterdir())
        and not (out / MARKER).exists()
        and not force
    ):
        raise InputError(
            "out",
            f"{out} holds files the demo did not write; choose another --out "
            "(or pass --force to write into it anyway)",
        )
    out.mkdir(parents=True, exist_ok=True)


def _png_data(path: Path) -> str:
    return base64.b64encode(path.read_bytes()).decode("ascii")


def _closest_pair_distances(report: CollisionReport, k: int = 6) -> dict[str, np.ndarray]:
    """Exact distance at every sample [m] of the ``k`` closest body pairs."""
    out = {}
    for pair in report.pairs[:k]:
        out[f"{pair.body_a}-{pair.body_b}"] = report.distances(pair.body_a, pair.body_b)
    return out


def _write_distance_csv(traj: Trajectory, dist: dict[str, np.ndarray], path: Path) -> Path:
    """Time, the closest pairs' distances and their minimum, in mm."""
    from robokin.io.atomic import write_atomic

    names = list(dist)
    D = np.column_stack([dist[n] for n in names]) * 1000.0
    table = np.column_stack([traj.t, D, D.min(axis=1)])
    header = ",".join(["t [s]"] + [f"{n} [mm]" for n in names] + ["min [mm]"])
    lines = [header] + [",".join(f"{v:.6f}" for v in row) for row in table]
    return write_atomic(path, "\n".join(lines) + "\n")


def _plot_press_views(traj: Trajectory, scene: Scene, report: CollisionReport,
                      path: Path) -> Path:
    """The tool path inside the press: side view (x-z) and top view (x-y)."""
    from matplotlib.patches import Rectangle

    from robokin.viz.plots import _figure, place_labels, save_figure

    if traj.pose is None:  # the planner stores them: a changed plan must too
        raise InputError("trajectory", "has no tool poses to draw")
    p = traj.pose[:, :3, 3] * 1000.0
    fig = _figure((11.0, 5.0))
    views = ((0, 2, "side view (x-z)", "z [mm]"), (0, 1, "top view (x-y)", "y [mm]"))
    placed: list[tuple[Any, list[tuple[float, float, str]]]] = []
    for k, (i, j, title, ylabel) in enumerate(views):
        ax = fig.add_subplot(1, 2, k + 1)
        labels: list[tuple[float, float, str]] = []
        for obj in scene.objects:
            box = getattr(obj.shape, "size", None)
            if box is None or obj.shape.kind != "box":
                continue
            c = obj.pose[:3, 3] * 1000.0
            s = np.abs(obj.pose[:3, :3]) @ (np.asarray(box) * 1000.0)
            press = obj.name in ("lower_die", "upper_die")
            ax.add_patch(
                Rectangle(
                    (c[i] - s[i] / 2, c[j] - s[j] / 2),
                    s[i],
                    s[j],
                    fc="tab:orange" if press else "0.85",
                    ec="0.3",
                    alpha=0.6 if press else 0.35,
                    lw=0.8,
                )
            )
            if press or k == 0:
                labels.append((c[i], c[j], obj.name))
        ax.plot(p[:, i], p[:, j], color="tab:blue", lw=1.4, label="TCP path")
        for tv in traj.via_times:
            m = min(int(round(tv / traj.dt)), len(p) - 1) if traj.dt else 0
            ax.plot(p[m, i], p[m, j], "o", color="tab:blue", ms=3)
        if report is not None and report.closest is not None:
            cpt = report.closest
            a, b = cpt.point_a * 1000.0, cpt.point_b * 1000.0
            ax.plot(
                [a[i], b[i]],
                [a[j], b[j]],
                color="red",
                lw=2,
                label=f"closest: {cpt.distance * 1000:.1f} mm at {cpt.t:.2f} s",
            )
        ax.set_xlim(300, 900)
        ax.set_ylim((200, 800) if j == 2 else (-450, 450))
        ax.set_aspect("equal")
        ax.set_xlabel("x [mm]")
        ax.set_ylabel(ylabel)
        ax.set_title(title)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="upper left")
        placed.append((ax, labels))
    fig.suptitle("the gripper's path into the press opening")
    for ax, labels in placed:  # once the layout is final; column_left and _right
        place_labels(ax, labels)  # share x and z: no two labels overlap
    return save_figure(fig, path, overwrite=True)


def _summary(
    robot: Robot,
    traj: Trajectory,
    report: CollisionReport,
    limits: Any,
    via: list,
    clearance: float,
    timings: dict[str, float],
) -> dict[str, Any]:
    qd = np.abs(traj.qd)
    qdd = np.abs(traj.qdd)
    c = report.closest
    closest = None
    if c is not None:
        closest = {
            "distance_mm": round(c.distance * 1000.0, 3),
            "time_s": round(float(c.t), 3),
            "sample": int(c.index),
            "between_samples": bool(c.between_samples),
            "robot_body": c.body_a,
            "scene_body": c.body_b,
            "point_robot_mm": (c.point_a * 1000.0).round(2).tolist(),
            "point_scene_mm": (c.point_b * 1000.0).round(2).tolist(),
        }
    ok = (
        (not report.collides)
        and report.min_distance >= clearance
        and not limits.violations
    )
    return {
        "robot": robot.name,
        "ok": bool(ok),
        "duration_s": round(float(traj.t[-1] - traj.t[0]), 3),
        "samples": int(traj.t.size),
        "dt_s": DT,
        "segments": list(traj.labels),
        "via_points": via,
        "peak_joint_speed_deg_s": np.degrees(qd.max(axis=0)).round(3).tolist(),
        "peak_joint_acceleration_deg_s2": np.degrees(qdd.max(axis=0)).round(3).tolist(),
        "joint_speed_limit_deg_s": round(math.degrees(V_MAX), 3),
        "joint_acceleration_limit_deg_s2": round(math.degrees(A_MAX), 3),
        "limit_violations": [str(v) for v in limits.violations],
        "required_clearance_mm": round(clearance * 1000.0, 3),
        "min_clearance_mm": round(float(report.min_distance) * 1000.0, 3),
        "closest": closest,
        "collisions": [
            {
                "first_sample": iv.first_index,
                "last_sample": iv.last_index,
                "robot_body": iv.body_a,
                "scene_body": iv.body_b,
                "t_start_s": round(float(iv.t_start), 3),
                "t_end_s": round(float(iv.t_end), 3),
            }
            for iv in report.intervals
        ],
        "exact_distance_queries": int(report.queries),
        "timings_s": {k: round(v, 3) for k, v in timings.items()},
    }


def _cycle_text(c: dict[str, Any]) -> str:
    if "minimum_s" not in c:
        return c.get("note", "not computed")
    return (f"{c['minimum_s']:.2f} s under the AUBO-i5's joint limits (robot file), "
            f"{c['minimum_demo_caps_s']:.2f} s under the demo's 150 deg/s and 300 "
            f"deg/s² caps, against the planned {c['planned_s']:.2f} s (the same "
            f"path, dwells kept; retimed: "
            f"{'collides' if c['retimed_collides'] else 'collision-free'}, "
            f"{c['retimed_min_clearance_mm']:.1f} mm clearance)")


def _planned_text(p: dict[str, Any]) -> str:
    hand = p.get("hand_made_minimum_s")
    versus = "" if hand is None else f" against {hand:.2f} s for the hand-made path"
    return (f"{p['duration_s']:.2f} s cycle under the AUBO-i5's joint limits{versus} "
            f"(the same limits, process lines and dwells); free moves planned in "
            f"{p['planning_ms']:.0f} ms; "
            f"{'collides' if p['collides'] else 'collision-free'}, "
            f"{p['min_clearance_mm']:.1f} mm clearance")


def _planned_html(p: dict[str, Any]) -> str:
    rows = "\n".join(
        f"<tr><td>{html.escape(m['label'])}</td><td>{m['waypoints']}</td>"
        f"<td>{m['length_rad']:.3f}</td><td>{m['planning_ms']:.1f}</td>"
        f"<td>{m['duration_s']:.3f}</td></tr>" for m in p["moves"])
    return (f"<h2>Planned by robokin</h2><p>{html.escape(_planned_text(p))}</p>"
            "<table><tr><th>free move</th><th>waypoints</th><th>length [rad]</th>"
            f"<th>planning [ms]</th><th>duration [s]</th></tr>{rows}</table>")


def _report_html(summary: dict[str, Any], images: dict[str, Path], extra: str = "") -> str:
    s = summary
    c = s["closest"] or {}
    verdict = (
        "PASS: collision-free with the required clearance"
        if s["ok"]
        else "FAIL: the plan collides, violates a limit or is closer than required"
    )
    colour = "#1a7f37" if s["ok"] else "#cf222e"
    rows = [
        ("duration", f"{s['duration_s']:.2f} s"),
        ("shortest cycle of this path", _cycle_text(s.get("cycle_time", {}))),
        ("samples", f"{s['samples']} at {s['dt_s'] * 1000:.0f} ms"),
        (
            "peak joint speed",
            ", ".join(f"{v:.1f}" for v in s["peak_joint_speed_deg_s"])
            + f" deg/s (limit {s['joint_speed_limit_deg_s']:.0f})",
        ),
        (
            "peak joint acceleration",
            ", ".join(f"{v:.1f}" for v in s["peak_joint_acceleration_deg_s2"])
            + f" deg/s² (cap {s['joint_acceleration_limit_deg_s2']:.0f})",
        ),
        ("joint limit violations", str(len(s["limit_violations"])) or "none"),
        (
            "minimum clearance",
            f"{s['min_clearance_mm']:.1f} mm between {c.get('robot_body', '?')} and "
            f"{c.get('scene_body', '?')} at t = {c.get('time_s', float('nan')):.2f} s "
            f"(sample {c.get('sample', '?')}, robot point {c.get('point_robot_mm')} mm)",
        ),
        ("required clearance", f"{s['required_clearance_mm']:.1f} mm"),
        (
            "collisions",
            "none"
            if not s["collisions"]
            else "; ".join(
                f"{x['robot_body']}–{x['scene_body']} {x['t_start_s']:.2f}–"
                f"{x['t_end_s']:.2f} s"
                for x in s["collisions"]
            ),
        ),
    ]
    table = "\n".join(
        f"<tr><th>{html.escape(k)}</th><td>{html.escape(str(v))}</td></tr>"
        for k, v in rows
    )
    vias = "\n".join(
        f"<tr><td>{html.escape(v['label'])}</td><td>{v['kind']}</td>"
        f"<td>{v.get('solutions', '')}</td>"
        f"<td>{html.escape(' '.join(f'{k}={b:+d}' for k, b in v.get('branch', {}).items()))}</td>"
        f"<td>{' '.join(f'{a:.2f}' for a in v['q_deg'])}</td></tr>"
        for v in s["via_points"]
    )
    figs = "\n".join(
        f"<figure><img alt='{html.escape(k)}' src='data:image/png;base64,{_png_data(p)}'>"
        f"<figcaption>{html.escape(k)}</figcaption></figure>"
        for k, p in images.items()
    )
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<title>robokin demo: AUBO-i5 loads a press</title>
<style>
body {{ font-family: system-ui, sans-serif; max-width: 1100px; margin: 1.5em auto;
       color: #1f2328; padding: 0 1em; }}
h1 {{ font-size: 1.5em; margin-bottom: 0.2em; }}
.verdict {{ color: white; background: {colour}; padding: 0.5em 0.8em; border-radius: 6px;
           font-weight: 600; display: inline-block; }}
table {{ border-collapse: collapse; margin: 0.8em 0; font-size: 0.92em; }}
th, td {{ border-bottom: 1px solid #d0d7de; padding: 0.3em 0.8em; text-align: left;
         vertical-align: top; }}
figure {{ margin: 1em 0; }} img {{ max-width: 100%; border: 1px solid #d0d7de; }}
figcaption {{ font-size: 0.85em; color: #57606a; }}
</style></head><body>
<h1>AUBO-i5 loads a press</h1>
<p>robokin's press-loading study: six via points, quintic blends, straight lines where
the gripper approaches, lifts, enters and retracts; closed-form IK (every solution,
the branch nearest the taught configuration, no branch flips); checked link by link
against the press cell. The motion plays in <a href="animation.html">animation.html</a>
(self-contained, no server).</p>
<p class="verdict">{html.escape(verdict)}</p>
<table>{table}</table>
<h2>Via points</h2>
<table><tr><th>step</th><th>kind</th><th>IK solutions</th><th>branch</th>
<th>joints [deg]</th></tr>{vias}</table>
{figs}
{extra}
<p style="font-size:0.8em;color:#57606a">Files: trajectory.csv (time and joints),
waypoints.csv (the via points, degrees), {html.escape(s["controller"]["file"])}
({html.escape(s["controller"]["description"])}),
distance.csv (closest body pairs over time, mm), summary.json. The workpiece rides
between the fingers inside the gripper's envelope and is not a separate body. Joint speed limit: AUBO-i5 published 150 deg/s; the acceleration cap
is the demo's choice.</p>
</body></html>
"""


def _timing_text(timings: dict[str, float]) -> str:
    """``3.2 s (plan 0.24, check 0.22, ...)``: every phase that ran, in run order."""
    parts = ", ".join(f"{k} {v:.2f}" for k, v in timings.items() if k != "total")
    return f"{timings['total']:.1f} s ({parts})"


def run_demo(
    out: str | Path = "robokin-demo",
    *,
    clearance_mm: float = 4.0,
    view: bool = False,
    force: bool = False,
    console: Any = None,
    html_animation: bool = True,
    sim: bool = False,
    place: bool = False,
    scheduler: Any = None,
    plan: bool = False,
) -> DemoResult:
    """Run the press-loading demo end to end and write its outputs.

    Args:
        out: Output folder (created; a folder with files the demo did not write is
            refused unless ``force``).
        clearance_mm: Required minimum distance to the press cell [mm].
        view: Open the live 3D viewer on the result afterwards (blocks).
        force: Write into a folder that holds other files.
        console: A rich Console for the terminal summary (default: a new one).
        html_animation: Also write ``animation.html``.
        sim: Also run the plan in MuJoCo (``robokin[sim]``): ``sim_*`` files and
            a "simulated run" report section (:mod:`robokin.sim.demo_run`).
        place: Also search the floor around the cell's base for robot placements
            that run the same task (``placement.png``: the map of feasible bases,
            ``placement.csv``; needs ``robokin[scale]``).
        scheduler: Where the placement search runs (None: this machine; a Dask
            scheduler address or client).
        plan: Also plan the free moves with robokin's planner and report that
            cycle time next to the hand-made one (:mod:`robokin.demo_plan`).

    Returns:
        A :class:`DemoResult`; ``ok`` is True only when the plan is collision-free
        with at least the required clearance and inside the joint limits.
    """
    from rich.console import Console
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
    from rich.table import Table

    import robokin
    from robokin import collision
    from robokin.io.atomic import write_atomic
    from robokin.io.strict_json import strict_json
    from robokin.trajectory import io
    from robokin.viz import plots

    if not (
        isinstance(clearance_mm, int | float)
        and math.isfinite(clearance_mm)
        and clearance_mm >= 0
    ):
        raise InputError(
            "clearance", f"expected a distance >= 0 [mm], got {clearance_mm!r}"
        )
    clearance = clearance_mm / 1000.0
    out = Path(out)
    _check_out_dir(out, force)
    con = console or Console(emoji=False)
    timings: dict[str, float] = {}
    files: dict[str, Path] = {}
    t_start = time.perf_counter()

    scene = collision.Scene.load(collision.scene_path("press"))
    bare = robokin.load("aubo_i5")
    robot = scene.attach(bare)  # base placement, gripper TCP and gripper shapes
    columns = (
        TextColumn("{task.description:<28}"),
        BarColumn(),
        TextColumn("{task.completed}/{task.total}"),
        TimeElapsedColumn(),
    )
    with Progress(*columns, console=con, transient=False) as bar:
        t = time.perf_counter()
        task = bar.add_task("planning the motion", total=len(PLAN))
        traj, via = plan_press_loading(
            robot, scene, progress=lambda done, total: bar.update(task, completed=done)
        )
        timings["plan"] = time.perf_counter() - t

        t = time.perf_counter()
        task = bar.add_task("checking limits and clearance", total=2)
        limits = traj.check_limits(robot, velocity=V_MAX, acceleration=A_MAX)
        bar.update(task, advance=1)
        report = collision.check(
            bare, scene, traj, clearance=clearance
        )  # attaches itself
        bar.update(task, advance=1)
        timings["check"] = time.perf_counter() - t
        t = time.perf_counter()
        cycle = _cycle_times(robot, bare, scene, traj, clearance)
        timings["retime"] = time.perf_counter() - t
        planned = None
        if plan:
            from robokin.demo_plan import planned_cycle

            t = time.perf_counter()
            task = bar.add_task("planning the free moves", total=None)
            planned, planned_summary = planned_cycle(bare, scene, traj, PLAN,
                                                     clearance=clearance, dt=DT)
            bar.update(task, completed=1, total=1)
            timings["robokin_plan"] = time.perf_counter() - t

        placement = None
        if place:
            t = time.perf_counter()
            task = bar.add_task("scoring robot placements", total=None)
            placement = search_placement(
                bare, scene, traj, clearance=clearance, scheduler=scheduler,
                progress=lambda d, n: bar.update(task, completed=d, total=n))
            placement.plot_floor(out / "placement.png", scene=scene, mark=scene.base)
            files["placement.png"] = out / "placement.png"
            files["placement.csv"] = placement.write_csv(out / "placement.csv")
            timings["place"] = time.perf_counter() - t

        t = time.perf_counter()
        from robokin.trajectory.controllers import controller_program

        program = controller_program(bare, traj)  # what the robot's controller runs
        program_name = "program" + program.suffix
        outputs = [
            "trajectory.csv",
            "waypoints.csv",
            program_name,
            "joints.png",
            "tool_path.png",
            "press_views.png",
            "distance.csv",
            "distance.png",
            "animation.html",
            "report.html",
        ]
        task = bar.add_task("writing the outputs", total=len(outputs))

        def done(name: str, path: Path) -> None:
            files[name] = path
            bar.update(task, advance=1)

        done(
            "trajectory.csv",
            io.write_csv(traj, out / "trajectory.csv", precision=9, overwrite=True),
        )
        from robokin.trajectory import Trajectory

        idx = np.unique(
            np.clip(
                np.rint((traj.via_times - traj.t[0]) / DT).astype(int),
                0,
                len(traj.t) - 1,
            )
        )
        waypoints = Trajectory(
            traj.t[idx],
            traj.q[idx],
            traj.qd[idx],
            traj.qdd[idx],
            joint_names=traj.joint_names,
            is_revolute=traj.is_revolute,
        )
        deg = io.ControllerProfile(name="aubo_i5 (degrees)", angle_unit="deg")
        done(
            "waypoints.csv",
            io.write_csv(
                waypoints,
                out / "waypoints.csv",
                profile=deg,
                precision=10,
                overwrite=True,
            ),
        )
        done(program_name, write_atomic(out / program_name, program.text))
        plots.plot_joints(
            traj,
            path=out / "joints.png",
            overwrite=True,
            title="AUBO-i5 press loading: joints",
        )
        done("joints.png", out / "joints.png")
        plots.plot_tool_path(
            traj,
            robot,
            path=out / "tool_path.png",
            overwrite=True,
            title="tool path with projections",
        )
        done("tool_path.png", out / "tool_path.png")
        done(
            "press_views.png",
            _plot_press_views(traj, scene, report, out / "press_views.png"),
        )
        dist = _closest_pair_distances(report)
        done("distance.csv", _write_distance_csv(traj, dist, out / "distance.csv"))
        from robokin.collision.plots import plot_distance

        pairs = [(p.body_a, p.body_b) for p in report.pairs[: len(dist)]]
        plot_distance(report, pairs, clearance=clearance, out=out / "distance.png")
        done("distance.png", out / "distance.png")
        if html_animation:
            from robokin.viz.html import write_html

            done(
                "animation.html",
                write_html(
                    out / "animation.html",
                    robot,
                    traj,
                    scene=scene,
                    report=report,
                    title="AUBO-i5 loads a press",
                ),
            )
        else:
            bar.update(task, advance=1)
        timings["write"] = time.perf_counter() - t
        timings["total"] = time.perf_counter() - t_start
        summary = _summary(robot, traj, report, limits, via, clearance, timings)
        if placement is not None:
            summary["placement"] = _placement_summary(placement, scene)
        summary["cycle_time"] = cycle
        if planned is not None:
            files["planned_trajectory.csv"] = io.write_csv(
                planned, out / "planned_trajectory.csv", precision=9, overwrite=True)
            summary["planned_by_robokin"] = {
                **planned_summary, "hand_made_planned_s": cycle.get("planned_s"),
                "hand_made_minimum_s": cycle.get("minimum_s")}
            summary["ok"] = bool(summary["ok"] and not planned_summary["collides"]
                                 and planned_summary["min_clearance_mm"]
                                 >= clearance * 1000.0)
        summary["controller"] = {"program": program.program, "file": program_name,
                                 "profile": program.profile.name,
                                 "description": program.describe()}
        shown = ("joints.png", "press_views.png", "distance.png", "tool_path.png",
                 "placement.png")
        images: dict[str, Path] = {k: files[k] for k in shown if k in files}
        sim_html = ""
        if sim:
            from robokin.sim.demo_run import simulated_run

            t = time.perf_counter()
            summary["simulated_run"], sim_files, sim_html = simulated_run(
                bare, scene, traj, out, report.min_distance)
            files.update({f"sim_{k}": v for k, v in sim_files.items()})
            timings["sim"] = time.perf_counter() - t
        timings["total"] = time.perf_counter() - t_start
        summary["timings_s"] = {k: round(v, 3) for k, v in timings.items()}
        report_path = out / "report.html"
        if "planned_by_robokin" in summary:
            sim_html = _planned_html(summary["planned_by_robokin"]) + sim_html
        write_atomic(report_path, _report_html(summary, images, sim_html))
        done("report.html", report_path)
    write_atomic(out / MARKER, strict_json(summary, indent=2) + "\n")
    files["summary.json"] = out / MARKER

    table = Table(title="robokin demo: AUBO-i5 loads a press", show_header=False)
    table.add_column(style="bold", overflow="fold")
    table.add_column(overflow="fold")  # never cut a value
    c = summary["closest"] or {}
    table.add_row(
        "duration",
        f"{summary['duration_s']:.2f} s, {summary['samples']} samples "
        f"at {DT * 1000:.0f} ms",
    )
    table.add_row(
        "peak joint speed",
        "  ".join(f"{v:.1f}" for v in summary["peak_joint_speed_deg_s"]) + " deg/s",
    )
    table.add_row(
        "peak joint acceleration",
        "  ".join(f"{v:.1f}" for v in summary["peak_joint_acceleration_deg_s2"])
        + " deg/s²",
    )
    table.add_row("shortest cycle", _cycle_text(summary["cycle_time"]))
    if "planned_by_robokin" in summary:
        table.add_row("planned by robokin", _planned_text(summary["planned_by_robokin"]))
    table.add_row("joint limit violations", str(len(summary["limit_violations"])))
    table.add_row(
        "minimum clearance",
        f"{summary['min_clearance_mm']:.1f} mm ({c.get('robot_body')} – "
        f"{c.get('scene_body')}, t = {c.get('time_s', float('nan')):.2f} s)",
    )
    table.add_row("required clearance", f"{summary['required_clearance_mm']:.1f} mm")
    table.add_row(
        "collisions",
        "none" if not summary["collisions"] else str(len(summary["collisions"])),
    )
    table.add_row("time", _timing_text(timings))
    table.add_row("controller program", f"{program_name}: {program.describe()}")
    if sim:
        from robokin.sim.report import speed_text

        sr = summary["simulated_run"]
        table.add_row("simulated run", (
            "max error " + "  ".join(f"{j['max_error']:.3f}" for j in sr["joints"])
            + f" deg; {speed_text(sr['timing']['real_time_factor'])}; "
            + ("PASS" if sr["ok"] else "FAIL")))
    if placement is not None:
        ps = summary["placement"]
        table.add_row(
            "placement",
            f"{ps['feasible']} of {ps['candidates']} bases feasible; this cell's base "
            + ("feasible" if ps["cell_base_feasible"] else f"not: {ps['cell_base_reason']}"),
        )
    table.add_row("report", str(report_path))
    con.print(table)
    con.print(
        ("[bold green]PASS[/]" if summary["ok"] else "[bold red]FAIL[/]")
        + f": outputs in {out}"
    )
    if view:
        from robokin.viz.viewer import view as open_viewer

        con.print("viewer on http://127.0.0.1:8080 (Ctrl-C to stop)")
        open_viewer(robot, traj, scene=scene, report=report)
    return DemoResult(summary["ok"], summary, files, traj, report)
