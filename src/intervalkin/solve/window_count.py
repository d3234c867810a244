"""Counting the roots of the reduced equation in the windows of a window model, at joint vectors.

A window model (:mod:`intervalkin.solve.window_model`, proofs/lemma-window-model.md) of a box R
fixes the roots off its windows for all of R; at a point q of R the roots in each window are
counted from certified signs of f(.; q): k sign changes prove at least k roots, and the window's
degree and end signs bound them.  :func:`window_root_counts` gives the count of each window at
each point; :func:`window_signature` sums them into the point's signature (count, n_wa1, n_wa2).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from intervalkin.core.errors import InputError
from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import sign_label
from intervalkin.solve.simple_roots import ReducedBoxes
from intervalkin.solve.window_model import DET_SIGN, POINT_CROWD, POINT_HALVINGS, WindowModels, cut_interval
from intervalkin.solve.window_split import root_d_signs, sign_changes

__all__ = ["WindowCounts", "window_root_counts", "window_signature"]


@dataclass(frozen=True, eq=False)
class WindowCounts:
    """Root counts per (point, window) pair.

    live : (k,) the points (indices into the query) whose box is modelled; pair j belongs to point
    ``live[pt[j]]`` and window ``win[j]`` (an index into the models' windows); roots : (p, 2) int64,
    (roots in the window, roots with det A > 0), -1 where not decided at that point.
    """

    live: np.ndarray
    pt: np.ndarray
    win: np.ndarray
    roots: np.ndarray

    def decided(self) -> np.ndarray:
        """(k,) bool: every window of the point's box was counted."""
        return np.bincount(self.pt, weights=self.roots[:, 0] < 0, minlength=self.live.size) == 0


def window_root_counts(geometry: Geometry, models: WindowModels, rows: np.ndarray, points: np.ndarray,
                       halvings: int = POINT_HALVINGS) -> "WindowCounts":
    """The certified number of roots in each window at joint vectors ``points`` (m, 3) (see :class:`WindowCounts`).

    ``rows`` (m,) names the box of ``models`` that holds each point.  In each window the signs of
    f(.; q) (r = q^2 an interval) are proved at cut points, bisected where needed: k sign changes
    prove at least k roots; with k = degree, or k = degree - 1 and both end signs proved (at q
    for an end sign 0), the degree and the parity prove exactly k, all simple; otherwise every
    sub-piece must show f != 0, or df/dphi != 0 with certified end signs.  A root where f rises
    has det A of sign DET_SIGN * sign(D); where it falls, the other sign (d_sign 0: sign(D) proved
    on the root's bracket).  Undecided: boxes not modelled, points on or very near g(S) (a
    multiple root), a root's bracket where D's sign is not proved, and (never when the model is
    sound) more sign changes than the degree or a sign at q against the model's.
    """
    rows = np.asarray(rows, dtype=np.int64)
    q = np.asarray(points, dtype=np.float64)
    if q.ndim != 2 or q.shape[1] != 3 or rows.shape != (len(q),):
        raise InputError(f"points: expected shape (m, 3) and rows (m,), got {q.shape} and {rows.shape}")
    box = models.boxes[rows]
    if np.any(~((box[:, :, 0] <= q) & (q <= box[:, :, 1]))):
        raise InputError("points: every point must lie in its box models.boxes[rows]")
    live = np.flatnonzero(models.ok[rows])
    wstart, wcount = models.windows_of(rows[live])
    pt = np.repeat(np.arange(live.size), wcount)  # pairs (point, window)
    win = np.repeat(wstart - (np.cumsum(wcount) - wcount), wcount) + np.arange(pt.size)
    if pt.size == 0:  # no windows at these points: every count is the roots off the windows (np.r_ below needs one)
        return WindowCounts(live, pt, win, np.full((0, 2), -1, dtype=np.int64))
    pstart = np.searchsorted(models.piece_window, win, side="left")
    pcount = np.searchsorted(models.piece_window, win, side="right") - pstart
    pair = np.repeat(np.arange(pt.size), pcount)  # sub-pieces, first the window's pieces
    piece = np.repeat(pstart - (np.cumsum(pcount) - pcount), pcount) + np.arange(pair.size)
    lo, hi = models.piece_lo[piece], models.piece_hi[piece]
    data = ReducedBoxes(geometry, np.stack([q[live], q[live]], axis=-1))

    def node_sign(at: np.ndarray, x: np.ndarray) -> np.ndarray:
        return sign_label(data.enclosure(pt[at], *cut_interval(x), 0)).astype(np.int64)

    # the window's ends carry their certified signs over all of R^2; the other cuts are proved at q
    s0, s1 = node_sign(pair, lo), node_sign(pair, hi)
    head = np.r_[True, pair[1:] != pair[:-1]]
    tail = np.r_[pair[1:] != pair[:-1], True]
    e0, e1 = models.end_signs[win[pair[head]], 0], models.end_signs[win[pair[tail]], 1]
    s0[head], s1[tail] = np.where(e0 != 0, e0, s0[head]), np.where(e1 != 0, e1, s1[tail])  # 0: proved at q
    done = np.zeros(pt.size, dtype=bool)
    result = np.full((pt.size, 2), -1, dtype=np.int64)  # (roots, roots with det A > 0)
    fixed = np.zeros(pair.size, dtype=bool)  # sub-piece proved: f != 0, or monotone with certified end signs
    degree = models.degree[win].astype(np.int64)
    rising = DET_SIGN * models.d_sign[win] > 0
    d_open = models.d_sign[win] == 0
    for round_ in range(halvings + 1):
        order = np.lexsort((lo, piece, pair))
        pair, piece, lo, hi, s0, s1, fixed = (a[order] for a in (pair, piece, lo, hi, s0, s1, fixed))
        open_ = np.flatnonzero(~fixed)
        sf = sign_label(data.enclosure(pt[pair[open_]], lo[open_], hi[open_], 0)).astype(np.int64)
        # f's sign on a sub-piece against a sign at its end (the model's, at a window end): refuse the pair
        clash = np.bincount(pair[open_], weights=(sf * s0[open_] < 0) | (sf * s1[open_] < 0), minlength=pt.size) > 0
        s0[open_] = np.where(sf != 0, sf, s0[open_])
        s1[open_] = np.where(sf != 0, sf, s1[open_])
        mono = np.flatnonzero(sf == 0)
        sd = sign_label(data.enclosure(pt[pair[open_[mono]]], lo[open_[mono]], hi[open_[mono]], 1))
        fixed[open_] = sf != 0
        fixed[open_[mono]] = (sd != 0) & (s0[open_[mono]] != 0) & (s1[open_[mono]] != 0)
        at, left, right, up_ = sign_changes(pair, lo, hi, s0, s1)
        k, up = np.bincount(at, minlength=pt.size), np.bincount(at, weights=up_, minlength=pt.size).astype(np.int64)
        unfixed = np.bincount(pair, weights=~fixed, minlength=pt.size)
        whole = unfixed == 0
        first, last = np.r_[True, pair[1:] != pair[:-1]], np.r_[pair[1:] != pair[:-1], True]
        known = np.zeros(pt.size, dtype=bool)  # both end signs of the window proved (at q, for an end sign 0)
        known[pair[first]] = (s0[first] != 0) & (s1[last] != 0)
        # at most `degree` roots with multiplicity, of the parity of the end signs: k = degree - 1 leaves only k
        now = ~done & ~clash & (k <= degree) & ((k == degree) | ((k == degree - 1) & known) | whole)
        # where D may vanish on the window: the sign of D proved on the bracket of each (simple) root
        roots = np.flatnonzero((now & d_open)[at])
        d_root = root_d_signs(geometry, left[roots], right[roots])
        now &= np.bincount(at[roots], weights=d_root == 0, minlength=pt.size) == 0
        pos = np.bincount(at[roots], weights=DET_SIGN * d_root * np.where(up_[roots], 1, -1) > 0, minlength=pt.size)
        result[now] = np.stack([k, np.where(d_open, pos, np.where(rising, up, k - up))], axis=1)[now]
        refuse = ~done & ((k > degree) | clash)  # more changes than the degree allows, or a clash: never if sound
        result[refuse] = -1
        crowd = ~done & ~now & (unfixed > POINT_CROWD)  # on a multiple root, where the open sub-pieces double each round
        done |= now | refuse | crowd
        drop = done[pair]
        pair, piece, lo, hi, s0, s1, fixed = (a[~drop] for a in (pair, piece, lo, hi, s0, s1, fixed))
        if pair.size == 0 or round_ == halvings:
            break
        cut = np.flatnonzero(~fixed)
        mid = np.minimum(np.maximum(0.5 * lo[cut] + 0.5 * hi[cut], lo[cut]), hi[cut])
        sm = node_sign(pair[cut], mid)
        pair, piece = np.r_[pair, pair[cut]], np.r_[piece, piece[cut]]
        lo, hi = np.r_[lo, mid], np.r_[hi, hi[cut]]
        hi[cut] = mid
        s0, s1 = np.r_[s0, sm], np.r_[s1, s1[cut]]
        s1[cut] = sm
        fixed = np.r_[fixed, np.zeros(cut.size, dtype=bool)]
    return WindowCounts(live, pt, win, result)


def window_signature(geometry: Geometry, models: WindowModels, rows: np.ndarray, points: np.ndarray,
                     halvings: int = POINT_HALVINGS) -> np.ndarray:
    """(m, 3) int64: the certified (count, n_wa1, n_wa2) at joint vectors ``points`` (m, 3), -1 where undecided.

    ``rows`` (m,) names the box of ``models`` that holds each point: the roots off the windows
    (:attr:`WindowModels.off`) plus the roots of each window counted by :func:`window_root_counts`.
    """
    rows = np.asarray(rows, dtype=np.int64)
    counts = window_root_counts(geometry, models, rows, points, halvings)
    live, pt, roots = counts.live, counts.pt, counts.roots
    out = np.full((len(rows), 3), -1, dtype=np.int64)
    good = counts.decided()
    total = np.stack([np.bincount(pt, weights=roots[:, i], minlength=live.size) for i in (0, 1)], axis=1)
    sig = models.off[rows[live]] + np.stack([total[:, 0], total[:, 1], total[:, 0] - total[:, 1]], axis=1).astype(np.int64)
    out[live[good]] = sig[good]
    return out
