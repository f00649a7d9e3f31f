"""Figures, tables and files of a simulated run.

Used by ``robokin sim`` and the demo's "simulated run" section:

* :func:`plot_torques`: the actuator torques of the run and the inverse dynamics
  of the plan over time, with the torque limits, and the joints' power;
* :func:`run_summary`: a JSON-ready summary (tracking error per joint and its
  correlation with acceleration, peak torques against limits, contacts,
  real-time ratio, the verdict and its reasons);
* :func:`write_run`: every output of a run into a folder.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from robokin.sim.inverse import InverseDynamics
    from robokin.sim.simulate import SimResult

__all__ = ["RUN_FILES", "plot_decoupling", "plot_torques", "run_summary", "speed_text",
           "write_run"]


def _unit(revolute: bool) -> tuple[str, str]:
    return ("N m", "W") if revolute else ("N", "W")


def plot_torques(result: SimResult, inverse: InverseDynamics | None = None, *,
                 path: str | Path | None = None, title: str | None = None,
                 overwrite: bool = False) -> Any:
    """Torque per joint over time, the limits, and the joints' power.

    The simulated torques are solid, the plan's inverse dynamics dashed, the
    limits horizontal lines.

    Args:
        result: A :class:`~robokin.sim.simulate.SimResult`.
        inverse: The plan's :class:`~robokin.sim.inverse.InverseDynamics` (power
            and dashed torques), or None.
        path: Also save the figure here (PNG, SVG, PDF).
        title: Figure title.
        overwrite: Replace an existing file.

    Returns:
        The matplotlib Figure.
    """
    from robokin.viz.plots import _figure, save_figure

    n = result.q.shape[1]
    names = result.plan.names()
    rev = result.plan.revolute()
    fig = _figure((10.0, 2.0 + 1.6 * n))
    axes = fig.subplots(n + (1 if inverse is not None else 0), 1, sharex=True,
                        squeeze=False)[:, 0]
    for j in range(n):
        ax = axes[j]
        u = _unit(bool(rev[j]))[0]
        ax.plot(result.t, result.tau[:, j], color=f"C{j}", lw=1.0, label="simulated")
        if inverse is not None:
            ax.plot(inverse.t, inverse.tau[:, j], color="k", lw=0.8, ls="--",
                    label="inverse dynamics of the plan")
        lim = result.torque_limits[j]
        if math.isfinite(lim):
            for s in (-1, 1):
                ax.axhline(s * lim, color="red", lw=0.8, ls=":",
                           label="limit" if s > 0 else None)
        ax.set_ylabel(f"{names[j]} [{u}]", fontsize="small")
        ax.grid(True, alpha=0.3)
        if j == 0:
            ax.legend(fontsize="x-small", loc="upper right")
    if inverse is not None:
        ax = axes[-1]
        for j in range(n):
            ax.plot(inverse.t, inverse.power[:, j], lw=1.0, label=names[j])
        ax.set_ylabel("power [W]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="x-small", loc="upper left", bbox_to_anchor=(1.0, 1.0))
    axes[-1].set_xlabel("time [s]")
    fig.suptitle(title or "joint torques (simulated and required) and power")
    if path is not None:
        save_figure(fig, path, overwrite=overwrite)
    return fig


def plot_decoupling(check: Any, *, path: str | Path | None = None,
                    overwrite: bool = False) -> Any:
    """The shaft's rotation and height: plan, decoupled and naive motor commands.

    Args:
        check: A :class:`~robokin.sim.decoupling.DecouplingCheck`.
        path: Also save the figure here.
        overwrite: Replace an existing file.
    """
    from robokin.viz.plots import _figure, save_figure

    j_rot, j_lift = check.joints
    fig = _figure((10.0, 6.0))
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    t = check.decoupled.t
    for ax, j, s, u, what in ((ax1, j_rot, 180 / math.pi, "deg", "shaft rotation"),
                              (ax2, j_lift, 1000.0, "mm", "shaft height (lift)")):
        ax.plot(t, check.decoupled.plan.q[:, j] * s, color="k", lw=2.2, alpha=0.4,
                label="joint plan")
        ax.plot(t, check.decoupled.q[:, j] * s, color="C0", lw=1.0,
                label="decoupled motor commands (A^+ (q - b))")
        ax.plot(t, check.naive.q[:, j] * s, color="C3", lw=1.0, ls="--",
                label="naive uncoupled commands")
        ax.set_ylabel(f"{what} [{u}]")
        ax.grid(True, alpha=0.3)
    ax1.legend(fontsize="small")
    ax2.set_xlabel("time [s]")
    fig.suptitle("SCARA ball-screw / ball-spline: the motors drive the shaft "
                 "(MuJoCo)")
    if path is not None:
        save_figure(fig, path, overwrite=overwrite)
    return fig


def speed_text(real_time_factor: float) -> str:
    """How fast a run went against the clock, in words.

    Args:
        real_time_factor: Wall time per simulated second (below 1: faster).

    Returns:
        ``"80x faster than real time"``, ``"2.5x slower than real time"`` or
        ``"at about real time"`` (within 5 %).
    """
    rtf = float(real_time_factor)
    if not math.isfinite(rtf) or rtf <= 0:
        return "at an unknown speed"
    if abs(rtf - 1.0) <= 0.05:
        return "at about real time"
    ratio = 1.0 / rtf if rtf < 1.0 else rtf
    shown = f"{ratio:.0f}" if ratio >= 10 else f"{ratio:.1f}"
    return f"{shown}x {'faster' if rtf < 1.0 else 'slower'} than real time"


def _display(revolute: bool) -> tuple[float, str]:
    return (180.0 / math.pi, "deg") if revolute else (1000.0, "mm")


def run_summary(result: SimResult, inverse: InverseDynamics | None = None
                ) -> dict[str, Any]:
    """A JSON-ready summary of a run (display units: degrees and millimetres).

    Returns:
        ``{"ok", "reasons", "joints": [per joint: max/RMS error, time of the
        max, correlation of |error| with |qdd|, peak torque, limit, ratio,
        required peak (inverse dynamics)], "contacts", "timing", "notes", ...}``.
    """
    cmp = result.comparison
    rev = result.plan.revolute()
    joints = []
    for j, name in enumerate(result.plan.names()):
        s, u = _display(bool(rev[j]))
        lim = float(result.torque_limits[j])
        row: dict[str, Any] = {
            "joint": name, "unit": u,
            "max_error": round(float(cmp.max_abs[j] * s), 6),
            "t_max_error_s": round(float(cmp.t_max[j]), 4),
            "rms_error": round(float(cmp.rms[j] * s), 6),
            "corr_error_acceleration": (None if math.isnan(cmp.acceleration_correlation[j])
                                        else round(float(cmp.acceleration_correlation[j]),
                                                   3)),
            "peak_torque": round(float(result.peak_tau[j]), 4),
            "torque_limit": lim if math.isfinite(lim) else None,
            "torque_ratio": (round(float(result.peak_tau[j] / lim), 4)
                             if math.isfinite(lim) else None),
        }
        if inverse is not None:
            row["required_peak_torque"] = round(float(inverse.peak[j]), 4)
            row["peak_power_w"] = round(float(inverse.peak_power[j]), 3)
            row["energy_j"] = round(float(inverse.energy[j]), 3)
        joints.append(row)
    return {
        "ok": bool(result.ok),
        "reasons": list(result.reasons),
        "tolerance": {"angle_deg": math.degrees(result.tolerance[0]),
                      "length_mm": result.tolerance[1] * 1000.0},
        "joints": joints,
        "contacts": [{"body_a": c.body_a, "body_b": c.body_b,
                      "t_start_s": round(c.t_start, 4), "t_end_s": round(c.t_end, 4),
                      "depth_mm": round(c.depth * 1000.0, 3)} for c in result.contacts],
        "feasible": None if inverse is None else bool(inverse.feasible),
        "torque_violations": [] if inverse is None else list(inverse.violations),
        "timing": {"simulated_s": round(result.duration, 4),
                   "wall_s": round(result.wall_time, 4),
                   "real_time_factor": round(result.real_time_factor, 5),
                   "steps": int(result.steps),
                   "physics_rate_hz": round(1.0 / result.export.timestep, 3)},
        "servo": {"actuators": result.export.actuators,
                  "kp": [round(float(v), 6) for v in result.export.kp],
                  "kv": [round(float(v), 6) for v in result.export.kv],
                  "gravity_compensation": result.export.gravity_compensation,
                  "velocity_feedforward": result.export.velocity_feedforward},
        "mass_properties": result.export.links.describe(),
        "notes": list(result.export.notes),
    }


#: The files :func:`write_run` writes (each after its ``prefix``).
RUN_FILES = ("model.xml", "simulated.csv", "tracking.png", "torques.png", "contacts.csv",
             "summary.json")


def write_run(result: SimResult, inverse: InverseDynamics | None, out: str | Path, *,
              prefix: str = "", title: str = "") -> dict[str, Path]:
    """Write a run's files into ``out`` (created), replacing earlier ones.

    Files (each name after ``prefix``): ``model.xml`` (the MJCF), ``simulated.csv``
    (time, simulated joints and rates, SI), ``tracking.png`` (error per joint and
    the plan's acceleration), ``torques.png``, ``contacts.csv`` and
    ``summary.json``.

    Returns:
        ``{file name: path}``.
    """
    from robokin.io.atomic import write_atomic
    from robokin.io.strict_json import strict_json
    from robokin.trajectory import io
    from robokin.viz.plots import plot_comparison

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    files: dict[str, Path] = {}

    def name(base: str) -> Path:
        return out / f"{prefix}{base}"

    files["model.xml"] = write_atomic(name("model.xml"), result.export.xml)
    files["simulated.csv"] = io.write_csv(result.trajectory(), name("simulated.csv"),
                                          rates=True, overwrite=True)
    plot_comparison(result.comparison, path=name("tracking.png"), overwrite=True,
                    title=f"{title}tracking error: MuJoCo run vs plan")
    files["tracking.png"] = name("tracking.png")
    plot_torques(result, inverse, path=name("torques.png"), overwrite=True,
                 title=f"{title}joint torques and power")
    files["torques.png"] = name("torques.png")
    lines = ["body_a,body_b,t_start [s],t_end [s],depth [mm]"]
    lines += [f"{c.body_a},{c.body_b},{c.t_start:.4f},{c.t_end:.4f},{c.depth * 1e3:.4f}"
              for c in result.contacts]
    files["contacts.csv"] = write_atomic(name("contacts.csv"), "\n".join(lines) + "\n")
    files["summary.json"] = write_atomic(
        name("summary.json"), strict_json(run_summary(result, inverse), indent=2) + "\n")
    for k, v in list(files.items()):
        files[k] = Path(v)
    return files
