"""The built-in robot library: one robot file per arm in this folder."""

from __future__ import annotations

from pathlib import Path

from robokin.exceptions import ModelError
from robokin.io.robot_files import load_parts
from robokin.robot import Robot

__all__ = ["URDF_SUFFIXES", "load", "names", "path"]

_HERE = Path(__file__).parent


def names() -> list[str]:
    """Names of the built-in robots, sorted."""
    return sorted(p.stem for p in _HERE.glob("*.yaml"))


def path(name: str) -> Path:
    """The robot file of a built-in robot.

    Raises:
        ModelError: unknown name; the message lists the known ones.
    """
    p = _HERE / f"{name}.yaml"
    if not p.is_file():
        raise ModelError(f"unknown robot {name!r}; built-in robots: {', '.join(names())}")
    return p


#: Names of files that are URDF or xacro, not robot files.
URDF_SUFFIXES = (".urdf", ".xacro", ".urdf.xml")


def load(name_or_path: str | Path) -> Robot:
    """Load a built-in robot by name, or a robot file by path.

    Raises:
        ModelError: an unknown name (listing the built-in ones), a bad robot
            file, or a URDF or xacro (pointing to ``Robot.from_urdf`` and
            ``robokin import``).
    """
    s = str(name_or_path)
    if s.lower().endswith(URDF_SUFFIXES):
        raise ModelError(
            "a URDF or xacro, not a robokin robot file: read it with "
            f"robokin.Robot.from_urdf({s!r}) or convert it once with "
            f"'robokin import {s} -o ROBOT.yaml'", file=s)
    if isinstance(name_or_path, Path) or s.endswith((".yaml", ".yml")) or "/" in s \
            or Path(s).is_file():
        return Robot.from_parts(load_parts(Path(name_or_path)))
    return Robot.from_parts(load_parts(path(s)))
