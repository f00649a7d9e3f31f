"""``robokin view``: the 3D viewer (live, viser) or a standalone HTML animation."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

__all__ = ["commands", "view"]

commands = typer.Typer()


def _load_scene(spec: str):
    """A scene file, or the name of a bundled scene (``press``)."""
    from robokin import collision

    path = Path(spec)
    if not path.exists() and not spec.endswith((".yaml", ".yml")):
        path = collision.scene_path(spec)
    return collision.Scene.load(path)


@commands.command()
def view(
    name: Annotated[str, typer.Argument(help="Built-in robot name or robot file.")],
    traj: Annotated[
        Path | None, typer.Option("--traj", help="Trajectory CSV to play.")
    ] = None,
    scene: Annotated[
        str | None,
        typer.Option("--scene", help="Scene file (or bundled scene name)."),
    ] = None,
    html: Annotated[
        Path | None,
        typer.Option(
            "--html", help="Write a standalone HTML animation here instead of serving."
        ),
    ] = None,
    check: Annotated[
        bool,
        typer.Option("--check/--no-check", help="Run the collision check to show it."),
    ] = True,
    host: Annotated[
        str, typer.Option(help="Interface to bind the live viewer to.")
    ] = "127.0.0.1",
    port: Annotated[
        int, typer.Option(help="Port of the live viewer (0: any free one).")
    ] = 8080,
) -> None:
    """Show a robot (free, with joint sliders and an IK target) or play a trajectory.

    With --scene the robot stands in the scene (its base and tool) and, with a
    trajectory, collisions and the closest-distance segment are shown.
    """
    import robokin
    from robokin.exceptions import InputError

    if html is not None:
        if html.is_dir():
            raise InputError("--html", f"{html} is a folder, expected a file name")
        for given in (name, traj, scene):
            src = Path(given) if given is not None else None
            if (
                src is not None
                and src.is_file()
                and html.exists()
                and html.resolve() == src.resolve()
            ):
                raise InputError(
                    "--html", f"{html} is an input file; choose another name"
                )
    bare = robot = robokin.load(name)
    sc = None
    if scene is not None:
        sc = _load_scene(scene)
        robot = sc.attach(bare)  # drawn as placed; check() places it itself
    motion = None
    if traj is not None:
        from robokin.trajectory.io import read_csv

        # joint columns matched to the robot's joints by name (any order)
        motion = read_csv(traj, joint_names=robot.joint_names,
                          is_revolute=robot.is_revolute)
    report = None
    if sc is not None and motion is not None and check:
        from robokin import collision

        try:
            report = collision.check(bare, sc, motion)
        except InputError as exc:
            if exc.argument != "robot":
                raise
            typer.echo(f"no collision check: {exc.reason}", err=True)
    if html is not None:
        from robokin.viz.html import write_html

        out = write_html(
            html,
            robot,
            motion,
            scene=sc,
            report=report,
            title=f"{robot.name}" + (f" in {sc.name}" if sc is not None else ""),
        )
        typer.echo(f"wrote {out}")
        return
    from robokin.viz.viewer import view as serve

    serve(robot, motion, scene=sc, report=report, host=host, port=port, block=True)
