"""Proposing a motion through a workspace paving: a shortest box path, its waypoints, and smoothing.

Nothing here certifies anything: the paving only PROPOSES the path, which
:func:`intervalkin.space.segment.certify_segment` then proves segment by segment.

1. Box path.  Dijkstra's search (scipy; exact for its metric) in the face-adjacency graph of the
   paving boxes certified INSIDE the aspect, from the box nearest the start
   pose to the box nearest the goal.  Edge weight: the distance of the box
   centres in the metric ``sqrt(dx^2 + dy^2 + (L dphi)^2)``, dphi taken modulo
   2 pi and L the root-mean-square distance of the platform points from B1
   (so a rotation costs about what it moves the platform).
2. Waypoints: the centre of the face piece shared by each pair of
   consecutive boxes, so that each straight segment between waypoints lies in
   one certified box.  phi is UNWRAPPED along the path: a box reached across
   the seam phi = +-pi is shifted by 2 pi, and the goal is met at its phi plus
   2 pi ``turns``.
3. Smoothing: a waypoint is dropped when the straight segment that skips it
   keeps to boxes certified in the aspect (a float look along it) and is
   itself certified; the farthest such waypoint is found by doubling the jump,
   then bisecting.

:class:`LeafIndex` finds the leaf holding each point, for the smoothing and for
the regions crossed by the path.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import PI_HI
from intervalkin.kinematics.formulas import approx_det_a, approx_inverse_kinematics
from intervalkin.paving.labels import Label
from intervalkin.paving.tree import Paving
from intervalkin.solve.continuation import shift_phi_boxes
from intervalkin.space.segment import certify_segment

__all__ = ['metric_length', 'wrap_phi', 'path_distance', 'shortest_box_path', 'crossing_waypoints', 'goal_turns',
           'shift_phi', 'smooth_waypoints', 'LeafIndex', 'sample_path']


# --------------------------------------------------------------------------------------
# Shortest path in the box graph
# --------------------------------------------------------------------------------------
def metric_length(geometry: Geometry) -> float:
    """L: root-mean-square distance of the three platform points from B1."""
    return math.sqrt(sum(float(geometry.platform_radius_sq(i)) for i in range(3)) / 3.0)


def wrap_phi(d: np.ndarray) -> np.ndarray:
    """d modulo 2 pi into [-pi, pi)."""
    return np.mod(d + math.pi, math.tau) - math.pi


def path_distance(a: np.ndarray, b: np.ndarray, L: float) -> np.ndarray:
    """sqrt(dx^2 + dy^2 + (L dphi)^2) between poses a and b (..., 3), dphi modulo 2 pi."""
    dphi = wrap_phi(b[..., 2] - a[..., 2])
    return np.sqrt((b[..., 0] - a[..., 0]) ** 2 + (b[..., 1] - a[..., 1]) ** 2 + (L * dphi) ** 2)


def _point_box_distance(p: np.ndarray, lo: np.ndarray, hi: np.ndarray, L: float) -> np.ndarray:
    dx = np.maximum(np.maximum(lo[:, 0] - p[0], p[0] - hi[:, 0]), 0.0)
    dy = np.maximum(np.maximum(lo[:, 1] - p[1], p[1] - hi[:, 1]), 0.0)
    best = np.full(lo.shape[0], np.inf)
    for shift in (-math.tau, 0.0, math.tau):
        ph = p[2] + shift
        best = np.minimum(best, np.maximum(np.maximum(lo[:, 2] - ph, ph - hi[:, 2]), 0.0))
    return np.sqrt(dx * dx + dy * dy + (L * best) ** 2)


def shortest_box_path(paving: Paving, edges: np.ndarray, name: str, start: np.ndarray, goal: np.ndarray,
                       L: float) -> np.ndarray | None:
    """Indices of the boxes of a shortest path (face contacts weighted by :func:`path_distance` between box
    centres), or None when start and goal are not connected.  ``edges``: the face contacts of the paving, each
    once (:func:`~intervalkin.paving.adjacency.shares_face`).  Dijkstra's search in scipy (compiled): on the
    paper's depth-8 aspects about 1 s a path, mostly building the graph, against 3 to 5.5 s for the pure-Python
    A* before it."""
    inside = paving.labels[name] == Label.INSIDE
    nodes = np.flatnonzero(inside)
    if nodes.size == 0:
        return None
    lo, hi = paving.lo[nodes], paving.hi[nodes]
    centre = 0.5 * (lo + hi)
    s = int(np.argmin(_point_box_distance(start, lo, hi, L)))
    t = int(np.argmin(_point_box_distance(goal, lo, hi, L)))
    if s == t:
        return nodes[[s]]
    local = np.full(len(paving), -1, dtype=np.int64)
    local[nodes] = np.arange(nodes.size)
    e = edges[:, inside[edges[0]] & inside[edges[1]]]
    # csr_matrix adds up repeated entries: the contacts of shares_face are listed once each, as needed here (a
    # contact given twice would only weigh double; the path proposed would still be a chain of contacts)
    u, v = local[e[0]], local[e[1]]
    graph = csr_matrix((path_distance(centre[u], centre[v], L), (u, v)), shape=(nodes.size, nodes.size))
    dist, prev = dijkstra(graph, directed=False, indices=s, return_predecessors=True)
    if not np.isfinite(dist[t]):
        return None
    path = [t]
    while path[-1] != s:
        path.append(int(prev[path[-1]]))
    return nodes[np.array(path[::-1], dtype=np.int64)]


def crossing_waypoints(paving: Paving, path: np.ndarray, start_phi: float) -> tuple[np.ndarray, np.ndarray]:
    """Centres of the shared face pieces along a box path, phi unwrapped; also each box's phi offset."""
    lo, hi = paving.lo[path], paving.hi[path]
    offs = np.zeros(len(path))
    c0 = 0.5 * (lo[0, 2] + hi[0, 2])
    offs[0] = math.tau * round((start_phi - c0) / math.tau)
    points = []
    for k in range(len(path) - 1):
        a_lo, a_hi, b_lo, b_hi = lo[k], hi[k], lo[k + 1], hi[k + 1]
        shift = 0.0
        if a_hi[2] == PI_HI and b_lo[2] == -PI_HI and not (b_lo[2] <= a_hi[2] and a_lo[2] <= b_hi[2]):
            shift = math.tau  # across the seam upward
        elif b_hi[2] == PI_HI and a_lo[2] == -PI_HI and not (b_lo[2] <= a_hi[2] and a_lo[2] <= b_hi[2]):
            shift = -math.tau
        offs[k + 1] = offs[k] + shift
        b_lo_u = b_lo.copy()
        b_hi_u = b_hi.copy()
        b_lo_u[2] += offs[k + 1] - offs[k]
        b_hi_u[2] += offs[k + 1] - offs[k]
        # in a's frame: the shared piece is the intersection of the two closed boxes
        p_lo = np.maximum(a_lo, b_lo_u)
        p_hi = np.minimum(a_hi, b_hi_u)
        p = 0.5 * (p_lo + p_hi)
        p[2] += offs[k]
        points.append(p)
    return np.array(points).reshape(-1, 3), offs


def goal_turns(goal_phi: float, last_centre_phi: float) -> int:
    """The number of turns k that brings goal_phi + 2 pi k nearest the phi reached by the path."""
    return int(round((last_centre_phi - goal_phi) / math.tau))


def shift_phi(box: np.ndarray, turns: int) -> np.ndarray:
    """The enclosure box (3, 2) with phi + 2 pi turns, rounded outward (the box itself for 0 turns)."""
    if turns == 0:
        return box.copy()
    lo, hi = shift_phi_boxes(box[None, :, 0], box[None, :, 1], np.array([turns]))
    return np.stack([lo[0], hi[0]], axis=1)


# --------------------------------------------------------------------------------------
# Smoothing
# --------------------------------------------------------------------------------------
def smooth_waypoints(geometry: Geometry, ends: list[np.ndarray], sign: int, quick: int,
                     leaves: LeafIndex, name: str) -> list[int]:
    """Indices of the waypoints kept: from each kept one, jump to the farthest acceptable one.

    A shortcut is acceptable when points sampled along it (steps below half the
    finest leaf width) all lie in boxes certified INSIDE the aspect, so the path
    keeps to the certified part of the paving (some clearance from det A = 0,
    readable region sequences), AND the segment is certified (the proof).  The
    farthest is searched by doubling the jump then bisecting, assuming (not
    requiring) monotonicity; a failed guess only costs length.
    """
    paving = leaves.paving
    inside = paving.labels[name] == Label.INSIDE
    step = (paving.domain[:, 1] - paving.domain[:, 0]) / (1 << paving.depth) / 2
    m = len(ends)
    mids = [0.5 * (e[:, 0] + e[:, 1]) for e in ends]
    lo_lim = np.array([float(v) for v in geometry.rho_min])
    hi_lim = np.array([float(v) for v in geometry.rho_max])

    def ok(i: int, j: int) -> bool:
        # a float look first (a heuristic filter only: it never certifies anything)
        n = int(np.ceil(np.max(np.abs(mids[j] - mids[i]) / step))) + 2
        t = np.linspace(0.0, 1.0, n)[:, None]
        pts = mids[i] + t * (mids[j] - mids[i])
        leaf = leaves.lookup(pts)
        if np.any(leaf < 0) or not np.all(inside[leaf]):
            return False
        if np.any(sign * approx_det_a(geometry, pts) <= 0):
            return False
        r = approx_inverse_kinematics(geometry, pts)
        if np.any(r < lo_lim) or np.any(r > hi_lim):
            return False
        return certify_segment(geometry, ends[i], ends[j], sign, max_bisections=quick, max_pieces=4096).certified

    kept = [0]
    i = 0
    while i < m - 1:
        if ok(i, m - 1):
            kept.append(m - 1)
            break
        good, step = i + 1, 1
        bad = m - 1
        while good + step < m - 1:
            if ok(i, good + step):
                good += step
                step *= 2
            else:
                bad = good + step
                break
        while bad - good > 1:
            mid = (good + bad) // 2
            if ok(i, mid):
                good = mid
            else:
                bad = mid
        kept.append(good)
        i = good
    return kept


# --------------------------------------------------------------------------------------
# Points along the path, and the leaves that hold them
# --------------------------------------------------------------------------------------
class LeafIndex:
    """Finds the leaf of a paving that holds each point (sorted integer keys per level)."""

    def __init__(self, paving: Paving):
        self.paving = paving
        d = paving.depth
        self.nb = d + 1
        self.levels = []
        for L in range(d + 1):
            sel = np.flatnonzero(paving.level == L)
            if sel.size == 0:
                continue
            ijk = paving.ijk[sel]
            keys = (ijk[:, 0] << (2 * self.nb)) | (ijk[:, 1] << self.nb) | ijk[:, 2]
            order = np.argsort(keys)
            self.levels.append((L, keys[order], sel[order]))

    def lookup(self, points: np.ndarray) -> np.ndarray:
        """Leaf index of each point (x, y, phi; phi any real, wrapped here), -1 outside the domain."""
        p = self.paving
        d = p.depth
        n = 1 << d
        pts = np.array(points, dtype=np.float64, copy=True).reshape(-1, 3)
        pts[:, 2] = wrap_phi(pts[:, 2])
        width = p.domain[:, 1] - p.domain[:, 0]
        f = np.floor((pts - p.domain[:, 0]) / (width / n)).astype(np.int64)
        ok = np.all((f >= 0) & (f < n), axis=1)
        f = np.clip(f, 0, n - 1)
        out = np.full(pts.shape[0], -1, dtype=np.int64)
        for L, ks, idx in self.levels:
            g = f >> (d - L)
            q = (g[:, 0] << (2 * self.nb)) | (g[:, 1] << self.nb) | g[:, 2]
            pos = np.minimum(np.searchsorted(ks, q), ks.size - 1)
            hit = (ks[pos] == q) & ok & (out < 0)
            out[hit] = idx[pos[hit]]
        return out


def sample_path(waypoints: np.ndarray, step: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points along each segment with every coordinate step below ``step``; segment index of each."""
    pts, seg = [], []
    for k in range(len(waypoints) - 1):
        a, b = waypoints[k], waypoints[k + 1]
        n = int(np.ceil(np.max(np.abs(b - a) / step))) + 1
        t = np.linspace(0.0, 1.0, max(n, 2) + 1)
        if k < len(waypoints) - 2:
            t = t[:-1]
        pts.append(a + t[:, None] * (b - a))
        seg.append(np.full(t.size, k))
    return np.concatenate(pts), np.concatenate(seg)
