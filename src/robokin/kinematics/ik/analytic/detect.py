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

Detection is cached per chain (chains are immutable).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from robokin.kinematics.ik.analytic import general_6r as _g6
from robokin.kinematics.ik.analytic import palletizer as _pal
from robokin.kinematics.ik.analytic import pieper as _pk
from robokin.kinematics.ik.analytic import scara as _scara
from robokin.kinematics.ik.analytic import spherical_wrist as _sw
from robokin.kinematics.ik.analytic import three_parallel as _tp
from robokin.kinematics.ik.analytic._geometry import poe_from_chain
from robokin.kinematics.per_chain import cached

if TYPE_CHECKING:
    from robokin.kinematics.ik.analytic._six_r import Kind

__all__ = ["Family", "detect"]

EXACT_TOL = 1e-9
NEAR_ANGLE = 5e-3
NEAR_DISTANCE = 5e-3


@dataclass(frozen=True, eq=False)
class Family:
    """The closed-form family of an arm.

    Attributes:
        name: ``"three_parallel"``, ``"spherical_wrist"``, ``"scara"``,
            ``"palletizer"``, ``"general_6r"``, or ``"none"``.
        solver: ``solver(robot, T, q_near=None, **options) -> SolutionSet``, or
            None when no closed form applies.
        reason: Why no closed form applies ("" when one does).
        measured: What the detector measured, e.g. "axes 2-4 parallel within
            3.0e-04 rad; axes 5, 6 meet within 2.1e-05 m".
        near: True when the arm matches only within the near tolerances (the result
            is polished by Newton steps on the true chain).
        deviation: The largest measured angle [rad] / distance [m] from the family.
        details: Every family's measurement (name -> text).
    """

    name: str
    solver: Callable[..., Any] | None
    reason: str = ""
    measured: str = ""
    near: bool = False
    deviation: float = 0.0
    details: dict[str, str] = field(default_factory=dict)

    def __str__(self) -> str:
        """One line: the family and what was measured, or why there is none."""
        if self.solver is None:
            return f"none: {self.reason}"
        tag = " (near family: closed form + Newton polish)" if self.near else ""
        return f"{self.name}{tag}: {self.measured}"




def detect(robot: Any, *, tol: float = EXACT_TOL, near_angle: float = NEAR_ANGLE,
           near_distance: float = NEAR_DISTANCE, general_6r: bool = True) -> Family:
    """The closed-form family of ``robot`` (a Robot or a Chain).

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
    chain = getattr(robot, "chain", robot)
    return cached(chain, ("ik_family", tol, near_angle, near_distance, general_6r),
                  lambda: _detect(chain, tol, near_angle, near_distance, general_6r))


def _none(reason: str, details: dict[str, str] | None = None) -> Family:
    return Family("none", None, reason=reason, details=dict(details or {}))


def _grade(ang: float, dist: float, tol: float, near_angle: float,
           near_distance: float) -> str | None:
    if ang <= tol and dist <= tol:
        return "exact"
    if ang <= near_angle and dist <= near_distance:
        return "near"
    return None


def _detect(chain: Any, tol: float, near_angle: float, near_distance: float,
            general_6r: bool = True) -> Family:
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
        found = []
        details = {}
        for mod in (_tp, _sw):
            ang, dist, text, why = mod.measure(poe)
            details[mod.NAME] = text
            if why:
                details[mod.NAME] += f" ({why})"
                continue
            grade = _grade(ang, dist, tol, near_angle, near_distance)
            if grade is not None:
                found.append((grade != "exact", max(ang, dist), mod, text))
        found.sort(key=lambda f: (f[0], f[1]))
        if found and not found[0][0]:  # an exact closed form
            _, dev, mod, text = found[0]
            return _six_r_family(chain, poe, mod.NAME, text, False, dev, details)
        pieper = _pieper_family(chain, details, tol)
        if pieper.solver is not None:
            return pieper
        details = pieper.details
        if general_6r:
            general = _general_6r_family(chain, details)
            if general.solver is not None:
                return general
            details = general.details
        if found:  # near family: the nominal closed form + Newton polish
            _, dev, mod, text = found[0]
            return _six_r_family(chain, poe, mod.NAME, text, True, dev, details)
        return _none(
            "6R arm without three parallel axes (2-4) with meeting axes 5, 6, without "
            "a spherical wrist with parallel axes 2, 3, and not solved by the general "
            "6R elimination: " + "; ".join(f"{k}: {v}" for k, v in details.items()),
            details)
    if nc == 4 and n == 4:
        if n_pri != 1 or not chain.coupling.is_identity:
            return _none(f"a 4-joint arm with {n_pri} prismatic joint(s): the SCARA "
                         "closed form needs 3 revolute and 1 prismatic")
        ang, _, text, why = _scara.measure(poe)
        if why or ang > tol:
            return _none(f"not a SCARA: {text}" + (f" ({why})" if why else ""),
                         {"scara": text})
        g = _scara.geometry(poe)

        def scara_solver(robot, T, q_near=None, **options):
            return _scara.solve_geometry(robot, g, T, **options)

        return Family("scara", scara_solver, measured=text, deviation=ang,
                      details={"scara": text})
    if n == 4 and nc == 5:
        if n_pri:
            return _none("a 4-axis arm on 5 chain joints with a prismatic joint")
        ang, _, text, why = _pal.measure(chain, poe)
        if why or ang > tol:
            return _none(f"not a level-tool palletizer: {text}"
                         + (f" ({why})" if why else ""), {"palletizer": text})
        pal = _pal.geometry(chain, poe)

        def pal_solver(robot, T, q_near=None, **options):
            return _pal.solve_geometry(robot, pal, T, **options)

        return Family("palletizer", pal_solver, measured=text, deviation=ang,
                      details={"palletizer": text})
    return _none(
        f"{n} joint coordinates on {nc} chain joints: the closed forms cover 6R arms "
        "(three parallel axes, spherical wrist), 4-axis SCARA (R-R-R-P) and the "
        "4-axis level-tool palletizer"
    )


def _pieper_family(chain: Any, details: dict[str, str], tol: float) -> Family:
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
    return Family(_pk.NAME, solver, measured=setup.measured, details=details)


def _general_6r_family(chain: Any, details: dict[str, str]) -> Family:
    """The general 6R solver when its set-up works for ``chain``.

    Else a "none" family whose details say why.
    """
    setup = _g6.setup(chain)
    details = dict(details)
    if setup.params is None:
        details[_g6.NAME] = setup.reason
        return _none(setup.reason, details)
    details[_g6.NAME] = setup.measured

    def general_solver(robot, T, q_near=None, **options):
        return _g6.solve(robot, T, q_near, **options)

    general_solver.single = _g6.make_single(chain)  # type: ignore[attr-defined]
    return Family(_g6.NAME, general_solver, measured=setup.measured, details=details)


def _six_r_family(chain: Any, poe: Any, name: Kind, text: str, near: bool, dev: float,
                  details: dict[str, str]) -> Family:
    from robokin.kinematics.ik.analytic._six_r import (
        SINGULAR_TOL,
        make_single,
        pack,
        solve_six_r,
    )

    params_cache: dict[tuple[float, float], np.ndarray] = {}
    method = f"analytic:{name}" + ("+newton" if near else "")
    info = {"family": name, "measured": text, "near_family": near}

    def solver(robot, T, q_near=None, *, singular_tol: float = SINGULAR_TOL,
               compute_error: bool = False, **options):
        key = (singular_tol, 1e-12)
        P = params_cache.get(key)
        if P is None:
            if near:  # seeds past a boundary the nominal geometry moved: mirror them
                P = pack(chain, name, singular_tol=singular_tol, poe=poe,
                         disc_tol=min(0.5, 100.0 * dev), mirror=True)
            else:
                P = pack(chain, name, singular_tol=singular_tol, poe=poe)
            params_cache[key] = P
        return solve_six_r(robot, T, q_near, params=P, method=method,
                           info=info, near=near, compute_error=compute_error, **options)

    solver.params = lambda: pack(chain, name, poe=poe)  # type: ignore[attr-defined]
    # the single-pose hot path (default options, exact family only)
    solver.single = None if near else make_single(  # type: ignore[attr-defined]
        chain, pack(chain, name, poe=poe), method=method, info=info)
    return Family(name, solver, measured=text, near=near, deviation=dev, details=details)
