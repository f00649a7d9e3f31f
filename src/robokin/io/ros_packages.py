"""Finding ROS packages without ROS: ``package://NAME/...`` and ``$(find NAME)``.

A URDF or xacro names files inside ROS packages. :class:`PackageFinder` looks a
package up, in this order, and stops at the first hit:

1. the package map the caller gave (``package_map={"NAME": "DIR"}``, CLI
   ``--package NAME=DIR``);
2. ``ROS_PACKAGE_PATH`` (ROS 1 convention): each folder in it, searched
   downwards for a ``package.xml`` whose ``<name>`` is the package (a folder
   holding a ``package.xml`` is a package: the search does not descend into it;
   a folder holding ``CATKIN_IGNORE`` is skipped), as ``rospack`` does;
3. ``AMENT_PREFIX_PATH`` (ROS 2 convention): ``PREFIX/share/NAME`` holding a
   ``package.xml``;
4. the folders above the file being read: the first one whose ``package.xml``
   names the package (a description package read in place).

Nothing is fetched and no ROS install is needed. A package that is not found is
reported with the places searched (:meth:`PackageFinder.not_found`).
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from pathlib import Path

from robokin.exceptions import InputError

__all__ = ["MAX_CRAWL_DIRS", "PackageFinder", "package_name"]

#: Most folders one ``ROS_PACKAGE_PATH`` search visits (a path set to ``/`` stops
#: here rather than walk the whole disk).
MAX_CRAWL_DIRS = 20_000

_NAME = re.compile(r"<name>\s*([^<\s]+)\s*</name>")
_COMMENT = re.compile(r"<!--.*?-->", re.S)


def package_name(package_xml: Path) -> str | None:
    """The ``<name>`` of a ``package.xml`` (None when unreadable or absent)."""
    try:
        with package_xml.open("rb") as fh:
            text = fh.read(256 * 1024).decode("utf-8", "replace")
    except OSError:
        return None
    m = _NAME.search(_COMMENT.sub("", text))
    return m.group(1) if m else None


class PackageFinder:
    """Where ROS packages are, looked up as the module docstring says.

    Args:
        package_map: ``{name: directory}`` given by the caller (searched first).
        near: The file being read: the folders above it are searched last.
        environ: The environment to read ``ROS_PACKAGE_PATH`` and
            ``AMENT_PREFIX_PATH`` from (default ``os.environ``).

    Raises:
        InputError: a package map entry with an empty name or a directory that
            does not exist.
    """

    def __init__(self, package_map: Mapping[str, str | Path] | None = None, *,
                 near: Path | None = None,
                 environ: Mapping[str, str] | None = None) -> None:
        """Check the package map and read the search path from the environment."""
        env = os.environ if environ is None else environ
        self.package_map: dict[str, Path] = {}
        for name, directory in (package_map or {}).items():
            if not isinstance(name, str) or not name or "/" in name:
                raise InputError("package_map", f"a package name must be non-empty "
                                 f"text without '/', got {name!r}")
            # absolute: xacro reads a relative include against the including file
            d = Path(directory).expanduser().absolute()
            if not d.is_dir():
                raise InputError("package_map", f"package '{name}': no such folder "
                                 f"{d}")
            self.package_map[name] = d
        self.ros_package_path = [Path(p).absolute() for p in
                                 env.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
        self.ament_prefix_path = [Path(p).absolute() for p in
                                  env.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
        self.near = None if near is None else Path(near).resolve().parent
        self._crawled: dict[str, Path] | None = None
        self._cache: dict[str, Path | None] = {}

    def find(self, name: str) -> Path | None:
        """The package's folder, or None when no place searched has it."""
        if name not in self._cache:
            self._cache[name] = self._lookup(name)
        return self._cache[name]

    def _lookup(self, name: str) -> Path | None:
        if name in self.package_map:
            return self.package_map[name]
        if self.ros_package_path:
            hit = self._crawl().get(name)
            if hit is not None:
                return hit
        for prefix in self.ament_prefix_path:
            d = prefix / "share" / name
            if (d / "package.xml").is_file():
                return d
        if self.near is not None:
            for d in (self.near, *self.near.parents):
                xml = d / "package.xml"
                if xml.is_file() and package_name(xml) == name:
                    return d
        return None

    def _crawl(self) -> dict[str, Path]:
        """Every package under ``ROS_PACKAGE_PATH``: the first of each name wins."""
        if self._crawled is not None:
            return self._crawled
        found: dict[str, Path] = {}
        visited = 0
        seen: set[str] = set()
        for top in self.ros_package_path:
            for d, dirs, files in os.walk(top, followlinks=True):
                real = os.path.realpath(d)
                visited += 1
                if real in seen or visited > MAX_CRAWL_DIRS or "CATKIN_IGNORE" in files:
                    dirs[:] = []
                    continue
                seen.add(real)
                if "package.xml" in files:
                    dirs[:] = []  # a package: packages do not nest
                    pname = package_name(Path(d) / "package.xml")
                    if pname is not None:
                        found.setdefault(pname, Path(d))
                    continue
                dirs[:] = sorted(x for x in dirs if not x.startswith("."))
        self._crawled = found
        return found

    def lookups(self) -> dict[str, str | None]:
        """Every package looked up so far: ``{name: folder or None}`` (JSON-ready)."""
        return {k: None if v is None else str(v) for k, v in self._cache.items()}

    def absorb(self, lookups: Mapping[str, str | None]) -> None:
        """Take lookups made by a copy of this finder (in a child process).

        Only names this finder has not looked up itself: its own answers stay.
        """
        for name, found in lookups.items():
            self._cache.setdefault(str(name), None if found is None else Path(found))

    def search_path(self) -> list[str]:
        """The places searched, in order, for messages."""
        out = []
        if self.package_map:
            out.append("the package map (" + ", ".join(sorted(self.package_map)) + ")")
        else:
            out.append("the package map (empty)")
        out.append("ROS_PACKAGE_PATH=" + (os.pathsep.join(map(str, self.ros_package_path))
                                          or "(not set)"))
        if self.ament_prefix_path:
            out.append("AMENT_PREFIX_PATH=" + os.pathsep.join(map(str, self.ament_prefix_path)))
        if self.near is not None:
            out.append(f"package.xml files in {self.near} and the folders above it")
        return out

    def not_found(self, name: str) -> str:
        """Why ``name`` was not found: the places searched and the fix."""
        return (f"package '{name}' not found; searched {'; '.join(self.search_path())}; "
                f"give its folder with --package {name}=DIR "
                f"(Python: package_map={{'{name}': DIR}})")
