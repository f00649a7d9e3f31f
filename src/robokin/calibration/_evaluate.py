"""Per-pose errors of a robot against measurements, hold-out reports and their plot."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, overload

import numpy as np
import numpy.typing as npt

from robokin.calibration._calibrate import CalibrationResult, check_measurements
from robokin.exceptions import InputError

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["ErrorStats", "HoldoutReport", "evaluate", "holdout_report", "plot_errors"]


def _check(robot: Robot, q: npt.ArrayLike, measured: npt.ArrayLike, kind: str
           ) -> tuple[np.ndarray, np.ndarray]:
    from robokin._validation import check_finite, check_joints

    qa = check_finite(check_joints(q, robot.n, "q"), "q")
    if qa.ndim != 2:
        raise InputError("q", f"expected joint coordinates (N, {robot.n}), got shape "
                         f"{qa.shape}")
    return qa, check_measurements(measured, len(qa), kind)


@overload
def evaluate(robot: Robot, q: npt.ArrayLike, measured: npt.ArrayLike, *,
             rotation: Literal[False] = False) -> np.ndarray: ...
@overload
def evaluate(robot: Robot, q: npt.ArrayLike, measured: npt.ArrayLike, *,
             rotation: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...
def evaluate(robot: Robot, q: npt.ArrayLike, measured: npt.ArrayLike, *,
             rotation: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Per-pose errors of ``robot`` against measurements in its base frame.

    Args:
        robot: A robot whose base is the measuring frame (a calibrated robot, or
            ``CalibrationResult.registered``).
        q: Joint coordinates (N, n) [rad, m].
        measured: Tool positions (N, 3) or poses (N, 4, 4) [m].
        rotation: Also return the rotation errors (needs poses).

    Returns:
        Position errors (N,) [m]: ``|p_fk - p_measured|``; with ``rotation=True``
        also rotation errors (N,) [rad]: the angle of ``R_fk R_measured^T``.

    Raises:
        InputError: shapes that do not match (named), or ``rotation=True`` with
            points.
    """
    kind = "pose" if rotation else "position"
    qa, m = _check(robot, q, measured, kind)
    T = robot.fk(qa)
    if not rotation:
        return np.linalg.norm(T[:, :3, 3] - m, axis=1)
    from robokin.spatial import pose_error

    e = pose_error(m, T)
    return np.linalg.norm(e[:, :3], axis=1), np.linalg.norm(e[:, 3:], axis=1)


@dataclass(frozen=True)
class ErrorStats:
    """Mean, RMS and largest of a set of errors (same unit as the errors)."""

    mean: float
    rms: float
    max: float

    @classmethod
    def of(cls, e: np.ndarray) -> ErrorStats:
        """The statistics of errors ``e`` (N,)."""
        e = np.asarray(e, float)
        if e.size == 0:
            return cls(math.nan, math.nan, math.nan)
        return cls(float(e.mean()), float(np.sqrt((e**2).mean())), float(e.max()))


@dataclass(frozen=True)
class HoldoutReport:
    """Errors on poses the calibration did not see, before and after.

    Attributes:
        before: Position errors of the nominal robot with base and tool fitted [m].
        after: Position errors of the calibrated robot [m].
        errors_before: Per pose (N,) [m].
        errors_after: Per pose (N,) [m].
        rotation_before: Rotation error statistics [rad] (poses), or None.
        rotation_after: Rotation error statistics [rad] (poses), or None.
    """

    before: ErrorStats
    after: ErrorStats
    errors_before: np.ndarray
    errors_after: np.ndarray
    rotation_before: ErrorStats | None = None
    rotation_after: ErrorStats | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready statistics (metres, radians), without the per-pose arrays."""
        out: dict[str, Any] = {"poses": int(self.errors_after.size),
                               "position_m": {"before": vars(self.before),
                                              "after": vars(self.after)}}
        if self.rotation_before is not None and self.rotation_after is not None:
            out["rotation_rad"] = {"before": vars(self.rotation_before),
                                   "after": vars(self.rotation_after)}
        return out

    def text(self) -> str:
        """A few lines for a terminal (mm and degrees)."""
        lines = [f"hold-out: {self.errors_after.size} poses",
                 "position [mm]      mean      rms      max"]
        for label, s in (("before", self.before), ("after", self.after)):
            lines.append(f"  {label:8s}  {s.mean * 1e3:9.4f} {s.rms * 1e3:8.4f} "
                         f"{s.max * 1e3:8.4f}")
        if self.rotation_before is not None and self.rotation_after is not None:
            lines.append("rotation [deg]     mean      rms      max")
            for label, s in (("before", self.rotation_before),
                             ("after", self.rotation_after)):
                d = 180.0 / math.pi
                lines.append(f"  {label:8s}  {s.mean * d:9.5f} {s.rms * d:8.5f} "
                             f"{s.max * d:8.5f}")
        return "\n".join(lines)


def holdout_report(result: CalibrationResult, q: npt.ArrayLike,
                   measured: npt.ArrayLike) -> HoldoutReport:
    """Before/after errors on hold-out poses.

    "Before" is the nominal robot with only base and tool fitted
    (``result.registered``), "after" the calibrated robot.

    Args:
        result: A calibration result.
        q: Hold-out joint coordinates (N, n).
        measured: Hold-out measurements (N, 3) or (N, 4, 4), like the calibration's.
    """
    if result.kind == "pose":
        pb, rb = evaluate(result.registered, q, measured, rotation=True)
        pa, ra = evaluate(result.robot, q, measured, rotation=True)
        return HoldoutReport(ErrorStats.of(pb), ErrorStats.of(pa), pb, pa,
                             ErrorStats.of(rb), ErrorStats.of(ra))
    pb = evaluate(result.registered, q, measured)
    pa = evaluate(result.robot, q, measured)
    return HoldoutReport(ErrorStats.of(pb), ErrorStats.of(pa), pb, pa)


def plot_errors(report: HoldoutReport, *, path: str | Path | None = None,
                title: str | None = None, overwrite: bool = False) -> Any:
    """Per-pose position errors before and after calibration (matplotlib, Agg).

    Left: the error of each hold-out pose [mm], before (grey) and after (blue),
    with their RMS as lines. Right: the histogram of both.

    Args:
        report: A :class:`HoldoutReport`.
        path: Also save the figure (PNG, SVG or PDF) atomically.
        title: The figure title.
        overwrite: Replace an existing file at ``path``.

    Returns:
        The matplotlib Figure.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from robokin.io.atomic import save_figure_atomic

    # a Figure on the Agg canvas (no pyplot state, no window) and io's atomic save:
    # calibration sits below viz (docs/conventions.md, "Layers"), as collision/plots.py
    if path is not None and Path(path).suffix.lower() not in (".png", ".svg", ".pdf"):
        raise InputError("path", f"expected a .png, .svg or .pdf file, got {Path(path).name}")
    fig = Figure(figsize=(10.0, 4.2), layout="constrained")
    FigureCanvasAgg(fig)
    ax, hx = fig.subplots(1, 2, gridspec_kw={"width_ratios": [3, 1]})
    i = np.arange(report.errors_after.size)
    for e, s, color, label in ((report.errors_before, report.before, "0.6", "before"),
                               (report.errors_after, report.after, "tab:blue", "after")):
        ax.plot(i, e * 1e3, ".", ms=3, color=color,
                label=f"{label}: RMS {s.rms * 1e3:.4f} mm, max {s.max * 1e3:.4f} mm")
        ax.axhline(s.rms * 1e3, color=color, lw=1)
    ax.set_xlabel("hold-out pose")
    ax.set_ylabel("position error [mm]")
    ax.set_yscale("log")
    ax.legend(loc="upper right", fontsize=8)
    bins = np.geomspace(max(min(report.errors_after.min(), report.errors_before.min())
                            * 1e3, 1e-6), max(report.errors_before.max(),
                                              report.errors_after.max()) * 1e3, 40)
    hx.hist(report.errors_before * 1e3, bins=bins, color="0.6", alpha=0.8)
    hx.hist(report.errors_after * 1e3, bins=bins, color="tab:blue", alpha=0.8)
    hx.set_xscale("log")
    hx.set_xlabel("position error [mm]")
    hx.set_ylabel("poses")
    fig.suptitle(title or "calibration: hold-out position errors")
    if path is not None:
        save_figure_atomic(fig, path, overwrite=overwrite, dpi=120)
    return fig
