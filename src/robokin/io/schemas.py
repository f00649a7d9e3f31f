"""JSON Schemas of the files robokin reads, generated from their pydantic models.

``robokin schema robot|scene|motion`` prints them. An editor given the schema
(e.g. a ``# yaml-language-server: $schema=robot.schema.json`` first line, with
the YAML language server of VS Code, or the schema setting of other editors)
validates a file while it is written and completes its keys. The schemas are
generated from the models the readers use, never written by hand, so a field
added to a reader appears in its schema.

A schema checks keys, types and allowed values; the readers check more (a joint
count that matches the robot, a mesh file that exists, magnitudes, units that
make sense), naming the file, line and field.
"""

from __future__ import annotations

from typing import Any, Literal

__all__ = ["FILE_KINDS", "json_schema"]

#: The file kinds with a schema.
FILE_KINDS = ("robot", "scene", "motion")

_DOCS = {"robot": "docs/robot-files.md", "scene": "docs/scene-files.md",
         "motion": "docs/motion-files.md"}


def _model(kind: str) -> Any:
    if kind == "robot":
        from robokin.io.robot_files import file_model

        return file_model()
    if kind == "scene":
        from robokin.io.scene_files import scene_model

        return scene_model()
    from robokin.io.motion_files import _schema

    return _schema()


def json_schema(kind: Literal["robot", "scene", "motion"]) -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of a robot, scene or motion file.

    Args:
        kind: ``"robot"``, ``"scene"`` or ``"motion"``.

    Returns:
        The schema as a JSON-ready dict (``$schema``, ``title``, ``description``
        naming the documentation page, ``properties``, ``$defs``).

    Raises:
        InputError: an unknown kind (the accepted ones listed).
    """
    from robokin.exceptions import InputError

    if kind not in FILE_KINDS:
        raise InputError("kind", f"unknown file kind {kind!r:.40}; accepted: "
                         + ", ".join(FILE_KINDS))
    schema = _model(kind).model_json_schema(mode="validation")
    described = schema.get("description", "").strip()
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        **schema,
        "title": f"robokin {kind} file",
        "description": f"{described} Every field: {_DOCS[kind]} (robokin).".strip(),
    }
