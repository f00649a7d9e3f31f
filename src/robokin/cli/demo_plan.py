"""``robokin demo --plan``: the press loading with its free moves planned by robokin.

The hand-made demo (:mod:`robokin.cli.demo`) moves between the scene's poses along
via points a person chose. Here the two free moves (home to the pick approach,
the pick approach to the press approach) are found by the collision-free planner
(:class:`robokin.planning.Planner`: RRT-Connect, shortcutting, corner cutting,
every segment proven clear of the press with the demo's clearance) between the
same configurations; the process moves (the straight approach, lift, entry and
retract lines) and the dwells stay as the hand-made plan has them. Every move is
run as fast as the AUBO-i5's joint limits allow (its robot file's rate limits:
:func:`robokin.trajectory.retime`), stopping between moves as the hand-made plan
does, and the whole cycle is checked against the press again, independently
(:func:`robokin.collision.check`, subdivision between samples).
"""

from __future__ import annotations

import html
import time
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from robokin.collision.scene import Scene
    from robokin.robot import Robot
    from robokin.trajectory.samples import Trajectory

__all__ = ["planned_cycle", "planned_html", "planned_text"]


def _dwell(q: np.ndarray, duration: float, dt: float, label: str) -> Trajectory:
    from robokin.trajectory import Trajectory

    t = np.append(np.arange(0.0, duration, dt), duration)
    zeros = np.zeros((t.size, q.size))
    return Trajectory(t, np.tile(q, (t.size, 1)), zeros, zeros.copy(),
                      labels=(label,))


def planned_cycle(robot: Robot, scene: Scene, hand: Trajectory, plan: tuple, *,
                  clearance: float, dt: float, seed: int = 0) -> tuple[Trajectory, dict]:
    """The press-loading cycle with its joint moves planned, retimed and checked.

    Args:
        robot: The AUBO-i5 (unplaced; the scene places it).
        scene: The press scene.
        hand: The hand-made trajectory (its via points give each move's ends).
        plan: The demo's steps ``(label, kind, pose, duration)``
            (:data:`robokin.cli.demo_job.PLAN`).
        clearance: Distance kept from the press [m].
        dt: Sampling period [s].
        seed: Planner seed.

    Returns:
        The planned cycle and a summary: its duration, the planning time, each
        planned move's waypoints and length, and the independent check.

    Raises:
        UnreachableError: a planned move found no path (the reason names why).
    """
    from robokin import collision, planning
    from robokin.exceptions import UnreachableError
    from robokin.trajectory import Trajectory, retime

    pl = planning.Planner(robot, scene)
    ends = hand.at(hand.via_times)  # (steps + 1, n): each step's start and end
    parts: list[Trajectory] = []
    moves: list[dict[str, Any]] = []
    t_plan = 0.0
    for k, (label, kind, _pose, duration) in enumerate(plan):
        q0, q1 = ends[k], ends[k + 1]
        if kind == "dwell":
            parts.append(_dwell(q0, duration, dt, label))
            continue
        if kind == "joint":
            res = pl.plan(q0, q1, clearance=clearance, seed=seed + k, time_limit=2.0)
            if not res.success:
                raise UnreachableError(f"planning '{label}': {res.reason}")
            t_plan += res.time
            part = pl.trajectory(res, clearance=clearance, dt=dt)
            moves.append({"label": label, "waypoints": int(res.q.shape[0]),
                          "length_rad": round(res.length, 4),
                          "planning_ms": round(res.time * 1e3, 2),
                          "duration_s": round(part.duration, 3)})
        else:  # a process line: the hand-made samples, run as fast as allowed
            inside = (hand.t >= hand.via_times[k] - 1e-9) & (
                hand.t <= hand.via_times[k + 1] + 1e-9)
            part = retime(pl.robot, hand.q[inside], dt=dt)
        parts.append(part.replace(labels=(label,)))
    cycle = Trajectory.concatenate(parts).replace(joint_names=hand.joint_names,
                                                  is_revolute=hand.is_revolute)
    t = time.perf_counter()
    rep = collision.check(robot, scene, cycle, clearance=clearance)
    summary = {
        "duration_s": round(cycle.duration, 3),
        "planning_ms": round(t_plan * 1e3, 2),
        "moves": moves,
        "collides": bool(rep.collides),
        "min_clearance_mm": round(float(rep.min_distance) * 1000.0, 3),
        "check_s": round(time.perf_counter() - t, 3),
    }
    return cycle, summary


def planned_text(p: dict[str, Any]) -> str:
    """The "planned by robokin" line of the terminal table and the report."""
    hand = p.get("hand_made_minimum_s")
    versus = "" if hand is None else f" against {hand:.2f} s for the hand-made path"
    return (f"{p['duration_s']:.2f} s cycle under the AUBO-i5's joint limits{versus} "
            f"(the same limits, process lines and dwells); free moves planned in "
            f"{p['planning_ms']:.0f} ms; "
            f"{'collides' if p['collides'] else 'collision-free'}, "
            f"{p['min_clearance_mm']:.1f} mm clearance")


def planned_html(p: dict[str, Any]) -> str:
    """The report's "Planned by robokin" section: the line and one row per free move."""
    rows = "\n".join(
        f"<tr><td>{html.escape(m['label'])}</td><td>{m['waypoints']}</td>"
        f"<td>{m['length_rad']:.3f}</td><td>{m['planning_ms']:.1f}</td>"
        f"<td>{m['duration_s']:.3f}</td></tr>" for m in p["moves"])
    return (f"<h2>Planned by robokin</h2><p>{html.escape(planned_text(p))}</p>"
            "<table><tr><th>free move</th><th>waypoints</th><th>length [rad]</th>"
            f"<th>planning [ms]</th><th>duration [s]</th></tr>{rows}</table>")
