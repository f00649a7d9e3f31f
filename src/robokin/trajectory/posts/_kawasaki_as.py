"""Kawasaki AS (E / F controllers), a program file ``NAME.as``.

The file is AS's own save format: ``.PROGRAM NAME()`` .. ``.END`` with the code,
then ``.TRANS`` .. ``.END`` (transformation values: ``name x y z o a t``, [mm],
[deg], ZYZ Euler angles ``R = Rz(O) Ry(A) Rz(T)``) and ``.JOINTS`` .. ``.END``
(joint values: ``#name j1 .. j6`` [deg]). The code sets the tool and base
(``TOOL rk_tool``, ``BASE rk_base``, both declared in ``.TRANS``), the speed (``SPEED
20 ALWAYS``: % for joint moves; ``SPEED 100 MM/S ALWAYS`` for linear ones) and the
accuracy (``ACCURACY 1 ALWAYS`` [mm]: the zone, or 1 mm, AS's default, for exact
stops), then ``JMOVE #rkjN`` and ``LMOVE rkpN``, and ``BREAK`` at the end.

Why Kawasaki: its AS language runs a large share of the world's installed arms
(automotive body shops, spot and arc welding, painting), a family the other
dialects do not cover, and it shows a second way of carrying the configuration: AS
locations hold no configuration flags; a joint move to joint values sets the
branch and a linear move keeps it. So this dialect writes joint moves always as
joint values (``#rkjN``; a Cartesian joint move is written that way too) and
linear moves as transformation values. AS location variables are global on the
controller: the names carry the ``rk`` prefix. Program names: letters, digits,
``_``, a letter first, at most 15 characters.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from robokin.trajectory.posts.base import (
    Move,
    PostProcessor,
    ProgramJob,
    Statement,
    euler_deg,
)

__all__ = ["KawasakiAs"]


@dataclass(frozen=True)
class KawasakiAs(PostProcessor):
    """Kawasaki AS (module docstring)."""

    length_decimals: int = 3
    angle_decimals: int = 4

    name: ClassVar[str] = "kawasaki_as"
    title: ClassVar[str] = "Kawasaki AS"
    name_limit: ClassVar[int] = 15
    max_moves: ClassVar[int] = 9999

    def file_names(self, name: str) -> tuple[str, ...]:
        """``NAME.as``."""
        return (f"{name}.as",)

    def _trans(self, T: np.ndarray, angles: np.ndarray | None = None) -> str:
        o, a, t = euler_deg(T[:3, :3], "ZYZ") if angles is None else angles
        return " ".join([self.length(v) for v in T[:3, 3]]
                        + [self.euler(v) for v in (o, a, t)])

    def header(self, job: ProgramJob) -> list[str]:
        """Comments (``;``), tool and base."""
        lines = self.comment_header(
            job, "; ", "lengths mm, angles deg; locations in .TRANS / .JOINTS below")
        return [*lines, "TOOL rk_tool", "BASE rk_base"]

    def _settings(self, move: Move, previous: Move | None) -> list[str]:
        out = []
        if previous is None or previous.kind != move.kind or previous.speed != move.speed:
            if move.kind == "joint":
                pct = min(100.0, 100.0 * move.speed)
                out.append(f"SPEED {pct:.4g} ALWAYS")
            else:
                out.append(f"SPEED {move.speed:.6g} MM/S ALWAYS")
        accuracy = move.zone if move.zone > 0.0 else 1.0
        before = None if previous is None else (previous.zone if previous.zone > 0 else 1.0)
        if accuracy != before:
            out.append(f"ACCURACY {self.length(accuracy)} ALWAYS")
        return out

    def joint_move(self, job: ProgramJob, move: Move, previous: Move | None
                   ) -> Statement:
        """``JMOVE #rkjN`` (always joint values: module docstring)."""
        t = move.target
        values = " ".join(self.angle(v) for v in t.joints)
        return Statement((*self._settings(move, previous), f"JMOVE #rkj{t.number}"),
                         (f"J\t#rkj{t.number} {values}",))

    def linear_move(self, job: ProgramJob, move: Move, previous: Move | None
                    ) -> Statement:
        """``LMOVE rkpN``."""
        t = move.target
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = t.rotation, t.position
        return Statement((*self._settings(move, previous), f"LMOVE rkp{t.number}"),
                         (f"T\trkp{t.number} {self._trans(T, t.euler('ZYZ'))}",))

    def footer(self, job: ProgramJob) -> list[str]:
        """``BREAK``: wait until the last motion ends."""
        return ["BREAK"]

    def assemble(self, job: ProgramJob, code: list[str], data: list[str]
                 ) -> dict[str, str]:
        """``.PROGRAM``, ``.TRANS``, ``.JOINTS``."""
        trans = [d.split("\t", 1)[1] for d in data if d.startswith("T\t")]
        joints = [d.split("\t", 1)[1] for d in data if d.startswith("J\t")]
        lines = [f".PROGRAM {job.name}()", *("  " + c for c in code), ".END",
                 ".TRANS", f"rk_tool {self._trans(job.tool)}",
                 f"rk_base {self._trans(job.base)}", *trans, ".END",
                 ".JOINTS", *joints, ".END"]
        return {self.file_names(job.name)[0]: "\r\n".join(lines) + "\r\n"}
