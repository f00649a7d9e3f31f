"""An independent, slow reference for process paths: the sampled graph built from
``robot.ik`` and numpy alone, and its exact shortest path by dense dynamic
programming (every pair of configurations of consecutive waypoints compared).

Nothing here calls the compiled process kernels: the configurations are every IK
solution of every sampled tool pose with *every* whole-turn equivalent inside the
limits listed explicitly (so steps need no wrapping), manipulability comes from
``robot.manipulability`` (an SVD), and the cost formulas of
``robokin.process.costs`` are written out again. Used by ``tests/process``.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from robokin.spatial import rotz


def ramp(x, margin):
    """((m - x) / m)^2 below the margin, 0 above (x clipped at 0)."""
    x = np.asarray(x, dtype=float)
    if margin <= 0:
        return np.zeros_like(x)
    r = (margin - np.maximum(x, 0.0)) / margin
    return np.where(x < margin, r * r, 0.0)


def configurations(robot, T, angles, *, mu_ref, singular_tol=1e-3):
    """Every usable configuration of pose T at each tool rotation: (q (m, n), angle (m,)).

    Whole-turn equivalents of revolute joints inside the limits are separate rows.
    """
    lim = robot.limits
    rev = robot.is_revolute
    rows, ang = [], []
    for a in angles:
        sols = robot.ik(T @ rotz(a))
        for q, sing in zip(sols.q[sols.valid], sols.singular[sols.valid], strict=True):
            if sing:
                continue
            choices = []
            for j in range(robot.n):
                if rev[j]:
                    w = (q[j] + np.pi) % (2 * np.pi) - np.pi
                    ks = range(-4, 5)
                    vals = [w + 2 * np.pi * k for k in ks]
                    vals = [v for v in vals if lim[j, 0] - 1e-9 <= v <= lim[j, 1] + 1e-9]
                else:
                    vals = [q[j]] if lim[j, 0] - 1e-9 <= q[j] <= lim[j, 1] + 1e-9 else []
                choices.append(vals)
            for combo in itertools.product(*choices):
                rows.append(combo)
                ang.append(a)
    q = np.array(rows, dtype=float).reshape(-1, robot.n)
    ang = np.array(ang, dtype=float)
    if q.shape[0]:
        mu = robot.manipulability(q) / mu_ref
        keep = mu >= singular_tol
        q, ang = q[keep], ang[keep]
    return q, ang


M_LIM = math.radians(5)


def node_costs(robot, q, *, mu_ref, w_sing=0.1, m_sing=0.05, w_lim=0.1, m_lim=M_LIM):
    """The node term of the objective for configurations q (m, n)."""
    if q.shape[0] == 0:
        return np.zeros(0)
    lim = robot.limits
    mu = robot.manipulability(q) / mu_ref
    dist = np.minimum(q - lim[:, 0], lim[:, 1] - q)
    return w_sing * ramp(mu, m_sing) + w_lim * ramp(dist, m_lim).sum(axis=1)


def shortest_path(layers, costs, *, max_step, weight=1.0, q_start=None):
    """Exact layered shortest path by dense DP.

    Args:
        layers: per waypoint an (m_i, n) array of configurations.
        costs: per waypoint (m_i,) node costs.

    Returns:
        (cost, [index per layer]) or (inf, None) when no path exists.
    """
    V = costs[0].copy()
    if q_start is not None:
        V = V + weight * np.abs(layers[0] - q_start).max(axis=1)
    preds = []
    for a, b, cb in zip(layers[:-1], layers[1:], costs[1:], strict=True):
        newV = np.full(b.shape[0], np.inf)
        pred = np.full(b.shape[0], -1)
        for s in range(0, b.shape[0], 256):
            step = np.abs(b[s:s + 256, None, :] - a[None, :, :]).max(axis=2)
            tot = np.where(step <= max_step, V[None, :] + weight * step, np.inf)
            k = np.argmin(tot, axis=1)
            newV[s:s + 256] = tot[np.arange(tot.shape[0]), k] + cb[s:s + 256]
            pred[s:s + 256] = np.where(np.isfinite(tot[np.arange(tot.shape[0]), k]), k, -1)
        preds.append(pred)
        V = newV
    if not np.isfinite(V).any():
        return math.inf, None
    i = int(np.argmin(V))
    path = [i]
    for pred in reversed(preds):
        i = int(pred[i])
        path.append(i)
    return float(V.min()), path[::-1]


def objective(robot, q, *, mu_ref, weight=1.0, q_start=None, **kw):
    """The objective of a motion q (N, n)."""
    c = float(node_costs(robot, q, mu_ref=mu_ref, **kw).sum())
    c += weight * float(np.abs(np.diff(q, axis=0)).max(axis=1).sum())
    if q_start is not None:
        c += weight * float(np.abs(q[0] - q_start).max())
    return c
