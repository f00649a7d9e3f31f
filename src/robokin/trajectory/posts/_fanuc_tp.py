"""FANUC TP (R-30iA / R-30iB / R-30iB Plus), ASCII source ``NAME.ls``.

``/PROG NAME``, ``/ATTR`` (owner, dates, ``DEFAULT_GROUP``), ``/MN`` with numbered
lines: the frame numbers (``UFRAME_NUM``, ``UTOOL_NUM``), then ``J P[n] 20% FINE``
(joint moves, % of the maximum joint speed) and ``L P[n] 100mm/sec CNT50`` (linear
moves), ``/POS`` with every position (``GP1``, ``UF``/``UT``): joint
representation ``J1= .. deg`` for joint targets, Cartesian ``X Y Z`` [mm], ``W P R``
[deg] (fixed-axis rotations about x, y, z: ``R = Rz(R) Ry(P) Rx(W)``) with the
configuration string ``CONFIG : 'N U T, 0, 0, 0'`` for linear moves and Cartesian
joint moves, and ``/END``.

Frames: the positions name user frame ``user_frame`` and tool ``user_tool``; their
values are written as comments, or, with ``set_frames=True``, set by the program
through position register ``frame_register`` (``PR[..]=LPOS-LPOS``, the six
elements, ``UTOOL[..]=PR[..]``, ``UFRAME[..]=PR[..]``). Blending: a move with a zone
ends with ``CNT`` ``cnt`` (FANUC's CNT is a 0-100 rounding, not a distance), else
``FINE``. The ``.ls`` is the text form: the controller loads it after conversion to
``.tp`` (Roboguide, or the ASCII Upload option). Program names: capitals, digits,
``_``, a letter first, at most 36 characters (R-30iB; older controllers 8).
"""

from __future__ import annotations

import textwrap
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import ClassVar

from robokin.exceptions import InputError
from robokin.trajectory.posts.arm_config import fanuc_config
from robokin.trajectory.posts.base import (
    Move,
    PostProcessor,
    ProgramJob,
    Statement,
    comment_text,
)

__all__ = ["FanucTp"]


@dataclass(frozen=True)
class FanucTp(PostProcessor):
    """FANUC TP (module docstring).

    Attributes:
        cnt: The CNT value (0-100) of moves that blend.
        user_frame: The user frame number (``UF``, 0 = world) of the positions.
        user_tool: The tool frame number (``UT``, 1-10).
        set_frames: Set the tool and user frame values in the program (through a
            position register) instead of writing them as comments.
        frame_register: The position register used by ``set_frames``.
        turn_axes: The axes whose turn numbers the configuration holds
            (``$SCR_GRP[1].$TURN_AXIS``).
    """

    length_decimals: int = 3
    angle_decimals: int = 3
    cnt: int = 50
    user_frame: int = 1
    user_tool: int = 1
    set_frames: bool = False
    frame_register: int = 90
    turn_axes: tuple[int, int, int] = (4, 5, 6)

    name: ClassVar[str] = "fanuc_tp"
    title: ClassVar[str] = "FANUC TP"
    name_limit: ClassVar[int] = 36
    upper_names: ClassVar[bool] = True
    max_moves: ClassVar[int] = 9999
    int_options: ClassVar[Mapping[str, tuple[int, int]]] = MappingProxyType(
        {"cnt": (0, 100), "user_frame": (0, 9), "user_tool": (1, 10),
         "frame_register": (1, 100)})

    def __post_init__(self) -> None:
        """Check the options."""
        super().__post_init__()
        axes = tuple(self.turn_axes)
        if len(axes) != 3 or any(a not in range(1, 7) for a in axes):
            raise InputError("turn_axes", f"expected three axes 1..6, got {axes!r}")
        object.__setattr__(self, "turn_axes", axes)

    def file_names(self, name: str) -> tuple[str, ...]:
        """``NAME.ls``."""
        return (f"{name}.ls",)

    def _frame_lines(self, job: ProgramJob) -> list[str]:
        tool, base = self.xyz_wpr(job.tool), self.xyz_wpr(job.base)
        if not self.set_frames:
            return [f"! UTOOL[{self.user_tool}] X Y Z W P R:",
                    "!  " + " ".join(tool[:3]), "!  " + " ".join(tool[3:]),
                    f"! UFRAME[{self.user_frame}] X Y Z W P R:",
                    "!  " + " ".join(base[:3]), "!  " + " ".join(base[3:])]
        pr = self.frame_register
        out = []
        for values, target in ((tool, f"UTOOL[{self.user_tool}]"),
                               (base, f"UFRAME[{self.user_frame}]")):
            if target.startswith("UFRAME") and self.user_frame == 0:
                continue
            out.append(f"PR[{pr}]=LPOS-LPOS")
            out += [f"PR[{pr},{k + 1}]={v}" for k, v in enumerate(values)]
            out.append(f"{target}=PR[{pr}]")
        return out

    def header(self, job: ProgramJob) -> list[str]:
        """Comments (at most 32 characters each), frames and frame numbers."""
        words = [f"{comment_text(job.description)}",
                 f"robokin: {comment_text(job.robot)}",
                 f"profile {comment_text(job.profile)}"] + [
                     f"note: {comment_text(n)}" for n in job.notes]
        words = [w.replace(";", ",").replace('"', "'") for w in words]
        lines = ["!" + part for text in words
                 for part in textwrap.wrap(text, 31, break_on_hyphens=False) or [""]]
        return [*lines, *self._frame_lines(job), f"UFRAME_NUM={self.user_frame}",
                f"UTOOL_NUM={self.user_tool}"]

    def _position(self, move: Move) -> list[str]:
        t = move.target
        head = [f"P[{t.number}]{{", "   GP1:"]
        frames = f"\tUF : {self.user_frame}, UT : {self.user_tool},"
        if move.kind == "joint" and not move.cartesian:
            j = [self.angle(v, 9) for v in t.joints]
            return head + [frames + "\t",
                           f"\tJ1={j[0]} deg,\tJ2={j[1]} deg,\tJ3={j[2]} deg,",
                           f"\tJ4={j[3]} deg,\tJ5={j[4]} deg,\tJ6={j[5]} deg", "};"]
        conf = fanuc_config(t.joints, t.behind_axis_1, t.behind_lower_arm,
                            self.turn_axes)[0]
        r, p, w = t.euler("ZYX")
        x, y, z = (self.length(v) for v in t.position)
        w, p, r = (self.euler(v) for v in (w, p, r))
        return head + [f"{frames}\t\tCONFIG : '{conf}',",
                       f"\tX = {x:>9}  mm,\tY = {y:>9}  mm,\tZ = {z:>9}  mm,",
                       f"\tW = {w:>9} deg,\tP = {p:>9} deg,\tR = {r:>9} deg", "};"]

    def _term(self, move: Move) -> str:
        return f"CNT{self.cnt}" if move.zone > 0.0 else "FINE"

    def joint_move(self, job: ProgramJob, move: Move, previous: Move | None
                   ) -> Statement:
        """``J P[n] NN% FINE|CNTn``."""
        pct = max(1, min(100, int(round(100.0 * move.speed))))
        return Statement((f"@J P[{move.target.number}] {pct}% {self._term(move)}",),
                         tuple(self._position(move)))

    def linear_move(self, job: ProgramJob, move: Move, previous: Move | None
                    ) -> Statement:
        """``L P[n] NNmm/sec FINE|CNTn``."""
        mm_s = max(1, int(round(move.speed)))
        return Statement((f"@L P[{move.target.number}] {mm_s}mm/sec {self._term(move)}",),
                         tuple(self._position(move)))

    def footer(self, job: ProgramJob) -> list[str]:
        """Nothing: ``/POS`` and ``/END`` follow in :meth:`assemble`."""
        return []

    def assemble(self, job: ProgramJob, code: list[str], data: list[str]
                 ) -> dict[str, str]:
        """``/PROG``, ``/ATTR``, numbered ``/MN`` lines, ``/POS``, ``/END``."""
        stamp = job.created.strftime("DATE %y-%m-%d  TIME %H:%M:%S")
        attr = ["/ATTR", "OWNER\t\t= MNEDITOR;", 'COMMENT\t\t= "robokin";',
                "PROG_SIZE\t= 0;", f"CREATE\t\t= {stamp};", f"MODIFIED\t= {stamp};",
                "FILE_NAME\t= ;", "VERSION\t\t= 0;", f"LINE_COUNT\t= {len(code)};",
                "MEMORY_SIZE\t= 0;", "PROTECT\t\t= READ_WRITE;",
                "TCD:  STACK_SIZE\t= 0,", "      TASK_PRIORITY\t= 50,",
                "      TIME_SLICE\t= 0,", "      BUSY_LAMP_OFF\t= 0,",
                "      ABORT_REQUEST\t= 0,", "      PAUSE_REQUEST\t= 0;",
                "DEFAULT_GROUP\t= 1,*,*,*,*;", "CONTROL_CODE\t= 00000000 00000000;"]
        mn = []
        for k, line in enumerate(code, start=1):
            if line.startswith("@"):  # a motion line: its letter right after the colon
                mn.append(f"{k:4d}:{line[1:]}    ;")
            else:
                mn.append(f"{k:4d}:  {line} ;")
        lines = [f"/PROG  {job.name}", *attr, "/MN", *mn, "/POS", *data, "/END"]
        return {self.file_names(job.name)[0]: "\r\n".join(lines) + "\r\n"}
