"""Reading a URDF's XML safely and strictly (the first step of :mod:`robokin.io.urdf`).

lxml parses with entities, DTDs, the network and huge trees switched off,
explicitly (:func:`_xml_parser`); a document with a ``<!DOCTYPE>`` is refused, so
yourdfpy's own parse of the same bytes has nothing to expand or fetch. Then the
structure and every numeric attribute are checked, each error naming the file,
the line, the element (``joint[j].origin.xyz``, ``link[l].box.size``) and the
reason: yourdfpy alone would silently "recover" broken XML and read ``nan``.
"""

from __future__ import annotations

import io
import math
from pathlib import Path
from typing import Any

from robokin._text import short_repr
from robokin._validation import MAX_TRANSLATION
from robokin.exceptions import MissingExtraError, ModelError
from robokin.io.text_files import read_file_bytes

__all__ = ["JOINT_TYPES", "MAX_URDF_JOINTS", "MOVABLE", "parse_urdf",
           "parse_xml_strictly", "read_source"]

#: Joint types that move.
MOVABLE = ("revolute", "continuous", "prismatic")
#: Every URDF joint type.
JOINT_TYPES = (*MOVABLE, "fixed", "floating", "planar")
#: Most joints a URDF may hold (a tree of at most this many joints plus one links).
MAX_URDF_JOINTS = 1000


def _yourdfpy():
    try:
        import yourdfpy
    except ImportError:
        raise MissingExtraError("yourdfpy", "urdf") from None
    return yourdfpy


def read_source(source: str | Path | bytes) -> tuple[bytes, Path | None]:
    """The XML bytes and the file they came from (None for a string)."""
    if isinstance(source, bytes):
        return source, None
    if isinstance(source, str) and source.lstrip().startswith("<"):
        return source.encode("utf-8"), None
    path = Path(source)
    return read_file_bytes(path), path


def _xml_parser() -> Any:
    """The lxml parser with every fetch and expansion switched off.

    Explicitly, not left to the version's defaults: no entities, no DTD, no
    network, no huge trees.
    """
    from lxml import etree

    return etree.XMLParser(remove_blank_text=True, resolve_entities=False,
                           no_network=True, load_dtd=False, dtd_validation=False,
                           huge_tree=False)


def parse_xml_strictly(data: bytes, file: Path | None, what: str = "URDF") -> Any:
    """The root element of an XML document, parsed strictly and safely.

    lxml with entities, DTDs, the network and huge trees off
    (:func:`_xml_parser`); a ``<!DOCTYPE>`` is refused. Used for URDF and SRDF.

    Args:
        data: The document's bytes.
        file: Its file, for messages (None for a string).
        what: The kind of document, for messages (``"URDF"``, ``"SRDF"``).

    Raises:
        ModelError: malformed XML or a ``<!DOCTYPE>`` (naming the file and line).
    """
    from lxml import etree

    try:
        tree = etree.ElementTree(etree.fromstring(data, parser=_xml_parser()))
    except etree.XMLSyntaxError as exc:
        raise ModelError(f"not valid XML: {exc.msg}"[:300], file=file,
                         line=getattr(exc, "lineno", None)) from None
    if tree.docinfo.doctype or tree.docinfo.internalDTD is not None:
        raise ModelError("a <!DOCTYPE> (a DTD, entity declarations) is not allowed "
                         f"in a{'n' if what[0] in 'AEFHILMNORSX' else ''} {what}",
                         file=file, line=1)
    return tree.getroot()


def _check_xml(data: bytes, file: Path | None) -> None:
    """Strict XML parse (yourdfpy silently 'recovers' broken XML) and structure."""
    root = parse_xml_strictly(data, file)
    if root.tag != "robot":
        raise ModelError(f"the root element must be <robot>, got "
                         f"<{short_repr(root.tag, 40)}>", file=file,
                         line=root.sourceline)
    if "name" not in root.attrib:
        raise ModelError("<robot> has no 'name' attribute", file=file,
                         line=root.sourceline)
    for tag, cap in (("joint", MAX_URDF_JOINTS), ("link", MAX_URDF_JOINTS + 1)):
        count = len(root.findall(tag))
        if count > cap:
            raise ModelError(f"{count:,} <{tag}> elements; robokin reads at most "
                             f"{cap:,}", file=file, line=root.sourceline)
    for el in root.findall("link"):
        if "name" not in el.attrib:
            raise ModelError("<link> has no 'name' attribute", file=file,
                             line=el.sourceline)
    for el in root.findall("joint"):
        _check_joint_element(el, file)
    for el in root.iter("geometry"):
        if len(el) == 0:
            raise ModelError("empty <geometry>", file=file, field=_field(el, None),
                             line=el.sourceline)
    _check_numbers(root, file)


def _check_joint_element(el: Any, file: Path | None) -> None:
    name = el.get("name")
    if name is None:
        raise ModelError("<joint> has no 'name' attribute", file=file,
                         line=el.sourceline)
    where = f"joint[{name}]"
    jtype = el.get("type")
    if jtype not in JOINT_TYPES:
        raise ModelError(
            f"type must be one of {list(JOINT_TYPES)}, got {short_repr(jtype)}",
            file=file, field=f"{where}.type", line=el.sourceline,
        )
    for tag in ("parent", "child"):
        sub = el.find(tag)
        if sub is None or sub.get("link") is None:
            raise ModelError(f"missing <{tag} link=...>", file=file,
                             field=f"{where}.{tag}", line=el.sourceline)
    if jtype in ("revolute", "prismatic") and el.find("limit") is None:
        raise ModelError(f"a {jtype} joint needs <limit lower=... upper=...>",
                         file=file, field=f"{where}.limit", line=el.sourceline)
    mim = el.find("mimic")
    if mim is not None and mim.get("joint") is None:
        raise ModelError("<mimic> has no 'joint' attribute", file=file,
                         field=f"{where}.mimic", line=mim.sourceline)


def _field(el: Any, key: str | None) -> str:
    """``joint[name].origin.xyz``: the element's owner, tag and attribute."""
    tail = el.tag if key is None else f"{el.tag}.{key}"
    for up in el.iterancestors():
        if up.tag in ("joint", "link") and up.get("name") is not None:
            return f"{up.tag}[{up.get('name')}].{tail}"
    if el.tag in ("joint", "link") and el.get("name") is not None and key is not None:
        return f"{el.tag}[{el.get('name')}].{key}"
    return tail


# Attributes holding numbers: (tag, attribute) -> (count or None for 1 or 3,
# positive required).
_NUMBERS: dict[tuple[str, str], tuple[int | None, bool]] = {
    ("*", "xyz"): (3, False),
    ("*", "rpy"): (3, False),
    ("limit", "lower"): (1, False),
    ("limit", "upper"): (1, False),
    ("limit", "effort"): (1, False),
    ("limit", "velocity"): (1, False),
    ("mimic", "multiplier"): (1, False),
    ("mimic", "offset"): (1, False),
    ("box", "size"): (3, True),
    ("cylinder", "radius"): (1, True),
    ("cylinder", "length"): (1, True),
    ("sphere", "radius"): (1, True),
    ("mesh", "scale"): (None, True),
    ("mass", "value"): (1, False),
    **{("inertia", k): (1, False) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")},
}
# Attributes that are lengths [m]: bounded by MAX_TRANSLATION as in robot files, so
# an import never writes a robot file robokin refuses to load.
_LENGTHS = {("origin", "xyz"), ("box", "size"), ("cylinder", "radius"),
            ("cylinder", "length"), ("sphere", "radius")}
_REQUIRED = {"box": ("size",), "cylinder": ("radius", "length"),
             "sphere": ("radius",), "mesh": ("filename",)}


def _check_numbers(root: Any, file: Path | None) -> None:
    """Check the numeric attributes and the shapes' required attributes.

    Numeric attributes hold the right count of finite numbers (positive sizes),
    shapes their required attributes; errors name the element, field and line.
    """
    for el in root.iter():
        if not isinstance(el.tag, str):
            continue  # comments, processing instructions
        for key in _REQUIRED.get(el.tag, ()):
            if el.get(key) is None and el.getparent() is not None \
                    and el.getparent().tag == "geometry":
                raise ModelError(f"<{el.tag}> needs a '{key}' attribute", file=file,
                                 field=_field(el, key), line=el.sourceline)
        for key, text in el.attrib.items():
            spec = _NUMBERS.get((el.tag, key)) or _NUMBERS.get(("*", key))
            if spec is not None:
                _check_number_text(el, key, text, spec, file)


def _check_number_text(el: Any, key: str, text: str, spec: tuple[int | None, bool],
                       file: Path | None) -> None:
    count, positive = spec
    try:
        values = [float(v) for v in text.split()]
    except ValueError:
        values = None
    expected = (f"{count} number{'s' if count != 1 else ''}" if count
                else "1 or 3 numbers")
    problem = None
    if values is None or (count and len(values) != count) or \
            (count is None and len(values) not in (1, 3)):
        problem = f"expected {expected}"
    elif not all(math.isfinite(v) for v in values):
        problem = f"expected {expected}, finite (no NaN or infinity)"
    elif positive and not all(v > 0 for v in values):
        problem = "expected positive sizes"
    elif _is_length(el, key) and max(abs(v) for v in values) > MAX_TRANSLATION:
        problem = (f"a length beyond the {MAX_TRANSLATION:g} m robokin accepts "
                   "(robokin._validation.MAX_TRANSLATION)")
    if problem:
        raise ModelError(f"<{el.tag} {key}={short_repr(text)}>: {problem}", file=file,
                         field=_field(el, key), line=el.sourceline)


def _is_length(el: Any, key: str) -> bool:
    """Whether ``el``'s attribute ``key`` is a length (an origin, a size, a limit)."""
    if (el.tag, key) in _LENGTHS:
        return True
    parent = el.getparent()
    return el.tag == "limit" and key in ("lower", "upper") and parent is not None \
        and parent.get("type") == "prismatic"


def parse_urdf(source: str | Path | bytes) -> tuple[Any, Path | None]:
    """Parse a URDF file or XML string with yourdfpy, strictly.

    The XML is first parsed by lxml with entities, DTDs and the network off
    (:func:`_xml_parser`); a document with a ``<!DOCTYPE>`` is refused, so
    yourdfpy's own parse of the same bytes has nothing to expand or fetch.

    Returns:
        ``(yourdfpy.Robot, path or None)``.

    Raises:
        ModelError: unreadable or too large file, malformed XML, a DTD, a
            non-finite or malformed number, or a structural error (naming the
            file, the element and the line).
        MissingExtraError: yourdfpy is not installed.
    """
    data, file = read_source(source)
    _check_xml(data, file)
    yourdfpy = _yourdfpy()
    try:
        urdf = yourdfpy.URDF.load(
            io.BytesIO(data),
            build_scene_graph=False,
            build_collision_scene_graph=False,
            load_meshes=False,
            load_collision_meshes=False,
        )
    except (KeyError, AttributeError, ValueError, TypeError, IndexError) as exc:
        raise ModelError(f"malformed URDF: {short_repr(str(exc), 200)}",
                         file=file) from None
    return urdf.robot, file
