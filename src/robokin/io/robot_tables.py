"""Robot tables as people read them: every arm in millimetres and degrees.

``robokin show`` and ``Robot._repr_html_`` show a robot's joint rows in one set
of units, whatever units its file declares (the Panda's file is in metres and
radians, the UR5's in millimetres and degrees).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

__all__ = ["MM_PER_M", "joint_rows_mm_deg"]

#: Millimetres per metre.
MM_PER_M = 1000.0


def joint_rows_mm_deg(doc: dict[str, Any]) -> tuple[list[str], list[Sequence[Any]]]:
    """The joint rows of a robot document in mm and degrees, whatever its units.

    Args:
        doc: A robot-file document (:func:`robokin.io.robot_files.document_from_robot`).

    Returns:
        ``(keys, rows)``: every key used by a row, and per row its values in key
        order (None where absent): lengths in mm, angles in degrees, limits and
        ``depends_offset`` by the joint's kind, a list as text; other values as
        they are.
    """
    units = doc.get("units") or {}
    to_m = 1e-3 if units.get("length") == "mm" else 1.0
    to_rad = math.pi / 180.0 if units.get("angle") == "deg" else 1.0
    length = to_m * MM_PER_M
    angle = to_rad * 180.0 / math.pi

    def scale(row: dict[str, Any], key: str) -> float:
        prismatic = row.get("joint") == "prismatic"
        if key in ("a", "d"):
            return length
        if key in ("alpha", "theta"):
            return angle
        if key == "value":
            return angle if str(row.get("op", "r")).startswith("r") else length
        if key in ("limits", "depends_offset"):
            return length if prismatic else angle
        return 1.0

    keys: list[str] = []
    for row in doc["joints"]:
        keys += [k for k in row if k not in keys]
    rows: list[Sequence[Any]] = []
    for row in doc["joints"]:
        out: list[Any] = []
        for k in keys:
            v = row.get(k)
            if isinstance(v, bool) or k == "sign":
                out.append(v)
            elif isinstance(v, int | float):
                out.append(float(v) * scale(row, k))
            elif isinstance(v, list | tuple) and all(isinstance(x, int | float)
                                                      for x in v):
                out.append("[" + ", ".join(f"{float(x) * scale(row, k):.10g}"
                                           for x in v) + "]")
            else:
                out.append(v)
        rows.append(out)
    return keys, rows
