"""The link and joint tree of a parsed URDF, and what the chain import made of it.

:class:`Tree` checks a parsed URDF's links and joints (names, parents, loops, roots)
and answers path queries (base to tip, the default tip); :class:`UrdfChain` records
what :func:`robokin.io.urdf.parts_from_urdf` made of the URDF besides the chain.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from robokin.exceptions import ModelError
from robokin.io.urdf_xml import MOVABLE

__all__ = ["Step", "Tree", "UrdfChain"]


@dataclass(frozen=True)
class Step:
    """One URDF joint on the path, walked forwards or (fixed joints only) backwards."""

    joint: Any
    reverse: bool


class Tree:
    """The link/joint tree of a parsed URDF with checks and path queries."""

    def __init__(self, urdf_robot: Any, file: Path | None) -> None:
        """Index the links and joints of ``urdf_robot`` (a ``yourdfpy.Robot``), checked.

        Raises:
            ModelError: a link or joint defined twice, an undefined parent or
                child, a link with two parents, a loop, several roots (naming
                ``file`` and the element).
        """
        self.file = file
        self.links: dict[str, Any] = {}
        for link in urdf_robot.links:
            if link.name in self.links:
                raise ModelError(f"link '{link.name}' is defined twice", file=file)
            self.links[link.name] = link
        self.joints: dict[str, Any] = {}
        self.parent_joint: dict[str, Any] = {}
        self.children: dict[str, list[Any]] = {name: [] for name in self.links}
        for j in urdf_robot.joints:
            where = f"joint[{j.name}]"
            if j.name in self.joints:
                raise ModelError("joint defined twice", file=file, field=where)
            for role in ("parent", "child"):
                link = getattr(j, role)
                if link not in self.links:
                    raise ModelError(
                        f"{role} link '{link}' is not defined", file=file,
                        field=f"{where}.{role}",
                    )
            if j.child in self.parent_joint:
                raise ModelError(
                    f"link '{j.child}' has two parent joints "
                    f"('{self.parent_joint[j.child].name}' and '{j.name}'): "
                    "a URDF must be a tree",
                    file=file, field=where,
                )
            self.joints[j.name] = j
            self.parent_joint[j.child] = j
            self.children[j.parent].append(j)
        roots = [n for n in self.links if n not in self.parent_joint]
        if not roots:
            raise ModelError("the joints form a loop: no root link", file=file)
        if len(roots) > 1:
            raise ModelError(
                f"several root links {roots}: a URDF must be one connected tree",
                file=file,
            )
        self.root = roots[0]
        # Every link must be reachable from the root (no loop elsewhere).
        seen = set(self._descendants(self.root))
        if len(seen) != len(self.links):
            loop = sorted(set(self.links) - seen)
            raise ModelError(f"links {loop} form a loop", file=file)

    def _descendants(self, link: str) -> list[str]:
        out, stack = [], [link]
        while stack:
            cur = stack.pop()
            out.append(cur)
            stack.extend(j.child for j in self.children[cur])
        return out

    def ancestors(self, link: str) -> list[str]:
        """The link, its parent link, ..., the root."""
        out = [link]
        while out[-1] in self.parent_joint:
            out.append(self.parent_joint[out[-1]].parent)
        return out

    def check_link(self, name: str, role: str) -> None:
        """Raise ModelError naming ``{role}_link`` unless ``name`` is a link."""
        if name not in self.links:
            names = sorted(self.links)
            shown = ", ".join(names[:30]) + (" ..." if len(names) > 30 else "")
            raise ModelError(
                f"unknown {role} link '{name}'; links: {shown}", file=self.file,
                field=f"{role}_link",
            )

    def path(self, base: str, tip: str) -> list[Step]:
        """The joints from ``base`` to ``tip``."""
        up = self.ancestors(base)
        down = self.ancestors(tip)
        down_set = set(down)
        common = next(a for a in up if a in down_set)  # one tree: the root at least
        steps = []
        for link in up[: up.index(common)]:
            j = self.parent_joint[link]
            if j.type != "fixed":
                raise ModelError(
                    f"the base link '{base}' hangs below the movable joint '{j.name}' "
                    f"that is not between it and the tip '{tip}'; choose a base link "
                    f"above it (e.g. '{self.root}')",
                    file=self.file, field="base_link",
                )
            steps.append(Step(j, True))
        for link in reversed(down[: down.index(common)]):
            steps.append(Step(self.parent_joint[link], False))
        return steps

    def default_tip(self, base: str) -> str:
        """The leaf below ``base`` whose path has the most movable joints."""
        top = base  # a base hanging by fixed joints (ROS-I 'base') looks from above
        while top in self.parent_joint and self.parent_joint[top].type == "fixed":
            top = self.parent_joint[top].parent
        leaves = [n for n in self._descendants(top) if not self.children[n]]
        counts = {
            leaf: sum(s.joint.type in MOVABLE for s in self.path(base, leaf))
            for leaf in leaves
        }
        best = max(counts.values())
        if best == 0:
            raise ModelError(
                f"no movable joint below the base link '{base}'", file=self.file,
                field="tip_link",
            )
        cands = sorted(leaf for leaf, c in counts.items() if c == best)
        if len(cands) == 1:
            return cands[0]
        if "tool0" in cands:
            return "tool0"
        raise ModelError(
            f"ambiguous tip link: {len(cands)} leaves {cands} are each {best} movable "
            f"joints from '{base}'; pass tip_link= (CLI: --tip) to choose one",
            file=self.file, field="tip_link",
        )


@dataclass(frozen=True)
class UrdfChain:
    """What :func:`parts_from_urdf` made of the URDF, besides the chain.

    Attributes:
        base_link: The chosen base link.
        tip_link: The chosen tip link.
        child_links: The URDF child link of every chain joint (n_chain).
        link_frames: Every URDF link rigidly attached to the chain:
            ``name -> (k, T)``, the link's pose ``T`` (4, 4) in the frame ``k`` of
            ``fk_all`` (0: the base link; k: chain joint k's child link); the
            tool's tree (fingers at ``tool_joints``) in frame ``n_chain``.
        dropped_links: Links not rigidly attached to the chain (they move with
            joints off the chain, other than the tool's), sorted.
        owners: The robokin link each placed URDF link belongs to: ``base``, a
            chain joint's name, or ``tool`` (see :mod:`robokin.io.urdf_tool`).
        tool_joints: The position [rad, m] each joint of the tool's tree is
            frozen at (mimic joints included).
        shaped_links: The URDF links whose shapes robokin's geometry holds.
    """

    base_link: str
    tip_link: str
    child_links: tuple[str, ...]
    link_frames: Mapping[str, tuple[int, np.ndarray]]
    dropped_links: tuple[str, ...]
    owners: Mapping[str, str] = field(default_factory=dict)
    tool_joints: Mapping[str, float] = field(default_factory=dict)
    shaped_links: frozenset[str] = frozenset()

    def parts(self) -> dict[str, tuple[str, ...]]:
        """The URDF links with shapes each robokin link holds: ``{link: (URDF links)}``."""
        out: dict[str, list[str]] = {}
        for link in sorted(self.shaped_links):
            owner = self.owners.get(link)
            if owner is not None:
                out.setdefault(owner, []).append(link)
        return {k: tuple(v) for k, v in out.items()}
