"""``robokin schema``: the JSON Schema of a robot, scene or motion file."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer

__all__ = ["commands", "schema"]

commands = typer.Typer()


@commands.command()
def schema(
    kind: Annotated[str, typer.Argument(help="robot | scene | motion")],
    out: Annotated[Path | None, typer.Option(
        "--out", "-o", help="Write the schema to this file (replaced if it exists) "
                            "instead of printing it.")] = None,
) -> None:
    """Print the JSON Schema of a file robokin reads, for editors to validate and complete.

    Generated from the pydantic models the readers use (robokin.io.schemas). With
    the YAML language server (VS Code and others), a first line
    '# yaml-language-server: $schema=robot.schema.json' in a robot file applies it.
    """
    from robokin.io.atomic import write_atomic
    from robokin.io.schemas import FILE_KINDS, json_schema

    if kind not in FILE_KINDS:
        from robokin.exceptions import InputError

        raise InputError("KIND", f"unknown file kind {kind[:40]!r}; accepted: "
                         + ", ".join(FILE_KINDS))
    text = json.dumps(json_schema(kind), indent=2)  # type: ignore[arg-type]
    if out is None:
        print(text)
        return
    write_atomic(out, text + "\n", argument="--out")
    typer.echo(f"wrote {out}")
