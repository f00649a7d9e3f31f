"""The cycle-time report: how fast a path can run, and what holds it back.

::

    from robokin.trajectory.cycle_time import cycle_time_report
    rep = cycle_time_report(robot, traj, cycle_time=12.0)
    rep.minimum_cycle_time          # [s], the time-optimal retiming (rep.minimum)
    rep.bottlenecks                 # which joint, which limit, when
    rep.slower                      # the same path in 12 s, rep.margins its margins
    print(rep)                      # a text table
    robokin.viz.retime_plots.plot_bottlenecks(rep, path="bottlenecks.png")

**Reading it.** A time-optimal motion always presses against some limit: while the
arm speeds up or slows down, one joint is at its acceleration limit; while it
cruises, one joint is at its speed limit (or the tool at its speed). That joint
and that limit are the *bottleneck* of the moment: raising that limit (or
changing the path there) is the only thing that shortens the cycle there.
:attr:`CycleTimeReport.bottlenecks` lists each stretch of samples where a joint
is within ``active_tol`` (0.1 %) of a limit (a speed ratio, the square root of an
acceleration ratio, the cube root of a jerk ratio, each before the section's own
final-check slow-down, :attr:`SectionTiming.stretch`); per section, ``limiting``
names the one active longest. A slower cycle time stretches every move by one factor ``c``,
so every speed has the margin ``1 - 1/c``, every acceleration ``1 - 1/c^2`` and
every jerk ``1 - 1/c^3`` to its limit at the bottleneck (and more elsewhere);
:attr:`CycleTimeReport.margins` gives, per joint, ``1 - peak / limit``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from robokin.exceptions import InputError
from robokin.trajectory.retiming import RetimeResult, retime_detailed

if TYPE_CHECKING:
    from robokin.robot import Robot

__all__ = ["Bottleneck", "CycleTimeReport", "SectionSummary", "cycle_time_report",
           "limit_ratios"]

KINDS = ("velocity", "acceleration", "jerk")


@dataclass(frozen=True)
class Bottleneck:
    """A stretch of samples where one joint (or the tool) is at one limit.

    Attributes:
        kind: ``"velocity"``, ``"acceleration"``, ``"jerk"`` or ``"tool_speed"``.
        joint: Joint index, or -1 for the tool speed.
        joint_name: Its name (``"tool"`` for the tool speed).
        section: The label of the section it lies in.
        t_start: Time of its first sample in the time-optimal motion [s].
        t_end: Time of its last sample [s].
    """

    kind: str
    joint: int
    joint_name: str
    section: str
    t_start: float
    t_end: float

    @property
    def duration(self) -> float:
        """``t_end - t_start`` [s]."""
        return self.t_end - self.t_start


@dataclass(frozen=True)
class SectionSummary:
    """One move or dwell: its times, and the limit that holds it back.

    Attributes:
        label: Source segment label.
        kind: ``"move"`` or ``"dwell"``.
        method: ``"toppra"``, ``"ruckig"`` or ``"dwell"``.
        planned: Its duration in the source [s] (NaN for a bare path).
        minimum: Its duration when time-optimal [s].
        slower: Its duration in the slower retiming [s], or None.
        limiting: ``"<joint> <kind>"`` active the longest (``""`` when none is,
            e.g. a dwell, or a curved jerk-limited stretch whose path-space limits
            are conservative).
        active_share: Fraction of the section's time some limit is active.
    """

    label: str
    kind: str
    method: str
    planned: float
    minimum: float
    slower: float | None
    limiting: str
    active_share: float


def limit_ratios(result: RetimeResult) -> dict[str, np.ndarray]:
    """``|value| / limit`` at every sample of a retimed motion.

    Returns:
        ``{"velocity": (m, n), "acceleration": (m, n), "jerk": (m, n) (with jerk
        limits), "tool_speed": (m,) (with a tool speed)}``.
    """
    tr, lim = result.trajectory, result.limits
    out = {"velocity": np.abs(tr.qd) / lim.velocity,
           "acceleration": np.abs(tr.qdd) / lim.acceleration}
    if lim.jerk is not None:
        out["jerk"] = np.abs(result.jerk) / lim.jerk
    if lim.tool_speed is not None:
        robot = result.robot
        v = np.einsum("kij,kj->ki", robot.jacobian(tr.q)[..., :3, :], tr.qd)
        out["tool_speed"] = np.linalg.norm(v, axis=1) / lim.tool_speed
    return out


def _columns(ratios: dict[str, np.ndarray], names: tuple[str, ...]
             ) -> tuple[np.ndarray, list[tuple[str, int, str]]]:
    """All ratios as (m, C) columns and what each column is (kind, joint, name)."""
    cols, what = [], []
    for kind, r in ratios.items():
        if r.ndim == 1:
            cols.append(r[:, None])
            what.append((kind, -1, "tool"))
        else:
            cols.append(r)
            what += [(kind, j, names[j]) for j in range(r.shape[1])]
    return np.hstack(cols), what


def _bottlenecks(result: RetimeResult, ratios: dict[str, np.ndarray], tol: float
                 ) -> tuple[tuple[Bottleneck, ...], np.ndarray,
                            list[tuple[str, int, str]], dict[str, np.ndarray]]:
    """Stretches where a limit is active, and where each limit is.

    Returns the stretches, the dominant column per sample (-1: none), what each
    column is, and the active samples per kind (shaped as ``ratios``).
    """
    tr = result.trajectory
    ratio, what = _columns(ratios, tr.names())
    section_of = np.zeros(tr.t.size, int)
    for k, s in enumerate(result.sections):
        section_of[(tr.t >= s.t_start) & (tr.t <= s.t_end)] = k
    # Compare the time law before the final check's slow-down of its section (a
    # stretch c lowers speeds by 1/c, accelerations by 1/c^2, jerks by 1/c^3): a
    # section slowed by 0.1 % to clear a sample keeps its bottleneck.
    power = np.array([{"acceleration": 2.0, "jerk": 3.0}.get(k, 1.0) for k, _, _ in what])
    stretch = np.array([s.stretch for s in result.sections])[section_of]
    linear = ratio ** (1.0 / power) * stretch[:, None]
    active = linear >= 1.0 - tol
    dominant = np.where(active.any(axis=1), np.argmax(linear, axis=1), -1)
    out = []
    for c in np.flatnonzero(active.any(axis=0)):
        col = active[:, c].astype(np.int8)
        edges = np.diff(np.concatenate([[0], col, [0]]))
        for a, b in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1):
            kind, j, name = what[c]
            out.append(Bottleneck(kind, j, name, result.sections[section_of[a]].label,
                                  float(tr.t[a]), float(tr.t[b])))
    out.sort(key=lambda x: (x.t_start, x.joint, x.kind))
    by_kind: dict[str, np.ndarray] = {}
    first = 0
    for kind, r in ratios.items():
        width = 1 if r.ndim == 1 else r.shape[1]
        by_kind[kind] = active[:, first:first + width].reshape(r.shape)
        first += width
    return tuple(out), dominant, what, by_kind


def _summaries(result: RetimeResult, slower: RetimeResult | None,
               dominant: np.ndarray, what: list[tuple[str, int, str]]
               ) -> tuple[SectionSummary, ...]:
    tr = result.trajectory
    out = []
    for k, s in enumerate(result.sections):
        inside = (tr.t >= s.t_start) & (tr.t < s.t_end)
        dom = dominant[inside]
        limiting, share = "", 0.0
        if s.kind == "move" and dom.size and (dom >= 0).any():
            counts = np.bincount(dom[dom >= 0], minlength=len(what))
            kind, _, name = what[int(np.argmax(counts))]
            limiting = f"{name} {kind.replace('_', ' ')}"
            share = float((dom >= 0).mean())
        planned = s.source_duration if result.source_duration is not None else np.nan
        out.append(SectionSummary(
            s.label, s.kind, s.method, float(planned), s.duration,
            None if slower is None else slower.sections[k].duration, limiting, share))
    return tuple(out)


def _margins(result: RetimeResult) -> dict[str, np.ndarray]:
    """Per joint (tool: one value), ``1 - peak / limit``."""
    return {kind: 1.0 - (r.max(axis=0) if r.ndim == 2 else np.array([r.max()]))
            for kind, r in limit_ratios(result).items()}


@dataclass(frozen=True, eq=False)
class CycleTimeReport:
    """How fast a path can run, what limits it, and a slower retiming with margins.

    Attributes:
        minimum: The time-optimal retiming.
        slower: The same path retimed to ``cycle_time``, or None.
        cycle_time: The cycle time asked for [s], or None.
        ratios: :func:`limit_ratios` of ``minimum``.
        active: Per kind, where a limit is active (shaped as ``ratios``).
        bottlenecks: Every stretch where a limit is active, by time.
        sections: One :class:`SectionSummary` per move and dwell.
        margins: ``1 - peak / limit`` per kind (per joint) of ``slower``, or None.
        active_tol: A limit counts as active within this fraction of it.
    """

    minimum: RetimeResult
    slower: RetimeResult | None
    cycle_time: float | None
    ratios: dict[str, np.ndarray]
    active: dict[str, np.ndarray]
    bottlenecks: tuple[Bottleneck, ...]
    sections: tuple[SectionSummary, ...]
    margins: dict[str, np.ndarray] | None
    active_tol: float

    @property
    def minimum_cycle_time(self) -> float:
        """The shortest cycle time [s] (moves plus kept dwells)."""
        return self.minimum.duration

    @property
    def source_duration(self) -> float | None:
        """The planned (source) duration [s], None for a bare path."""
        return self.minimum.source_duration

    def with_cycle_time(self, cycle_time: float) -> CycleTimeReport:
        """The same report with the path also retimed to ``cycle_time`` [s].

        Raises:
            InputError: ``cycle_time`` below the minimum (argument ``cycle_time``).
        """
        return _report(self.minimum, cycle_time, self.active_tol)

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready summary (SI units; joint names as given)."""
        names = self.minimum.trajectory.names()
        lim = self.minimum.limits
        out: dict[str, Any] = {
            "planned_s": self.source_duration,
            "minimum_cycle_time_s": self.minimum_cycle_time,
            "motion_time_s": self.minimum.motion_time,
            "dwell_time_s": self.minimum.dwell_time,
            "cycle_time_s": self.cycle_time,
            "joints": list(names),
            "limits": {"velocity": lim.velocity.tolist(),
                       "acceleration": lim.acceleration.tolist(),
                       "jerk": None if lim.jerk is None else lim.jerk.tolist(),
                       "tool_speed": lim.tool_speed,
                       "sources": dict(lim.sources)},
            "sections": [vars(s) for s in self.sections],
            "bottlenecks": [{**vars(b), "duration": b.duration}
                            for b in self.bottlenecks],
            "peak_ratio": {k: float(v.max()) for k, v in self.ratios.items()},
        }
        if self.margins is not None:
            out["margins"] = {k: v.tolist() for k, v in self.margins.items()}
        return out

    def __str__(self) -> str:
        """The report as a text table: times per section, limits, margins."""
        rows = [f"minimum cycle time {self.minimum_cycle_time:.3f} s"
                + ("" if self.source_duration is None
                   else f" (planned {self.source_duration:.3f} s)")
                + f": motion {self.minimum.motion_time:.3f} s, dwells "
                  f"{self.minimum.dwell_time:.3f} s"]
        for s in self.sections:
            slow = "" if s.slower is None else f"  slower {s.slower:7.3f} s"
            rows.append(f"  {s.label or s.kind:<24} planned {s.planned:7.3f} s  minimum "
                        f"{s.minimum:7.3f} s{slow}  {s.limiting}")
        if self.margins is not None:
            rows.append(f"retimed to {self.cycle_time:.3f} s; smallest margins: " +
                        ", ".join(f"{k.replace('_', ' ')} {v.min():.1%}"
                                  for k, v in self.margins.items()))
        return "\n".join(rows)


def cycle_time_report(
    robot: Robot,
    traj: Any,
    *,
    cycle_time: float | None = None,
    active_tol: float = 1e-3,
    **retime_options: Any,
) -> CycleTimeReport:
    """Retime a path to its minimum cycle time and report what limits it.

    Args:
        robot: The :class:`~robokin.robot.Robot`.
        traj: The path (as :func:`robokin.trajectory.retime` takes it).
        cycle_time: Also retime to this longer cycle time [s] and report its
            margins; None: only the minimum.
        active_tol: A limit is active within this fraction of it (default 0.1 %).
        **retime_options: ``v_max``, ``a_max``, ``j_max``, ``tool_speed``, ``dt``,
            ``keep_dwells``, ``grid_points`` (see :func:`~robokin.trajectory.retime`).

    Returns:
        A :class:`CycleTimeReport`.

    Raises:
        InputError: as :func:`~robokin.trajectory.retime`; a ``cycle_time`` below
            the minimum (argument ``cycle_time``); a bad ``active_tol``.
    """
    if not (isinstance(active_tol, float | int) and 0 < active_tol < 1):
        raise InputError("active_tol", f"expected a fraction in (0, 1), got "
                         f"{active_tol!r}")
    if "round_to_dt" in retime_options:
        raise InputError("round_to_dt", "the report is about the exact minimum; "
                         "retime with round_to_dt=True separately")
    return _report(retime_detailed(robot, traj, **retime_options), cycle_time,
                   float(active_tol))


def _report(minimum: RetimeResult, cycle_time: float | None, active_tol: float
            ) -> CycleTimeReport:
    slower = None if cycle_time is None else minimum.slowed(cycle_time)
    ratios = limit_ratios(minimum)
    bottlenecks, dominant, what, active = _bottlenecks(minimum, ratios, active_tol)
    sections = _summaries(minimum, slower, dominant, what)
    return CycleTimeReport(minimum, slower, None if cycle_time is None else
                           float(cycle_time), ratios, active, bottlenecks, sections,
                           None if slower is None else _margins(slower), active_tol)
