"""Fold models of joint boxes: one sheet of g(S) as a certified graph, cutting the box in two.

The claim
---------
Let R = R_1 x R_2 x R_3 be a joint box that is not clear (:mod:`intervalkin.solve.joint_box`),
k one of its axes and (i, j) the other two.  Every singular pose X with g(X) in R lies
in the pose boxes of the torus cells that the clear-box search left live; let X be a
pose box holding all of them.  Consider, for p = (r_i, r_j) in R_i x R_j, the system

    E(X; p) = ( rho_i^2(X) - r_i^2,  rho_j^2(X) - r_j^2,  det A(X) ) = 0

(the singular poses of the four-bar with legs i and j of lengths r_i, r_j).  If the
parametric Krawczyk operator

    K = m - Y E(m; R_i x R_j) + (I - Y E'(X)) (X - m)        (E' does not depend on p)

lies in the interior of X, then for EVERY p the system has exactly one zero X*(p) in X,
every matrix of E'(X) is regular, and X*(p) is C^1 in p (implicit function theorem).
So on every line of R parallel to axis k there is at most one point of g(S), at
h(p) = rho_k(X*(p)): g(S) meets R in the graph of a continuous function, and R minus
g(S) is the union of B = {q_k < h} and T = {q_k > h}.  B and T are each connected (or
empty) when either

* the enclosure of h over R_i x R_j (rho_k over K) lies strictly inside R_k (then B
  holds the face q_k = lo and T the face q_k = hi, and every point joins its face along
  a line parallel to axis k), or
* dh/dr_i and dh/dr_j have certified signs: the normal of g(S) at g(X), X singular, is
  (rho_1 w_1, rho_2 w_2, rho_3 w_3) with w = (u_2 x u_3, u_3 x u_1, u_1 x u_2) and
  u_l = B_l - A_l (the left null vector of A), so dh/dr_i = -rho_i w_i / (rho_k w_k);
  signs of w_i, w_j, w_k certified on K give them.  Then B is monotone towards one corner
  of R_i x R_j, and every point of B joins the line over that corner (nested
  monotonicity), which meets B in one segment; the same for T; or
* dh/dr_b has a certified sign for one parameter b, and h stays above lo_k on the edge
  of R_i x R_j where h is largest along b (below hi_k on the opposite edge): every point
  of B moves along b to that edge's face, then down to the edge, which lies in B.

The two pieces have different counts (X*(p) is a fold point of g: E' regular means the
kernel of A is transverse to S), and a point q of R off g(S) is placed in B or T by a
Krawczyk step at the point parameter (q_i, q_j) (:func:`side_of`).
See proofs/lemma-fold-joint-box.md.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import Interval
from intervalkin.kinematics.enclosures import (det_a_gradient_interval, jacobian_interval, rho_sq_interval,
                                               rho_sq_leg_interval)
from intervalkin.kinematics.point_enclosures import rho_sq_det_at
from intervalkin.solve.pose_hull import pose_hulls

__all__ = ["FoldModels", "fold_models", "side_of", "pose_hulls", "krawczyk_image", "normal_signs", "height_slopes", "preconditioned", "SIDE_STEPS"]

#: Krawczyk rounds before a box is given up: the first shrink the pose box to its intersection with
#: the images, the last INFLATE_ROUNDS grow it to the hull of the box and the images (plus a margin).
ROUNDS = 6
INFLATE_ROUNDS = 2
#: Krawczyk steps of the side test (each one shrinks the enclosure of X*(q) by about the norm of C).
SIDE_STEPS = 4
_CHUNK = 32768
#: Points of a side test evaluated together (a few MB of temporaries: they stay in cache).
_SIDE_CHUNK = 16384


@dataclass(frozen=True, eq=False)
class FoldModels:
    """Fold models of n joint boxes (entries where ``ok`` is False carry no claim).

    ok : (n,) bool, a model is proved for the box.
    axis : (n,) int8, the axis k along which g(S) is a graph (-1: no model).
    pose : (n, 3, 2) the Krawczyk box X (holds every singular pose with g(X) in the box,
        and exactly one zero X*(p) for each p).
    height : Interval (n,), an enclosure of h = rho_k(X*(p)) over all p.
    inv : (n, 3, 3) the float preconditioner Y of the proof (reused by the side test).
    contraction : Interval (n, 3, 3), C = I - Y E'(X) over the pose box (reused by the side test).
    void : (n,) bool, the box is proved to hold no singular pose (clear; ``ok`` is False there).
    """

    ok: np.ndarray
    axis: np.ndarray
    pose: np.ndarray
    height: Interval
    inv: np.ndarray
    contraction: Interval
    void: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.ok)

    def take(self, rows: np.ndarray) -> "FoldModels":
        """The models of the given rows, in that order."""
        return FoldModels(self.ok[rows], self.axis[rows], self.pose[rows], self.height[rows], self.inv[rows],
                          self.contraction[rows], None if self.void is None else self.void[rows])

    def concat(self, other: "FoldModels") -> "FoldModels":
        def cat(a, b):
            return np.concatenate([a, b])
        return FoldModels(cat(self.ok, other.ok), cat(self.axis, other.axis), cat(self.pose, other.pose),
                          Interval(cat(self.height.lo, other.height.lo), cat(self.height.hi, other.height.hi)),
                          cat(self.inv, other.inv),
                          Interval(cat(self.contraction.lo, other.contraction.lo),
                                   cat(self.contraction.hi, other.contraction.hi)),
                          None if self.void is None or other.void is None else cat(self.void, other.void))


def _gradients(geometry: Geometry, X: np.ndarray) -> tuple[Interval, Interval]:
    """(A, grad det A) over pose boxes X: every row E' may take, for any axis."""
    return jacobian_interval(geometry, X), det_a_gradient_interval(geometry, X)


def _values(geometry: Geometry, m: np.ndarray) -> tuple[Interval, Interval]:
    """(rho_l^2, det A) at float poses m (n, 3), enclosed."""
    return rho_sq_det_at(geometry, m)


def _residual(values: tuple[Interval, Interval], k: int, P: Interval) -> Interval:
    """E(m; P) from the values at m, for parameter boxes P (n, 2) of (r_i, r_j)."""
    e, d = values
    i, j = [a for a in range(3) if a != k]
    ri, rj = e[:, i] - P[:, 0].sqr(), e[:, j] - P[:, 1].sqr()
    return Interval(np.stack([ri.lo, rj.lo, d.lo], 1), np.stack([ri.hi, rj.hi, d.hi], 1))


def preconditioned(grads: tuple[Interval, Interval], k: int) -> tuple[np.ndarray, Interval]:
    """(Y, C): Y = mid(E'(X))^-1 (NaN where singular) and C = I - Y E'(X) (interval), from the gradients over X."""
    A, G = grads
    i, j = [a for a in range(3) if a != k]
    J = Interval(np.stack([A.lo[:, i], A.lo[:, j], G.lo], 1), np.stack([A.hi[:, i], A.hi[:, j], G.hi], 1))
    with np.errstate(all="ignore"):
        M = 0.5 * (J.lo + J.hi)
        ok = np.isfinite(M).all(axis=(1, 2)) & (np.abs(np.linalg.det(np.where(np.isfinite(M), M, 0.0))) > 1e-300)
        Y = np.full(M.shape, np.nan)
        if ok.any():
            Y[ok] = np.linalg.inv(M[ok])
    C_lo, C_hi = np.empty(M.shape), np.empty(M.shape)
    for a in range(3):
        for b in range(3):
            c = Interval.point(np.full(len(M), 1.0 if a == b else 0.0))
            for d in range(3):
                c = c - J[:, d, b] * Y[:, a, d]
            C_lo[:, a, b], C_hi[:, a, b] = c.lo, c.hi
    return Y, Interval(C_lo, C_hi)


def krawczyk_image(geometry: Geometry, X: np.ndarray, k: int, P: Interval, Y: np.ndarray, C: Interval,
              values: tuple[Interval, Interval] | None = None) -> np.ndarray:
    """The Krawczyk image (n, 3, 2) of pose boxes X for parameters P, with Y and C = I - Y E'(X') for X' containing X.

    Any C computed over a box containing X is sound (the mean value theorem only needs
    an enclosure of E' over X), so a side test reuses the C of its model's proof.
    ``values`` are the enclosures at mid(X) when already known.
    """
    Xi = Interval(X[:, :, 0], X[:, :, 1])
    m = Xi.mid()
    F = _residual(_values(geometry, m) if values is None else values, k, P)
    D = Xi - m
    K_lo, K_hi = np.empty(m.shape), np.empty(m.shape)
    for a in range(3):
        acc = Interval.point(m[:, a])
        for b in range(3):
            acc = acc - F[:, b] * Y[:, a, b] + C[:, a, b] * D[:, b]
        K_lo[:, a], K_hi[:, a] = acc.lo, acc.hi
    K = np.stack([K_lo, K_hi], axis=-1)
    K[~np.isfinite(K).all(axis=(1, 2))] = np.nan
    return K


def _inside(K: np.ndarray, X: np.ndarray) -> np.ndarray:
    with np.errstate(invalid="ignore"):
        return ((K[:, :, 0] > X[:, :, 0]) & (K[:, :, 1] < X[:, :, 1])).all(axis=1)


def _cross(ax, ay, bx, by):
    return ax * by - ay * bx


def normal_signs(geometry: Geometry, K: np.ndarray) -> np.ndarray:
    """(n, 3) int8: certified signs of w_l = u_m x u_n over the pose boxes (0: not proved)."""
    A = jacobian_interval(geometry, K)  # row l is 2 (u_lx, u_ly, r_l x u_l)
    u = [(A[:, l, 0], A[:, l, 1]) for l in range(3)]
    out = np.zeros((len(K), 3), dtype=np.int8)
    for l in range(3):
        m, n = (l + 1) % 3, (l + 2) % 3
        w = _cross(u[m][0], u[m][1], u[n][0], u[n][1])
        out[:, l] = np.where(w.lo > 0, 1, np.where(w.hi < 0, -1, 0))
    return out


def height_slopes(geometry: Geometry, models: FoldModels) -> np.ndarray:
    """(m, 3) int8: the sign of dh/dr_l over the whole box for each axis l other than the model's axis k, 0
    where not proved (and at l = k).  The sheet's normal at g(X) is (rho_1 w_1, rho_2 w_2, rho_3 w_3)
    (module docstring), so dh/dr_l = -rho_l w_l / (rho_k w_k) and, with every rho > 0, its
    sign is -sign(w_l) sign(w_k); the signs of w are certified over the Krawczyk box, which holds X*(p) for every
    p of the box's face."""
    m = len(models)
    out = np.zeros((m, 3), dtype=np.int8)
    rows = np.flatnonzero(models.ok & np.isfinite(models.pose).all(axis=(1, 2)))
    if rows.size:
        w = normal_signs(geometry, models.pose[rows]).astype(np.int64)
        k = models.axis[rows].astype(np.int64)
        slope = -w * w[np.arange(rows.size), k][:, None]
        slope[np.arange(rows.size), k] = 0
        out[rows] = slope
    return out


def fold_models(geometry: Geometry, joint_boxes: np.ndarray, hulls: np.ndarray, rounds: int = ROUNDS) -> FoldModels:
    """Fold models of joint boxes (n, 3, 2) whose singular poses lie in ``hulls`` (n, 3, 2), if provable.

    Each round evaluates E' and E(m) once over the current pose box X and forms the
    Krawczyk image K_k for the three axes k.  A model is kept for the first axis whose
    K_k lies in the interior of X and whose pieces pass a connectivity condition
    (module docstring).  Otherwise X shrinks to X ∩ K_0 ∩ K_1 ∩ K_2: every singular pose
    with its joint vector in the box is a zero of each E_k in X, so it stays in the
    intersection, and a smaller X gives a smaller C.  An EMPTY intersection proves the
    box holds no singular pose at all: ``void`` (the box is clear,
    proofs/lemma-fold-joint-box.md, part 6).  Certified where ``ok`` or ``void``.
    """
    n = len(joint_boxes)
    ok, void = np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
    axis = np.full(n, -1, dtype=np.int8)
    pose = np.full((n, 3, 2), np.nan)
    height = Interval(np.full(n, np.nan), np.full(n, np.nan))
    inv = np.full((n, 3, 3), np.nan)
    contraction = Interval(np.full((n, 3, 3), np.nan), np.full((n, 3, 3), np.nan))
    rho = Interval(joint_boxes[:, :, 0], joint_boxes[:, :, 1])
    todo = np.flatnonzero(np.isfinite(hulls).all(axis=(1, 2)))
    for s in range(0, todo.size, _CHUNK):
        idx = todo[s:s + _CHUNK]
        w0 = hulls[idx, :, 1] - hulls[idx, :, 0]
        # a little room around the hull: the inclusion test needs the solutions off the boundary of X
        X = hulls[idx] + np.stack([-0.1 * w0 - 1e-9, 0.1 * w0 + 1e-9], axis=-1)
        live = np.arange(idx.size)
        for _round in range(rounds):
            if live.size == 0:
                break
            Xl = X[live]
            grads = _gradients(geometry, Xl)
            vals = _values(geometry, Interval(Xl[:, :, 0], Xl[:, :, 1]).mid())
            shrunk, grown = Xl.copy(), Xl.copy()
            done = np.zeros(live.size, dtype=bool)
            for k in range(3):
                i, j = [a for a in range(3) if a != k]
                rows = idx[live]
                P = Interval(np.stack([rho.lo[rows, i], rho.lo[rows, j]], 1),
                             np.stack([rho.hi[rows, i], rho.hi[rows, j]], 1))
                Y, C = preconditioned(grads, k)
                K = krawczyk_image(geometry, Xl, k, P, Y, C, vals)
                fin = np.isfinite(K).all(axis=(1, 2))
                shrunk[fin, :, 0] = np.maximum(shrunk[fin, :, 0], K[fin, :, 0])
                shrunk[fin, :, 1] = np.minimum(shrunk[fin, :, 1], K[fin, :, 1])
                grown[fin, :, 0] = np.minimum(grown[fin, :, 0], K[fin, :, 0])
                grown[fin, :, 1] = np.maximum(grown[fin, :, 1], K[fin, :, 1])
                cand = np.flatnonzero(~done & _inside(K, Xl))
                if cand.size == 0:
                    continue
                good, hk = _connected(geometry, K[cand], Xl[cand], k, rho[rows[cand]], Y[cand], C[cand])
                g = cand[good]
                done[g] = True
                ok[rows[g]], axis[rows[g]] = True, k
                pose[rows[g]] = Xl[g]
                height.lo[rows[g]], height.hi[rows[g]] = hk.lo[good], hk.hi[good]
                inv[rows[g]] = Y[g]
                contraction.lo[rows[g]], contraction.hi[rows[g]] = C.lo[g], C.hi[g]
            empty = (shrunk[:, :, 0] > shrunk[:, :, 1]).any(axis=1)
            void[idx[live[empty]]] = True
            if _round < rounds - INFLATE_ROUNDS:
                X[live[~empty]] = shrunk[~empty]
            else:
                # the sheet may leave the box: the zeros of E over the whole parameter box then reach
                # outside the hull, and X must grow to hold them (it still holds every singular pose)
                X[live] = _inflated(Xl, grown)
            live = live[~done & ~empty]
    # no singular pose at all beats a sheet whose height leaves the box: the box is clear
    ok &= ~void
    axis[void] = -1
    return FoldModels(ok, axis, pose, height, inv, contraction, void)


def _inflated(X: np.ndarray, grown: np.ndarray) -> np.ndarray:
    """Epsilon inflation: the hull of X and its images, widened by a quarter on each side."""
    gw = grown[:, :, 1] - grown[:, :, 0]
    return grown + np.stack([-0.25 * gw, 0.25 * gw], axis=-1)


def _connected(geometry: Geometry, K: np.ndarray, X: np.ndarray, k: int, R: Interval, Y: np.ndarray,
               C: Interval) -> tuple[np.ndarray, Interval]:
    """(which models of axis k have two connected pieces, the enclosure of h = rho_k over K).

    Conditions (a), (b), (c) of the module docstring, for Krawczyk images K inside pose
    boxes X over joint boxes R.
    """
    i, j = [a for a in range(3) if a != k]
    hk = rho_sq_interval(geometry, K)[:, k].sqrt()
    inside_k = (hk.lo > R.lo[:, k]) & (hk.hi < R.hi[:, k])
    sg = normal_signs(geometry, K)
    good = inside_k | ((sg[:, i] != 0) & (sg[:, j] != 0) & (sg[:, k] != 0))
    for a, b in ((0, 1), (1, 0)):  # monotone along parameter b, both end edges checked along a
        cand = np.flatnonzero(~good & (sg[:, k] != 0) & (sg[:, (i, j)[b]] != 0))
        if cand.size == 0:
            continue
        rb, ra = (i, j)[b], (i, j)[a]
        rising = -sg[cand, rb] * sg[cand, k] > 0  # dh/dr_b > 0
        top = np.where(rising, R.hi[cand, rb], R.lo[cand, rb])  # where h is largest along b
        low = np.where(rising, R.lo[cand, rb], R.hi[cand, rb])
        edge = []
        for at in (top, low):
            lo_p, hi_p = np.empty((cand.size, 2)), np.empty((cand.size, 2))
            lo_p[:, a], hi_p[:, a] = R.lo[cand, ra], R.hi[cand, ra]
            lo_p[:, b], hi_p[:, b] = at, at
            edge.append(_height(geometry, X[cand], k, Interval(lo_p, hi_p), Y[cand], C[cand]))
        good[cand] = (edge[0].lo > R.lo[cand, k]) & (edge[1].hi < R.hi[cand, k])
    return good, hk


def _height(geometry: Geometry, X: np.ndarray, k: int, P: Interval, Y: np.ndarray, C: Interval) -> Interval:
    """An enclosure of h = rho_k(X*(p)) over the parameters P, by Krawczyk steps from the model's box X.

    Every step keeps X*(p) (any box inside the model's X may take its Y and C), so the
    intersection of the images holds it; NaN bounds where a step failed (no claim).
    """
    for _ in range(SIDE_STEPS):
        K = krawczyk_image(geometry, X, k, P, Y, C)
        fin = np.isfinite(K).all(axis=(1, 2))
        K = np.where(fin[:, None, None], K, np.stack([np.full(X.shape[:2], np.nan)] * 2, axis=-1))
        X = np.stack([np.fmax(X[:, :, 0], K[:, :, 0]), np.fmin(X[:, :, 1], K[:, :, 1])], axis=-1)
        X[~fin] = np.nan
    h = rho_sq_interval(geometry, np.where(np.isfinite(X), X, 0.0))[:, k].sqrt()
    bad = ~np.isfinite(X).all(axis=(1, 2)) | (X[:, :, 0] > X[:, :, 1]).any(axis=1)
    h.lo[bad], h.hi[bad] = np.nan, np.nan
    return h


def side_of(geometry: Geometry, models: FoldModels, box: np.ndarray, points: np.ndarray,
            poses: np.ndarray | None = None) -> np.ndarray:
    """(m,) int8: -1 where point q lies below the sheet of model ``box`` (q_k < h(q_i, q_j)), +1 above, 0 undecided.

    box : (m,) indices of boxes with a model; points : (m, 3) float joint vectors inside
    those boxes.  A few Krawczyk steps at the point parameter enclose X*(q_i, q_j) (the
    unique zero in the model's pose box); q is placed when q_k^2 is outside the
    enclosure of rho_k^2 there.  Certified.  ``poses`` (m, 3, 2), when given, receives the
    contracted pose box of each point (it holds X*(q_i, q_j); NaN where a step failed), from
    which a tighter test may go on.
    """
    box = np.asarray(box, dtype=np.int64)
    q = np.asarray(points, dtype=np.float64)
    out = np.zeros(len(box), dtype=np.int8)
    for k in range(3):
        sel = np.flatnonzero(models.axis[box] == k)
        sel = sel[np.argsort(box[sel], kind="stable")]  # the points of a box together: they share a first step
        # each point's answer depends on it alone; in cache-sized pieces the interval kernels run far faster
        for s in range(0, sel.size, _SIDE_CHUNK):
            c = sel[s:s + _SIDE_CHUNK]
            out[c], X = _side(geometry, models, k, box[c], q[c])
            if poses is not None:
                poses[c] = X
    return out


def _side(geometry: Geometry, models: FoldModels, k: int, rows: np.ndarray,
          q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`side_of` for points q (m, 3) in boxes ``rows`` whose models have axis k: (sides, contracted poses)."""
    out = np.zeros(len(rows), dtype=np.int8)
    i, j = [a for a in range(3) if a != k]
    P = Interval.point(q[:, [i, j]])
    X = models.pose[rows]
    qk2 = Interval.point(q[:, k]).sqr()
    todo = np.arange(len(rows))
    # the first step starts from the model's pose box: its values at the midpoint are the box's, found once
    uniq, inv = np.unique(rows, return_inverse=True)
    e, d = _values(geometry, Interval(models.pose[uniq, :, 0], models.pose[uniq, :, 1]).mid())
    first = (e[inv], d[inv])
    for step in range(SIDE_STEPS):  # a point placed after a step stops there
        t = todo
        K = krawczyk_image(geometry, X[t], k, P[t], models.inv[rows[t]], models.contraction[rows[t]],
                      first if step == 0 else None)
        fin = np.isfinite(K).all(axis=(1, 2))
        K = np.where(fin[:, None, None], K, X[t])
        Xt = np.stack([np.maximum(X[t, :, 0], K[:, :, 0]), np.minimum(X[t, :, 1], K[:, :, 1])], axis=-1)
        # an empty intersection cannot happen for a proved model; claim nothing then
        dead = ~fin | (Xt[:, :, 0] > Xt[:, :, 1]).any(axis=1)
        X[t] = np.where(dead[:, None, None], np.nan, Xt)
        h2 = rho_sq_leg_interval(geometry, np.where(dead[:, None, None], models.pose[rows[t]], Xt), k)
        below = ~dead & (qk2.hi[t] < h2.lo)
        above = ~dead & (qk2.lo[t] > h2.hi)
        out[t[below]], out[t[above]] = -1, 1
        todo = t[~dead & ~below & ~above]
        if todo.size == 0:
            break
    return out, X
