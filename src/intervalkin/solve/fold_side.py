"""Which piece of a fold box holds the two extra solutions.

A fold model (:mod:`intervalkin.solve.fold_model`) cuts a joint box R into the pieces
below (q_k < h) and above (q_k > h) the sheet, each of constant count and aspect split,
and the singular pose X*(p) over each sheet point (p, h(p)) is the only one over R.
Take ONE sheet point z = (p, h(p)) in the interior of R.  Near z the pieces are the
points just below and just above z, and every solution over z but X*(p) is regular
and continues across the sheet; at X*(p) the sign of the curvature f'' of rho_k^2
along the four-bar curve of legs i, j (:mod:`intervalkin.kinematics.fold_side`) says
on which side two solutions are born, one per aspect.  So

    signature(above) = signature(below) + s (2, 1, 1),   s = sign f''(X*(p)),

for the whole pieces, not only near z.  One certified point fixes s for the box: a
few Krawczyk steps at the point parameter p enclose X*(p) in a tight pose box, which
also encloses h(p) (it must lie strictly inside R_k), and the interval sign of f'' on
that tight box is s.  A piece that no point of the paving could be placed in, or that
is joined to no cell, then takes its signature from the other piece.
See proofs/lemma-fold-side.md.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import Interval
from intervalkin.kinematics.enclosures import det_a_gradient_interval, jacobian_interval, rho_sq_leg_interval
from intervalkin.kinematics.fold_side import pair_side
from intervalkin.solve.fold_model import (SIDE_STEPS, FoldModels, height_slopes, krawczyk_image, preconditioned,
                                          side_of)

__all__ = ["pair_sides", "side_of_tight", "placed_side", "empty_by_parts", "EMPTY_LEVELS", "FoldSides", "PAIR", "GRID", "BISECTIONS"]

#: The signature change (count, n_wa1, n_wa2) from the piece below to the piece above when s = +1.
PAIR = np.array([2, 1, 1], dtype=np.int64)
#: The parameters p (fractions of the box's two parameter sides) where the sheet's height is enclosed
#: after the centre: the corners, where a monotone height takes its extremes (corner (a, b) at 2 a + b).
GRID = ((0.0, 0.0), (0.0, 1.0), (1.0, 0.0), (1.0, 1.0))
#: Krawczyk steps with a preconditioner recomputed on the shrunk box (after the model's SIDE_STEPS).
TIGHT_STEPS = 2
#: Bisection steps along a grid segment whose ends lie on either side of the box's middle height.
BISECTIONS = 12
#: Halvings of a fold box's parameter rectangle by :func:`empty_by_parts` (4 ** EMPTY_LEVELS parts at most; only the
#: parts the face's height crosses are halved, about 2 ** level of them).  On the paper's paving 4, 6 and 8 levels
#: prove 618, 729 and 763 of 817 unknown pieces empty, in about a second each.
EMPTY_LEVELS = 6


def _sheet_pose(geometry: Geometry, models: FoldModels, rows: np.ndarray, k: int, p: np.ndarray | Interval,
                tight: bool = True, start: np.ndarray | None = None) -> np.ndarray:
    """Enclosures (m, 3, 2) of X*(p) for point parameters p (m, 2) of the models ``rows`` (axis k), or of X*(p) for
    every p in parameter boxes (an Interval (m, 2)); NaN where lost.

    Krawczyk steps with the model's preconditioner first, then (``tight``) TIGHT_STEPS with one recomputed
    over the current, smaller box (any preconditioner keeps every zero of the box, so each
    intersection still holds X*(p)).  ``start``: boxes already contracted by the model's steps (each holding
    X*(p), as :func:`~intervalkin.solve.fold_model.side_of` returns them): only the recomputed steps are taken.
    """
    X = models.pose[rows].copy() if start is None else np.array(start, dtype=np.float64)
    P = p if isinstance(p, Interval) else Interval.point(p)
    first = 0 if start is None else SIDE_STEPS
    for step in range(first, SIDE_STEPS + (TIGHT_STEPS if tight else 0)):
        if step < SIDE_STEPS:
            Y, C = models.inv[rows], models.contraction[rows]
        else:
            safe = np.where(np.isfinite(X), X, 0.0)
            Y, C = preconditioned((jacobian_interval(geometry, safe), det_a_gradient_interval(geometry, safe)), k)
        K = krawczyk_image(geometry, np.where(np.isfinite(X), X, 0.0), k, P, Y, C)
        with np.errstate(invalid="ignore"):
            X = np.stack([np.fmax(X[:, :, 0], K[:, :, 0]), np.fmin(X[:, :, 1], K[:, :, 1])], axis=-1)
            bad = ~np.isfinite(K).all(axis=(1, 2)) | ~np.isfinite(X).all(axis=(1, 2)) | (X[:, :, 0] > X[:, :, 1]).any(axis=1)
        X[bad] = np.nan
    return X


class _Search:
    """The fold boxes of one axis k still without a proved side, and how to try a parameter point on them."""

    def __init__(self, geometry: Geometry, R: np.ndarray, models: FoldModels, k: int, out: np.ndarray):
        self.geometry, self.R, self.models, self.k, self.out = geometry, R, models, k, out
        self.i, self.j = [a for a in range(3) if a != k]
        # h^2 must exceed lo_k^2 and stay below hi_k^2, both rounded towards the box
        self.lo2 = Interval.point(R[:, k, 0]).sqr().hi
        self.hi2 = Interval.point(R[:, k, 1]).sqr().lo

    def point(self, rows: np.ndarray, f: np.ndarray) -> np.ndarray:
        """Parameters p (m, 2) at fractions f (m, 2) of the rows' parameter sides."""
        R, i, j = self.R, self.i, self.j
        return np.stack([R[rows, i, 0] + f[:, 0] * (R[rows, i, 1] - R[rows, i, 0]),
                         R[rows, j, 0] + f[:, 1] * (R[rows, j, 1] - R[rows, j, 0])], axis=1)

    def heights(self, rows: np.ndarray, p: np.ndarray, tight: bool = True) -> Interval:
        """Enclosures of h(p)^2 (NaN where X*(p) was lost), recording the sides proved at interior sheet points."""
        R, k = self.R, self.k
        X = _sheet_pose(self.geometry, self.models, rows, k, p, tight)
        fin = np.isfinite(X).all(axis=(1, 2))
        h2 = rho_sq_leg_interval(self.geometry, np.where(fin[:, None, None], X, 0.0), k)
        h2.lo[~fin], h2.hi[~fin] = np.nan, np.nan
        interior = ((p > R[rows][:, [self.i, self.j], 0]) & (p < R[rows][:, [self.i, self.j], 1])).all(axis=1)
        ok = fin & interior & (h2.lo > self.lo2[rows]) & (h2.hi < self.hi2[rows])
        if ok.any():
            s = pair_side(self.geometry, X[ok], np.full(int(ok.sum()), k))
            at = rows[ok]
            self.out[at] = np.where(self.out[at] != 0, self.out[at], s)
        return h2


@dataclass(frozen=True, eq=False)
class FoldSides:
    """Per fold box: ``side`` (+1: the piece above holds the extra pair of solutions, -1: the piece
    below, 0: not proved) and ``empty`` (-1: the piece below is proved empty, +1: the piece above,
    0: neither proved)."""

    side: np.ndarray
    empty: np.ndarray


def pair_sides(geometry: Geometry, joint_boxes: np.ndarray, models: FoldModels) -> FoldSides:
    """The side of the extra pair, and the empty pieces, of fold boxes (n, 3, 2) with their models.

    Certified (module docstring): a side comes from one sheet point strictly inside the box at
    which the curvature's sign is proved on an enclosure of the singular pose.  The point is
    looked for at the centre, at the corners, then by bisection along the segment whose ends lie below and above a height inside the box (float heights
    only steer the search; the point found is checked with intervals).  A piece is proved empty
    when h is monotone in both parameters (certified signs of the normal over the model's pose
    box) and its value at the extreme corner, enclosed, lies beyond the box's face.
    """
    R = np.asarray(joint_boxes, dtype=np.float64)
    out = np.zeros(len(R), dtype=np.int8)
    empty = np.zeros(len(R), dtype=np.int8)
    grid = np.array(GRID, dtype=np.float64)
    for k in range(3):
        search = _Search(geometry, R, models, k, out)
        todo = np.flatnonzero(models.ok & (models.axis == k))
        # the centre, without the recomputed preconditioner; what it leaves goes to the search below
        search.heights(todo, search.point(todo, np.full((todo.size, 2), 0.5)), tight=False)
        todo = todo[out[todo] == 0]
        if todo.size == 0:
            continue
        h2 = [search.heights(todo, search.point(todo, np.broadcast_to(f, (todo.size, 2))), tight=False) for f in grid]
        keep = out[todo] == 0
        h2 = [Interval(e.lo[keep], e.hi[keep]) for e in h2]
        todo = todo[keep]
        h = np.sqrt(np.stack([0.5 * (e.lo + e.hi) for e in h2], axis=1))
        _empty_pieces(geometry, search, todo, h2, empty)
        # bisect from the grid's lowest point to its highest, onto a height inside the box
        with np.errstate(invalid="ignore"):
            lo_at = np.argmin(np.where(np.isfinite(h), h, np.inf), axis=1)
            hi_at = np.argmax(np.where(np.isfinite(h), h, -np.inf), axis=1)
        rows = np.arange(todo.size)
        h_min, h_max = h[rows, lo_at], h[rows, hi_at]
        target = 0.5 * (np.maximum(h_min, R[todo, k, 0]) + np.minimum(h_max, R[todo, k, 1]))
        both = (h_min < target) & (target < h_max) & (empty[todo] == 0)
        todo, a, b, target = todo[both], grid[lo_at[both]], grid[hi_at[both]], target[both]
        for step in range(BISECTIONS + 1):
            if todo.size == 0:
                break
            mid = 0.5 * (a + b)
            e = search.heights(todo, search.point(todo, mid), tight=step == BISECTIONS)
            hm = np.sqrt(0.5 * (e.lo + e.hi))
            keep = (out[todo] == 0) & np.isfinite(hm)
            up = hm > target
            b = np.where(up[:, None], mid, b)
            a = np.where(up[:, None], a, mid)
            todo, a, b, target = todo[keep], a[keep], b[keep], target[keep]
    return FoldSides(out, empty)


def _empty_pieces(geometry: Geometry, search: _Search, rows: np.ndarray, corners: list[Interval],
                  empty: np.ndarray) -> None:
    """Prove pieces of the rows' boxes empty where h is monotone in both parameters (sets ``empty``).

    corners: the enclosures of h^2 at the :data:`GRID` corners (quick ones); where they do not
    decide, the extreme corner is enclosed again with the recomputed preconditioner.
    """
    k, R = search.k, search.R
    i, j = search.i, search.j
    slope = height_slopes(geometry, search.models.take(rows))
    at = np.flatnonzero((slope[:, i] != 0) & (slope[:, j] != 0))
    if at.size == 0:
        return
    # the corner where h is largest takes the upper end of each parameter along which it rises
    rise = np.stack([slope[at, i] > 0, slope[at, j] > 0], axis=1)
    top_at = 2 * rise[:, 0] + rise[:, 1]  # the index of corner (a, b) in GRID is 2 a + b
    low_at = 3 - top_at
    lo2 = np.stack([c.lo[at] for c in corners], axis=1)
    hi2 = np.stack([c.hi[at] for c in corners], axis=1)
    r = np.arange(at.size)
    top = Interval(lo2[r, top_at], hi2[r, top_at])
    low = Interval(lo2[r, low_at], hi2[r, low_at])
    lo_down = Interval.point(R[rows[at], k, 0]).sqr().lo  # lo_k^2 rounded down
    hi_up = Interval.point(R[rows[at], k, 1]).sqr().hi
    with np.errstate(invalid="ignore"):
        # the quick enclosure straddles the face: enclose the extreme corner tightly
        redo_top = ~(top.hi <= lo_down) & (top.lo <= lo_down)
        redo_low = ~(low.lo >= hi_up) & (low.hi >= hi_up)
    for redo, box, corner in ((redo_top, top, rise), (redo_low, low, ~rise)):
        if redo.any():
            t = search.heights(rows[at[redo]], search.point(rows[at[redo]], corner[redo].astype(np.float64)))
            box.lo[redo], box.hi[redo] = t.lo, t.hi
    # h <= h(top corner) <= lo_k everywhere: nothing lies below the sheet; likewise above
    below_empty = top.hi <= lo_down
    above_empty = low.lo >= hi_up
    empty[rows[at[below_empty]]] = -1
    empty[rows[at[above_empty & ~below_empty]]] = 1


def side_of_tight(geometry: Geometry, models: FoldModels, box: np.ndarray, points: np.ndarray,
                  start: np.ndarray | None = None) -> np.ndarray:
    """(m,) int8: like :func:`intervalkin.solve.fold_model.side_of` (-1 below the sheet, +1 above, 0 undecided),
    with the tight enclosure of X*(q_i, q_j) (recomputed preconditioner): for the points the quick side test
    leaves undecided, close to the sheet or in a box whose model's C contracts weakly.  ``start``: their pose
    boxes as the quick test left them (the model's steps are not taken again).  Certified.
    """
    box = np.asarray(box, dtype=np.int64)
    q = np.asarray(points, dtype=np.float64)
    out = np.zeros(len(box), dtype=np.int8)
    for k in range(3):
        sel = np.flatnonzero((models.axis[box] == k) & models.ok[box])
        if sel.size == 0:
            continue
        i, j = [a for a in range(3) if a != k]
        X = _sheet_pose(geometry, models, box[sel], k, q[sel][:, [i, j]],
                        start=None if start is None else np.asarray(start)[sel])
        fin = np.isfinite(X).all(axis=(1, 2))
        h2 = rho_sq_leg_interval(geometry, np.where(fin[:, None, None], X, 0.0), k)
        qk2 = Interval.point(q[sel, k]).sqr()
        out[sel[fin & (qk2.hi < h2.lo)]] = -1
        out[sel[fin & (qk2.lo > h2.hi)]] = 1
    return out


def placed_side(geometry: Geometry, models: FoldModels, box: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(m,) int8: the quick side test (:func:`intervalkin.solve.fold_model.side_of`), and the tight one
    (:func:`side_of_tight`) where it does not decide: a point close to the sheet, or in a box whose model's own
    C contracts weakly (there the quick test stalls at every point of the box).  Certified."""
    poses = np.full((len(box), 3, 2), np.nan)
    side = side_of(geometry, models, box, points, poses=poses)
    near = np.flatnonzero(side == 0)
    if near.size:  # the tight steps go on from the boxes the quick ones left
        side[near] = side_of_tight(geometry, models, np.asarray(box)[near], np.asarray(points)[near], poses[near])
    return side


def empty_by_parts(geometry: Geometry, joint_boxes: np.ndarray, models: FoldModels, piece: np.ndarray,
                   levels: int = EMPTY_LEVELS) -> np.ndarray:
    """(n,) bool: the piece ``piece`` (n,) (0 below, 1 above) of each fold box (n, 3, 2) is proved empty.

    The piece above, {q_k > h(p)}, is empty when h(p) >= hi_k for every p of the box's parameter rectangle, the
    piece below when h(p) <= lo_k.  The rectangle is halved in both parameters, only where undecided, up to
    ``levels`` times; over each part P a Krawczyk run with the parameter box P (the model's Y and C, then ones taken
    again over the shrunk pose box) encloses X*(p) for every p in P (proofs/lemma-fold-joint-box.md, points 1, 5
    and 6: each image holds every zero of E(.; p), p in P), so rho_k^2 over it encloses h^2 there.  A part where h
    is proved on the piece's side of the face settles that part; one where h is proved off it (the piece reaches
    into the box there) or where the run fails ends the box's attempt.  Certified.
    """
    R = np.asarray(joint_boxes, dtype=np.float64)
    piece = np.asarray(piece, dtype=np.int64)
    n = len(R)
    out = np.zeros(n, dtype=bool)
    open_ = np.ones(n, dtype=bool)  # no part found where the piece may reach
    for k in range(3):
        i, j = [a for a in range(3) if a != k]
        rows = np.flatnonzero(models.ok & (models.axis == k))
        # parts: (row, lo_i, hi_i, lo_j, hi_j), the whole rectangle first
        part = rows
        p_lo = np.stack([R[rows, i, 0], R[rows, j, 0]], axis=1)
        p_hi = np.stack([R[rows, i, 1], R[rows, j, 1]], axis=1)
        face_lo = Interval.point(R[:, k, 0]).sqr().lo  # lo_k^2 rounded down, hi_k^2 up: h beyond them is strict
        face_hi = Interval.point(R[:, k, 1]).sqr().hi
        for level in range(levels + 1):
            if part.size == 0:
                break
            h2 = _part_heights(geometry, models, part, k, Interval(p_lo, p_hi))
            with np.errstate(invalid="ignore"):
                beyond = np.where(piece[part] == 1, h2.lo >= face_hi[part], h2.hi <= face_lo[part])
                inside = np.where(piece[part] == 1, h2.hi < face_hi[part], h2.lo > face_lo[part])
            lost = ~np.isfinite(h2.lo) | ~np.isfinite(h2.hi)
            open_[part[inside | lost]] = False
            if level == levels:
                open_[part[~beyond]] = False
                break
            split = ~beyond & ~inside & ~lost & open_[part]
            part, p_lo, p_hi = part[split], p_lo[split], p_hi[split]
            mid = 0.5 * (p_lo + p_hi)
            quarters = [(np.where(c, mid, p_lo), np.where(c, p_hi, mid))
                        for c in (np.array([a, b], dtype=bool) for a in (0, 1) for b in (0, 1))]
            part = np.tile(part, 4)
            p_lo = np.concatenate([q[0] for q in quarters])
            p_hi = np.concatenate([q[1] for q in quarters])
        out[rows] = open_[rows]
    return out


def _part_heights(geometry: Geometry, models: FoldModels, rows: np.ndarray, k: int, P: Interval) -> Interval:
    """Enclosures of h^2 over parameter boxes P (m, 2) of the models ``rows`` (axis k); NaN where a run failed."""
    X = _sheet_pose(geometry, models, rows, k, P)
    lost = ~np.isfinite(X).all(axis=(1, 2))
    h2 = rho_sq_leg_interval(geometry, np.where(lost[:, None, None], 0.0, X), k)
    return Interval(np.where(lost, np.nan, h2.lo), np.where(lost, np.nan, h2.hi))
