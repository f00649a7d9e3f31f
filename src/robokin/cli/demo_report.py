"""The outputs of ``robokin demo``: figures, CSV files, the summary and the HTML report."""

from __future__ import annotations

import base64
import html
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from robokin.cli.demo_job import A_MAX, DT, V_MAX
from robokin.exceptions import InputError
from robokin.io.atomic import write_atomic
from robokin.viz.plots import _figure, place_labels, save_figure

if TYPE_CHECKING:
    from robokin.collision.report import CollisionReport
    from robokin.collision.scene import Scene
    from robokin.robot import Robot
    from robokin.trajectory.samples import Trajectory

__all__ = ["MARKER", "check_out_dir", "closest_pair_distances", "cycle_text",
           "demo_summary", "plot_press_views", "report_html", "timing_text",
           "write_distance_csv"]

MARKER = "summary.json"  # an output folder holding this was written by the demo


def check_out_dir(out: Path, force: bool) -> None:
    """Create ``out``; refuse a file, or a folder holding files the demo did not write.

    Raises:
        InputError: naming ``out``; ``force`` writes into a foreign folder anyway.
    """
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


def closest_pair_distances(report: CollisionReport, k: int = 6) -> dict[str, np.ndarray]:
    """Exact distance at every sample [m] of the ``k`` closest body pairs."""
    out = {}
    for pair in report.pairs[:k]:
        out[f"{pair.body_a}-{pair.body_b}"] = report.distances(pair.body_a, pair.body_b)
    return out


def write_distance_csv(traj: Trajectory, dist: dict[str, np.ndarray], path: Path) -> Path:
    """Time, the closest pairs' distances and their minimum, in mm."""
    names = list(dist)
    D = np.column_stack([dist[n] for n in names]) * 1000.0
    table = np.column_stack([traj.t, D, D.min(axis=1)])
    header = ",".join(["t [s]"] + [f"{n} [mm]" for n in names] + ["min [mm]"])
    lines = [header] + [",".join(f"{v:.6f}" for v in row) for row in table]
    return write_atomic(path, "\n".join(lines) + "\n")


def plot_press_views(traj: Trajectory, scene: Scene, report: CollisionReport,
                     path: Path) -> Path:
    """The tool path inside the press: side view (x-z) and top view (x-y)."""
    from matplotlib.patches import Rectangle

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


def demo_summary(
    robot: Robot,
    traj: Trajectory,
    report: CollisionReport,
    limits: Any,
    via: list[dict[str, Any]],
    clearance: float,
    timings: dict[str, float],
) -> dict[str, Any]:
    """What ``summary.json`` holds of the plan and its checks (JSON-ready values).

    ``ok`` is True only when the plan is collision-free, keeps ``clearance`` [m]
    and breaks no joint limit.
    """
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


def cycle_text(c: dict[str, Any]) -> str:
    """The shortest-cycle line of the terminal table and the report."""
    if "minimum_s" not in c:
        return c.get("note", "not computed")
    return (f"{c['minimum_s']:.2f} s under the AUBO-i5's joint limits (robot file), "
            f"{c['minimum_demo_caps_s']:.2f} s under the demo's 150 deg/s and 300 "
            f"deg/s² caps, against the planned {c['planned_s']:.2f} s (the same "
            f"path, dwells kept; retimed: "
            f"{'collides' if c['retimed_collides'] else 'collision-free'}, "
            f"{c['retimed_min_clearance_mm']:.1f} mm clearance)")


def _report_rows(s: dict[str, Any]) -> list[tuple[str, str]]:
    """The report's table: (what, value) per line."""
    c = s["closest"] or {}
    return [
        ("duration", f"{s['duration_s']:.2f} s"),
        ("shortest cycle of this path", cycle_text(s.get("cycle_time", {}))),
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


def report_html(summary: dict[str, Any], images: dict[str, Path], extra: str = "") -> str:
    """``report.html``: the verdict, the table, the via points, the figures (inline).

    Args:
        summary: What :func:`demo_summary` returned, with the cycle time and the
            controller program added.
        images: Figure name -> PNG file, embedded in that order.
        extra: HTML added after the figures (the simulated run's section).
    """
    s = summary
    verdict = (
        "PASS: collision-free with the required clearance"
        if s["ok"]
        else "FAIL: the plan collides, violates a limit or is closer than required"
    )
    colour = "#1a7f37" if s["ok"] else "#cf222e"
    rows = _report_rows(s)
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


def timing_text(timings: dict[str, float]) -> str:
    """``3.2 s (plan 0.24, check 0.22, ...)``: every phase that ran, in run order."""
    parts = ", ".join(f"{k} {v:.2f}" for k, v in timings.items() if k != "total")
    return f"{timings['total']:.1f} s ({parts})"
