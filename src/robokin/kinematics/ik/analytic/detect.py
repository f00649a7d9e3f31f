"""Pick the closed-form family of an arm from its canonical chain's geometry.

The chain's joint axes and points at zero chain values (its product-of-exponentials
description, ``_geometry.poe_from_chain``) are tested for the structures the closed
forms need: parallel axes (angle between directions) and axes that meet (distance
between lines). An arm within ``tol`` is solved exactly by its family; one within
the near tolerances (a calibrated arm: 1e-4 rad, a fraction of a millimetre) is
solved by the nominal family's closed form and then polished by Newton steps on the
true chain (``near.polish``); the detector reports what it measured.

Families, tried in this order:

* ``three_parallel``: 6R, axes 2-4 parallel, axes 5/6 meet (UR, AUBO, Doosan);
* ``spherical_wrist``: 6R, axes 2/3 parallel, axes 4-6 meet (Puma, KUKA, ABB...);
* ``pieper``: 6R, axes 1-3 or axes 4-6 meet in a point (a spherical shoulder or a
  spherical wrist without axes 2, 3 parallel; the Panda or an SRS arm with one
  joint held, ``fixed.py``), exact arms only;
* ``scara``: 3 revolute + 1 prismatic, all axes parallel;
* ``palletizer``: 4 coordinates on 5 revolute chain joints, a parallelogram keeping
  the tool level (QFMD010);
* ``general_6r``: every other arm of six revolute joints without dependent joints,
  and the near-family 6R arms: Raghavan-Roth elimination (``general_6r``), taken
  when its per-arm set-up finds an elimination variant that solves its test poses
  completely. Near-family arms go to it rather than to the nominal closed form +
  Newton polish because that misses solutions the calibration error moves away
  from the nominal ones (measured in ``docs/ik.md``).

Detection is kept in the arm's :class:`~robokin.kinematics.arm.Arm` (chains are
immutable); each family's solver is a declared record taking the arm as an argument,
with the option names it accepts (the dispatcher checks them before calling).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol, TypeAlias

import numpy as np
import numpy.typing as npt

from robokin.kinematics.arm import Arm, ArmSource, Derived, arm_of
from robokin.kinematics.ik.analytic import general_6r as _g6
from robokin.kinematics.ik.analytic import palletizer as _pal
from robokin.kinematics.ik.analytic import pieper as _pk
from robokin.kinematics.ik.analytic import scara as _scara
from robokin.kinematics.ik.analytic._geometry import Poe, poe_from_chain
from robokin.kinematics.ik.analytic._six_r import SINGULAR_TOL
from robokin.kinematics.ik.analytic.six_r_families import SHAPES, measure
from robokin.model.chain import Chain

if TYPE_CHECKING:
    from robokin.kinematics.ik.analytic._six_r import Kind
    from robokin.kinematics.ik.solutions import SolutionSet

__all__ = ["FAMILIES", "FAMILY", "Family", "FamilyKey", "FamilySolver", "SingleSolver", "detect"]

#: ``detect``'s settings: (tol, near_angle, near_distance, general_6r).
FamilyKey: TypeAlias = tuple[float, float, float, bool]

EXACT_TOL = 1e-9
NEAR_ANGLE = 5e-3
NEAR_DISTANCE = 5e-3


class SingleSolver(Protocol):
    """The single-pose hot path: ``single(T, q6) -> SolutionSet | None``.

    One pose ``T`` (4, 4) float64, default options; ``q6`` is the joint-6 value kept
    at a wrist singularity. None when T is not a rigid transform (the caller
    re-checks it and raises the detailed error).
    """

    def __call__(self, T: npt.NDArray[np.float64], q6: float, /) -> SolutionSet | None:
        """The solutions of one pose, or None."""


@dataclass(frozen=True, eq=False)
class Family:
    """The closed-form family of an arm.

    Attributes:
        name: ``"three_parallel"``, ``"spherical_wrist"``, ``"pieper"``, ``"scara"``,
            ``"palletizer"``, ``"general_6r"``, or ``"none"``.
        solver: A :class:`FamilySolver`, or None when no closed form applies.
        reason: Why no closed form applies ("" when one does).
        measured: What the detector measured, e.g. "axes 2-4 parallel within
            3.0e-04 rad; axes 5, 6 meet within 2.1e-05 m".
        near: True when the arm matches only within the near tolerances (the result
            is polished by Newton steps on the true chain).
        deviation: The largest measured angle [rad] / distance [m] from the family.
        details: Every family's measurement (name -> text).
        options: The option names ``solver`` accepts (checked before calling it).
        single: The single-pose hot path (:class:`SingleSolver`), or None.
    """

    name: str
    solver: FamilySolver | None
    reason: str = ""
    measured: str = ""
    near: bool = False
    deviation: float = 0.0
    details: dict[str, str] = field(default_factory=dict)
    options: frozenset[str] = frozenset()
    single: SingleSolver | None = None

    def __str__(self) -> str:
        """One line: the family and what was measured, or why there is none."""
        if self.solver is None:
            return f"none: {self.reason}"
        tag = " (near family: closed form + Newton polish)" if self.near else ""
        return f"{self.name}{tag}: {self.measured}"


#: The options of each family's solver (the keyword-only parameters of the
#: function it calls; ``tests/kinematics/ik/test_analytic_detect.py`` ties them).
SIX_R_OPTIONS = frozenset({"singular_tol", "compute_error", "polish_iterations", "tol"})
SCARA_OPTIONS = frozenset({"orientation_tol", "compute_error"})
PALLETIZER_OPTIONS = frozenset({"level_tol", "compute_error"})
PIEPER_OPTIONS = frozenset({"compute_error"})
GENERAL_6R_OPTIONS = frozenset({"singular_tol", "compute_error", "parallel"})


@dataclass(frozen=True, eq=False)
class SixRSolver:
    """The closed form of a three-parallel or spherical-wrist arm.

    Attributes:
        kind: The family name (``_six_r.Kind``).
        poe: The chain's product-of-exponentials description.
        near: A near-family arm (seeds mirrored, Newton polish).
        deviation: The measured deviation from the family [rad or m].
        method: The sets' ``method`` text.
        info: The sets' ``info``.
        params: The packed parameters at the default ``singular_tol``
            (``_six_r.SINGULAR_TOL``).
        tuned: Parameters packed for other ``singular_tol`` values.
    """

    kind: Kind
    poe: Poe
    near: bool
    deviation: float
    method: str
    info: dict[str, Any]
    params: npt.NDArray[np.float64]
    tuned: dict[float, npt.NDArray[np.float64]] = field(default_factory=dict)

    def __call__(self, robot: ArmSource, T: npt.NDArray[np.float64],
                 q_near: npt.NDArray[np.float64] | None = None, *,
                 singular_tol: float = SINGULAR_TOL, compute_error: bool = False,
                 polish_iterations: int = 8, tol: float = 1e-9) -> SolutionSet:
        """Every solution for poses T (..., 4, 4); see ``_six_r.solve_six_r``."""
        from robokin.kinematics.ik.analytic._six_r import solve_six_r

        arm = arm_of(robot)
        P = self.params if singular_tol == SINGULAR_TOL else self.tuned.get(singular_tol)
        if P is None:
            P = self.tuned[singular_tol] = self.pack(arm.chain, singular_tol)
        return solve_six_r(arm, T, q_near, params=P, method=self.method, info=self.info,
                           near=self.near, compute_error=compute_error,
                           polish_iterations=polish_iterations, tol=tol)

    def pack(self, chain: Chain, singular_tol: float = SINGULAR_TOL) -> npt.NDArray[np.float64]:
        """The kernel parameters of ``chain`` (this family's) at ``singular_tol``."""
        from robokin.kinematics.ik.analytic._six_r import pack

        if self.near:  # seeds past a boundary the nominal geometry moved: mirror them
            return pack(chain, self.kind, singular_tol=singular_tol, poe=self.poe,
                        disc_tol=min(0.5, 100.0 * self.deviation), mirror=True)
        return pack(chain, self.kind, singular_tol=singular_tol, poe=self.poe)


@dataclass(frozen=True, eq=False)
class ScaraSolver:
    """The SCARA closed form (``scara.solve_geometry``) of one geometry."""

    geometry: _scara.ScaraGeometry

    def __call__(self, robot: ArmSource, T: npt.NDArray[np.float64],
                 q_near: npt.NDArray[np.float64] | None = None, *,
                 orientation_tol: float = 1e-9, compute_error: bool = False) -> SolutionSet:
        """Every solution (up to 2) for poses T (..., 4, 4)."""
        return _scara.solve_geometry(arm_of(robot), self.geometry, T,
                                     orientation_tol=orientation_tol,
                                     compute_error=compute_error)


@dataclass(frozen=True, eq=False)
class PalletizerSolver:
    """The level-tool palletizer closed form (``palletizer.solve_geometry``)."""

    geometry: _pal.PalletizerGeometry

    def __call__(self, robot: ArmSource, T: npt.NDArray[np.float64],
                 q_near: npt.NDArray[np.float64] | None = None, *,
                 level_tol: float = 1e-9, compute_error: bool = False) -> SolutionSet:
        """Every solution (up to 4) for poses T (..., 4, 4)."""
        return _pal.solve_geometry(arm_of(robot), self.geometry, T, level_tol=level_tol,
                                   compute_error=compute_error)


@dataclass(frozen=True, eq=False)
class General6RSolver:
    """The general 6R elimination (``general_6r.solve``); its set-up is the arm's."""

    def __call__(self, robot: ArmSource, T: npt.NDArray[np.float64],
                 q_near: npt.NDArray[np.float64] | None = None, *,
                 singular_tol: float = 1e-6, compute_error: bool = False,
                 parallel: bool | None = None) -> SolutionSet:
        """Every solution for poses T (..., 4, 4)."""
        return _g6.solve(arm_of(robot), T, q_near, singular_tol=singular_tol,
                         compute_error=compute_error, parallel=parallel)


#: A family's solver: ``solver(robot, T, q_near=None, **options) -> SolutionSet``
#: (``robot`` an :class:`~robokin.kinematics.arm.Arm` or a Robot, ``T`` validated
#: poses (..., 4, 4) [m]), one of these declared records; its options are the
#: keyword-only parameters of its ``__call__`` (``Family.options``).
FamilySolver: TypeAlias = (
    "SixRSolver | ScaraSolver | PalletizerSolver | _pk.FamilySolver | General6RSolver")


def detect(robot: ArmSource, *, tol: float = EXACT_TOL, near_angle: float = NEAR_ANGLE,
           near_distance: float = NEAR_DISTANCE, general_6r: bool = True) -> Family:
    """The closed-form family of ``robot`` (a Robot, an Arm or a Chain).

    Kept in the arm (a bare Chain is detected afresh on every call).

    Args:
        robot: The arm.
        tol: Angle [rad] / distance [m] within which the structure is exact.
        near_angle: Angle [rad] within which the arm is a near-family member.
        near_distance: Distance [m] within which axes count as nearly meeting.
        general_6r: Offer the general 6R solver (default); False gives a
            near-family arm its nominal closed form + Newton polish and other 6R
            arms no family.

    Returns:
        A :class:`Family`.
    """
    arm = arm_of(robot)
    key: FamilyKey = (tol, near_angle, near_distance, general_6r)
    if key == _DEFAULT_KEY:
        return arm.derived(FAMILY)
    kept = arm.derived(FAMILIES)
    fam = kept.get(key)
    if fam is None:
        fam = kept[key] = _detect(arm, *key)
    return fam


_DEFAULT_KEY: FamilyKey = (EXACT_TOL, NEAR_ANGLE, NEAR_DISTANCE, True)

#: The arm's family at the default settings, kept in its ``Arm`` (the single-pose
#: IK path reads it on every call).
FAMILY: Derived[Family] = Derived(
    "closed-form family", lambda arm: _detect(arm, *_DEFAULT_KEY))


def _no_families(arm: Arm) -> dict[FamilyKey, Family]:
    """A new, empty table of families by settings."""
    return {}


#: The arm's families detected at other settings, by settings.
FAMILIES: Derived[dict[FamilyKey, Family]] = Derived(
    "closed-form families at other settings", _no_families)


def _none(reason: str, details: dict[str, str] | None = None) -> Family:
    return Family("none", None, reason=reason, details=dict(details or {}))


def _grade(ang: float, dist: float, tol: float, near_angle: float,
           near_distance: float) -> str | None:
    if ang <= tol and dist <= tol:
        return "exact"
    if ang <= near_angle and dist <= near_distance:
        return "near"
    return None


def _detect(arm: Arm, tol: float, near_angle: float, near_distance: float,
            general_6r: bool = True) -> Family:
    chain = arm.chain
    nc, n = chain.n_chain, chain.n
    poe = poe_from_chain(chain)
    n_pri = int(poe.prismatic.sum())
    if nc == 6 and n == 6:
        if n_pri:
            return _none("a 6-joint arm with a prismatic joint: no closed form here, and "
                         + _g6.why_not(chain))
        if not chain.coupling.is_identity:
            return _none("a 6R arm with dependent joints: no closed form here, and "
                         + _g6.why_not(chain))
        return _detect_6r(arm, poe, tol, near_angle, near_distance, general_6r)
    if nc == 4 and n == 4:
        if n_pri != 1 or not chain.coupling.is_identity:
            return _none(f"a 4-joint arm with {n_pri} prismatic joint(s): the SCARA "
                         "closed form needs 3 revolute and 1 prismatic")
        ang, _, text, why = _scara.measure(poe)
        if why or ang > tol:
            return _none(f"not a SCARA: {text}" + (f" ({why})" if why else ""),
                         {"scara": text})
        return Family("scara", ScaraSolver(_scara.geometry(poe)), measured=text,
                      deviation=ang, details={"scara": text}, options=SCARA_OPTIONS)
    if n == 4 and nc == 5:
        if n_pri:
            return _none("a 4-axis arm on 5 chain joints with a prismatic joint")
        ang, _, text, why = _pal.measure(chain, poe)
        if why or ang > tol:
            return _none(f"not a level-tool palletizer: {text}"
                         + (f" ({why})" if why else ""), {"palletizer": text})
        return Family("palletizer", PalletizerSolver(_pal.geometry(chain, poe)),
                      measured=text, deviation=ang, details={"palletizer": text},
                      options=PALLETIZER_OPTIONS)
    return _none(
        f"{n} joint coordinates on {nc} chain joints: the closed forms cover 6R arms "
        "(three parallel axes, spherical wrist), 4-axis SCARA (R-R-R-P) and the "
        "4-axis level-tool palletizer"
    )


def _detect_6r(arm: Arm, poe: Poe, tol: float, near_angle: float, near_distance: float,
               general_6r: bool) -> Family:
    """The family of a 6R arm without dependent joints, in the module's order."""
    chain = arm.chain
    found = []
    details: dict[str, str] = {}
    for shape in SHAPES:
        ang, dist, text, why = measure(poe, shape)
        details[shape.name] = text
        if why:
            details[shape.name] += f" ({why})"
            continue
        grade = _grade(ang, dist, tol, near_angle, near_distance)
        if grade is not None:
            found.append((grade != "exact", max(ang, dist), shape.name, text))
    found.sort(key=lambda f: (f[0], f[1]))
    if found and not found[0][0]:  # an exact closed form
        _, dev, name, text = found[0]
        return _six_r_family(chain, poe, name, text, False, dev, details)
    pieper = _pieper_family(chain, details, tol)
    if pieper.solver is not None:
        return pieper
    details = pieper.details
    if general_6r:
        general = _general_6r_family(arm, details)
        if general.solver is not None:
            return general
        details = general.details
    if found:  # near family: the nominal closed form + Newton polish
        _, dev, name, text = found[0]
        return _six_r_family(chain, poe, name, text, True, dev, details)
    return _none(
        "6R arm without three parallel axes (2-4) with meeting axes 5, 6, without "
        "a spherical wrist with parallel axes 2, 3, and not solved by the general "
        "6R elimination: " + "; ".join(f"{k}: {v}" for k, v in details.items()),
        details)


def _pieper_family(chain: Chain, details: dict[str, str], tol: float) -> Family:
    """The ``pieper`` closed form when an axis triple of ``chain`` meets exactly.

    Else a "none" family whose details say why.
    """
    setup = _pk.setup(chain, tol=tol)
    details = dict(details)
    if setup.params is None:
        details[_pk.NAME] = setup.reason
        return _none(setup.reason, details)
    details[_pk.NAME] = setup.measured
    solver = _pk.family_solver(chain, setup)
    return Family(_pk.NAME, solver, measured=setup.measured, details=details,
                  options=PIEPER_OPTIONS, single=solver.single)


def _general_6r_family(arm: Arm, details: dict[str, str]) -> Family:
    """The general 6R solver when its set-up works for the arm.

    Else a "none" family whose details say why.
    """
    setup = _g6.setup(arm)
    details = dict(details)
    if setup.params is None:
        details[_g6.NAME] = setup.reason
        return _none(setup.reason, details)
    details[_g6.NAME] = setup.measured
    return Family(_g6.NAME, General6RSolver(), measured=setup.measured, details=details,
                  options=GENERAL_6R_OPTIONS, single=_g6.make_single(arm))


def _six_r_family(chain: Chain, poe: Poe, name: Kind, text: str, near: bool, dev: float,
                  details: dict[str, str]) -> Family:
    """A three-parallel or spherical-wrist family (near: + Newton polish)."""
    from robokin.kinematics.ik.analytic._six_r import make_single, pack

    method = f"analytic:{name}" + ("+newton" if near else "")
    info: dict[str, Any] = {"family": name, "measured": text, "near_family": near}
    nominal = pack(chain, name, poe=poe)
    solver = SixRSolver(name, poe, near, dev, method, info, nominal)
    if near:
        solver = SixRSolver(name, poe, near, dev, method, info, solver.pack(chain))
    # the single-pose hot path (default options, exact family only)
    single = None if near else make_single(chain, nominal, method=method, info=info)
    return Family(name, solver, measured=text, near=near, deviation=dev, details=details,
                  options=SIX_R_OPTIONS, single=single)
