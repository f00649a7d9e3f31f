"""The demo's optional ``--sim`` step: the press-loading plan run in MuJoCo.

:func:`simulated_run` simulates the plan through the AUBO-i5's servos in the
press cell, computes its inverse dynamics, checks the *simulated* motion's
clearance with robokin's own collision check, writes the ``sim_*`` files and
returns the summary and the report's "simulated run" section.
"""

from __future__ import annotations

import base64
import html
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from robokin.collision.scene import Scene
    from robokin.robot import Robot
    from robokin.trajectory.samples import Trajectory

__all__ = ["simulated_run"]


def simulated_run(robot: Robot, scene: Scene, traj: Trajectory, out: Path,
                  plan_clearance: float) -> tuple[dict[str, Any], dict[str, Path], str]:
    """Simulate the plan, write ``sim_*`` files, and describe the run.

    Args:
        robot: The bare robot (the scene places it).
        scene: The press scene.
        traj: The planned trajectory.
        out: The demo's output folder.
        plan_clearance: The plan's minimum clearance [m], for comparison.

    Returns:
        ``(summary, files, html)``: the run's JSON-ready summary (with the
        simulated motion's clearance), the files written, and the HTML section.
    """
    from robokin import collision
    from robokin.sim import inverse_dynamics, simulate
    from robokin.sim.report import run_summary, write_run

    res = simulate(robot, traj, scene)
    inv = inverse_dynamics(robot, traj, scene)
    files = write_run(res, inv, out, prefix="sim_", title="simulated run: ")
    summary = run_summary(res, inv)
    rep = collision.check(robot, scene, res.trajectory())
    summary["simulated_min_clearance_mm"] = round(float(rep.min_distance) * 1000.0, 3)
    summary["plan_min_clearance_mm"] = round(float(plan_clearance) * 1000.0, 3)
    return summary, files, _section_html(summary, files)


def _img(path: Path, alt: str) -> str:
    data = base64.b64encode(Path(path).read_bytes()).decode("ascii")
    return (f"<figure><img alt='{html.escape(alt)}' src='data:image/png;base64,{data}'>"
            f"<figcaption>{html.escape(alt)}</figcaption></figure>")


def _section_html(s: dict[str, Any], files: dict[str, Path]) -> str:
    from robokin.sim.report import speed_text

    e = html.escape
    rows = []
    for r in s["joints"]:
        corr = r["corr_error_acceleration"]
        lim = r["torque_limit"]
        rows.append(
            f"<tr><td>{e(r['joint'])}</td><td>{r['max_error']:.4f}</td>"
            f"<td>{r['t_max_error_s']:.2f}</td><td>{r['rms_error']:.4f}</td>"
            f"<td>{'-' if corr is None else f'{corr:.2f}'}</td>"
            f"<td>{r['peak_torque']:.2f}</td><td>{r['required_peak_torque']:.2f}</td>"
            f"<td>{'unknown' if lim is None else f'{lim:.0f}'}</td>"
            f"<td>{r['peak_power_w']:.1f}</td></tr>")
    t = s["timing"]
    verdict = "PASS" if s["ok"] else "FAIL: " + "; ".join(s["reasons"])
    contacts = ("none" if not s["contacts"] else "; ".join(
        f"{c['body_a']}–{c['body_b']} {c['t_start_s']:.3f}–{c['t_end_s']:.3f} s"
        for c in s["contacts"]))
    tol = s["tolerance"]
    return f"""<h2>Simulated run (MuJoCo)</h2>
<p>The plan driven through the arm's position servos in MuJoCo (stepped at
{t['physics_rate_hz']:.0f} Hz, the plan's samples as set points; PD with velocity
feed-forward and gravity compensation, {e(s['servo']['actuators'])} servos). Mass
properties: {e(s['mass_properties'])}.</p>
<p><b>{e(verdict)}</b> (tolerance {tol['angle_deg']:.2g} deg, {tol['length_mm']:.2g} mm;
torques against the published limits where known; contacts: {e(contacts)}).
{t['simulated_s']:.1f} s simulated in {t['wall_s']:.2f} s:
{e(speed_text(t['real_time_factor']))}. Minimum clearance of the simulated motion
{s['simulated_min_clearance_mm']:.2f} mm (plan {s['plan_min_clearance_mm']:.2f} mm).</p>
<table><tr><th>joint</th><th>max |error| [deg]</th><th>at [s]</th><th>RMS [deg]</th>
<th>corr(|error|, |acc|)</th><th>peak torque [N m]</th><th>required (inverse
dynamics) [N m]</th><th>limit [N m]</th><th>peak power [W]</th></tr>
{''.join(rows)}</table>
{_img(files['tracking.png'], 'tracking error of the simulated run, and the planned acceleration')}
{_img(files['torques.png'], 'joint torques (simulated, and required by the plan) and power')}
"""
