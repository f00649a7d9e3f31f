"""Mass properties of an arm's links and the torque its joints can give.

Per link (the link names of :mod:`robokin.model.geometry`: ``base``, one per chain
joint, ``tool``), a :class:`LinkInertia`: mass [kg], centre of mass (3,) [m] and
the inertia tensor about the centre of mass (3, 3) [kg m^2], both in the link
frame (``robot.fk_all(q)[..., k, :, :]``; the tool's in the tool frame, where it
is the payload or the tool's own mass). :class:`RobotDynamics` holds them with
the joints' torque limits [N m, or N for prismatic joints], the data's source
and an optional density for the links without data.

A link without data can be estimated from its shapes (:func:`estimate_link`,
trimesh's mass properties of each shape at a uniform density, then combined);
:func:`resolve_links` does that for a whole robot and says which links it
estimated. This module holds data and that estimate only; it reads no file (the
robot file's ``dynamics:`` section is :mod:`robokin.io.dynamics_section`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from robokin._text import short_repr
from robokin.exceptions import InputError, ModelError

if TYPE_CHECKING:
    from robokin.model.geometry import HasChain, Shape

__all__ = [
    "DEFAULT_DENSITY",
    "LinkInertia",
    "ResolvedLinks",
    "RobotDynamics",
    "estimate_link",
    "resolve_links",
]

#: Density [kg/m^3] used to estimate a link from its shapes when none is given:
#: water's (and MuJoCo's default geom density). robokin's shapes are solid
#: envelopes of hollow cast links, so a metal's density would overestimate them.
DEFAULT_DENSITY = 1000.0

F64 = npt.NDArray[np.float64]


def _ro(a: npt.ArrayLike) -> F64:
    out = np.array(a, dtype=np.float64)
    out.setflags(write=False)
    return out


@dataclass(frozen=True, eq=False)
class LinkInertia:
    """The mass properties of one rigid link.

    Attributes:
        mass: Mass [kg], >= 0.
        com: Centre of mass in the link frame, (3,) [m].
        inertia: Inertia tensor about the centre of mass, axes of the link frame,
            (3, 3) [kg m^2], symmetric positive semi-definite.
    """

    mass: float
    com: F64 = field(default_factory=lambda: _ro(np.zeros(3)))
    inertia: F64 = field(default_factory=lambda: _ro(np.zeros((3, 3))))

    def __post_init__(self) -> None:
        """Check the values and freeze the arrays (raises InputError naming the field)."""
        try:
            m = float(self.mass)
        except (TypeError, ValueError):
            raise InputError("mass", f"expected a number [kg], got {short_repr(self.mass)}"
                             ) from None
        if not (math.isfinite(m) and m >= 0.0):
            raise InputError("mass", f"expected a finite mass >= 0 [kg], got {m}")
        com = np.asarray(self.com, dtype=np.float64)
        if com.shape != (3,) or not np.isfinite(com).all():
            raise InputError("com", f"expected 3 finite numbers [m], got shape {com.shape}")
        inertia = np.asarray(self.inertia, dtype=np.float64)
        if inertia.shape != (3, 3) or not np.isfinite(inertia).all():
            raise InputError("inertia", "expected a finite (3, 3) tensor [kg m^2], got "
                             f"shape {inertia.shape}")
        scale = max(float(np.abs(inertia).max()), 1e-300)
        if np.abs(inertia - inertia.T).max() > 1e-9 * scale:
            raise InputError("inertia", "the tensor is not symmetric")
        inertia = 0.5 * (inertia + inertia.T)
        if np.linalg.eigvalsh(inertia).min() < -1e-9 * scale:
            raise InputError("inertia", "the tensor has a negative principal moment "
                             f"({np.linalg.eigvalsh(inertia).round(12).tolist()})")
        object.__setattr__(self, "mass", m)
        object.__setattr__(self, "com", _ro(com))
        object.__setattr__(self, "inertia", _ro(inertia))

    @classmethod
    def from_moments(
        cls, mass: float, com: npt.ArrayLike, moments: Sequence[float]
    ) -> LinkInertia:
        """Build from ``(ixx, iyy, izz, ixy, ixz, iyz)`` [kg m^2] about the centre of mass.

        Raises:
            InputError: not six finite numbers, or the checks of the class.
        """
        v = np.asarray(moments, dtype=np.float64).reshape(-1)
        if v.shape != (6,):
            raise InputError("inertia", "expected 6 numbers (ixx, iyy, izz, ixy, ixz, "
                             f"iyz), got {v.shape[0]}")
        ixx, iyy, izz, ixy, ixz, iyz = v
        tensor = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        return cls(mass, np.asarray(com, dtype=np.float64), tensor)

    @property
    def moments(self) -> F64:
        """``(ixx, iyy, izz, ixy, ixz, iyz)`` [kg m^2] (MuJoCo's ``fullinertia`` order)."""
        i = self.inertia
        return np.array([i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]])

    def moved(self, pose: npt.ArrayLike) -> LinkInertia:
        """The same body described in another frame.

        Args:
            pose: This description's frame in the new one, (4, 4) [m].

        Returns:
            The centre of mass ``R c + t`` and the tensor ``R I R^T``.
        """
        T = np.asarray(pose, dtype=np.float64)
        R = T[:3, :3]
        return LinkInertia(self.mass, R @ self.com + T[:3, 3], R @ self.inertia @ R.T)

    def about_origin(self) -> F64:
        """The inertia tensor about the frame's origin (parallel axis theorem), (3, 3)."""
        c = self.com
        return self.inertia + self.mass * (float(c @ c) * np.eye(3) - np.outer(c, c))

    @staticmethod
    def combine(parts: Iterable[LinkInertia]) -> LinkInertia | None:
        """Several rigidly joined bodies (same frame) as one; None for no parts."""
        parts = list(parts)
        if not parts:
            return None
        m = float(sum(p.mass for p in parts))
        if m <= 0.0:
            return LinkInertia(0.0, np.zeros(3), np.sum([p.inertia for p in parts], 0))
        c = np.sum([p.mass * p.com for p in parts], axis=0) / m
        about_origin = np.sum([p.about_origin() for p in parts], axis=0)
        inertia = about_origin - m * (float(c @ c) * np.eye(3) - np.outer(c, c))
        return LinkInertia(m, c, inertia)


@dataclass(frozen=True, eq=False)
class RobotDynamics:
    """The mass properties of a robot's links and its joints' torque limits.

    Attributes:
        names: Link names (n_chain + 2): ``base``, each chain joint's link, ``tool``.
        links: Per link a :class:`LinkInertia`, or None where there is no data.
        torque_limits: Largest torque [N m] (force [N] for a prismatic joint) of
            each independent joint coordinate, (n,), > 0 (inf: unknown); or None.
        source: Where the numbers come from.
        density: Density [kg/m^3] for estimating the links without data from their
            shapes, or None for :data:`DEFAULT_DENSITY`.
    """

    names: tuple[str, ...]
    links: tuple[LinkInertia | None, ...]
    torque_limits: F64 | None = None
    source: str = ""
    density: float | None = None

    def __post_init__(self) -> None:
        """Check the per-link entries, the torque limits and the density."""
        if len(self.links) != len(self.names):
            raise InputError("links", f"expected one entry per link ({len(self.names)}),"
                             f" got {len(self.links)}")
        for name, link in zip(self.names, self.links):
            if link is not None and not isinstance(link, LinkInertia):
                raise InputError("links", f"link {name!r}: expected a LinkInertia or None"
                                 f", got {type(link).__name__}")
        if self.torque_limits is not None:
            lim = np.array(self.torque_limits, dtype=np.float64).reshape(-1)
            if np.isnan(lim).any() or (lim <= 0).any():
                raise InputError("torque_limits", f"expected values > 0 [N m or N], got "
                                 f"{lim.tolist()}")
            object.__setattr__(self, "torque_limits", _ro(lim))
        if self.density is not None:
            d = float(self.density)
            if not (math.isfinite(d) and d > 0):
                raise InputError("density", f"expected a density > 0 [kg/m^3], got {d}")
            object.__setattr__(self, "density", d)

    @classmethod
    def from_mapping(
        cls,
        robot: HasChain,
        links: Mapping[str, LinkInertia],
        *,
        torque_limits: npt.ArrayLike | None = None,
        source: str = "",
        density: float | None = None,
    ) -> RobotDynamics:
        """Build from ``{link name: LinkInertia}`` (links left out have no data).

        Raises:
            InputError: an unknown link name (the message lists the links), or
                torque limits of the wrong length.
        """
        from robokin.model.geometry import link_names

        names = link_names(robot)
        for key in links:
            if key not in names:
                raise InputError("links", f"unknown link {key!r}; the links are "
                                 f"{list(names)}")
        n = robot.chain.n
        if torque_limits is not None:
            lim = np.asarray(torque_limits, dtype=np.float64).reshape(-1)
            if lim.shape != (n,):
                raise InputError("torque_limits", f"expected {n} values (one per "
                                 f"joint), got {lim.shape[0]}")
        return cls(names, tuple(links.get(nm) for nm in names),
                   None if torque_limits is None else np.asarray(torque_limits, float),
                   source, density)

    def link(self, name: str) -> LinkInertia | None:
        """The data of one link (None when it has none).

        Raises:
            InputError: an unknown link name.
        """
        if name not in self.names:
            raise InputError("link", f"unknown link {name!r}; the links are "
                             f"{list(self.names)}")
        return self.links[self.names.index(name)]


def estimate_link(shapes: Iterable[Shape], density: float) -> LinkInertia | None:
    """Mass properties of a link's shapes as uniform solids (trimesh).

    Each shape's mesh (primitives as trimesh meshes, mesh files as loaded; a mesh
    that is not watertight through its convex hull) gives its volume, centre
    of mass and inertia at ``density``; placed in the link frame and combined.
    Overlapping shapes count twice.

    Args:
        shapes: The link's shapes (their placements in the link frame).
        density: [kg/m^3], > 0.

    Returns:
        The combined :class:`LinkInertia`, or None for no shapes.

    Raises:
        MissingExtraError: trimesh is not installed.
        ModelError: a mesh file that cannot be read.
    """
    parts = []
    for shape in shapes:
        mesh = shape.trimesh()
        if not mesh.is_watertight:
            mesh = mesh.convex_hull
        props = mesh.mass_properties  # at unit density: mass = volume
        volume = float(props["mass"])
        if volume <= 0.0:
            continue
        # trimesh's inertia is about the centre of mass, at unit density
        part = LinkInertia(volume * density, np.asarray(props["center_mass"]),
                           np.asarray(props["inertia"]) * density)
        parts.append(part.moved(shape.placement))
    return LinkInertia.combine(parts)


@dataclass(frozen=True)
class ResolvedLinks:
    """Every link's mass properties, as a simulation uses them.

    Attributes:
        names: Link names (n_chain + 2).
        links: Per link a :class:`LinkInertia`, or None (no data and no shapes).
        origin: Per link ``"data"`` (from the robot's dynamics), ``"estimated"``
            (from its shapes at ``density``) or ``"none"``.
        density: The density used for the estimates [kg/m^3].
        source: The robot's dynamics source text ("" when it has none).
    """

    names: tuple[str, ...]
    links: tuple[LinkInertia | None, ...]
    origin: tuple[str, ...]
    density: float
    source: str

    @property
    def estimated(self) -> tuple[str, ...]:
        """Names of the links estimated from their shapes."""
        return tuple(n for n, o in zip(self.names, self.origin) if o == "estimated")

    def describe(self) -> str:
        """One line for a report: where the mass properties come from."""
        moving = [(n, o) for n, o in zip(self.names, self.origin) if n != "base"]
        data = [n for n, o in moving if o == "data"]
        est = [n for n, o in moving if o == "estimated"]
        none = [n for n, o in moving if o == "none"]
        parts = []
        if data:
            src = self.source if len(self.source) <= 90 else self.source[:89] + "…"
            parts.append(f"{len(data)} link(s) from the robot's data"
                         + (f" ({src})" if src else ""))
        if est:
            parts.append(f"{', '.join(est)} ESTIMATED from the shapes at "
                         f"{self.density:g} kg/m^3")
        if none:
            parts.append(f"{', '.join(none)} without mass (no data, no shapes)")
        return "; ".join(parts) or "no mass data"


def resolve_links(
    robot: HasChain, *, strict: bool = False, density: float | None = None
) -> ResolvedLinks:
    """Every link's mass properties: the robot's data, else estimated from its shapes.

    Args:
        robot: A robot (its ``dynamics`` and ``geometry``, either may be None).
        strict: Refuse to estimate: every chain link must have data.
        density: [kg/m^3] for the estimates; default the robot's
            ``dynamics.density``, else :data:`DEFAULT_DENSITY`.

    Returns:
        A :class:`ResolvedLinks`.

    Raises:
        ModelError: in strict mode, a chain link without data (naming the
            field ``dynamics.links.<link>``).
        InputError: a density that is not a positive number.
    """
    from robokin.model.geometry import RobotGeometry, link_names

    names = link_names(robot)
    dyn = getattr(robot, "dynamics", None)
    geo = getattr(robot, "geometry", None)
    if density is None:
        density = (dyn.density if isinstance(dyn, RobotDynamics) and dyn.density
                   else DEFAULT_DENSITY)
    if not (isinstance(density, int | float) and math.isfinite(density) and density > 0):
        raise InputError("density", f"expected a density > 0 [kg/m^3], got "
                         f"{short_repr(density)}")
    links: list[LinkInertia | None] = []
    origin: list[str] = []
    chain_links = set(names[1:-1])
    for k, name in enumerate(names):
        data = dyn.links[k] if isinstance(dyn, RobotDynamics) else None
        if data is not None:
            links.append(data)
            origin.append("data")
            continue
        if strict and name in chain_links:
            raise ModelError(
                f"no mass data for link {name!r} (strict: nothing is estimated); give "
                "it mass, com and inertia in the robot file's dynamics: section",
                field=f"dynamics.links.{name}")
        shapes = geo.shapes[k] if isinstance(geo, RobotGeometry) else ()
        est = estimate_link(shapes, float(density)) if shapes else None
        links.append(est)
        origin.append("estimated" if est is not None else "none")
    source = dyn.source if isinstance(dyn, RobotDynamics) else ""
    return ResolvedLinks(names, tuple(links), tuple(origin), float(density), source)
