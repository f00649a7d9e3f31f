"""Staubli VAL3 (CS8 / CS9, SRS): an application folder ``NAME/``.

``NAME/NAME.pjx`` (the project: millimetre units, its programs and data file),
``NAME/start.pgx`` (the program, XML with its code in CDATA: ``movej(jPath[k],
tRk[0], mRk[k])`` / ``movel(pPath[k], tRk[0], mRk[k])``, then ``waitEndMove()``),
``NAME/stop.pgx`` and ``NAME/NAME.dtx`` (the data, XML): every target both as
``jointRx`` ``jPath[k]`` (j1..j6 [deg]) and as ``pointRx`` ``pPath[k]`` (x, y, z
[mm]; rx, ry, rz [deg], ``R = Rx Ry Rz``; shoulder lefty / righty, elbow epositive /
enegative, wrist wpositive / wnegative; in the frame ``fRk[0]``), one motion
descriptor ``mdesc`` ``mRk[k]`` per move (joint moves: ``vel`` [%]; linear moves:
``tmax`` [mm/s]; ``blend`` off / joint / cartesian with ``leave`` = ``reach`` = the
zone [mm]), the tool ``tRk[0]`` (in ``flange[0]``) and the frame ``fRk[0]`` (in
``world[0]``). Names: letters, digits, ``_``, a letter first, at most 15
characters.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from robokin.exceptions import InputError
from robokin.trajectory.posts.arm_config import staubli_config
from robokin.trajectory.posts.base import (
    Move,
    PostProcessor,
    ProgramJob,
    Statement,
    euler_deg,
)

__all__ = ["StaubliVal3"]

_XSI = "http://www.w3.org/2001/XMLSchema-instance"
_STOP = """<?xml version="1.0" encoding="utf-8"?>
<Programs xmlns:xsi="{xsi}" xmlns="http://www.staubli.com/robotics/VAL3/Program/2">
  <Program name="stop" access="private">
    <Code><![CDATA[
begin
  resetMotion()
end
]]></Code>
  </Program>
</Programs>
"""


@dataclass(frozen=True)
class StaubliVal3(PostProcessor):
    """Staubli VAL3 (module docstring).

    Attributes:
        rotation_speed: ``rmax`` [deg/s] of the motion descriptors.
        version: The VAL3 version written in the project file.
    """

    length_decimals: int = 3
    angle_decimals: int = 3
    rotation_speed: float = 9999.0
    version: str = "s7.3.1"

    name: ClassVar[str] = "staubli_val3"
    title: ClassVar[str] = "Staubli VAL3"
    name_limit: ClassVar[int] = 15
    max_moves: ClassVar[int] = 10000
    positive_options: ClassVar[tuple[str, ...]] = ("rotation_speed",)

    def __post_init__(self) -> None:
        """Check the options."""
        super().__post_init__()
        if not isinstance(self.version, str) or not self.version.replace(".", "").isalnum():
            raise InputError("version", f"expected a version such as 's7.3.1', got "
                             f"{self.version!r}")

    def file_names(self, name: str) -> tuple[str, ...]:
        """``NAME/NAME.pjx``, ``NAME/start.pgx``, ``NAME/stop.pgx``, ``NAME/NAME.dtx``."""
        return (f"{name}/{name}.pjx", f"{name}/start.pgx", f"{name}/stop.pgx",
                f"{name}/{name}.dtx")

    def _pose_attrs(self, R: np.ndarray, p: np.ndarray, angles: np.ndarray | None = None
                    ) -> str:
        rx, ry, rz = euler_deg(R, "XYZ") if angles is None else angles
        return (f'x="{self.length(p[0])}" y="{self.length(p[1])}" '
                f'z="{self.length(p[2])}" rx="{self.euler(rx)}" ry="{self.euler(ry)}" '
                f'rz="{self.euler(rz)}"')

    def header(self, job: ProgramJob) -> list[str]:
        """Comment lines (``//``)."""
        return self.comment_header(job, "// ",
                                   "lengths mm, angles deg; pPath in fRk[0], tool tRk[0]")

    def _data(self, move: Move) -> tuple[str, ...]:
        t = move.target
        k = t.number - 1
        joints = " ".join(f'j{i + 1}="{self.angle(v)}"' for i, v in enumerate(t.joints))
        shoulder, elbow, wrist = staubli_config(t.joints, t.behind_axis_1)[0]
        point = (f'<Value key="{k}" {self._pose_attrs(t.rotation, t.position, t.euler("XYZ"))} '
                 f'shoulder="{shoulder}" elbow="{elbow}" wrist="{wrist}" '
                 'fatherId="fRk[0]" />')
        blend = "off" if move.zone == 0.0 else ("joint" if move.kind == "joint"
                                                else "cartesian")
        zone = self.length(move.zone)
        if move.kind == "joint":
            vel, tmax = f"{min(100.0, 100.0 * move.speed):.4g}", "99999"
        else:
            vel, tmax = "100", f"{move.speed:.6g}"
        desc = (f'<Value key="{k}" accel="100" vel="{vel}" decel="100" tmax="{tmax}" '
                f'rmax="{self.rotation_speed:g}" blend="{blend}" leave="{zone}" '
                f'reach="{zone}" />')
        return (f"J\t<Value key=\"{k}\" {joints} />", f"P\t{point}", f"M\t{desc}")

    def joint_move(self, job: ProgramJob, move: Move, previous: Move | None
                   ) -> Statement:
        """``movej(jPath[k], tRk[0], mRk[k])`` (``pPath[k]`` for Cartesian)."""
        k = move.target.number - 1
        what = f"pPath[{k}]" if move.cartesian else f"jPath[{k}]"
        return Statement((f"movej({what}, tRk[0], mRk[{k}])",), self._data(move))

    def linear_move(self, job: ProgramJob, move: Move, previous: Move | None
                    ) -> Statement:
        """``movel(pPath[k], tRk[0], mRk[k])``."""
        k = move.target.number - 1
        return Statement((f"movel(pPath[{k}], tRk[0], mRk[{k}])",), self._data(move))

    def footer(self, job: ProgramJob) -> list[str]:
        """``waitEndMove()``."""
        return ["waitEndMove()"]

    def assemble(self, job: ProgramJob, code: list[str], data: list[str]
                 ) -> dict[str, str]:
        """The project, the two programs and the data file."""
        pjx_name, start, stop, dtx_name = self.file_names(job.name)
        pjx = "\n".join([
            '<?xml version="1.0" encoding="utf-8"?>',
            '<Project xmlns="http://www.staubli.com/robotics/VAL3/Project/3">',
            f'  <Parameters version="{self.version}" stackSize="5000" '
            'millimeterUnit="true" />',
            "  <Programs>", '    <Program file="start.pgx" />',
            '    <Program file="stop.pgx" />', "  </Programs>",
            "  <Database>", f'    <Data file="{job.name}.dtx" />', "  </Database>",
            "  <Libraries />", "</Project>"]) + "\n"
        body = "\n".join("  " + c.replace("]]>", "]] >") for c in code)
        pgx = (f'<?xml version="1.0" encoding="utf-8"?>\n<Programs xmlns:xsi="{_XSI}" '
               'xmlns="http://www.staubli.com/robotics/VAL3/Program/2">\n'
               '  <Program name="start" access="public">\n'
               f"    <Code><![CDATA[\nbegin\n{body}\nend\n]]></Code>\n"
               "  </Program>\n</Programs>\n")
        n = len(job.moves)
        groups = {tag: [d.split("\t", 1)[1] for d in data if d.startswith(tag + "\t")]
                  for tag in "JPM"}

        def array(name: str, kind: str, values: list[str], size: int) -> list[str]:
            return ([f'    <Data name="{name}" access="public" xsi:type="array" '
                     f'type="{kind}" size="{size}">']
                    + ["      " + v for v in values] + ["    </Data>"])

        tool = (f'<Value key="0" {self._pose_attrs(job.tool[:3, :3], job.tool[:3, 3])} '
                'fatherId="flange[0]" ioLink="valve1" />')
        frame = (f'<Value key="0" {self._pose_attrs(job.base[:3, :3], job.base[:3, 3])} '
                 'fatherId="world[0]" />')
        dtx = "\n".join([
            '<?xml version="1.0" encoding="utf-8"?>',
            f'<Database xmlns:xsi="{_XSI}" '
            'xmlns="http://www.staubli.com/robotics/VAL3/Data/2">', "  <Datas>",
            *array("fRk", "frame", [frame], 1), *array("tRk", "tool", [tool], 1),
            *array("jPath", "jointRx", groups["J"], n),
            *array("pPath", "pointRx", groups["P"], n),
            *array("mRk", "mdesc", groups["M"], n), "  </Datas>", "</Database>"]) + "\n"
        return {pjx_name: pjx, start: pgx, stop: _STOP.format(xsi=_XSI), dtx_name: dtx}
