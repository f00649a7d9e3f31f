"""The post processor: a small declared class that turns a program job into files.

A :class:`ProgramJob` is what every dialect writes: a program name, the robot's tool
and base frames, and a list of :class:`Move` records (a joint or a linear move to a
:class:`Target`, with a speed and a blending zone). The target holds both the
controller's joint values and the Cartesian pose, so each dialect writes whichever
its language uses. Units are the controllers': degrees and millimetres, joint
values in the controller's convention (the robot file's ``controller:`` section
applied).

A post processor is a frozen dataclass deriving :class:`PostProcessor`. Its fields
are its options (number formatting and dialect settings, e.g. FANUC's ``cnt``); its
class attributes declare the dialect (``name``, ``title``, name rules, target
limit); its methods write the parts:

- :meth:`~PostProcessor.file_names` -- the files of a program called ``name``;
- :meth:`~PostProcessor.header` / :meth:`~PostProcessor.footer` -- the code before
  and after the moves;
- :meth:`~PostProcessor.joint_move` / :meth:`~PostProcessor.linear_move` -- one
  :class:`Statement` per move: code lines and data lines (declarations);
- :meth:`~PostProcessor.assemble` -- the files' texts from the code and data lines.

:meth:`~PostProcessor.render` runs them in that order. Register a new dialect with
:func:`robokin.trajectory.posts.register` or the ``robokin.post_processors`` entry
point group (docs/controllers.md).
"""

from __future__ import annotations

import math
import re
import warnings
from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from datetime import datetime
from types import MappingProxyType
from typing import Any, ClassVar, Literal

import numpy as np
import numpy.typing as npt

from robokin._validation import frozen_floats
from robokin.exceptions import InputError
from robokin.spatial import quaternion_from_matrix, rpy_from_matrix

__all__ = [
    "Move",
    "PostProcessor",
    "ProgramJob",
    "Statement",
    "Target",
    "comment_text",
    "euler_deg",
    "quaternion_wxyz",
]

MoveKind = Literal["joint", "linear"]


@dataclass(frozen=True, eq=False)
class Target:
    """A place a move goes to, in the controller's units and convention.

    Attributes:
        number: 1-based number of the target in its program.
        joints: Controller joint values (n,) [deg for revolute, mm for prismatic]:
            the profile's order, signs and zeros applied.
        position: TCP position (3,) [mm] in the program's base (work-object) frame.
        rotation: TCP orientation (3, 3) in the base frame.
        behind_axis_1: The wrist point is behind axis 1
            (:mod:`~robokin.trajectory.posts.arm_config`).
        behind_lower_arm: The elbow point is behind the line through axes 2 and 3.
        orientations: The rotation's Euler angles [deg] by sequence (``"ZYX"``,
            ``"XYZ"``, ``"ZYZ"``) and ``"wxyz"``, its quaternion, computed for a whole
            program at once by :func:`~robokin.trajectory.posts.program_job`; those
            missing are computed when asked for (:meth:`euler`,
            :meth:`quaternion`).
    """

    number: int
    joints: npt.NDArray[np.float64]
    position: npt.NDArray[np.float64]
    rotation: npt.NDArray[np.float64]
    behind_axis_1: bool = False
    behind_lower_arm: bool = False
    orientations: Mapping[str, npt.NDArray[np.float64]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        """Freeze the arrays."""
        joints = np.array(self.joints, dtype=np.float64).reshape(-1)
        for key, value, shape in (("joints", joints, joints.shape),
                                  ("position", self.position, (3,)),
                                  ("rotation", self.rotation, (3, 3))):
            object.__setattr__(self, key, frozen_floats(value, key, shape=shape))
        object.__setattr__(self, "orientations", MappingProxyType(
            {k: frozen_floats(v, k, shape=np.shape(v))
             for k, v in dict(self.orientations).items()}))

    def euler(self, sequence: Literal["ZYX", "XYZ", "ZYZ"]) -> np.ndarray:
        """The rotation's Euler angles (3,) [deg] (:func:`euler_deg`)."""
        got = self.orientations.get(sequence)
        return euler_deg(self.rotation, sequence) if got is None else got

    def quaternion(self) -> np.ndarray:
        """The rotation's unit quaternion ``(w, x, y, z)``, ``w >= 0``."""
        got = self.orientations.get("wxyz")
        return quaternion_wxyz(self.rotation) if got is None else got


@dataclass(frozen=True)
class Move:
    """One motion statement.

    Attributes:
        kind: ``"joint"`` (PTP / MoveJ / J / MOVJ / movej: interpolated in joint
            space) or ``"linear"`` (LIN / MoveL / L / MOVL / movel: a straight TCP
            line).
        target: Where it goes.
        speed: Joint moves: a fraction (0, 1] of the axes' maximum speed; linear
            moves: the TCP speed [mm/s].
        zone: Blending distance [mm]; 0 stops exactly at the target (fine / FINE /
            PL=0). Dialects whose blending is not a distance map it (each dialect's
            docstring says how).
        cartesian: For joint moves: write the target as a Cartesian pose with the
            configuration flags rather than as joint values (linear moves are always
            Cartesian where the language has a choice).
    """

    kind: MoveKind
    target: Target
    speed: float
    zone: float = 0.0
    cartesian: bool = False

    def __post_init__(self) -> None:
        """Check the kind, speed and zone."""
        if self.kind not in ("joint", "linear"):
            raise InputError("kind", f"expected 'joint' or 'linear', got {self.kind!r}")
        if not (math.isfinite(self.speed) and self.speed > 0.0):
            raise InputError("speed", f"expected a positive speed, got {self.speed}")
        if self.kind == "joint" and self.speed > 1.0:
            raise InputError("speed", "joint moves take a fraction of the maximum "
                             f"speed in (0, 1], got {self.speed}")
        if not (math.isfinite(self.zone) and self.zone >= 0.0):
            raise InputError("zone", f"expected a blending distance >= 0 mm, got {self.zone}")


@dataclass(frozen=True, eq=False)
class ProgramJob:
    """Everything a dialect writes.

    Attributes:
        name: The program name, already legal for the dialect.
        moves: The motion statements, in order (at least one; the first is a joint
            move to joint values, as every controller needs a defined start).
        tool: The TCP in the controller's flange frame (4, 4) [mm].
        base: The base (work-object) frame in the controller's robot root frame
            (4, 4) [mm]; the targets' poses are in it.
        robot: The robot's name.
        profile: The controller profile's name.
        description: One line: what the program holds.
        notes: Remarks written as comments (and returned to the caller).
        created: When the program was made (dialects that date their files).
    """

    name: str
    moves: tuple[Move, ...]
    tool: npt.NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    base: npt.NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    robot: str = "robot"
    profile: str = "default"
    description: str = ""
    notes: tuple[str, ...] = ()
    created: datetime = field(default_factory=lambda: datetime(2000, 1, 1))

    def __post_init__(self) -> None:
        """Check the moves; freeze the frames."""
        object.__setattr__(self, "moves", tuple(self.moves))
        object.__setattr__(self, "notes", tuple(self.notes))
        if not self.moves:
            raise InputError("moves", "a program needs at least one move")
        object.__setattr__(self, "tool", frozen_floats(self.tool, "tool", shape=(4, 4)))
        object.__setattr__(self, "base", frozen_floats(self.base, "base", shape=(4, 4)))

    @property
    def targets(self) -> tuple[Target, ...]:
        """The moves' targets, in order."""
        return tuple(m.target for m in self.moves)


@dataclass(frozen=True)
class Statement:
    """What one move adds: code lines (in the program) and data lines (declarations)."""

    code: tuple[str, ...] = ()
    data: tuple[str, ...] = ()


def euler_deg(rotation: npt.ArrayLike, sequence: Literal["ZYX", "XYZ", "ZYZ"]
              ) -> np.ndarray:
    """Euler angles [deg] of a rotation in a vendor's convention.

    Args:
        rotation: A rotation matrix (3, 3) or (..., 3, 3).
        sequence: ``"ZYX"`` (intrinsic: KUKA A, B, C and, reversed, FANUC / Yaskawa
            W, P, R about the fixed x, y, z), ``"XYZ"`` (intrinsic: Staubli rx, ry,
            rz) or ``"ZYZ"`` (Kawasaki O, A, T); scipy's upper-case (intrinsic)
            sequences.

    Returns:
        The three angles (..., 3) [deg] in the sequence's order; at a gimbal lock
        the split between the first and third is scipy's (the matrix is still
        reproduced).
    """
    R = np.asarray(rotation, dtype=np.float64)
    if sequence == "ZYX":
        rpy = rpy_from_matrix(_as_pose(R))
        return np.degrees(rpy[..., ::-1])
    from scipy.spatial.transform import Rotation

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # gimbal lock: still exact
        flat = Rotation.from_matrix(R.reshape(-1, 3, 3)).as_euler(sequence, degrees=True)
    return flat.reshape(R.shape[:-2] + (3,))


def _as_pose(R: np.ndarray) -> np.ndarray:
    T = np.zeros(R.shape[:-2] + (4, 4))
    T[..., :3, :3] = R
    T[..., 3, 3] = 1.0
    return T


def quaternion_wxyz(rotation: npt.ArrayLike) -> np.ndarray:
    """Unit quaternion ``(w, x, y, z)`` of a rotation, with ``w >= 0`` (ABB q1..q4)."""
    q = quaternion_from_matrix(_as_pose(np.asarray(rotation, dtype=np.float64)))
    return np.where(q[..., :1] < 0.0, -q, q)


_NAME_REST = re.compile(r"[^A-Za-z0-9_]")


@dataclass(frozen=True)
class PostProcessor(ABC):
    """Abstract post processor (module docstring). Fields are the options.

    Attributes:
        length_decimals: Decimals of lengths [mm] in the files.
        angle_decimals: Decimals of angles [deg] (and quaternion digits - 1 for ABB).
    """

    length_decimals: int = 3
    angle_decimals: int = 4

    #: Registry name, e.g. ``"kuka_krl"``.
    name: ClassVar[str] = ""
    #: One line for people: the language and controllers.
    title: ClassVar[str] = ""
    #: Longest legal program name (characters).
    name_limit: ClassVar[int] = 24
    #: Whether program names are written in capitals.
    upper_names: ClassVar[bool] = False
    #: Words the language reserves (a program name that is one gets a prefix).
    reserved: ClassVar[frozenset[str]] = frozenset()
    #: Most moves a program may hold (more: decimate, or split the path).
    max_moves: ClassVar[int] = 100_000
    #: Axes the dialect drives.
    axes: ClassVar[int] = 6
    #: The dialect's integer options and their ranges ``{field: (lowest, highest)}``
    #: (checked after the precision options, in this order).
    int_options: ClassVar[Mapping[str, tuple[int, int]]] = MappingProxyType({})
    #: The dialect's options that must be positive numbers.
    positive_options: ClassVar[tuple[str, ...]] = ()

    def __post_init__(self) -> None:
        """Check the options: precision, :attr:`int_options`, :attr:`positive_options`."""
        ranges = {"length_decimals": (0, 9), "angle_decimals": (0, 9), **self.int_options}
        for f, (lo, hi) in ranges.items():
            v = getattr(self, f)
            if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
                raise InputError(f, f"expected an integer {lo}..{hi}, got {v!r}")
        for f in self.positive_options:
            v = getattr(self, f)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not v > 0:
                raise InputError(f, f"expected a positive number, got {v!r}")

    @classmethod
    def options(cls) -> tuple[str, ...]:
        """The option names (the dataclass fields)."""
        return tuple(f.name for f in fields(cls))

    # ------------------------------------------------------------ names and files
    def program_name(self, requested: str) -> tuple[str, str | None]:
        """A legal program name made from ``requested``, and a note when it changed.

        Letters, digits and ``_`` are kept (runs of anything else become one ``_``), the name
        starts with a letter (``P`` is put in front otherwise), is cut to
        :attr:`name_limit` and capitalised where the dialect wants it.
        """
        name = re.sub("_+", "_", _NAME_REST.sub("_", requested)).strip("_") or "robokin"
        if not name[0].isalpha():
            name = "P" + name
        name = name[: self.name_limit]
        if self.upper_names:
            name = name.upper()
        if name.upper() in self.reserved:
            name = ("RK_" + name)[: self.name_limit]
        if name == requested:
            return name, None
        return name, (f"program name {requested!r} is not a legal {self.title} name "
                      f"(letters, digits and _, a letter first, at most "
                      f"{self.name_limit} characters): written as {name!r}")

    @abstractmethod
    def file_names(self, name: str) -> tuple[str, ...]:
        """The files of a program called ``name`` (relative paths, '/'-separated)."""

    # ------------------------------------------------------------------ the parts
    def comment_header(self, job: ProgramJob, prefix: str, units: str) -> list[str]:
        """The comment lines most dialects open with, each starting with ``prefix``.

        The description, what wrote the program for which robot and profile,
        ``units`` (the units and where the targets are), then one line per note.
        """
        lines = [f"{prefix}{comment_text(job.description)}",
                 f"{prefix}generated by robokin for {comment_text(job.robot)}, "
                 f"controller profile '{comment_text(job.profile)}'",
                 f"{prefix}{units}"]
        return lines + [f"{prefix}note: {comment_text(n)}" for n in job.notes]

    @abstractmethod
    def header(self, job: ProgramJob) -> list[str]:
        """Code lines before the first move."""

    @abstractmethod
    def joint_move(self, job: ProgramJob, move: Move, previous: Move | None
                   ) -> Statement:
        """A joint move (``previous``: the move before it, or None)."""

    @abstractmethod
    def linear_move(self, job: ProgramJob, move: Move, previous: Move | None
                    ) -> Statement:
        """A linear move (``previous``: the move before it)."""

    @abstractmethod
    def footer(self, job: ProgramJob) -> list[str]:
        """Code lines after the last move."""

    @abstractmethod
    def assemble(self, job: ProgramJob, code: list[str], data: list[str]
                 ) -> dict[str, str]:
        """The files' texts (by :meth:`file_names`) from all code and data lines."""

    def render(self, job: ProgramJob) -> dict[str, str]:
        """Every file of the program, ``{relative path: text}``.

        Raises:
            InputError: more moves than :attr:`max_moves`, a name that is not legal,
                or targets with the wrong number of axes.
        """
        legal, note = self.program_name(job.name)
        if note is not None:
            raise InputError("name", note)
        if len(job.moves) > self.max_moves:
            raise InputError("moves", f"{len(job.moves)} moves; a {self.title} program "
                             f"holds at most {self.max_moves}: keep fewer samples "
                             "(stride, tolerance) or split the path")
        bad = [m.target.number for m in job.moves if m.target.joints.size != self.axes]
        if bad:
            raise InputError("moves", f"{self.title} programs drive {self.axes} axes; "
                             f"target {bad[0]} has {job.moves[0].target.joints.size}")
        code = list(self.header(job))
        data: list[str] = []
        previous: Move | None = None
        for move in job.moves:
            step = (self.joint_move if move.kind == "joint" else self.linear_move)(
                job, move, previous)
            code += step.code
            data += step.data
            previous = move
        code += self.footer(job)
        return self.assemble(job, code, data)

    # ----------------------------------------------------------------- formatting
    def length(self, value: float, width: int = 0) -> str:
        """A length [mm] at :attr:`length_decimals` (never ``-0``)."""
        return _fixed(value, self.length_decimals, width)

    def angle(self, value: float, width: int = 0) -> str:
        """An angle [deg] at :attr:`angle_decimals` (never ``-0``)."""
        return _fixed(value, self.angle_decimals, width)

    def euler(self, value: float, width: int = 0) -> str:
        """An Euler angle [deg]: as :meth:`angle`, -180 written as 180.

        The same rotation; rounding noise would otherwise flip the sign from target
        to target.
        """
        text = self.angle(value, width)
        if float(text) == -180.0:
            text = self.angle(180.0, width)
        return text

    def quaternion(self, wxyz: npt.ArrayLike, digits: int) -> list[str]:
        """A unit quaternion ``w x y z`` at ``digits`` decimals, one sign, never ``-0``.

        The first component that is not zero after rounding is positive (the same
        rotation is written the same way whatever the rounding noise).
        """
        q = np.asarray(wxyz, dtype=np.float64)
        rounded = np.round(q, digits)
        first = next((v for v in rounded if v != 0.0), 1.0)
        if first < 0.0:
            q = -q
        return [_fixed(v, digits) for v in q]

    def xyz_wpr(self, T: npt.ArrayLike) -> list[str]:
        """``x, y, z`` [mm] and fixed-axis ``rx, ry, rz`` [deg] of a pose (4, 4), as text.

        ``R = Rz(rz) Ry(ry) Rx(rx)``: FANUC W, P, R; Yaskawa Rx, Ry, Rz.
        """
        pose = np.asarray(T, dtype=np.float64)
        rz, ry, rx = euler_deg(pose[:3, :3], "ZYX")
        return [self.length(v) for v in pose[:3, 3]] + [self.euler(v) for v in (rx, ry, rz)]

    def axis_value(self, value: float, revolute: bool = True, width: int = 0) -> str:
        """A joint value: an angle [deg] or a length [mm]."""
        return self.angle(value, width) if revolute else self.length(value, width)


def _fixed(value: float, decimals: int, width: int = 0) -> str:
    text = f"{float(value):{width}.{decimals}f}"
    if text.strip().startswith("-") and float(text) == 0.0:
        text = text.replace("-", " " if width else "", 1)
        if not width:
            text = text.strip()
    return text


def comment_text(text: str, limit: int = 200) -> str:
    """``text`` safe inside any dialect's comment: printable ASCII, one line, cut."""
    clean = "".join(c if 32 <= ord(c) < 127 else "?" for c in str(text))
    return clean[:limit]


def options_error(cls: type[PostProcessor], given: dict[str, Any]) -> InputError | None:
    """An InputError naming unknown options of ``cls`` (None when all are known)."""
    unknown = sorted(set(given) - set(cls.options()))
    if not unknown:
        return None
    return InputError("options", f"unknown {cls.name} option(s) {unknown}; known: "
                      f"{list(cls.options())}")
