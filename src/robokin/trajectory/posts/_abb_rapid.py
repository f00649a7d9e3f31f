r"""ABB RAPID (IRC5 / OmniCore, RobotWare 6 / 7): one module ``NAME.mod``.

``MODULE NAME`` declares the tool (``PERS tooldata rkTool``: TCP in the flange, a
load placeholder), the work object (``TASK PERS wobjdata rkWobj``: the base frame as
its user frame, relative to the world = robot base), custom ``speeddata`` /
``zonedata`` where a move's value is not a predefined one, and every target:
``CONST jointtarget jN`` (axes 1-6 [deg], external axes ``9E+09``) and ``CONST
robtarget pN`` (position [mm], quaternion ``q1..q4 = w x y z``, confdata
``[cf1, cf4, cf6, cfx]``, external axes ``9E+09``). ``PROC main()`` switches the
configuration checks on (``ConfJ \On; ConfL \On``) and moves: ``MoveAbsJ`` to
joint targets, ``MoveJ`` to robtargets, ``MoveL`` along lines, each with
``speeddata`` (``vNNN``) and ``zonedata`` (``zNN`` or ``fine``), ``rkTool \WObj:=
rkWobj``.

Speeds: linear moves use the move's TCP speed; joint moves (which ABB limits by a
TCP speed too) use ``joint_tcp_speed`` [mm/s] times the move's fraction. A speed or
zone equal to a predefined one (``v5`` .. ``v7000``, ``z0`` .. ``z200``) uses it;
others are declared (``rkV123``, ``rkZ2_5``). RAPID identifiers: a letter, then
letters, digits and ``_``, at most 32 characters.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from robokin.trajectory.posts.arm_config import abb_confdata
from robokin.trajectory.posts.base import (
    Move,
    PostProcessor,
    ProgramJob,
    Statement,
    quaternion_wxyz,
)

__all__ = ["AbbRapid"]

#: Predefined speeddata v_tcp [mm/s] (RAPID reference, "speeddata").
SPEEDS = (5, 10, 20, 30, 40, 50, 60, 80, 100, 150, 200, 300, 400, 500, 600, 800, 1000,
          1500, 2000, 2500, 3000, 4000, 5000, 6000, 7000)
#: Predefined zonedata pzone_tcp [mm] (RAPID reference, "zonedata").
ZONES = (0, 1, 5, 10, 15, 20, 30, 40, 50, 60, 80, 100, 150, 200)
_EXT = "[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]"
_RESERVED = frozenset(
    ["ALIAS", "AND", "BACKWARD", "CASE", "CONNECT", "CONST", "DEFAULT", "DIV", "DO", "ELSE", "ELSEIF", "ENDFOR", "ENDFUNC", "ENDIF", "ENDMODULE", "ENDPROC", "ENDRECORD", "ENDTEST", "ENDTRAP", "ENDWHILE", "ERROR", "EXIT", "FALSE", "FOR", "FROM", "FUNC", "GOTO", "IF", "INOUT", "LOCAL", "MOD", "MODULE", "NOSTEPIN", "NOT", "NOVIEW", "OR", "PERS", "PROC", "RAISE", "READONLY", "RECORD", "RETRY", "RETURN", "STEP", "SYSMODULE", "TEST", "THEN", "TO", "TRAP", "TRUE", "TRYNEXT", "UNDO", "VAR", "VIEWONLY", "WHILE", "WITH", "XOR"])


@dataclass(frozen=True)
class AbbRapid(PostProcessor):
    """ABB RAPID (module docstring).

    Attributes:
        joint_tcp_speed: TCP speed [mm/s] of a joint move at the full fraction 1.0.
        tool_mass: ``tooldata.tload.mass`` [kg]: a placeholder (RAPID needs a
            mass > 0); identify the real load (LoadIdentify) before running.
        orientation_speed: ``v_ori`` [deg/s] of declared speeddata.
    """

    joint_tcp_speed: float = 1000.0
    tool_mass: float = 1.0
    orientation_speed: float = 500.0

    name: ClassVar[str] = "abb_rapid"
    title: ClassVar[str] = "ABB RAPID"
    name_limit: ClassVar[int] = 32
    reserved: ClassVar[frozenset[str]] = _RESERVED
    max_moves: ClassVar[int] = 10000
    positive_options: ClassVar[tuple[str, ...]] = (
        "joint_tcp_speed", "tool_mass", "orientation_speed")

    def file_names(self, name: str) -> tuple[str, ...]:
        """``NAME.mod``."""
        return (f"{name}.mod",)

    # ------------------------------------------------------------ data values
    def _pose(self, T: np.ndarray) -> str:
        """``[[x,y,z],[q1,q2,q3,q4]]`` (a pose)."""
        return f"[{self._trans(T[:3, 3])},{self._quat(quaternion_wxyz(T[:3, :3]))}]"

    def _trans(self, p: np.ndarray) -> str:
        return "[" + ",".join(self.length(v) for v in p) + "]"

    def _quat(self, wxyz: np.ndarray) -> str:
        return "[" + ",".join(self.quaternion(wxyz, self.angle_decimals + 4)) + "]"

    def speed_name(self, mm_s: float) -> str:
        """``vNNN`` when predefined, else the declared ``rkVNNN``."""
        v = round(float(mm_s), 3)
        if v in SPEEDS:
            return f"v{int(v)}"
        return "rkV" + f"{v:g}".replace(".", "_")

    def zone_name(self, mm: float) -> str:
        """``fine``, ``zNN`` when predefined, else the declared ``rkZNN``."""
        z = round(float(mm), 3)
        if z == 0.0:
            return "fine"
        if z in ZONES:
            return f"z{int(z)}"
        return "rkZ" + f"{z:g}".replace(".", "_")

    def _speed(self, move: Move) -> float:
        return move.speed * self.joint_tcp_speed if move.kind == "joint" else move.speed

    def _declarations(self, job: ProgramJob) -> list[str]:
        """Custom speeddata and zonedata the moves need."""
        out = []
        for v in sorted({round(self._speed(m), 3) for m in job.moves}):
            if self.speed_name(v).startswith("rk"):
                out.append(f"CONST speeddata {self.speed_name(v)} := [{v:g},"
                           f"{self.orientation_speed:g},5000,1000];")
        for z in sorted({round(m.zone, 3) for m in job.moves}):
            if self.zone_name(z).startswith("rk"):
                # pzone_tcp, pzone_ori, pzone_eax, zone_ori, zone_leax, zone_reax
                out.append(f"CONST zonedata {self.zone_name(z)} := [FALSE,{z:g},"
                           f"{1.5 * z:g},{1.5 * z:g},{0.15 * z:g},{1.5 * z:g},"
                           f"{0.15 * z:g}];")
        return out

    # ------------------------------------------------------------------ parts
    def header(self, job: ProgramJob) -> list[str]:
        """Comments, ``PROC main()`` and the configuration checks."""
        lines = self.comment_header(job, "! ", "lengths mm, angles deg; robtargets in "
                                    "rkWobj, quaternion q1..q4 = w x y z, confdata "
                                    "[cf1,cf4,cf6,cfx]")
        return [*lines, "PROC main()", "  ConfJ \\On;", "  ConfL \\On;"]

    def _call(self, instr: str, name: str, move: Move) -> str:
        return (f"  {instr} {name}, {self.speed_name(self._speed(move))}, "
                f"{self.zone_name(move.zone)}, rkTool \\WObj:=rkWobj;")

    def _robtarget(self, move: Move) -> str:
        t = move.target
        cf = abb_confdata(t.joints, t.behind_axis_1, t.behind_lower_arm)
        return (f"CONST robtarget p{t.number} := [{self._trans(t.position)},"
                f"{self._quat(t.quaternion())},[{','.join(str(int(c)) for c in cf)}],{_EXT}];")

    def joint_move(self, job: ProgramJob, move: Move, previous: Move | None
                   ) -> Statement:
        """``MoveAbsJ jN`` (joint values) or ``MoveJ pN`` (a robtarget)."""
        t = move.target
        if move.cartesian:
            return Statement((self._call("MoveJ", f"p{t.number}", move),),
                             (self._robtarget(move),))
        axes = ",".join(self.angle(v) for v in t.joints)
        return Statement((self._call("MoveAbsJ", f"j{t.number}", move),),
                         (f"CONST jointtarget j{t.number} := [[{axes}],{_EXT}];",))

    def linear_move(self, job: ProgramJob, move: Move, previous: Move | None
                    ) -> Statement:
        """``MoveL pN``."""
        return Statement((self._call("MoveL", f"p{move.target.number}", move),),
                         (self._robtarget(move),))

    def footer(self, job: ProgramJob) -> list[str]:
        """``ENDPROC``."""
        return ["ENDPROC"]

    def assemble(self, job: ProgramJob, code: list[str], data: list[str]
                 ) -> dict[str, str]:
        """The module: declarations first, then the routine."""
        mass = f"{self.tool_mass:g}"
        decl = [f"PERS tooldata rkTool := [TRUE,{self._pose(job.tool)},"
                f"[{mass},[0,0,0.001],[1,0,0,0],0,0,0]];",
                "TASK PERS wobjdata rkWobj := [FALSE,TRUE,\"\","
                f"{self._pose(job.base)},[[0,0,0],[1,0,0,0]]];",
                *self._declarations(job), *data]
        n_comments = next(i for i, c in enumerate(code) if c == "PROC main()")
        lines = ([f"MODULE {job.name}"] + ["  " + c for c in code[:n_comments]]
                 + ["  " + d for d in decl] + [""]
                 + ["  " + c for c in code[n_comments:]] + ["ENDMODULE"])
        return {self.file_names(job.name)[0]: "\n".join(lines) + "\n"}
