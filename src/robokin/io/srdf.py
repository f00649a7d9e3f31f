"""SRDF in: MoveIt's semantic robot description, for the collision pairs and the tip.

An SRDF (``robot.srdf``, written by the MoveIt Setup Assistant) names groups of
joints, end effectors and, above all for robokin, the link pairs whose
collisions are never checked (``<disable_collisions link1= link2= reason=/>``).
:func:`parse_srdf` reads one safely (the same lxml parser as URDF: no entities,
no DTD, no network; at most :data:`MAX_SRDF_ELEMENTS` elements and 16 MiB) and
strictly (an element without its attributes is a
:class:`~robokin.exceptions.ModelError` naming the file, the line and the
element). :func:`excluded_link_pairs` turns URDF-level pairs into robokin-level
ones (see its docstring and ``docs/urdf.md`` for the rule).

What robokin uses, with MoveIt's meaning (``AllowedCollisionMatrix(srdf)``):

* ``<disable_collisions>``: the pair is allowed to touch (never checked);
* ``<enable_collisions>``: the pair is checked (unless also disabled: disabling
  wins, as in MoveIt);
* ``<disable_default_collisions link=>``: every pair with the link is allowed
  unless enabled (robokin applies it to self pairs; the link is still checked
  against the scene, which MoveIt would not do: the conservative side);
* ``<group><chain base_link= tip_link=/></group>`` and
  ``<end_effector parent_link=>``: the default tip link (:meth:`Srdf.default_tip`).

The other elements (``virtual_joint``, ``group_state``, ``passive_joint``,
``link_sphere_approximation``, ``joint_property``) are read past; an element
robokin does not know is a warning naming its line (srdfdom ignores them).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Collection, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from robokin._text import control_character, short_repr
from robokin.exceptions import ModelError
from robokin.io.urdf_xml import parse_xml_strictly, read_source

__all__ = [
    "MAX_SRDF_ELEMENTS",
    "LinkPair",
    "Srdf",
    "SrdfChain",
    "SrdfEndEffector",
    "excluded_link_pairs",
    "parse_srdf",
]

#: Most elements an SRDF may hold (a 1000-link robot's full pair list is ~500 000;
#: the Setup Assistant writes a few hundred to a few thousand).
MAX_SRDF_ELEMENTS = 300_000

#: Top-level elements srdfdom reads.
KNOWN_ELEMENTS = (
    "virtual_joint", "group", "group_state", "end_effector",
    "link_sphere_approximation", "disable_default_collisions", "enable_collisions",
    "disable_collisions", "passive_joint", "joint_property",
)


@dataclass(frozen=True)
class LinkPair:
    """One ``<disable_collisions>`` or ``<enable_collisions>`` element.

    Attributes:
        link1: First URDF link.
        link2: Second URDF link.
        reason: The ``reason`` attribute (``Adjacent``, ``Never``, ...), or "".
        line: Its line in the SRDF.
    """

    link1: str
    link2: str
    reason: str
    line: int


@dataclass(frozen=True)
class SrdfChain:
    """A ``<group>``'s ``<chain base_link= tip_link=/>``.

    Attributes:
        group: The group's name.
        base_link: The chain's base link.
        tip_link: The chain's tip link.
        line: Its line in the SRDF.
    """

    group: str
    base_link: str
    tip_link: str
    line: int


@dataclass(frozen=True)
class SrdfEndEffector:
    """An ``<end_effector>``: the group of links (a gripper) on a parent link.

    Attributes:
        name: The end effector's name.
        parent_link: The link it is mounted on (the arm's tip).
        group: The group of its links.
        parent_group: The arm's group, or "".
        line: Its line in the SRDF.
    """

    name: str
    parent_link: str
    group: str
    parent_group: str
    line: int


@dataclass(frozen=True)
class Srdf:
    """What robokin reads of an SRDF.

    Attributes:
        name: The ``<robot name>``.
        file: The file (None for a string).
        chains: Every group's chain, in file order.
        end_effectors: The end effectors, in file order.
        disabled: The ``<disable_collisions>`` pairs.
        enabled: The ``<enable_collisions>`` pairs.
        no_default: ``(link, line)`` of each ``<disable_default_collisions>``.
    """

    name: str
    file: Path | None
    chains: tuple[SrdfChain, ...] = ()
    end_effectors: tuple[SrdfEndEffector, ...] = ()
    disabled: tuple[LinkPair, ...] = ()
    enabled: tuple[LinkPair, ...] = ()
    no_default: tuple[tuple[str, int], ...] = ()

    def links(self) -> list[tuple[str, int, str]]:
        """Every link the SRDF names in collision rules: ``(link, line, element)``."""
        out = [(link, p.line, "disable_collisions") for p in self.disabled
               for link in (p.link1, p.link2)]
        out += [(link, p.line, "enable_collisions") for p in self.enabled
                for link in (p.link1, p.link2)]
        out += [(link, line, "disable_default_collisions")
                for link, line in self.no_default]
        return out

    def allowed(self) -> Callable[[str, str], bool]:
        """MoveIt's rule: ``allows(a, b)`` is True when the pair is never checked.

        Disabled pairs are allowed, then enabled pairs are checked, then a link
        with ``<disable_default_collisions>`` is allowed with every other.
        """
        disabled = {frozenset((p.link1, p.link2)) for p in self.disabled}
        enabled = {frozenset((p.link1, p.link2)) for p in self.enabled} - disabled
        no_default = {link for link, _ in self.no_default}

        def allows(a: str, b: str) -> bool:
            pair = frozenset((a, b))
            if pair in disabled:
                return True
            if pair in enabled:
                return False
            return a in no_default or b in no_default

        return allows

    def check_links(self, links: Collection[str], urdf_name: str | None = None) -> None:
        """Warn about links the URDF does not define, as srdfdom does.

        A rule naming an unknown link is skipped by MoveIt (robokin's rule never
        matches it either: the pair stays checked, the conservative side).

        Args:
            links: The URDF's link names.
            urdf_name: The URDF's ``<robot name>``: a different SRDF name is
                warned about (srdfdom logs it as an error and goes on).
        """
        where = "SRDF string" if self.file is None else str(self.file)
        if urdf_name is not None and self.name != urdf_name:
            warnings.warn(f"{where}: the SRDF is for robot {short_repr(self.name)}, "
                          f"the URDF is {short_repr(urdf_name)}", UserWarning,
                          stacklevel=3)
        unknown = [(link, line, el) for link, line, el in self.links()
                   if link not in links]
        for link, line, el in unknown[:5]:
            warnings.warn(f"{where}:{line}: <{el}> names link {short_repr(link)}, "
                          "which the URDF does not define; the rule is skipped",
                          UserWarning, stacklevel=3)
        if len(unknown) > 5:
            warnings.warn(f"{where}: {len(unknown) - 5} more rules name links the "
                          "URDF does not define; they are skipped", UserWarning,
                          stacklevel=3)

    def default_tip(self, links: Collection[str]) -> str:
        """The tip link the SRDF implies, for ``Robot.from_urdf(srdf=...)``.

        The parent link of the end effector(s), when they agree on one; else the
        tip of the groups' chains, when they agree on one.

        Args:
            links: The URDF's link names (an SRDF tip it does not define is an
                error).

        Raises:
            ModelError: no end effector or chain, or several candidates (listing
                them: pass ``tip_link=``).
        """
        for what, cands in (
            ("end_effector parent_link", [(e.parent_link, e.line)
                                           for e in self.end_effectors]),
            ("group chain tip_link", [(c.tip_link, c.line) for c in self.chains]),
        ):
            names = sorted({c for c, _ in cands})
            if len(names) == 1:
                tip, line = cands[0]
                if tip not in links:
                    raise ModelError(f"the {what} {short_repr(tip)} is not a link "
                                     "of the URDF", file=self.file, line=line,
                                     field="tip_link")
                return tip
            if len(names) > 1:
                raise ModelError(f"ambiguous tip link: the SRDF's {what}s are "
                                 f"{names}; pass tip_link= to choose one",
                                 file=self.file, field="tip_link")
        raise ModelError("the SRDF has no <end_effector> and no <group> with a "
                         "<chain>, so it names no tip: pass tip_link=",
                         file=self.file, field="tip_link")


def _attribute(el: Any, key: str, file: Path | None) -> str:
    """A required name attribute, trimmed (as srdfdom does), printable."""
    value = el.get(key)
    if value is None or not value.strip():
        raise ModelError(f"<{el.tag}> needs a '{key}' attribute", file=file,
                         field=f"{el.tag}.{key}", line=el.sourceline)
    value = value.strip()
    problem = control_character(value)
    if problem is not None or len(value) > 1000:
        raise ModelError(problem or "a name longer than 1000 characters", file=file,
                         field=f"{el.tag}.{key}", line=el.sourceline)
    return value


def _pairs(root: Any, tag: str, file: Path | None) -> tuple[LinkPair, ...]:
    return tuple(
        LinkPair(_attribute(el, "link1", file), _attribute(el, "link2", file),
                 (el.get("reason") or "").strip(), el.sourceline)
        for el in root.findall(tag)
    )


def _groups(root: Any, file: Path | None) -> tuple[SrdfChain, ...]:
    out = []
    for group in root.findall("group"):
        name = _attribute(group, "name", file)
        for ch in group.findall("chain"):
            out.append(SrdfChain(name, _attribute(ch, "base_link", file),
                                 _attribute(ch, "tip_link", file), ch.sourceline))
    return tuple(out)


def _end_effectors(root: Any, file: Path | None) -> tuple[SrdfEndEffector, ...]:
    return tuple(
        SrdfEndEffector(_attribute(el, "name", file),
                        _attribute(el, "parent_link", file),
                        _attribute(el, "group", file),
                        (el.get("parent_group") or "").strip(), el.sourceline)
        for el in root.findall("end_effector")
    )


def parse_srdf(source: str | Path | bytes) -> Srdf:
    """Read an SRDF file (or XML string / bytes).

    Args:
        source: A path, or the XML itself (a string starting with ``<``, or bytes).

    Returns:
        The :class:`Srdf`.

    Raises:
        ModelError: unreadable or oversized file, malformed XML, a
            ``<!DOCTYPE>``, a root that is not ``<robot>``, more than
            :data:`MAX_SRDF_ELEMENTS` elements, or an element without a
            required attribute (naming the file, the line and the element).
        MissingExtraError: lxml is not installed (``robokin[urdf]``).
    """
    data, file = read_source(source)
    root = parse_xml_strictly(data, file, "SRDF")
    if root.tag != "robot":
        raise ModelError(f"the root element must be <robot>, got "
                         f"<{short_repr(root.tag, 40)}>", file=file,
                         line=root.sourceline)
    for count, el in enumerate(root.iter(), start=1):
        if count > MAX_SRDF_ELEMENTS:
            raise ModelError(f"more than {MAX_SRDF_ELEMENTS:,} elements; robokin reads "
                             "at most that many (robokin.io.srdf.MAX_SRDF_ELEMENTS)",
                             file=file, line=el.sourceline)
    where = "SRDF string" if file is None else str(file)
    for el in root:
        if isinstance(el.tag, str) and el.tag not in KNOWN_ELEMENTS:
            warnings.warn(f"{where}:{el.sourceline}: unknown SRDF element "
                          f"<{el.tag[:40]}> skipped (known: "
                          f"{', '.join(KNOWN_ELEMENTS)})", UserWarning, stacklevel=2)
    return Srdf(
        name=(root.get("name") or "").strip(),
        file=file,
        chains=_groups(root, file),
        end_effectors=_end_effectors(root, file),
        disabled=_pairs(root, "disable_collisions", file),
        enabled=_pairs(root, "enable_collisions", file),
        no_default=tuple((_attribute(el, "link", file), el.sourceline)
                         for el in root.findall("disable_default_collisions")),
    )


def excluded_link_pairs(
    parts: Mapping[str, Iterable[str]], allows: Callable[[str, str], bool]
) -> set[frozenset[str]]:
    """The robokin link pairs never checked, from URDF-level allowed pairs.

    robokin merges URDF links that move together into one link (the links hung
    by fixed joints, a gripper's tree in the tool). The rule:

    * a pair of URDF links inside one robokin link vanishes (one rigid body is
      never checked against itself);
    * robokin links ``A`` and ``B`` are excluded only if **every** pair
      ``(a, b)``, ``a`` a URDF link of ``A`` and ``b`` of ``B`` that carry shapes,
      is allowed: one checked URDF pair keeps the whole robokin pair checked (a
      robokin pair is checked as a whole, so excluding it on a partial match
      would drop a pair MoveIt checks; keeping it checks a few pairs MoveIt
      skips, the conservative side).

    Args:
        parts: robokin link name -> the URDF links it holds that carry shapes.
        allows: ``allows(a, b)``: True when the URDF pair is never checked.

    Returns:
        The excluded robokin pairs (links without URDF shapes never appear).
    """
    items = [(name, tuple(p)) for name, p in parts.items()]
    items = [(name, p) for name, p in items if p]
    out: set[frozenset[str]] = set()
    for i, (na, pa) in enumerate(items):
        for nb, pb in items[i + 1:]:
            if all(allows(a, b) for a in pa for b in pb):
                out.add(frozenset((na, nb)))
    return out
