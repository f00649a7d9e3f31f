"""KUKA KRL (KR C4 / KR C5, KUKA System Software 8): ``NAME.src`` and ``NAME.dat``.

The ``.src`` holds the motion: ``DEF NAME( )``, ``BAS(#INITMOV, 0)``, the tool and
base frames (``$TOOL``, ``$BASE``), the speeds (``BAS(#VEL_PTP, %)`` for joint
moves, ``$VEL.CP`` [m/s] for linear ones), the approximation (``$APO.CPTP`` [%],
``$APO.CDIS`` [mm]), then ``PTP XJn`` / ``PTP XPn`` / ``LIN XPn`` with ``C_PTP`` /
``C_DIS`` where the move blends, and ``END``. The ``.dat`` declares every target:
``E6AXIS XJn`` (joint values A1..A6 [deg]) and ``E6POS XPn`` (X, Y, Z [mm]; A, B, C
[deg], ``R = Rz(A) Ry(B) Rx(C)``; Status ``S`` and Turn ``T``), and the frames
``RK_TOOL`` (TCP in the flange) and ``RK_BASE`` (the base frame in ``$WORLD``,
assumed to be the robot root), as ``FRAME``.

Blending: linear moves with a zone approximate with ``C_DIS`` at ``$APO.CDIS`` = the
zone [mm]; joint moves with a zone use ``C_PTP`` at ``$APO.CPTP`` =
``ptp_approximation`` [%] (a PTP approximation is a share of the axis travel, not a
distance). KRL names: letters, digits, ``_``, at most 24 characters.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from robokin.exceptions import InputError
from robokin.trajectory.posts.arm_config import kuka_status_turn
from robokin.trajectory.posts.base import (
    Move,
    PostProcessor,
    ProgramJob,
    Statement,
    euler_deg,
)

__all__ = ["KukaKrl"]

_RESERVED = frozenset(
    ["AND", "ANIN", "ANOUT", "B_AND", "B_NOT", "B_OR", "B_EXOR", "BOOL", "BRAKE", "C_DIS", "C_ORI", "C_PTP", "C_VEL", "CASE", "CAST_FROM", "CAST_TO", "CHAR", "CIRC", "CIRC_REL", "CONST", "CONTINUE", "DECL", "DEF", "DEFAULT", "DEFDAT", "DEFFCT", "DELAY", "DIGIN", "DO", "ELSE", "END", "ENDDAT", "ENDFCT", "ENDFOR", "ENDIF", "ENDLOOP", "ENDSWITCH", "ENDWHILE", "ENUM", "EXIT", "EXT", "EXTFCT", "FALSE", "FOR", "GLOBAL", "GOTO", "HALT", "IF", "IMPORT", "INT", "INTERRUPT", "IS", "LIN", "LIN_REL", "LOOP", "MAXIMUM", "MINIMUM", "NOT", "OR", "PRIO", "PTP", "PTP_REL", "PUBLIC", "PULSE", "REAL", "REPEAT", "RETURN", "SEC", "SIGNAL", "STRUC", "SWITCH", "THEN", "TO", "TRIGGER", "TRUE", "UNTIL", "WAIT", "WHEN", "WHILE", "EXOR"])


@dataclass(frozen=True)
class KukaKrl(PostProcessor):
    """KUKA KRL (module docstring).

    Attributes:
        ptp_approximation: ``$APO.CPTP`` [%] for joint moves that blend (``C_PTP``).
        init_bas: Start with ``BAS(#INITMOV, 0)`` (KUKA's standard initialisation;
            needs BAS.SRC, present on every KSS 8 controller).
    """

    ptp_approximation: float = 50.0
    init_bas: bool = True

    name: ClassVar[str] = "kuka_krl"
    title: ClassVar[str] = "KUKA KRL"
    name_limit: ClassVar[int] = 24
    reserved: ClassVar[frozenset[str]] = _RESERVED
    max_moves: ClassVar[int] = 5000

    def __post_init__(self) -> None:
        """Check the options."""
        super().__post_init__()
        if not 0.0 < float(self.ptp_approximation) <= 100.0:
            raise InputError("ptp_approximation", "expected a percentage in (0, 100], "
                             f"got {self.ptp_approximation!r}")

    def file_names(self, name: str) -> tuple[str, ...]:
        """``NAME.src`` and ``NAME.dat``."""
        return (f"{name}.src", f"{name}.dat")

    def frame(self, T: np.ndarray) -> str:
        """A KRL FRAME aggregate ``{X .., Y .., Z .., A .., B .., C ..}``."""
        a, b, c = euler_deg(T[:3, :3], "ZYX")
        x, y, z = T[:3, 3]
        return (f"{{X {self.length(x)},Y {self.length(y)},Z {self.length(z)},"
                f"A {self.euler(a)},B {self.euler(b)},C {self.euler(c)}}}")

    def header(self, job: ProgramJob) -> list[str]:
        """``DEF``, comments, initialisation, frames and approximation parameters."""
        lines = [f"DEF {job.name}( )", *self.comment_header(
            job, "; ", f"lengths mm, angles deg; targets in {job.name}.dat: E6AXIS XJn "
            "(joint values), E6POS XPn (TCP in $BASE, Status S, Turn T)")]
        if self.init_bas:
            lines.append("BAS(#INITMOV, 0)")
        lines += ["$TOOL = RK_TOOL", "$BASE = RK_BASE",
                  f"$APO.CPTP = {self.ptp_approximation:g}"]
        return lines

    def _target_decl(self, move: Move) -> tuple[str, str]:
        """The data name and its declaration."""
        t = move.target
        if move.kind == "joint" and not move.cartesian:
            axes = ",".join(f"A{k + 1} {self.angle(v)}" for k, v in enumerate(t.joints))
            ext = ",".join(f"E{k} 0.0" for k in range(1, 7))
            return f"XJ{t.number}", f"DECL E6AXIS XJ{t.number}={{{axes},{ext}}}"
        s, turn = kuka_status_turn(t.joints, t.behind_axis_1, t.behind_lower_arm)
        a, b, c = t.euler("ZYX")
        x, y, z = t.position
        ext = ",".join(f"E{k} 0.0" for k in range(1, 7))
        return f"XP{t.number}", (
            f"DECL E6POS XP{t.number}={{X {self.length(x)},Y {self.length(y)},"
            f"Z {self.length(z)},A {self.euler(a)},B {self.euler(b)},C {self.euler(c)},"
            f"S {int(s)},T {int(turn)},{ext}}}")

    def joint_move(self, job: ProgramJob, move: Move, previous: Move | None
                   ) -> Statement:
        """``PTP XJn`` (or ``XPn``), ``C_PTP`` when it blends."""
        code = []
        if previous is None or previous.kind != "joint" or previous.speed != move.speed:
            code.append(f"BAS(#VEL_PTP, {_percent(move.speed)})")
        name, decl = self._target_decl(move)
        code.append(f"PTP {name}" + (" C_PTP" if move.zone > 0.0 else ""))
        return Statement(tuple(code), (decl,))

    def linear_move(self, job: ProgramJob, move: Move, previous: Move | None
                    ) -> Statement:
        """``LIN XPn``, ``C_DIS`` when it blends; ``$VEL.CP`` / ``$APO.CDIS`` on change."""
        code = []
        if previous is None or previous.kind != "linear" or previous.speed != move.speed:
            code.append(f"$VEL.CP = {move.speed / 1000.0:.6g}")
        if move.zone > 0.0 and (previous is None or previous.zone != move.zone
                                or previous.kind != "linear"):
            code.append(f"$APO.CDIS = {self.length(move.zone)}")
        name, decl = self._target_decl(move)
        code.append(f"LIN {name}" + (" C_DIS" if move.zone > 0.0 else ""))
        return Statement(tuple(code), (decl,))

    def footer(self, job: ProgramJob) -> list[str]:
        """``END``."""
        return ["END"]

    def assemble(self, job: ProgramJob, code: list[str], data: list[str]
                 ) -> dict[str, str]:
        """The ``.src`` (indented body) and the ``.dat`` (frames, then targets)."""
        head = ["&ACCESS RVP", "&REL 1"]
        body = [code[0]] + ["  " + c for c in code[1:-1]] + [code[-1]]
        dat = head + [f"DEFDAT {job.name}",
                      f"; targets of {job.name}.src (robokin)",
                      f"DECL FRAME RK_TOOL={self.frame(job.tool)}",
                      f"DECL FRAME RK_BASE={self.frame(job.base)}",
                      *data, "ENDDAT"]
        src, datname = self.file_names(job.name)
        return {src: "\r\n".join(head + body) + "\r\n",
                datname: "\r\n".join(dat) + "\r\n"}


def _percent(fraction: float) -> str:
    """A speed fraction as a whole percentage, at least 1."""
    return str(max(1, min(100, int(round(100.0 * fraction)))))
