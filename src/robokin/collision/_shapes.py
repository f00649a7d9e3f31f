"""Per-shape constants of the compiled collision check, and collision intervals.

Pure functions of one shape (or of the per-sample results) used by
:class:`robokin.collision._problem._Problem`: the segment of a capsule or sphere
(closed-form distances), the rounded box bounding a shape (broad phase), whether
the last joint moving a link turns a shape onto itself (motion bounds), and the
grouping of colliding samples into :class:`~robokin.collision.report.Interval`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING

import numpy as np

from robokin.collision.report import Interval

if TYPE_CHECKING:
    from robokin.model.chain import Chain
    from robokin.model.geometry import Shape


def segment_of(sh: Shape) -> tuple[np.ndarray | None, float]:
    """A sphere's or capsule's axis segment (2, 3) in its link frame and its radius.

    Other shapes: ``(None, 0.0)`` (no closed-form distance).
    """
    if sh.kind == "sphere":
        c = sh.placement[:3, 3]
        return np.stack([c, c]), float(sh.size[0])
    if sh.kind == "capsule":
        h = sh.size[1] / 2 * sh.placement[:3, 2]
        c = sh.placement[:3, 3]
        return np.stack([c - h, c + h]), float(sh.size[0])
    return None, 0.0


def rounded_box(sh: Shape) -> tuple[np.ndarray, np.ndarray, float]:
    """A box with rounded edges containing the shape: pose (4, 4), half sizes (3,), radius."""
    k, sz = sh.kind, sh.size
    T = np.array(sh.placement)
    if k == "capsule":
        return T, np.array([0.0, 0.0, sz[1] / 2]), float(sz[0])
    if k == "sphere":
        return T, np.zeros(3), float(sz[0])
    c, h = sh.local_box()
    T[:3, 3] = T[:3, :3] @ c + T[:3, 3]
    return T, np.array(h, dtype=float), 0.0


def spins_about_last_joint(shape: Shape, k: int, chain: Chain) -> bool:
    """True when the last joint moving link k turns ``shape`` onto itself.

    A sphere centred on that revolute joint's axis, or a cylinder or capsule
    along it, does not move when the joint turns.
    """
    nc = chain.n_chain
    kk = min(k, nc)
    if kk == 0 or chain.joints[kk - 1].kind != "revolute":
        return False
    if shape.kind not in ("sphere", "cylinder", "capsule"):
        return False
    T = chain.frame_offsets[kk - 1]
    if k == nc + 1:
        T = T @ chain.link_offsets[nc - 1] @ chain.tool
    inv = np.linalg.inv(T)  # the joint's axis in the link frame
    p0, axis = inv[:3, 3], inv[:3, 2]
    c = shape.placement[:3, 3]
    off = (c - p0) - np.dot(c - p0, axis) * axis
    if np.linalg.norm(off) > 1e-9:
        return False
    if shape.kind == "sphere":
        return True
    return bool(np.linalg.norm(np.cross(shape.placement[:3, 2], axis)) < 1e-9)


def collision_intervals(mask: np.ndarray, bmask: np.ndarray,
                        bfrac: Mapping[int, tuple[float, float]], per_sample: np.ndarray,
                        ba: str, bb: str, t_at: Callable[..., float]) -> list[Interval]:
    """Group colliding samples and between-sample hits into intervals.

    Positions 2i are samples, 2i + 1 the motion from sample i to i + 1.
    """
    m = len(mask)
    seq = np.zeros(2 * m - 1, dtype=bool)
    seq[0::2] = mask
    if m > 1:
        seq[1::2] = bmask | (mask[:-1] & mask[1:])
    out: list[Interval] = []
    edges = np.flatnonzero(np.diff(np.concatenate([[0], seq.astype(np.int8), [0]])))
    for s, e in zip(edges[0::2], edges[1::2] - 1):
        s, e = int(s), int(e)
        dvals = [float(per_sample[k // 2]) for k in range(s, e + 1) if k % 2 == 0]
        dvals += [
            bfrac[k // 2][1] for k in range(s, e + 1) if k % 2 and (k // 2) in bfrac
        ]
        t0 = t_at(s // 2) if s % 2 == 0 else t_at(s // 2, bfrac[s // 2][0])
        t1 = t_at(e // 2) if e % 2 == 0 else t_at(e // 2, bfrac[e // 2][0])
        only_between = s == e and s % 2 == 1
        out.append(
            Interval(s // 2, (e + 1) // 2, ba, bb, t0, t1, min(dvals), only_between)
        )
    return out
