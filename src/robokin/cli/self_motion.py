"""``robokin self-motion``: the whole self-motion of a 7-joint arm at one pose.

The command parses, calls :meth:`robokin.robot.Robot.self_motion` and formats: the
parameter intervals where a branch is inside every joint limit, the best
configuration on them (``--best``), the one nearest ``--near``, optionally every
limit crossing and singular point (``--points``) and a plot of the branches
(``--plot``). Decisions: ``docs/ik.md``, "The command line: robokin self-motion".
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import numpy as np
import typer

from robokin.cli.common import (
    DomainFailure,
    joint_values,
    json_text,
    load_robot,
    tool_pose,
)
from robokin.cli.options import (
    DegFlag,
    JsonFlag,
    MmFlag,
    PitchArg,
    RobotName,
    RollArg,
    XArg,
    YArg,
    YawArg,
    ZArg,
)
from robokin.cli.output import (
    Column,
    FormatOption,
    OutputTable,
    emit,
    fixed,
    general,
    resolve_format,
    say,
)
from robokin.exceptions import InputError

if TYPE_CHECKING:
    from robokin.kinematics.ik.self_motion import ManifoldPoint, SelfMotion
    from robokin.kinematics.ik.self_motion_continua import Continua
    from robokin.robot import Robot

__all__ = ["commands", "interval_motion", "self_motion"]

commands = typer.Typer()

#: The criteria of ``--best`` (:meth:`SelfMotion.best`).
CRITERIA = ("margin", "manipulability")

#: What each argument of the library call is called on the command line.
_OPTION = {"parameter": "--parameter", "robot": "NAME", "q_near": "--near"}


@dataclass(frozen=True)
class _Units:
    """The units the command prints in (``--deg``, ``--mm``).

    Attributes:
        t: Parameter values [rad or m] -> printed (a prismatic parameter in m or mm).
        t_unit: The parameter's unit.
        q: (n,) per joint, [rad or m] -> printed.
        q_unit: Each joint's unit.
        dist: The margin and the nearest distance -> printed (an angle when every
            joint is revolute; else as the library gives them, rad and m mixed).
        dist_unit: Their unit.
    """

    t: float
    t_unit: str
    q: np.ndarray
    q_unit: list[str]
    dist: float
    dist_unit: str


def _units(r: Robot, sm: SelfMotion, deg: bool, mm: bool) -> _Units:
    per_rad, per_m = (180.0 / math.pi if deg else 1.0), (1000.0 if mm else 1.0)
    au, lu = ("deg" if deg else "rad"), ("mm" if mm else "m")
    rev = [bool(v) for v in r.is_revolute]
    angle = sm.joint is None or rev[sm.joint]
    revolute = all(rev)
    return _Units(per_rad if angle else per_m, au if angle else lu,
                  np.where(rev, per_rad, per_m), [au if v else lu for v in rev],
                  per_rad if revolute else 1.0, au if revolute else "rad, m")


def _manifold(robot: Robot, T: np.ndarray, parameter: str) -> SelfMotion:
    """``robot.self_motion(T, parameter)``, its input errors naming the CLI's options."""
    try:
        return robot.self_motion(T, parameter)
    except InputError as exc:
        if exc.argument not in _OPTION:
            raise
        raise InputError(_OPTION[exc.argument], exc.reason) from None


def _plot_path(plot: Path | None, force: bool) -> Path | None:
    """The ``--plot`` file (:func:`_output_path`)."""
    from robokin.viz.plots import FIGURE_FORMATS

    return _output_path(plot, "--plot", FIGURE_FORMATS, force)


def _output_path(path: Path | None, option: str, suffixes: tuple[str, ...],
                 force: bool) -> Path | None:
    """An output file, refused before any work when it exists without --force."""
    if path is None:
        return None
    if path.suffix.lower() not in suffixes:
        raise InputError(option, f"expected a {', '.join(suffixes)} file, got "
                         f"{path.name!r}")
    if path.exists() and not force:
        raise InputError(option, f"{path} exists (an earlier run's?): pass --force to "
                         "replace it, or name another file")
    return path


def interval_motion(sm: SelfMotion, branch: int, interval: int, *,
                    frames: int = 241) -> tuple[np.ndarray, np.ndarray]:
    """Configurations along one in-limit interval of a branch, there and back.

    Args:
        sm: The manifold.
        branch: The branch.
        interval: The row of ``sm.intervals`` (an interval of ``branch``).
        frames: Parameter values inside the interval (its ends excluded: a fold's
            row may not exist exactly there).

    Returns:
        ``(t, Q)``: the parameter values (2 frames - 1,) [rad, or m for a track] and
        the branch's rows (2 frames - 1, n) there, forward then back; rows that do
        not exist are dropped.
    """
    a, e = (float(v) for v in sm.intervals[interval])
    t = np.linspace(a, e, frames + 2)[1:-1] if e > a else np.array([a])
    Q = sm.sample(t)[:, branch]
    ok = np.isfinite(Q).all(-1)
    t, Q = t[ok], Q[ok]
    return np.concatenate([t, t[-2::-1]]), np.concatenate([Q, Q[-2::-1]])


def _shown_interval(sm: SelfMotion, top: ManifoldPoint | None,
                    branch: int | None) -> int | None:
    """The row of ``sm.intervals`` that ``--html`` animates, or None (no interval).

    ``--branch``'s longest interval, else the one holding the best configuration.

    Raises:
        InputError: ``--branch`` is not a branch, or has no in-limit interval.
    """
    if branch is not None:
        if not 0 <= branch < sm.n_branches:
            raise InputError("--branch", f"expected 0 ... {sm.n_branches - 1}, got {branch}")
        mine = np.flatnonzero(sm.interval_branch == branch)
        if not len(mine):
            has = sorted(set(sm.interval_branch.tolist()))
            raise InputError("--branch", f"branch {branch} has no in-limit interval; "
                             f"branches with one: {has}")
        return int(mine[np.argmax(np.diff(sm.intervals[mine], axis=1)[:, 0])])
    if top is None:
        return None  # no interval: nothing to animate (exit code 1 says why)
    on = (sm.interval_branch == top.branch) & (sm.intervals[:, 0] <= top.t) & (
        top.t <= sm.intervals[:, 1])
    return int(np.flatnonzero(on)[0])


def _animate(r: Robot, sm: SelfMotion, page: Path, k: int, u: _Units) -> dict[str, Any]:
    """Write the ``--html`` animation of interval ``k``; what it shows."""
    from robokin.viz.html import write_html

    b = int(sm.interval_branch[k])
    _, Q = interval_motion(sm, b, k)
    a, e = (float(v) * u.t for v in sm.intervals[k])
    write_html(page, r, Q, dt=8.0 / max(len(Q), 1), title=(
        f"{r.name}: self-motion, branch {b}, {sm.parameter} in [{a:.4g}, {e:.4g}] "
        f"{u.t_unit}"))
    return {"branch": b, "from": a, "to": e, "frames": int(len(Q))}


def _point_json(p: ManifoldPoint, u: _Units) -> dict[str, Any]:
    return {"t": p.t * u.t, "branch": p.branch, "q": (p.q * u.q).tolist()}


@commands.command("self-motion", context_settings={"ignore_unknown_options": True})
def self_motion(
    name: RobotName,
    x: XArg,
    y: YArg,
    z: ZArg,
    roll: RollArg,
    pitch: PitchArg,
    yaw: YawArg,
    deg: DegFlag = False,
    mm: MmFlag = False,
    parameter: Annotated[str, typer.Option(
        "--parameter", help="auto | swivel | a joint name: the parameter t of the "
        "branches (auto: the swivel angle on SRS arms, else a joint with a closed form, "
        "joint7 on the Panda; on other arms a track, or the last joint).")] = "auto",
    best: Annotated[str, typer.Option(
        "--best", help="margin | manipulability: the configuration that maximises the "
        "smallest distance to a joint limit, or Yoshikawa's manipulability.")] = "margin",
    near: Annotated[str | None, typer.Option(
        "--near", help="Current joint values q1 ... qn (rad/m, or deg/mm with "
        "--deg/--mm): also the in-limit configuration nearest them.")] = None,
    points: Annotated[bool, typer.Option(
        "--points", help="Also list every limit crossing and singular point.")] = False,
    plot: Annotated[Path | None, typer.Option(
        "--plot", help="Write a plot of the branches (PNG, SVG or PDF): one panel per "
        "joint, thick over the in-limit intervals.")] = None,
    html: Annotated[Path | None, typer.Option(
        "--html", help="Write a standalone HTML animation of the arm moving along one "
        "in-limit interval, the tool held at the pose (the best configuration's "
        "interval, or --branch's longest).")] = None,
    branch: Annotated[int | None, typer.Option(
        "--branch", help="The branch --html animates (its longest interval).")] = None,
    force: Annotated[bool, typer.Option(
        "--force", help="Replace the --plot / --html file of an earlier run.")] = False,
    as_json: JsonFlag = False,
    output_format: FormatOption = None,
) -> None:
    """The self-motion of a 7-joint arm at the pose x y z roll pitch yaw.

    Every branch of configurations over the parameter t, the intervals of t where a
    branch is inside every joint limit (found exactly, not by sampling), the best
    configuration on them and, with --near, the one nearest the current joints.
    Exit code 1 when no part of the self-motion is inside the limits.
    """
    fmt = resolve_format(output_format, as_json)
    if best not in CRITERIA:
        raise InputError("--best", f"expected one of {', '.join(CRITERIA)}, got {best!r}")
    r = load_robot(name)
    T = tool_pose(x, y, z, roll, pitch, yaw, deg=deg, mm=mm)
    q_near = None if near is None else joint_values(near, r, "--near", deg=deg, mm=mm)
    path = _plot_path(plot, force)
    page = _output_path(html, "--html", (".html",), force)
    if branch is not None and html is None:
        raise InputError("--branch", "chooses the interval --html animates: pass --html "
                         "FILE too")
    sm = _manifold(r, T, parameter)
    u = _units(r, sm, deg, mm)
    top = sm.best(best, robot=r)
    close = None if q_near is None else _nearest(sm, q_near)
    shown = None if page is None else _shown_interval(sm, top, branch)  # checked first
    if path is not None:
        from robokin.viz.plots import plot_self_motion

        plot_self_motion(sm, path=path, degrees=deg, mm=mm, overwrite=force,
                         title=f"{r.name}: self-motion over {sm.parameter}")
    animated = None
    if page is not None and shown is not None:
        animated = _animate(r, sm, page, shown, u)
    lines = sm.continua()
    if fmt == "json":
        print(json_text({
            "robot": r.name, "parameter": sm.parameter, "unit": u.t_unit,
            "domain": (sm.domain * u.t).tolist(), "periodic": sm.periodic,
            "branches": sm.n_branches, "method": sm.method,
            "intervals": [{"branch": int(b), "from": float(a) * u.t, "to": float(e) * u.t}
                          for (a, e), b in zip(sm.intervals, sm.interval_branch)],
            "crossings": [{"t": c.t * u.t, "branch": c.branch,
                           "joint": r.joint_names[c.joint], "limit": c.limit}
                          for c in sm.crossings],
            "singular": [{"t": s.t * u.t, "branch": s.branch, "kind": s.kind}
                         for s in sm.singular],
            "continua": [] if lines is None else [
                {"joints": [r.joint_names[int(a)], r.joint_names[int(b)]],
                 "from": (q0 * u.q).tolist(), "to": (q1 * u.q).tolist()}
                for a, b, q0, q1 in zip(lines.a, lines.b, *_piece_ends(lines),
                                        strict=True)],
            "best": None if top is None else {
                **_point_json(top, u), "criterion": best,
                "score": top.score * (u.dist if best == "margin" else 1.0)},
            "nearest": None if close is None else {
                **_point_json(close, u), "distance": -close.score * u.dist},
            "plot": None if path is None else str(path),
            "html": None if page is None else str(page),
            "animated": animated,
        }))
    else:
        tables = [_intervals_table(r, sm, u, top)]
        if lines is not None and len(lines.base):
            tables[0].notes.append(
                f"{len(lines.base)} aligned continuum piece(s) inside the limits: "
                "configurations off the branches, two joints on one axis turned against "
                "each other (" + ", ".join(
                    f"{r.joint_names[int(a)]} / {r.joint_names[int(b)]}"
                    for a, b in zip(lines.a, lines.b, strict=True)) + "; --format json "
                "lists their ends)")
        if top is not None or close is not None:
            tables.append(_configurations_table(top, close, best, u))
        if points:
            tables.append(_points_table(r, sm, u))
        emit(tables, fmt)
        for written in (path, page):
            if written is not None:
                say(f"wrote {written}", fmt)
    if not sm.reachable:
        raise DomainFailure(_empty_reason(sm))


def _piece_ends(lines: Continua) -> tuple[np.ndarray, np.ndarray]:
    """Each continuum piece's configurations at the two ends of its stretch, (p, n) each."""
    every = np.arange(len(lines.base))
    return (lines.at(every, np.zeros(len(every))), lines.at(every, np.ones(len(every))))


def _nearest(sm: SelfMotion, q_near: np.ndarray) -> ManifoldPoint | None:
    try:
        return sm.nearest(q_near)
    except InputError as exc:
        raise InputError("--near", exc.reason) from None


def _empty_reason(sm: SelfMotion) -> str:
    """Why no interval: the pose out of reach (no branch anywhere) or the limits."""
    t = np.linspace(float(sm.domain[0]), float(sm.domain[1]), 361)
    if not np.isfinite(sm.sample(t)).all(-1).any() and not sm.crossings and not sm.singular:
        return "the pose is out of reach: no branch of the self-motion exists"
    return "no part of the self-motion is inside the joint limits"


def _intervals_table(r: Robot, sm: SelfMotion, u: _Units,
                     top: ManifoldPoint | None = None) -> OutputTable:
    unit = u.t_unit
    table = OutputTable(
        f"{r.name}: self-motion over {sm.parameter} [{unit}]: {sm.n_branches} "
        f"branch{'es' if sm.n_branches != 1 else ''}, "
        f"{len(sm.intervals)} in-limit interval(s) [{sm.method}]",
        [Column("branch", right=True), Column(f"from [{unit}]", fmt=fixed(6), right=True),
         Column(f"to [{unit}]", fmt=fixed(6), right=True),
         Column(f"length [{unit}]", fmt=fixed(6), right=True)])
    for (a, e), b in zip(sm.intervals, sm.interval_branch):
        table.add_row(int(b), float(a) * u.t, float(e) * u.t, float(e - a) * u.t)
    folds = sum(s.kind == "fold" for s in sm.singular)
    lo, hi = (float(v) * u.t for v in sm.domain)
    table.notes.append(
        f"{sm.parameter} ranges over [{lo:.6g}, {hi:.6g}] {unit}"
        + (" (periodic: an interval through +-pi is one, its end past it)"
           if sm.periodic else "")
        + f"; {len(sm.crossings)} limit crossing(s) (the other joints inside), "
        f"{folds} branch end(s), "
        f"{len(sm.singular) - folds} aligned-axes point(s) (--points lists them)")
    if not len(sm.intervals) and top is not None:
        table.notes.append(
            "no branch is inside the limits, but an aligned continuum is (an axis pair on "
            "one line, its two joints turned against each other): the configuration below")
    if sm.method.startswith("continued numeric"):
        table.notes.append(
            f"{r.name} with {sm.parameter} held has neither a closed form nor the general "
            f"6R solver: its rows are numeric samples, and a branch can be missing")
    if sm.info.get("dropped"):
        table.notes.append(
            f"{sm.info['dropped']} short piece(s) of branches left out (only the 64 "
            f"longest are followed): a branch can be missing")
    return table


def _configurations_table(top: ManifoldPoint | None, close: ManifoldPoint | None,
                          best: str, u: _Units) -> OutputTable:
    table = OutputTable(
        "configurations on the self-motion, inside every limit",
        [Column("which"), Column(f"t [{u.t_unit}]", fmt=fixed(6), right=True),
         Column("branch", right=True),
         *[Column(f"q{j + 1} [{unit}]", fmt=fixed(6), right=True)
           for j, unit in enumerate(u.q_unit)],
         Column("score", fmt=general(6), right=True)])
    if top is not None:
        value = top.score * u.dist if best == "margin" else top.score
        table.add_row(f"best {best}", top.t * u.t, top.branch,
                      *(float(v) for v in top.q * u.q), value)
    if close is not None:
        table.add_row("nearest --near", close.t * u.t, close.branch,
                      *(float(v) for v in close.q * u.q), -close.score * u.dist)
    table.notes.append(
        f"score: margin = the smallest distance to a joint limit [{u.dist_unit}]; "
        "manipulability = sqrt(det(J J^T)); nearest = the wrapped joint-space distance "
        f"[{u.dist_unit}]")
    return table


def _points_table(r: Robot, sm: SelfMotion, u: _Units) -> OutputTable:
    table = OutputTable(
        "limit crossings and singular points",
        [Column(f"t [{u.t_unit}]", fmt=fixed(9), right=True), Column("branch", right=True),
         Column("what")])
    rows = [(c.t, c.branch, f"{r.joint_names[c.joint]} at its {c.limit} limit")
            for c in sm.crossings]
    rows += [(s.t, s.branch, "branch end (fold)" if s.kind == "fold" else s.kind)
             for s in sm.singular]
    for t, b, what in sorted(rows, key=lambda row: (row[1], row[0])):
        table.add_row(t * u.t, b, what)
    return table
