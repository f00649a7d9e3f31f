"""The schema of scene files (YAML): a pydantic model of their keys and types.

:class:`robokin.collision.Scene` reads scene files (``Scene.load``); this module
holds what the file may contain, for the key checks of that reader and for
``robokin schema scene`` (the JSON Schema editors validate and complete with).
See ``docs/scene-files.md`` for every field with an example.
"""

from __future__ import annotations

import functools
from typing import Any

from robokin.io.geometry_sections import shape_models
from robokin.io.validate import list_of, tagged_union, union_of

__all__ = ["scene_model", "scene_section_keys"]


@functools.cache
def scene_model() -> Any:
    """The pydantic model of a scene file (numbers in the file's ``units``)."""
    from typing import Annotated, Literal

    from pydantic import (
        BaseModel,
        ConfigDict,
        Field,
        StrictFloat,
        StrictStr,
        create_model,
    )

    Name = Annotated[StrictStr, Field(max_length=200)]
    Vec3 = tuple[StrictFloat, StrictFloat, StrictFloat]

    class Strict(BaseModel):
        model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    class Units(Strict):
        """The units of every number of the file."""

        length: Literal["m", "mm", "cm"] = "m"
        angle: Literal["rad", "deg"] = "rad"

    class Placement(Strict):
        """A pose: translation ``xyz`` [length], then roll-pitch-yaw ``rpy`` [angle]."""

        xyz: Vec3 = (0.0, 0.0, 0.0)
        rpy: Vec3 = (0.0, 0.0, 0.0)

    class RobotPlacement(Strict):
        """The robot of the cell and where its base stands in the world."""

        name: Name | None = None
        base: Placement | None = None

    shapes = tuple(shape_models().values())
    # the tool's shapes are in the flange frame; an object is a shape with a
    # name (required), placed in the world
    tool = create_model(
        "Tool", __base__=Strict,
        __doc__="The tool on the robot's flange: its TCP and shapes (flange frame).",
        name=(Name, "tool"), tcp=(union_of(Placement, None), None),
        shapes=(union_of(list_of(tagged_union(*shapes)), None), None))
    objects = [create_model(f"{m.__name__}Object", __base__=m, __doc__=m.__doc__,
                            name=(Name, ...)) for m in shapes]

    class NamedPose(Placement):
        """A named TCP pose in the world; ``q``: joints that reach it [angle, length]."""

        q: list[StrictFloat] | StrictFloat | None = None

    class Base(Strict):
        """A robot cell: static objects, the robot's base, its tool, named poses."""

        name: Name | None = None
        source: Annotated[StrictStr, Field(max_length=4096)] = ""
        units: Units = Field(default_factory=Units)
        robot: RobotPlacement | None = None
        exclude: list[tuple[Name, Name]] | None = None
        poses: dict[Name, NamedPose] | None = None

    return create_model(
        "SceneFile", __base__=Base, __doc__=Base.__doc__,
        tool=(union_of(tool, None), None),
        objects=(union_of(list_of(tagged_union(*objects)), None), None))


def scene_section_keys(section: str | None = None) -> list[str]:
    """The keys of a scene file (``None``) or of one of its sections.

    Args:
        section: ``None`` (the top level), ``"robot"``, ``"tool"``, ``"units"`` or
            a placement (``"placement"``: ``robot.base``, ``tool.tcp``, a pose
            without ``q``).
    """
    import typing

    model = scene_model()
    if section is None:
        return list(model.model_fields)
    field = {"placement": "robot"}.get(section, section)
    sub = model.model_fields[field].annotation
    sub = next(a for a in typing.get_args(sub) if a is not type(None)) \
        if typing.get_args(sub) else sub
    if section == "placement":
        sub = sub.model_fields["base"].annotation
        sub = next(a for a in typing.get_args(sub) if a is not type(None))
    return list(sub.model_fields)
