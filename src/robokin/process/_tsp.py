"""The visiting order of clustered points: a generalised travelling salesman.

Each pose to visit is a *cluster*: its usable nodes (every IK solution at every
sampled tool rotation, ``_graph.Layers``). A visit picks one node per cluster; the
cost of a visiting order with its nodes is the travel between consecutive nodes
(weighted), the nodes' own costs and the approach from ``q_start``
(``robokin.process.costs``). The path is open: it starts at ``q_start`` (or
anywhere without one) and ends anywhere.

The heuristic (after Karapetyan & Gutin, "Efficient local search algorithms for
known and new neighborhoods for the generalized traveling salesman problem",
EJOR 219(2), 2012: local search over orders alternating with *cluster
optimisation*, the exact best nodes of a fixed order by dynamic programming):

1. **Nearest neighbour** in node space, from ``q_start`` (or from each of a few
   peripheral clusters): the next cluster is the one with the cheapest node.
2. **Local search with the nodes fixed**: 2-opt (reverse a stretch) and Or-opt
   (move a stretch of 1-3 clusters, either way round), first improvement.
3. **Re-insertion with node choice**: take one cluster out, put it back where it
   costs least with its best node for that place.
4. **Cluster optimisation**: the exact best node of every cluster for the order
   (``process_dp`` over the clusters in order, no step limit). 2-4 repeat until
   nothing improves.
5. **Perturbation**: a double bridge on the best order (seeded from the input),
   then 2-4 again, kept when better (iterated local search).

The lower bound is Held and Karp's 1-tree bound with subgradient optimisation
(Held & Karp, "The traveling-salesman problem and minimum spanning trees: part II",
Math. Programming 1, 1971) on the cluster graph, whose edge between two clusters is
the least distance between any of their nodes, with a depot joined to every cluster
at zero cost (the path is open), plus every cluster's cheapest node and the
cheapest approach from ``q_start``. Every visit costs at least that.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from robokin import _native
from robokin.spatial import wrap_angle

__all__ = ["Tour", "TourProblem", "double_bridge", "held_karp_bound", "improve",
           "nearest_neighbour"]

_EPS = 1e-12  # an improvement must beat this


@dataclass(frozen=True, eq=False)
class TourProblem:
    """The clusters to visit and how to measure them.

    Attributes:
        Q: Node values (P, M, n) [rad, m] (circle joints in [-pi, pi)).
        cost: Node costs (P, M) (inf: not usable).
        circle: (n,) bool: joints measured the short way round.
        weight: Cost per unit of travel.
        q_start: Start configuration (n,), or None.
        bound: Least weighted travel between any nodes of every two clusters
            (P, P) (``process_clusters``).
        near: (P, G0) each cluster's nearest clusters by ``bound``.
    """

    Q: np.ndarray
    cost: np.ndarray
    circle: np.ndarray
    weight: float
    q_start: np.ndarray | None
    bound: np.ndarray
    near: np.ndarray

    @property
    def size(self) -> int:
        """P, the clusters."""
        return int(self.cost.shape[0])

    def dist(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Largest joint change between node values a (..., n) and b (..., n)."""
        d = b - a
        d = np.where(self.circle, wrap_angle(d), d)
        return np.abs(d).max(axis=-1)

    def pairs(self, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """Weighted largest joint change between all rows: (a, n), (b, n) -> (a, b)."""
        out = np.empty((A.shape[0], B.shape[0]))
        _native.kernels.process_pairs(np.ascontiguousarray(A), np.ascontiguousarray(B),
                                      self.circle.astype(np.uint8), out)
        return self.weight * out

    def approach(self, k: int) -> np.ndarray:
        """Weighted approach from ``q_start`` to every node of cluster k (M,)."""
        if self.q_start is None:
            return np.zeros(self.cost.shape[1])
        return self.weight * self.dist(self.q_start, self.Q[k])


@dataclass(eq=False)
class Tour:
    """An order of the clusters, the node chosen in each, and what they cost.

    Attributes:
        order: Clusters in visiting order (P,).
        node: Node chosen per *cluster* (P,) (index into its M nodes).
        X: Values of the chosen nodes per cluster (P, n).
        D: Weighted travel between the chosen nodes of every two clusters (P, P).
        a: Weighted approach from ``q_start`` to each chosen node (P,) (zeros
            without).
        c: Cost of each chosen node (P,).
        DN: Weighted travel from every node of every cluster to the chosen node of
            every cluster, then from ``q_start`` (the approach; 0 without) and to
            the open end (0): (P, M, P + 2).
    """

    order: np.ndarray
    node: np.ndarray
    X: np.ndarray
    D: np.ndarray
    a: np.ndarray
    c: np.ndarray
    DN: np.ndarray

    @classmethod
    def make(cls, pb: TourProblem, order: np.ndarray, node: np.ndarray) -> Tour:
        """The tour visiting ``order`` with node ``node[k]`` in cluster k."""
        P, M, n = pb.Q.shape
        k = np.arange(P)
        X = pb.Q[k, node]
        DN = np.zeros((P, M, P + 2))
        DN[:, :, :P] = pb.pairs(pb.Q.reshape(-1, n), X).reshape(P, M, P)
        if pb.q_start is not None:
            DN[:, :, P] = pb.weight * pb.dist(pb.q_start, pb.Q)
        D = DN[k, node, :P]
        a = (np.zeros(P) if pb.q_start is None else pb.weight * pb.dist(pb.q_start, X))
        return cls(np.asarray(order).copy(), np.asarray(node).copy(), X, D, a,
                   pb.cost[k, node].copy(), DN)

    @property
    def cost(self) -> float:
        """The objective of the tour."""
        o = self.order
        return float(self.c.sum() + self.D[o[:-1], o[1:]].sum() + self.a[o[0]])

    def copy(self) -> Tour:
        """An independent copy."""
        return Tour(self.order.copy(), self.node.copy(), self.X.copy(), self.D.copy(),
                    self.a.copy(), self.c.copy(), self.DN.copy())

    def set_node(self, pb: TourProblem, k: int, u: int) -> None:
        """Choose node u in cluster k (updating the distances)."""
        P, M, n = pb.Q.shape
        self.node[k] = u
        self.X[k] = pb.Q[k, u]
        self.DN[:, :, k] = pb.pairs(pb.Q.reshape(-1, n), self.X[k:k + 1]).reshape(P, M)
        d = self.DN[np.arange(P), self.node, k]
        self.D[k, :] = d
        self.D[:, k] = d
        self.D[k, k] = 0.0
        if pb.q_start is not None:
            self.a[k] = pb.weight * float(pb.dist(pb.q_start, self.X[k]))
        self.c[k] = pb.cost[k, u]


def nearest_neighbour(pb: TourProblem, first: int | None) -> Tour:
    """Greedy in node space from ``q_start`` (``first`` None) or from cluster ``first``."""
    P = pb.size
    left = np.ones(P, dtype=bool)
    order = []
    node = np.zeros(P, dtype=np.int64)
    if first is None:  # from q_start (the caller passes a cluster without one)
        x = pb.q_start if pb.q_start is not None else pb.Q[0, 0]
        gain = pb.weight * pb.dist(x, pb.Q) + pb.cost  # (P, M)
        k, u = (int(v) for v in np.unravel_index(int(np.argmin(gain)), gain.shape))
    else:
        k = first
        u = int(np.argmin(pb.cost[k] + pb.approach(k)))
    while True:
        order.append(int(k))
        node[k] = int(u)
        left[k] = False
        if not left.any():
            break
        rest = np.flatnonzero(left)
        g = pb.weight * pb.dist(pb.Q[k, u], pb.Q[rest]) + pb.cost[rest]
        r, u = (int(v) for v in np.unravel_index(int(np.argmin(g)), g.shape))
        k = int(rest[r])
    return Tour.make(pb, np.array(order), node)


def two_opt(pb: TourProblem, t: Tour) -> bool:
    """Best-improvement 2-opt (nodes fixed): reverse t.order[i..j]; True if improved."""
    o = t.order
    P = o.size
    if P < 2:
        return False
    i, j = np.triu_indices(P, k=1)
    # the edge into the stretch (o[i-1], o[i]) -> (o[i-1], o[j]); at i = 0 the approach
    im = np.maximum(i - 1, 0)
    before = np.where(i > 0, t.D[o[im], o[j]] - t.D[o[im], o[i]], t.a[o[j]] - t.a[o[i]])
    jn = np.minimum(j + 1, P - 1)
    after = np.where(j < P - 1, t.D[o[i], o[jn]] - t.D[o[j], o[jn]], 0.0)
    delta = before + after
    b = int(np.argmin(delta))
    if delta[b] < -_EPS:
        ib, jb = int(i[b]), int(j[b])
        t.order[ib:jb + 1] = o[ib:jb + 1][::-1].copy()
        return True
    return False


def _extended(t: Tour) -> tuple[np.ndarray, np.ndarray]:
    """The order between a START (index P) and an END (P + 1), and the edge costs.

    Returns ``(seq (P + 2,), E (P + 2, P + 2))``: ``E[START, x]`` is the approach
    to x, ``E[x, END]`` is 0 (the path is open).
    """
    P = t.order.size
    E = np.zeros((P + 2, P + 2))
    E[:P, :P] = t.D
    E[P, :P] = t.a
    seq = np.concatenate([[P], t.order, [P + 1]])
    return seq, E


def _without(seq: np.ndarray, first: np.ndarray, length: int) -> np.ndarray:
    """Per start position i (k,), ``seq`` without positions i .. i + length - 1."""
    m = seq.size - length
    j = np.arange(m)[None, :]
    return seq[j + np.where(j >= first[:, None], length, 0)]


def or_opt(pb: TourProblem, t: Tour) -> bool:
    """Best-improvement Or-opt: move a stretch of 1-3 clusters, either way round."""
    P = t.order.size
    seq, E = _extended(t)
    best, move = -_EPS, None
    for length in (1, 2, 3):
        if length >= P:
            break
        i = np.arange(1, P - length + 2)  # stretch at seq[i .. i + length - 1]
        f, last = seq[i], seq[i + length - 1]
        removal = (E[seq[i - 1], seq[i + length]] - E[seq[i - 1], f]
                   - E[last, seq[i + length]])
        rest = _without(seq, i, length)  # (k, P + 2 - length)
        a, b = rest[:, :-1], rest[:, 1:]  # gaps q = 1 .. : between a and b
        gap = E[a, b]
        for rev, (x, y) in enumerate(((f, last), (last, f))):
            delta = removal[:, None] + E[a, x[:, None]] + E[y[:, None], b] - gap
            m = int(np.argmin(delta))
            if delta.flat[m] < best:
                r, q = (int(v) for v in np.unravel_index(m, delta.shape))
                best, move = float(delta.flat[m]), (length, int(i[r]), rev, q + 1)
    if move is None:
        return False
    length, i0, rev, q = move
    rest = _without(seq, np.array([i0]), length)[0]
    stretch = seq[i0:i0 + length][::-1] if rev else seq[i0:i0 + length]
    t.order = np.concatenate([rest[1:q], stretch, rest[q:-1]])
    return True


def reinsert(pb: TourProblem, t: Tour) -> bool:
    """Best-improvement re-insertion of one cluster with its best node for the place.

    The places tried for cluster k are next to its ``near`` clusters (either side),
    the start and the open end: a neighbour list, as in Lin-Kernighan's candidates.
    """
    P = t.order.size
    if P < 2:
        return False
    seq, E = _extended(t)
    i = np.arange(1, P + 1)
    k = seq[i]
    removal = E[seq[i - 1], seq[i + 1]] - E[seq[i - 1], k] - E[k, seq[i + 1]] - t.c[k]
    rest = _without(seq, i, 1)  # (P, P + 1): START, the others, END
    pos = np.empty(P, dtype=np.int64)
    pos[t.order] = np.arange(P)
    near = pb.near[k]  # (P, G0)
    r = pos[near] - (pos[near] > pos[k][:, None])  # their positions without k
    R = P - 1  # gap g lies between rest[:, g] and rest[:, g + 1], g = 0 .. R
    gaps = np.concatenate([np.zeros((P, 1), np.int64), np.full((P, 1), R), r, r + 1],
                          axis=1)
    rows = np.arange(P)[:, None]
    a, b = rest[rows, gaps], rest[rows, gaps + 1]  # (P, G), rows in visiting order
    by = pos  # rows of cluster c: visiting position pos[c]
    a, b, removal, gaps = a[by], b[by], removal[by], gaps[by]
    delta = (removal[:, None, None] + pb.cost[:, :, None]
             + np.take_along_axis(t.DN, a[:, None, :], axis=2)
             + np.take_along_axis(t.DN, b[:, None, :], axis=2)
             - E[a, b][:, None, :])  # (P clusters, M, G)
    m = int(np.argmin(delta))
    if not delta.flat[m] < -_EPS:
        return False
    c, u, g = (int(x) for x in np.unravel_index(m, delta.shape))
    q, w = int(gaps[c, g]), int(pos[c])
    t.order = np.concatenate([rest[w, 1:q + 1], [c], rest[w, q + 1:-1]])
    t.set_node(pb, c, int(u))
    return True


def improve(pb: TourProblem, t: Tour, best_nodes: Callable[[np.ndarray], np.ndarray],
            max_rounds: int = 100) -> Tour:
    """Local search to a local optimum: moves, then the exact nodes, repeated."""
    for _ in range(max_rounds):
        before = t.cost
        while two_opt(pb, t) or or_opt(pb, t) or reinsert(pb, t):
            pass
        node = best_nodes(t.order)
        if np.any(node != t.node):
            opt = t.copy()
            for k in np.flatnonzero(node != t.node):
                opt.set_node(pb, int(k), int(node[k]))
            if opt.cost < t.cost - _EPS:
                t = opt
        if t.cost >= before - _EPS:
            break
    return t


def double_bridge(t: Tour, rng: np.random.Generator) -> Tour:
    """The classic 4-opt kick: A B C D -> A C B D (cut points inside the path)."""
    P = t.order.size
    if P < 8:
        idx = rng.permutation(P)
    else:
        a, b, c = np.sort(rng.choice(np.arange(1, P), size=3, replace=False))
        idx = np.r_[np.arange(a), np.arange(b, c), np.arange(a, b), np.arange(c, P)]
    out = t.copy()
    out.order = t.order[idx]
    return out


def held_karp_bound(D: np.ndarray, upper: float, iterations: int = 300) -> float:
    """Held-Karp 1-tree bound of an open path through P clusters.

    Args:
        D: Symmetric least distances between clusters (P, P) (weighted).
        upper: A known path cost (the subgradient step's target).
        iterations: Subgradient steps.

    Returns:
        A lower bound on the cost of every Hamiltonian path through the clusters
        (the depot, joined to all at zero cost, closes it into a tour).
    """
    P = D.shape[0]
    if P <= 1:
        return 0.0
    V = P + 1
    C = np.zeros((V, V))
    C[:P, :P] = D
    pi = np.zeros(V)
    best = -math.inf
    lam, stall = 2.0, 0
    for _ in range(iterations):
        W = C + pi[:, None] + pi[None, :]
        value, degree = _one_tree(W)
        value -= 2.0 * float(pi.sum())
        if value > best + 1e-12:
            best, stall = value, 0
        else:
            stall += 1
            if stall >= 20:
                lam, stall = lam / 2.0, 0
        g = degree - 2.0
        norm = float(g @ g)
        if norm == 0.0 or lam < 1e-6:
            break
        pi += lam * max(upper - value, 1e-9) / norm * g
    return max(best, 0.0)


def _one_tree(W: np.ndarray) -> tuple[float, np.ndarray]:
    """Minimum 1-tree of the complete graph W (V, V), the depot its last node.

    A spanning tree of the other nodes (Prim) plus the depot's two cheapest edges.
    Returns (cost, degrees).
    """
    V = W.shape[0]
    depot = V - 1
    others = np.arange(V - 1)
    degree = np.zeros(V)
    in_tree = np.zeros(V - 1, dtype=bool)
    in_tree[0] = True
    best = W[0, others].copy()
    parent = np.zeros(V - 1, dtype=np.int64)
    total = 0.0
    for _ in range(V - 2):
        cand = np.where(in_tree, np.inf, best)
        v = int(np.argmin(cand))
        total += float(cand[v])
        degree[v] += 1
        degree[parent[v]] += 1
        in_tree[v] = True
        closer = W[v, others] < best
        best = np.where(closer, W[v, others], best)
        parent = np.where(closer, v, parent)
    e = W[depot, others]
    two = np.argsort(e, kind="stable")[:2]
    total += float(e[two].sum())
    degree[two] += 1
    degree[depot] = 2
    return total, degree
