"""The IK solution set: every solution for every pose, with flags and labels.

A :class:`SolutionSet` for target poses of leading shape ``(...)`` holds up to ``k``
candidate rows per pose: ``q`` ``(..., k, n)`` and a ``valid`` mask ``(..., k)``
(batches have a different count per pose). Rows that are not solutions are NaN.
Per-pose ``status`` says why a pose has no solution.

For one pose the set behaves like a collection of its valid solutions::

    sols = robot.ik(T)
    len(sols)          # how many
    for q in sols: ... # each (n,)
    list(sols)         # [q1, q2, ...]

A batch iterates (and ``len`` counts) its poses, each a one-pose set.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import numpy.typing as npt

from robokin._validation import check_broadcasts, check_finite, check_joints
from robokin.exceptions import UnreachableError
from robokin.kinematics.arm import ArmSource, arm_of
from robokin.spatial import wrap_angle

__all__ = ["SolutionSet", "wrap_angle"]

STATUS_OK = "ok"


@dataclass(frozen=True, eq=False, init=False)
class SolutionSet:
    """Every IK solution found for a batch of target poses.

    Attributes:
        q: Joint solutions (..., k, n) [rad, m]; rows where ``valid`` is False are
            NaN.
        valid: (..., k) bool, which rows are real solutions.
        is_revolute: (n,) bool, which coordinates are angles (wrap) vs lengths.
        limits: (n, 2) joint limits [rad, m].
        flags: Per-solution boolean arrays (..., k), e.g. ``"within_limits"``,
            ``"singular"`` (the wrist singularity: one of infinitely many
            solutions), ``"polished"`` (near-family Newton polish applied).
        branches: Per-solution integer labels (..., k) by name, e.g.
            ``"shoulder"`` (+1 right / -1 left), ``"elbow"`` (+1 up / -1 down),
            ``"wrist"`` (+1 / -1 flip); SCARA: ``"elbow"`` (+1 right-handed / -1 left).
        status: (...) str array: ``"ok"`` or why there is no solution ("out of
            reach", "orientation not achievable", "outside joint limits: ...").
        method: Which solver produced the set (e.g. ``"analytic:three_parallel"``).
        error: (..., k) FK error of each solution (position [m] + rotation [rad]
            norm), where the solver computed it.
        info: Extra solver facts (e.g. the near-family residual).
    """

    q: npt.NDArray[np.float64]
    valid: npt.NDArray[np.bool_]
    is_revolute: npt.NDArray[np.bool_]
    limits: npt.NDArray[np.float64]
    flags: dict[str, npt.NDArray[np.bool_]]
    branches: dict[str, npt.NDArray[np.integer[Any]]]
    status: npt.NDArray[np.object_]
    method: str
    error: npt.NDArray[np.float64] | None
    info: dict[str, Any]

    def __init__(
        self,
        q: npt.ArrayLike,
        valid: npt.ArrayLike,
        is_revolute: npt.ArrayLike,
        limits: npt.ArrayLike,
        flags: dict[str, npt.NDArray[np.bool_]] | None = None,
        branches: dict[str, npt.NDArray[np.integer[Any]]] | None = None,
        status: npt.ArrayLike | None = None,
        method: str = "",
        error: npt.NDArray[np.float64] | None = None,
        info: dict[str, Any] | None = None,
    ) -> None:
        """Check the shapes; NaN the rows that are not valid; fill in the defaults.

        Args:
            q: Joint solutions [rad, m], shape (..., k, n).
            valid: Which rows are solutions, bool, shape (..., k).
            is_revolute: Which coordinates are angles, bool, shape (n,).
            limits: Joint limits [rad, m], shape (n, 2).
            flags: Per-solution flags (..., k); ``"within_limits"`` is computed
                (and added to this dict) when missing.
            branches: Per-solution integer labels (..., k) by name.
            status: Per-pose status (...); ``"ok"`` where a pose has a valid row,
                else ``"no solution"``, when None.
            method: Which solver produced the set.
            error: FK error of each solution (..., k), or None.
            info: Extra solver facts.

        Raises:
            ValueError: ``q`` and ``valid`` disagree in shape.
        """
        q = np.asarray(q, dtype=np.float64)
        valid = np.asarray(valid, dtype=bool)
        if q.shape[:-1] != valid.shape:
            raise ValueError(f"q {q.shape} and valid {valid.shape} disagree")
        if not valid.all():
            q = np.where(valid[..., None], q, np.nan)
        lim = np.asarray(limits, dtype=np.float64)
        flags = {} if flags is None else flags
        if "within_limits" not in flags:
            inside = (q >= lim[:, 0] - 1e-9) & (q <= lim[:, 1] + 1e-9)
            flags["within_limits"] = np.all(inside, axis=-1)
        if status is None:
            st = np.where(valid.any(axis=-1), STATUS_OK, "no solution")
            status = np.asarray(st, dtype=object)
        init = object.__setattr__
        init(self, "q", q)
        init(self, "valid", valid)
        init(self, "is_revolute", np.asarray(is_revolute, dtype=bool))
        init(self, "limits", lim)
        init(self, "flags", flags)
        init(self, "branches", {} if branches is None else branches)
        init(self, "status", status)
        init(self, "method", method)
        init(self, "error", error)
        init(self, "info", {} if info is None else info)

    @classmethod
    def _trusted(cls, q: np.ndarray, valid: np.ndarray, is_revolute: np.ndarray,
                 limits: np.ndarray, flags: dict[str, np.ndarray],
                 branches: dict[str, np.ndarray], status: np.ndarray, method: str,
                 error: np.ndarray | None, info: dict[str, Any]) -> SolutionSet:
        """Build a set from arrays already in final form, without conversions or checks.

        Final form: float64 ``q``, bool masks, a ``within_limits`` flag, an object
        ``status``; the hot path of the closed forms. Callers pass fresh arrays (or
        read-only shared ones), never buffers they reuse, and rows of ``q`` that are
        not valid already NaN (the compiled closed forms write them so).
        """
        self = object.__new__(cls)
        # item by item: ~75 ns less than one update(**fields) (no keyword dict)
        d = self.__dict__
        d["q"] = q
        d["valid"] = valid
        d["is_revolute"] = is_revolute
        d["limits"] = limits
        d["flags"] = flags
        d["branches"] = branches
        d["status"] = status
        d["method"] = method
        d["error"] = error
        d["info"] = info
        return self

    # ------------------------------------------------------------------ basics
    @classmethod
    def empty(cls, lead: tuple[int, ...], n: int, is_revolute: npt.ArrayLike,
              limits: npt.ArrayLike, status: str, method: str = "") -> SolutionSet:
        """A set with no solution for any of the poses, all with ``status``."""
        st = np.empty(lead, dtype=object)
        st[...] = status
        return cls(np.zeros(lead + (0, n)), np.zeros(lead + (0,), bool), is_revolute,
                   limits, status=st, method=method)

    @property
    def shape(self) -> tuple[int, ...]:
        """Leading (pose batch) shape."""
        return self.valid.shape[:-1]

    @property
    def n(self) -> int:
        """Number of joint coordinates."""
        return int(self.q.shape[-1])

    @property
    def count(self) -> np.ndarray:
        """(...) number of valid solutions per pose."""
        count: np.ndarray = self.valid.sum(axis=-1)
        return count

    @property
    def singular(self) -> np.ndarray:
        """(..., k) bool, solutions at a singularity (one of infinitely many)."""
        return self.flags.get("singular", np.zeros_like(self.valid))

    @property
    def within_limits(self) -> np.ndarray:
        """(..., k) bool, solutions inside every joint limit.

        See :meth:`keep_within_limits` for the set of those alone.
        """
        return self.flags["within_limits"] & self.valid

    def __len__(self) -> int:
        """One pose: the number of valid solutions; a batch: its first dimension."""
        if self.shape:
            return self.shape[0]
        return int(self.count)

    def __iter__(self) -> Iterator[Any]:
        """One pose: each valid solution (n,); a batch: each pose's set."""
        if self.shape:
            return (self[i] for i in range(self.shape[0]))
        return iter(list(self.q[self.valid]))

    def solutions(self) -> np.ndarray:
        """The valid solutions of a single pose, (count, n)."""
        if self.shape:
            raise TypeError("solutions() needs a single pose; index the batch first")
        return self.q[self.valid]

    def __getitem__(self, index: Any) -> SolutionSet:
        """Index the pose batch (not the solutions): ``sols[3]``, ``sols[2:5]``."""
        if not isinstance(index, tuple):
            index = (index,)
        if len(index) > len(self.shape):
            raise IndexError("SolutionSet indexes the pose batch only")
        return replace(
            self,
            q=self.q[index],
            valid=self.valid[index],
            flags={k: v[index] for k, v in self.flags.items()},
            branches={k: v[index] for k, v in self.branches.items()},
            status=np.asarray(self.status[index], dtype=object),
            error=None if self.error is None else self.error[index],
        )

    def _masked(self, keep: np.ndarray, reason: str | None = None) -> SolutionSet:
        valid = self.valid & keep
        status = self.status.copy()
        lost = self.valid.any(axis=-1) & ~valid.any(axis=-1)
        if reason is not None and lost.any():
            status[lost] = reason
        q = np.where(valid[..., None], self.q, np.nan)
        return replace(self, q=q, valid=valid, status=status)

    def keep_within_limits(self) -> SolutionSet:
        """Only the solutions inside every joint limit.

        Poses whose every solution is outside the limits get a status naming the
        joint and limit that rejected the first of them.
        """
        inside = self.flags["within_limits"]
        out = self._masked(inside)
        lost = self.valid.any(axis=-1) & ~out.valid.any(axis=-1)
        if lost.any():
            status = out.status.copy()
            k, n = self.q.shape[-2:]
            rows = np.flatnonzero(lost)
            q = self.q.reshape(-1, k, n)[rows]  # (m, k, n): the poses that lost all
            lo, hi = self.limits[:, 0] - 1e-9, self.limits[:, 1] + 1e-9
            bad = (q < lo) | (q > hi)
            j = bad.argmax(axis=-1)  # (m, k): the first joint outside its limits
            qj = np.take_along_axis(q, j[..., None], axis=-1)[..., 0]
            flat = status.reshape(-1)
            outside: list[list[bool]] = np.any(bad, axis=-1).tolist()
            for r, valid, out_k, j_k, q_k in zip(
                rows.tolist(), self.valid.reshape(-1, k)[rows].tolist(),
                outside, j.tolist(), qj.tolist(), strict=True
            ):
                flat[r] = "outside joint limits: " + "; ".join(
                    f"solution {c + 1}: "
                    + (self._limit_reason(j_k[c], q_k[c]) if out_k[c] else "")
                    for c in range(k) if valid[c]
                )
            out = replace(out, status=flat.reshape(status.shape))
        return out

    def _limit_reason(self, j: int, value: float) -> str:
        """Why joint ``j`` at ``value`` is outside its limits."""
        lo, hi = self.limits[j]
        if value < lo - 1e-9:
            return f"joint {j + 1} at {value:.6g} < lower limit {lo:.6g}"
        return f"joint {j + 1} at {value:.6g} > upper limit {hi:.6g}"

    def _q_current(self, q_current: npt.ArrayLike) -> np.ndarray:
        """``q_current`` checked: finite, (..., n), broadcasting to the pose batch."""
        qc = check_finite(check_joints(q_current, self.n, "q_current"), "q_current")
        return check_broadcasts(qc, self.shape + (self.n,), "q_current",
                                "the pose batch + joints")

    def distance(self, q_current: npt.ArrayLike) -> np.ndarray:
        """(..., k) joint-space distance from ``q_current`` (..., n) to every row.

        Revolute differences are wrapped into [-pi, pi); prismatic ones never are.
        Invalid rows get +inf.
        """
        qc = self._q_current(q_current)
        diff = self.q - qc[..., None, :]
        diff = np.where(self.is_revolute, wrap_angle(diff), diff)
        d = np.linalg.norm(diff, axis=-1)
        return np.where(self.valid, d, np.inf)

    def nearest(self, q_current: npt.ArrayLike, *, respect_limits: bool = True) -> np.ndarray:
        """The valid solution nearest ``q_current`` for every pose, (..., n).

        Distance wraps revolute joints; the returned angles are the 2*pi-equivalents
        closest to ``q_current`` that stay inside the joint limits (so a path of
        nearest solutions is continuous). With ``respect_limits`` (default) only
        solutions inside the joint limits are candidates.

        Raises:
            UnreachableError: a pose has no valid solution (its status is named).
        """
        q, found, status = self.nearest_each(q_current, respect_limits=respect_limits)
        if not found.all():
            idx = np.argwhere(~found)
            first = tuple(int(i) for i in idx[0]) if idx.size else ()
            raise UnreachableError(
                f"{int((~found).sum())} pose(s) have no solution; first at index "
                f"{first}: {status[first]}"
            )
        return q

    def nearest_each(
        self, q_current: npt.ArrayLike, *, respect_limits: bool = True
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.bool_] | np.bool_,
               npt.NDArray[np.object_]]:
        """Like :meth:`nearest`, without raising for poses that have no solution.

        Returns:
            ``(q, found, status)``: ``q`` (..., n) the nearest solution where
            ``found`` (...) is True and NaN elsewhere; ``status`` (...) why a pose
            has none (``"ok"`` where found).
        """
        qc = self._q_current(q_current)
        ok = self.within_limits if respect_limits else self.valid
        found = ok.any(axis=-1)
        status = self.status
        if not found.all() and respect_limits and (self.valid.any(axis=-1) & ~found).any():
            status = self.keep_within_limits().status  # names the limits that rejected
        if ok.shape[-1] == 0:  # no candidate row at all
            return np.full(self.shape + (self.n,), np.nan), found, status
        diff = self.q - qc[..., None, :]
        diff = np.where(self.is_revolute, wrap_angle(diff), diff)
        d = np.where(ok, np.einsum("...i,...i->...", diff, diff), np.inf)
        k = np.argmin(d, axis=-1)[..., None, None]
        best = np.take_along_axis(self.q, k, axis=-2)[..., 0, :]
        step = np.take_along_axis(diff, k, axis=-2)[..., 0, :]
        qcb = np.broadcast_to(qc, best.shape)
        shifted = qcb + step  # the 2 pi equivalent nearest q_current
        lim = self.limits
        keep = ((shifted >= lim[:, 0] - 1e-12) & (shifted <= lim[:, 1] + 1e-12)
                & self.is_revolute)
        q = np.where(keep, shifted, best)
        if not found.all():
            q = np.where(np.expand_dims(found, -1), q, np.nan)
        return q, found, status

    def expand_turns(self) -> SolutionSet:
        """Add every 2*pi-equivalent of revolute joints whose range exceeds 2*pi.

        E.g. a UR joint with limits +-360 deg has two values for each angle. New
        rows inherit the flags and branch labels of their source row; rows outside
        the limits are dropped (marked invalid).
        """
        lim = self.limits
        span = lim[:, 1] - lim[:, 0]
        wide = self.is_revolute & (span > 2 * np.pi - 1e-12)
        if not wide.any() or self.valid.shape[-1] == 0:  # nothing to expand
            return self
        shifts_per_joint = []
        for j in range(self.n):
            if not wide[j] or not np.isfinite(span[j]):
                shifts_per_joint.append(np.array([0.0]))
                continue
            m = int(np.ceil(span[j] / (2 * np.pi))) + 1
            shifts_per_joint.append(2 * np.pi * np.arange(-m, m + 1))
        grids = np.meshgrid(*shifts_per_joint, indexing="ij")
        shifts = np.stack([g.ravel() for g in grids], axis=-1)  # (s, n)
        base = wrap_angle(self.q)
        base = np.where(self.is_revolute, base, self.q)
        q = base[..., :, None, :] + shifts  # (..., k, s, n)
        inside = ((q >= lim[:, 0] - 1e-9) & (q <= lim[:, 1] + 1e-9)).all(axis=-1)
        valid = self.valid[..., :, None] & inside
        lead = self.shape
        k, s = q.shape[-3], q.shape[-2]
        def flat(a: np.ndarray) -> np.ndarray:
            return a.reshape(lead + (k * s,) + a.shape[len(lead) + 2:])

        def rep(a: np.ndarray) -> np.ndarray:
            return flat(np.broadcast_to(a[..., :, None], lead + (k, s)))

        flags = {key: rep(v) for key, v in self.flags.items()}
        flags["within_limits"] = flat(inside)
        # Keep only columns that are valid somewhere, to bound the size.
        V = flat(valid)
        keep = V.reshape(-1, k * s).any(axis=0)
        def sel(a: np.ndarray) -> np.ndarray:
            return a[..., keep] if a.ndim == len(lead) + 1 else a[..., keep, :]

        return replace(
            self,
            q=sel(flat(q)),
            valid=sel(V),
            flags={key: sel(v) for key, v in flags.items()},
            branches={key: sel(rep(v)) for key, v in self.branches.items()},
            error=None if self.error is None else sel(rep(self.error)),
        )

    def to_actuator_space(self, robot: ArmSource) -> SolutionSet:
        """The same set in motor coordinates (limits checked in both spaces).

        Args:
            robot: The arm (a Robot or its :class:`~robokin.kinematics.arm.Arm`),
                whose actuator map and motor limits apply.
        """
        arm = arm_of(robot)
        lim, actuators = arm.actuator_limits, arm.actuators
        if actuators is None or lim is None:  # limits come with the map
            return self
        phi = actuators.inverse(self.q, what=f"actuator map of '{arm.name}'")
        inside = self.flags["within_limits"] & (
            (phi >= lim[:, 0] - 1e-9) & (phi <= lim[:, 1] + 1e-9)
        ).all(axis=-1)
        flags = dict(self.flags)
        flags["within_limits"] = inside
        flags["joint_within_limits"] = self.flags["within_limits"]
        is_rev = np.zeros(phi.shape[-1], bool)  # motor angles are multi-turn: never wrap
        return replace(self, q=phi, flags=flags, is_revolute=is_rev, limits=lim,
                       info={**self.info, "space": "actuator"})

    def _repr_html_(self) -> str:
        """Jupyter: one pose's solutions with branches and flags; a batch summarised.

        One pose: a row per valid solution (degrees for angles, mm for lengths),
        its branch labels and flags. A batch: the poses, how many have k
        solutions, the statuses; never more than a few kilobytes.
        """
        from collections import Counter

        from robokin import _html

        title = f"SolutionSet [{self.method}]"
        if self.shape:
            counts = Counter(self.count.reshape(-1).tolist())
            status = Counter(str(v) for v in np.asarray(self.status).reshape(-1))
            return _html.box(
                f"{title}: {int(np.prod(self.shape)):,} poses, shape {self.shape}",
                _html.table(["solutions per pose", "poses"], sorted(counts.items())),
                _html.table(["status", "poses"], status.most_common(),
                            right=[False, True]))
        q = self.q[self.valid]
        scale = np.where(self.is_revolute, 180.0 / np.pi, 1000.0)
        unit = ["deg" if r else "mm" for r in self.is_revolute]
        flags = {k: v[self.valid] for k, v in self.flags.items()}
        branches = {k: np.asarray(v)[self.valid] for k, v in self.branches.items()}
        rows = []
        for i in range(len(q)):
            fl = [k for k, v in flags.items() if k != "within_limits" and v[i]]
            if not flags.get("within_limits", np.ones(len(q), bool))[i]:
                fl.append("outside limits")
            rows.append([i + 1, *(q[i] * scale),
                         " ".join(f"{k} {'+' if v[i] > 0 else '-'}"
                                  for k, v in branches.items()) or "-",
                         ", ".join(fl) or "-"])
        st = self.status.item() if isinstance(self.status, np.ndarray) else self.status
        return _html.box(
            f"{title}: {len(q)} solution(s), status {st}",
            _html.table(["#", *(f"q{j + 1} [{u}]" for j, u in enumerate(unit)),
                         "branch", "flags"], rows, max_rows=32))

    def __repr__(self) -> str:
        """A short summary: poses, solutions per pose, method."""
        if not self.shape:
            st = self.status.item() if isinstance(self.status, np.ndarray) else self.status
            return (f"SolutionSet({int(self.count)} solution(s), method={self.method!r}, "
                    f"status={st!r})")
        return f"SolutionSet(shape={self.shape}, counts={self.count.tolist()!r:.80})"
