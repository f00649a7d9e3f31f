"""The servo side of the MJCF export: joint map, effective inertias, physics step.

The joint map of the written model (:class:`JointMap`), the effective inertias the
default gains are tuned on, and the physics step the servos' stiffness needs.

Used by :mod:`robokin.sim.mjcf` (which re-exports :class:`JointMap`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from robokin._text import short_repr
from robokin.exceptions import InputError

F64 = npt.NDArray[np.float64]


def _mj() -> Any:
    from robokin.sim._mujoco import mujoco

    return mujoco()


@dataclass(frozen=True)
class JointMap:
    """How the robot's joint coordinates set the MuJoCo joints.

    Every MuJoCo joint robokin writes has the value ``matrix[j] @ q`` (the
    constant parts of the chain sit in the body poses).

    Attributes:
        names: The MuJoCo joints, in tree order (J).
        matrix: (J, n): each joint's value per unit of each coordinate.
        masters: Per coordinate (n), the joint whose value it is (named as the
            coordinate).
    """

    names: tuple[str, ...]
    matrix: F64
    masters: tuple[str, ...]

    def selection(self, model: Any) -> tuple[np.ndarray, np.ndarray, F64]:
        """Addresses in a compiled model and the map ``x = S q``.

        Returns:
            ``(qpos_adr (J,), dof_adr (J,), S (nv, n))``: where each joint sits in
            ``qpos`` and ``qvel``, and the matrix taking coordinates (and their
            rates) to every degree of freedom.
        """
        mj = _mj()
        ids = [mj.mj_name2id(model, mj.mjtObj.mjOBJ_JOINT, nm) for nm in self.names]
        qadr = np.array([model.jnt_qposadr[i] for i in ids], dtype=np.int64)
        dadr = np.array([model.jnt_dofadr[i] for i in ids], dtype=np.int64)
        S = np.zeros((model.nv, len(self.masters)))
        S[dadr] = self.matrix
        return qadr, dadr, S

    def qpos(self, model: Any, q: npt.ArrayLike) -> F64:
        """A full ``qpos`` (nq,) for joint coordinates ``q`` (n,)."""
        qadr, _, _ = self.selection(model)
        out = np.array(model.qpos0, dtype=np.float64)
        out[qadr] = self.matrix @ np.asarray(q, dtype=np.float64)
        return out

    def master_qpos(self, model: Any) -> np.ndarray:
        """``qpos`` addresses of the coordinates' joints, (n,)."""
        mj = _mj()
        return np.array([model.jnt_qposadr[mj.mj_name2id(model, mj.mjtObj.mjOBJ_JOINT,
                                                         nm)] for nm in self.masters],
                        dtype=np.int64)


def _effective_inertia(xml: str, joints: JointMap, q_ref: np.ndarray,
                       A: np.ndarray | None) -> tuple[F64, F64, F64]:
    """Effective inertias for the servos, and how to spread a coordinate's force.

    Returns:
        ``(inertia, weights, matrices)``: the diagonal of the mass matrix in joint
        (or motor) coordinates ``M = S^T M_x S`` (``A^T S^T M_x S A``): the inertia
        each actuator moves with the other joints held, averaged over the rows of
        ``q_ref`` (k, n); per coordinate the tendon weights over the
        MuJoCo joints (n, J), ``W = (X^T D X)^-1 X^T D`` (``x = X q`` the joint
        map, ``D`` the joints' own inertias): ``W X = I`` makes each tendon's
        length its coordinate, and its force pushes each joint in proportion to
        that joint's inertia, so a coupled joint's equality constraint barely has
        to act (forcing one light joint and letting a soft constraint drag the
        rest along is unstable); and the mass matrices in those coordinates at
        each row of ``q_ref``, (k, n, n).
    """
    from robokin.sim._mujoco import full_mass_matrix, load_model

    mj = _mj()
    model = load_model(xml)
    data = mj.MjData(model)
    _, dadr, S = joints.selection(model)
    out, diag, mats = [], [], []
    for q in np.atleast_2d(q_ref):
        data.qpos[:] = joints.qpos(model, q)
        mj.mj_forward(model, data)
        Mfull = full_mass_matrix(model, data)
        Mq = S.T @ Mfull @ S
        if A is not None:
            Mq = A.T @ Mq @ A
        out.append(np.diag(Mq).copy())
        mats.append(Mq)
        diag.append(np.diag(Mfull)[dadr])
    D = np.diag(np.mean(diag, axis=0))
    X = joints.matrix  # (J, n)
    weights = np.linalg.solve(X.T @ D @ X, X.T @ D)  # W X = I: tendon length = q
    exact = np.abs(weights - np.round(weights)) < 1e-12
    weights[exact] = np.round(weights[exact])
    return np.mean(out, axis=0), weights, np.array(mats)


#: At most this many physics steps per requested step when the servos are stiff.
MAX_SUBSTEPS = 16


def _stable_step(kp: F64, mats: F64, dt: float, names: Sequence[str]
                 ) -> tuple[float, str]:
    """The physics step: ``dt``, or a fraction of it the servos' stiffness needs.

    The servos' damping is integrated implicitly; their stiffness is not, so the
    fastest mode of ``M^-1 K`` (``M`` the mass matrix in the actuators'
    coordinates at each reference configuration, ``K = diag(kp)``) must be well
    resolved: ``omega_max step <= 0.5``. Gains tuned joint by joint on the
    diagonal of ``M`` can make a coupled mode much faster than any joint's loop
    (a heavy tip on light links); the step is then divided by the smallest
    integer that resolves it (the default 10 Hz servos on the AUBO-i5 at 1 kHz:
    0.25, no division).

    Returns:
        ``(step [s], note)``: the note says why the step was refined ("" if not).

    Raises:
        InputError: more than :data:`MAX_SUBSTEPS` divisions would be needed
            (naming ``gains``).
    """
    worst, where = 0.0, 0
    for M in mats:
        lam, vec = np.linalg.eig(np.linalg.solve(M, np.diag(kp)))
        k = int(np.argmax(lam.real))
        if lam.real[k] > worst:
            worst, where = float(lam.real[k]), int(np.argmax(np.abs(vec[:, k])))
    w_dt = math.sqrt(max(worst, 0.0)) * dt
    split = max(1, math.ceil(w_dt / 0.5 - 1e-12))
    if split > MAX_SUBSTEPS:
        raise InputError("gains", f"too stiff for a {dt:g} s step: the fastest servo "
                         f"mode (mostly {names[where]!r}) has omega dt = {w_dt:.3g}, "
                         f"more than {MAX_SUBSTEPS} substeps could resolve (lower the "
                         "gains or the step)")
    if split == 1:
        return dt, ""
    return dt / split, (f"physics step refined to {dt / split * 1e3:.4g} ms: the "
                        f"servos' fastest mode (mostly {names[where]!r}) is at "
                        f"{math.sqrt(worst) / (2 * math.pi):.3g} Hz")


def _check_q_ref(q_ref: npt.ArrayLike, n: int) -> F64:
    try:
        q = np.array(q_ref, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError("q_ref", f"expected joint values, got {short_repr(q_ref)}"
                         ) from None
    q = np.atleast_2d(q)
    if q.ndim != 2 or q.shape[1] != n or not np.isfinite(q).all():
        raise InputError("q_ref", f"expected finite (n,) or (k, n) values with n = {n}, "
                         f"got shape {q.shape}")
    return q
