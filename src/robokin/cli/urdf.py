"""``robokin import``, ``robokin export`` and ``robokin dh``: URDF in and out, MJCF out.

``robokin export NAME -o robot.xml`` chooses the format by the suffix. Files are written only where ``-o`` names them; without ``-o`` the result goes to
standard output.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from robokin.cli.common import cell, console, json_text, load_robot
from robokin.cli.options import JsonFlag, MmFlag, RobotName
from robokin.cli.output import FormatOption

__all__ = ["commands", "dh", "export_urdf", "import_urdf"]

commands = typer.Typer()


def _not_the_input(out: Path, source: str | Path) -> None:
    """Refuse to write over the file being read (it would be lost)."""
    from robokin.exceptions import InputError

    src = Path(source)
    if src.is_file() and out.exists() and out.resolve() == src.resolve():
        raise InputError("--out", f"{out} is the input file; choose another name")


def _pairs(items: list[str] | None, option: str) -> dict[str, str]:
    """``NAME=VALUE`` options as a dict (a usage error names the option)."""
    out: dict[str, str] = {}
    for item in items or []:
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            raise typer.BadParameter(f"{option} expects NAME=VALUE, got {item!r}")
        out[name.strip()] = value
    return out


@commands.command("import")
def import_urdf(
    file: Annotated[Path, typer.Argument(help="The URDF or xacro (.xacro, .urdf.xacro) file.")],
    base: Annotated[str | None, typer.Option("--base", help="Base link.")] = None,
    tip: Annotated[str | None, typer.Option("--tip", help="Tip link.")] = None,
    out: Annotated[
        Path | None, typer.Option("-o", "--out", help="Robot file to write (YAML; replaced if it exists).")
    ] = None,
    package: Annotated[
        list[str] | None,
        typer.Option("--package", help="NAME=DIR for package:// and $(find NAME) "
                     "(repeatable; searched before ROS_PACKAGE_PATH)."),
    ] = None,
    arg: Annotated[
        list[str] | None,
        typer.Option("--arg", help="NAME=VALUE for a xacro's <xacro:arg> (repeatable)."),
    ] = None,
) -> None:
    """Read a URDF's or xacro's serial chain and write it as a robokin robot file.

    A xacro is expanded first (robokin[ros]; no ROS install). Every visual or
    collision shape left out (a mesh whose package or file is not found, a
    remote or unsupported mesh, a non-uniform scale) is reported on stderr,
    one line per reason (every mesh of a missing package on one line).
    """
    import yaml

    from robokin.io.robot_files import document_from_robot, save_robot
    from robokin.io.urdf import parts_from_urdf

    pmap = _pairs(package, "--package")
    if out is not None:
        _not_the_input(out, file)
    robot = parts_from_urdf(file, base_link=base, tip_link=tip, package_map=pmap,
                            xacro_args=_pairs(arg, "--arg"), missing_mesh="ignore")
    info = robot.meta["urdf"]
    for note in robot.meta.get("urdf_dropped_notes", ()):
        typer.echo(f"robokin: note: left out {note}", err=True)
    if out is None:
        print(yaml.safe_dump(document_from_robot(robot), sort_keys=False,
                             default_flow_style=None), end="")
        return
    save_robot(robot, out)
    console().print(
        f"{cell(robot.name, markup=False)}: {robot.n} joints, "
        f"{cell(info.base_link, markup=False)} -> {cell(info.tip_link, markup=False)}; "
        f"wrote {out}", markup=False,
    )


def _export_format(out: Path | None, fmt: str | None) -> str:
    """``urdf`` or ``mjcf``: ``--format`` when given, else by the suffix of ``-o``.

    ``.xml`` and ``.mjcf`` (but not ``.urdf.xml``) are MJCF; every other name is
    URDF, as it was before MJCF export existed.
    """
    from robokin.exceptions import InputError

    if fmt is not None:
        if fmt not in ("urdf", "mjcf"):
            raise InputError("--format", f"expected 'urdf' or 'mjcf', got {fmt!r}")
        return fmt
    if out is None:
        return "urdf"
    name = out.name.lower()
    if name.endswith((".xml", ".mjcf")) and not name.endswith(".urdf.xml"):
        return "mjcf"
    return "urdf"  # .urdf, and any other name as before MJCF export existed


@commands.command("export")
def export_urdf(
    name: RobotName,
    out: Annotated[
        Path | None, typer.Option(
            "-o", "--out", help="File to write (replaced if it exists): .xml or .mjcf "
            "for a MuJoCo model, any other name (.urdf) for URDF.")
    ] = None,
    fmt: Annotated[
        str | None, typer.Option("--format", help="urdf or mjcf (default: by the "
                                 "suffix of -o, else urdf).")
    ] = None,
    scene: Annotated[
        str | None, typer.Option("--scene", help="MJCF only: a scene file or bundled "
                                 "name; the robot is placed in it with its objects.")
    ] = None,
) -> None:
    """Write a robot as a URDF, or as a MuJoCo MJCF model, with the same FK and limits."""
    from robokin.exceptions import InputError

    if out is not None:
        _not_the_input(out, name)
    kind = _export_format(out, fmt)
    if scene is not None and kind != "mjcf":
        raise InputError("--scene", "a scene goes into an MJCF model only (-o NAME.xml)")
    robot = load_robot(name)
    if kind == "mjcf":
        from robokin.cli.common import load_scene
        from robokin.sim import to_mjcf

        text = to_mjcf(robot, None if scene is None else load_scene(scene))
    else:
        from robokin.io.urdf_export import urdf_from_robot

        text = urdf_from_robot(robot)
    if out is None:
        print(text, end="")
        return
    from robokin.io.atomic import write_atomic

    write_atomic(out, text)
    console().print(f"{cell(robot.name, markup=False)}: wrote {out} ({kind.upper()})",
                     markup=False)


@commands.command("dh")
def dh(
    file: Annotated[Path, typer.Argument(help="The URDF or xacro file.")],
    base: Annotated[str | None, typer.Option("--base", help="Base link.")] = None,
    tip: Annotated[str | None, typer.Option("--tip", help="Tip link.")] = None,
    modified: Annotated[
        bool, typer.Option("--modified", help="Modified (Craig) DH.")
    ] = False,
    reference: Annotated[
        str | None,
        typer.Option("--reference", help="Link whose frame guides DH frame 0."),
    ] = None,
    virtual: Annotated[
        bool,
        typer.Option("--virtual-frames", help="Fold base/tool into fixed rows."),
    ] = False,
    mm: MmFlag = False,
    as_json: JsonFlag = False,
    output_format: FormatOption = None,
    package: Annotated[list[str] | None, typer.Option(
        "--package", help="NAME=DIR for a xacro's $(find NAME) (repeatable).")] = None,
    arg: Annotated[list[str] | None, typer.Option(
        "--arg", help="NAME=VALUE for a xacro's <xacro:arg> (repeatable).")] = None,
) -> None:
    """Derive the DH table of a URDF or xacro arm (degrees; metres unless --mm)."""
    from robokin.cli.output import Column, OutputTable, emit, general, resolve_format
    from robokin.io.dh_extract import describe
    from robokin.io.urdf import dh_from_urdf

    fmt = resolve_format(output_format, as_json)
    ext = dh_from_urdf(
        file, base, tip, convention="modified" if modified else "standard",
        reference_link=reference, virtual_frames=virtual,
        package_map=_pairs(package, "--package"), xacro_args=_pairs(arg, "--arg"),
    )
    doc = describe(ext, deg=True)
    L = 1000.0 if mm else 1.0
    for r in doc["rows"]:
        r["a"] *= L
        r["d"] *= L
        if r["joint"] == "prismatic" and "limits" in r:
            r["limits"] = [v * L for v in r["limits"]]
    for key in ("base", "tool"):
        doc[key]["xyz"] = [v * L for v in doc[key]["xyz"]]
    doc["units"] = {"length": "mm" if mm else "m", "angle": "deg"}
    if fmt == "json":
        print(json_text(doc))
        return
    lu = "mm" if mm else "m"
    cols = (("alpha", "deg"), ("a", lu), ("theta", "deg"), ("d", lu)) if modified \
        else (("theta", "deg"), ("d", lu), ("a", lu), ("alpha", "deg"))
    table = OutputTable(f"{doc['convention']} DH of {file.name}",
                        [Column("joint"), Column("kind"),
                         *(Column(f"{c} [{u}]", general(10), True) for c, u in cols)])
    for r in doc["rows"]:
        table.add_row(r["name"], r["joint"], *(float(r[c]) for c, _ in cols))
    for key in ("base", "tool"):
        p = doc[key]
        table.notes.append(
            f"{key} transform: xyz [{lu}] "
            + " ".join(f"{v:.10g}" for v in p["xyz"])
            + "  rpy [deg] " + " ".join(f"{v:.10g}" for v in p["rpy"]))
    if ext.needs_virtual_frames and not virtual:
        table.notes.append("this arm needs virtual frames to stand as a table alone "
                           "(a base or tool transform remains); --virtual-frames "
                           "emits them")
    table.notes += [f"note: {note}" for note in doc["notes"]]
    emit(table, fmt)
