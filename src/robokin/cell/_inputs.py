"""Inputs shared by maps and placement: the robot in the world, the IK method, progress."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

from robokin._text import short_repr
from robokin.cell._scheduler import describe
from robokin.exceptions import InputError

if TYPE_CHECKING:
    from robokin.collision.scene import Scene
    from robokin.robot import Robot

__all__ = ["Progress", "ik_method", "manifold_sweep", "placed_robot", "progress_callback"]

Progress = bool | Callable[[int, int], None] | None


def placed_robot(robot: Robot, scene: Scene | None) -> tuple[Robot, Robot | None]:
    """The robot in the world and, with a scene, the bare robot it places."""
    from robokin.robot import Robot as _Robot

    if not isinstance(robot, _Robot):
        raise InputError("robot", f"expected a robokin.Robot, got {short_repr(robot)}")
    if scene is None:
        return robot, None
    from robokin.collision.scene import Scene as _Scene

    if not isinstance(scene, _Scene):
        raise InputError("scene", f"expected a collision.Scene, got {short_repr(scene)}")
    bare = scene.unplaced(robot)
    return scene.attach(bare), bare


def ik_method(robot: Robot, method: str) -> tuple[bool, str]:
    """(numeric?, the method's name) for ``method`` on this robot."""
    from robokin.kinematics.ik.analytic.detect import detect
    from robokin.kinematics.ik.dispatch import _METHODS

    if method not in _METHODS:
        raise InputError(
            "method", f"expected 'auto', 'analytic' or 'numeric', got {short_repr(method)}"
        )
    fam = detect(robot)
    if method == "numeric" or (method == "auto" and fam.solver is None):
        return True, "numeric"
    if fam.solver is None:
        raise InputError("method", f"no closed form for robot '{robot.name}': {fam.reason}")
    return False, f"analytic:{fam.name}"


def manifold_sweep(robot: Robot, method: str) -> str | None:
    """The joint whose values sweep a 7R arm's self-motion manifold, or None.

    With ``method="auto"`` a 7-joint arm with a held-joint closed form counts a
    pose reachable when any part of its manifold is inside the joint limits
    (:mod:`robokin.cell._manifold`); ``"numeric"`` keeps the one numeric sample.
    """
    if method != "auto" or robot.n != 7:
        return None
    from robokin.cell._manifold import sweep_joint

    return sweep_joint(robot)


@contextmanager
def progress_callback(progress: Progress, total: int, text: str,
              scheduler: Any) -> Iterator[Callable[[int, int], None] | None]:
    """The per-task callback: the user's, a rich bar (``progress=True``), or None."""
    if progress is None or progress is False:
        yield None
        return
    if callable(progress):
        yield progress
        return
    from rich.console import Console
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    console = Console(stderr=True, emoji=False)  # an address is printed as typed
    console.print(f"{text}: {total:,} Dask tasks on {describe(scheduler)}", markup=False,
                  highlight=False)
    with Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        TimeRemainingColumn(),
        console=console,
        transient=False,
    ) as bar:
        task = bar.add_task(text, total=total)
        yield lambda done, total_: bar.update(task, completed=done)
