"""Yaskawa Motoman INFORM (DX100 / DX200 / YRC1000), job file ``NAME.JBI``.

``/JOB``, ``//NAME``, ``//POS`` (``///NPOS``, ``///TOOL``, ``///POSTYPE``, the
position variables ``C00000=..``), ``//INST`` (``///DATE``, ``///COMM``,
``///ATTR``, ``///GROUP1 RB1``), ``NOP``, the moves ``MOVJ Cnnnnn VJ=20.00 PL=0``
(joint, % of the maximum speed) and ``MOVL Cnnnnn V=100.0 PL=3`` (linear [mm/s]),
``END``.

Position variables are pulses when the robot file gives the axes' pulses per degree
(``controller.posts.yaskawa_inform.pulses_per_degree``): ``///POSTYPE PULSE``,
``///PULSE``, one integer per axis (the controller degrees times the ratio,
rounded), every target (``MOVL`` to a pulse variable moves in a line, as taught
jobs do). Without them the variables are Cartesian: ``///RECTAN``, ``///RCONF``
(the configuration: flip, upper/lower arm, front/rear, R/T/S >= 180), ``x, y, z``
[mm], ``Rx, Ry, Rz`` [deg] (fixed-axis rotations, ``R = Rz Ry Rx``) in the robot
frame (``///POSTYPE ROBOT``) or user frame ``user_frame`` when the base frame is not
the robot's; such a job is a relative job (``///ATTR SC,RW,RJ``), which needs the
controller's relative job function. The tool (``///TOOL tool``) and user frame
values are comments: INFORM keeps them in the controller's tool and user frame
files. Blending: ``PL=pl`` (a positioning level 1-8, not a distance) when the move
has a zone, ``PL=0`` otherwise. Job names: capitals, digits, ``_``, at most 32
characters.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import ClassVar

import numpy as np

from robokin.exceptions import InputError
from robokin.trajectory.posts.arm_config import yaskawa_rconf
from robokin.trajectory.posts.base import (
    Move,
    PostProcessor,
    ProgramJob,
    Statement,
    comment_text,
)

__all__ = ["YaskawaInform"]


@dataclass(frozen=True)
class YaskawaInform(PostProcessor):
    """Yaskawa INFORM (module docstring).

    Attributes:
        pulses_per_degree: Encoder pulses per controller degree of axes S, L, U, R,
            B, T (None: Cartesian position variables).
        pl: The positioning level (1-8) of moves that blend.
        tool: The tool number (``///TOOL``).
        user_frame: The user frame number the Cartesian variables use when the
            base frame is not the robot frame.
    """

    pulses_per_degree: tuple[float, ...] | None = None
    pl: int = 3
    tool: int = 1
    user_frame: int = 1

    name: ClassVar[str] = "yaskawa_inform"
    title: ClassVar[str] = "Yaskawa INFORM"
    name_limit: ClassVar[int] = 32
    upper_names: ClassVar[bool] = True
    max_moves: ClassVar[int] = 9999
    int_options: ClassVar[Mapping[str, tuple[int, int]]] = MappingProxyType(
        {"pl": (1, 8), "tool": (0, 63), "user_frame": (1, 63)})

    def __post_init__(self) -> None:
        """Check the options."""
        super().__post_init__()
        if self.pulses_per_degree is not None:
            ppd = tuple(self.pulses_per_degree)
            if len(ppd) != 6 or not all(
                    isinstance(v, (int, float)) and not isinstance(v, bool) and v != 0
                    and np.isfinite(v) for v in ppd):
                raise InputError("pulses_per_degree", "expected six non-zero numbers "
                                 f"(S, L, U, R, B, T), got {ppd!r}")
            object.__setattr__(self, "pulses_per_degree", ppd)

    def file_names(self, name: str) -> tuple[str, ...]:
        """``NAME.JBI``."""
        return (f"{name}.JBI",)

    def _rectan(self, job: ProgramJob) -> bool:
        return self.pulses_per_degree is None

    def _frame(self, job: ProgramJob) -> str:
        """``ROBOT`` or ``USER n``."""
        return "ROBOT" if np.allclose(job.base, np.eye(4), atol=1e-9) \
            else f"USER {self.user_frame}"

    def _mode(self, job: ProgramJob, move: Move) -> tuple[str, ...]:
        """The pseudo-instructions the variable needs: pulse, or rectan + RCONF."""
        if not self._rectan(job):
            return ("PULSE",)
        t = move.target
        rconf = yaskawa_rconf(t.joints, t.behind_axis_1, t.behind_lower_arm)
        return ("RECTAN", ",".join(str(int(v)) for v in rconf))

    def _variable(self, job: ProgramJob, move: Move) -> str:
        t = move.target
        name = f"C{t.number - 1:05d}"
        if not self._rectan(job):
            ppd = np.asarray(self.pulses_per_degree)
            pulses = np.rint(t.joints * ppd).astype(np.int64)
            return f"{name}=" + ",".join(str(int(p)) for p in pulses)
        rz, ry, rx = t.euler("ZYX")
        return (f"{name}=" + ",".join(self.length(v) for v in t.position) + ","
                + ",".join(self.euler(v) for v in (rx, ry, rz)))

    def _data(self, job: ProgramJob, move: Move, previous: Move | None) -> tuple[str, ...]:
        mode = self._mode(job, move)
        before = None if previous is None else self._mode(job, previous)
        out = []
        if mode != before:
            if mode[0] == "PULSE":
                out += ["///POSTYPE PULSE", "///PULSE"]
            else:
                frame = self._frame(job)
                if before is None or before[0] != "RECTAN":
                    if frame != "ROBOT":
                        out.append(f"///USER {self.user_frame}")
                    out += [f"///POSTYPE {frame.split()[0]}", "///RECTAN"]
                out.append(f"///RCONF {mode[1]}")
        out.append(self._variable(job, move))
        return tuple(out)

    def header(self, job: ProgramJob) -> list[str]:
        """Comment lines (``'``) and ``NOP``."""
        tool, base = (" ".join(self.xyz_wpr(T)) for T in (job.tool, job.base))
        lines = [f"'{comment_text(job.description, 60)}",
                 f"'robokin: {comment_text(job.robot, 40)}, profile "
                 f"{comment_text(job.profile, 40)}",
                 f"'TOOL {self.tool}: {tool}"]
        if self._frame(job) != "ROBOT":
            lines.append(f"'USER {self.user_frame}: {base}")
        lines += [f"'note: {comment_text(n, 60)}" for n in job.notes]
        return ["NOP", *lines]

    def joint_move(self, job: ProgramJob, move: Move, previous: Move | None
                   ) -> Statement:
        """``MOVJ Cnnnnn VJ=xx.xx PL=n``."""
        vj = min(100.0, max(0.01, 100.0 * move.speed))
        pl = self.pl if move.zone > 0.0 else 0
        return Statement((f"MOVJ C{move.target.number - 1:05d} VJ={vj:.2f} PL={pl}",),
                         self._data(job, move, previous))

    def linear_move(self, job: ProgramJob, move: Move, previous: Move | None
                    ) -> Statement:
        """``MOVL Cnnnnn V=xxx.x PL=n``."""
        pl = self.pl if move.zone > 0.0 else 0
        return Statement((f"MOVL C{move.target.number - 1:05d} V={max(0.1, move.speed):.1f} "
                          f"PL={pl}",), self._data(job, move, previous))

    def footer(self, job: ProgramJob) -> list[str]:
        """``END``."""
        return ["END"]

    def assemble(self, job: ProgramJob, code: list[str], data: list[str]
                 ) -> dict[str, str]:
        """``//POS`` (counts, tool, variables) and ``//INST`` (attributes, code)."""
        rect = self._rectan(job)
        attr = "SC,RW,RJ" if rect else "SC,RW"
        inst = ["//INST", job.created.strftime("///DATE %Y/%m/%d %H:%M"),
                f"///COMM {comment_text(job.description, 32)}", f"///ATTR {attr}"]
        if rect:
            inst.append(f"///FRAME {self._frame(job)}")
        inst.append("///GROUP1 RB1")
        lines = ["/JOB", f"//NAME {job.name}", "//POS",
                 f"///NPOS {len(job.moves)},0,0,0,0,0", f"///TOOL {self.tool}",
                 *data, *inst, *code]
        return {self.file_names(job.name)[0]: "\r\n".join(lines) + "\r\n"}

