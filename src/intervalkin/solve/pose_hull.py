"""The pose box that holds every singular pose over a joint box: the hull of its live torus cells.

The clear-box search (:mod:`intervalkin.solve.joint_box`) leaves, for a joint box R, the
cells Theta x Phi of the torus that may hold a singular pose X with g(X) in R; every such
X lies in the pose box [x] x [y] x Phi of its cell, with [x] = a_1x + R_1 cos(Theta) and
[y] = a_1y + R_1 sin(Theta) (B1 on the circle of leg 1).  The hull of those pose boxes
is where the Krawczyk proof of a fold model starts (:mod:`intervalkin.solve.fold_model`).
"""

from __future__ import annotations

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import PI_HI, PI_LO, Interval
from intervalkin.core.rows import distinct_rows
from intervalkin.kinematics.constants import constants

__all__ = ["pose_hulls"]

#: Keys evaluated together (cache-sized temporaries).
_CHUNK = 32768


def pose_hulls(geometry: Geometry, joint_boxes: np.ndarray, owner: np.ndarray, cells: np.ndarray):
    """Per joint box, the hull of the pose boxes of its live torus cells: (n, 3, 2), NaN where none.

    ``owner`` must be sorted (the cells of one box form one run).

    A cluster that straddles the phi seam is shifted by 2 pi (every quantity is
    2 pi-periodic in phi), so the hull stays narrow where it can.
    """
    n = len(joint_boxes)
    out = np.full((n, 3, 2), np.nan)
    if owner.size == 0:
        return out
    if np.any(np.diff(owner) < 0):
        raise ValueError("pose_hulls: the cells must be sorted by owner")
    x, y = _circle_boxes(geometry, joint_boxes, owner, cells)
    plo, phi_hi = cells[:, 2].copy(), cells[:, 3].copy()
    starts = np.flatnonzero(np.r_[True, owner[1:] != owner[:-1]])
    who = owner[starts]

    def hull(lo, hi):
        return np.minimum.reduceat(lo, starts), np.maximum.reduceat(hi, starts)

    wide = np.zeros(n, dtype=bool)
    a, b = hull(plo, phi_hi)
    wide[who] = b - a > np.pi
    shift = wide[owner] & (phi_hi <= 0.0)
    # phi + 2 pi for the cells below the seam, rounded outward (2 pi itself is only enclosed)
    moved = Interval(plo[shift], phi_hi[shift]) + Interval.from_bounds(2.0 * PI_LO, 2.0 * PI_HI)
    plo[shift], phi_hi[shift] = moved.lo, moved.hi
    for ax, (lo, hi) in enumerate(((x.lo, x.hi), (y.lo, y.hi), (plo, phi_hi))):
        a, b = hull(lo, hi)
        out[who, ax, 0], out[who, ax, 1] = a, b
    return out


def _circle_boxes(geometry: Geometry, joint_boxes: np.ndarray, owner: np.ndarray,
                  cells: np.ndarray) -> tuple[Interval, Interval]:
    """[x] = a_1x + R_1 cos(Theta), [y] = a_1y + R_1 sin(Theta) for each cell (m,), R_1 of its owner.

    They depend on (R_1, Theta) only, which many cells share (boxes with one R_1, the cells of
    a box across phi), so each distinct pair is evaluated once, bit for bit as for any of its
    cells (:func:`intervalkin.core.rows.distinct_rows`).
    """
    k = constants(geometry)
    _, r1_of = distinct_rows([joint_boxes[:, 0, 0], joint_boxes[:, 0, 1]])
    rep, key = distinct_rows([r1_of[owner], cells[:, 0], cells[:, 1]])
    out = [np.empty(rep.size) for _ in range(4)]
    for s in range(0, rep.size, _CHUNK):
        r = rep[s:s + _CHUNK]
        r1 = Interval(joint_boxes[owner[r], 0, 0], joint_boxes[owner[r], 0, 1])
        th = Interval(cells[r, 0], cells[r, 1])
        x, y = r1 * th.cos() + k.ax_iv[0], r1 * th.sin() + k.ay_iv[0]
        for o, v in zip(out, (x.lo, x.hi, y.lo, y.hi)):
            o[s:s + _CHUNK] = v
    xl, xh, yl, yh = (o[key] for o in out)
    return Interval(xl, xh), Interval(yl, yh)
