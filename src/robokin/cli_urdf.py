"""``robokin import``, ``robokin export`` and ``robokin dh``: URDF in and out.

Files are written only where ``-o`` names them; without ``-o`` the result goes to
standard output.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from robokin.cli import _console, _load, app, cell, json_text
from robokin.cli_output import FormatOption

__all__ = ["dh", "export_urdf", "import_urdf"]


def _not_the_input(out: Path, source: str | Path) -> None:
    """Refuse to write over the file being read (it would be lost)."""
    from robokin.exceptions import InputError

    src = Path(source)
    if src.is_file() and out.exists() and out.resolve() == src.resolve():
        raise InputError("--out", f"{out} is the input file; choose another name")


@app.command("import")
def import_urdf(
    file: Annotated[Path, typer.Argument(help="The URDF file.")],
    base: Annotated[str | None, typer.Option("--base", help="Base link.")] = None,
    tip: Annotated[str | None, typer.Option("--tip", help="Tip link.")] = None,
    out: Annotated[
        Path | None, typer.Option("-o", "--out", help="Robot file to write (YAML; replaced if it exists).")
    ] = None,
    package: Annotated[
        list[str] | None,
        typer.Option("--package", help="NAME=DIR for package:// meshes (repeatable)."),
    ] = None,
) -> None:
    """Read a URDF's serial chain and write it as a robokin robot file.

    Every visual or collision shape left out (a missing, remote or unsupported
    mesh, a non-uniform scale) is reported on stderr, one line each.
    """
    import yaml

    from robokin.io.robot_files import document_from_robot, save_robot
    from robokin.io.urdf import robot_from_urdf

    pmap = {}
    for item in package or []:
        name, sep, directory = item.partition("=")
        if not sep or not name:
            raise typer.BadParameter(f"--package expects NAME=DIR, got {item!r}")
        pmap[name] = directory
    if out is not None:
        _not_the_input(out, file)
    robot = robot_from_urdf(file, base_link=base, tip_link=tip, package_map=pmap,
                            missing_mesh="ignore")
    info = robot.meta["urdf"]
    for msg in robot.meta.get("urdf_dropped_shapes", ()):
        typer.echo(f"robokin: note: left out {msg}", err=True)
    if out is None:
        print(yaml.safe_dump(document_from_robot(robot), sort_keys=False,
                             default_flow_style=None), end="")
        return
    save_robot(robot, out)
    _console().print(
        f"{cell(robot.name, markup=False)}: {robot.n} joints, "
        f"{cell(info.base_link, markup=False)} -> {cell(info.tip_link, markup=False)}; "
        f"wrote {out}", markup=False,
    )


@app.command("export")
def export_urdf(
    name: Annotated[str, typer.Argument(help="Built-in name or robot file.")],
    out: Annotated[
        Path | None, typer.Option("-o", "--out", help="URDF file to write (replaced if it exists).")
    ] = None,
) -> None:
    """Write a robot as a URDF with the same FK and limits."""
    from robokin.io.urdf_export import urdf_from_robot, write_urdf

    if out is not None:
        _not_the_input(out, name)
    robot = _load(name)
    if out is None:
        print(urdf_from_robot(robot), end="")
        return
    write_urdf(robot, out)
    _console().print(f"{cell(robot.name, markup=False)}: wrote {out}", markup=False)


@app.command("dh")
def dh(
    file: Annotated[Path, typer.Argument(help="The URDF file.")],
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
    mm: Annotated[bool, typer.Option("--mm", help="Lengths in millimetres.")] = False,
    as_json: Annotated[bool, typer.Option("--json", help="Same as --format json.")
                       ] = False,
    output_format: FormatOption = None,
) -> None:
    """Derive the DH table of a URDF arm (degrees; metres unless --mm)."""
    from robokin.cli_output import Column, OutputTable, emit, general, resolve_format
    from robokin.io.dh_extract import describe
    from robokin.io.urdf import dh_from_urdf

    fmt = resolve_format(output_format, as_json)
    ext = dh_from_urdf(
        file, base, tip, convention="modified" if modified else "standard",
        reference_link=reference, virtual_frames=virtual,
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
