"""Every claimed label of an array of boxes, re-proved by interval evaluation and vectorised bisection.

A claim (label name, value) holds on a box when it holds on sub-boxes that
cover the box.  :func:`confirm_labels` evaluates the claim's test
(:data:`~intervalkin.recheck.model.TESTS`) on all boxes at once; the boxes not
confirmed are cut in two across their widest side (the phi width weighted by
the platform's reach, since a turn d phi moves a platform point by up to
reach * d phi), and the halves are evaluated again, all of them together, for
at most ``rounds`` rounds, and while a box has at most :data:`PER_BOX` open
sub-boxes after the split.  The halves [lo, m] and [m, hi] cover [lo, hi] for
any float m with lo <= m <= hi, so rounding the midpoint costs nothing.

On every sub-box still undecided the opposite label is also tried
(:data:`~intervalkin.recheck.model.REFUTATIONS`): when it holds, the claim is
FALSE on that sub-box, and so on the box (a wrong label, not merely an
unproved one).  The result per box is :data:`CONFIRMED`, :data:`REFUTED`, or
:data:`NOT_CONFIRMED` (rounds or work budget spent: nothing is claimed).
"""

from __future__ import annotations

import numpy as np

from intervalkin.recheck.model import REFUTATIONS, TESTS, Constants

__all__ = ['CONFIRMED', 'NOT_CONFIRMED', 'REFUTED', 'ROUNDS', 'PER_BOX', 'MAX_PENDING', 'CHUNK', 'confirm_labels']

CONFIRMED, NOT_CONFIRMED, REFUTED = 1, 0, -1
#: Bisection rounds per box (each round halves the open sub-boxes; ten rounds halve every side about three times).
ROUNDS = 30
#: Open sub-boxes of one box at most: a box whose open part keeps spreading (a label that is wrong
#: along a surface, or undecidable) is given up as not confirmed rather than allowed to cost millions.
PER_BOX = 64
#: Sub-boxes evaluated at once at most; past it the bisection stops and the rest are not confirmed.
MAX_PENDING = 1_000_000
#: Boxes evaluated at once in the first pass (memory: a few dozen float arrays of this length).
CHUNK = 200_000


def _evaluate(k: Constants, lo: np.ndarray, hi: np.ndarray, name: str, values: np.ndarray, table: dict) -> np.ndarray:
    """table[(name, v)] on every row whose claimed value is v; True where it is proved."""
    out = np.zeros(len(lo), dtype=bool)
    for v in (1, -1):
        rows = np.flatnonzero(values == v)
        for s in range(0, len(rows), CHUNK):
            r = rows[s:s + CHUNK]
            box = tuple((lo[r, a], hi[r, a]) for a in range(3))
            out[r] = table[(name, v)](k, box)
    return out


def _halves(lo: np.ndarray, hi: np.ndarray, reach: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Both halves of each box cut across its widest (weighted) side: (lo, hi, parent row) of 2n boxes."""
    w = hi - lo
    w[:, 2] *= reach
    axis = np.argmax(w, axis=1)
    rows = np.arange(len(lo))
    a, b = lo[rows, axis], hi[rows, axis]
    mid = np.clip(a + (b - a) / 2, a, b)  # a float between the ends: the halves cover the box
    lo_l, hi_l = lo.copy(), hi.copy()
    hi_l[rows, axis] = mid
    lo_r, hi_r = lo.copy(), hi.copy()
    lo_r[rows, axis] = mid
    return np.concatenate([lo_l, lo_r]), np.concatenate([hi_l, hi_r]), np.concatenate([rows, rows])


def confirm_labels(k: Constants, lo: np.ndarray, hi: np.ndarray, name: str, values: np.ndarray,
                   rounds: int = ROUNDS, max_pending: int = MAX_PENDING) -> np.ndarray:
    """Status (n,) int8 of the claims ``name`` = ``values[j]`` (1 or -1) on the boxes ``lo[j], hi[j]``.

    Parameters
    ----------
    k : the geometry's enclosed constants (:func:`~intervalkin.recheck.model.constants`).
    lo, hi : ndarray of shape (n, 3), float64, the boxes (x, y, phi), finite, lo <= hi.
    name : ``"in_workspace"`` or ``"det_sign"``.
    values : ndarray of shape (n,), the claimed labels, each 1 or -1.

    Returns
    -------
    ndarray of shape (n,), int8: :data:`CONFIRMED` where the claim is proved on the
    whole box, :data:`REFUTED` where its opposite is proved on part of it,
    :data:`NOT_CONFIRMED` otherwise.
    """
    n = len(lo)
    status = np.full(n, NOT_CONFIRMED, dtype=np.int8)
    owner = np.arange(n)
    cur_lo, cur_hi, cur_v = lo, hi, np.asarray(values)
    refuted = np.zeros(n, dtype=bool)
    given_up = np.zeros(n, dtype=bool)
    for r in range(rounds + 1):
        ok = _evaluate(k, cur_lo, cur_hi, name, cur_v, TESTS)
        open_ = ~ok
        wrong = np.zeros(len(cur_lo), dtype=bool)
        wrong[open_] = _evaluate(k, cur_lo[open_], cur_hi[open_], name, cur_v[open_], REFUTATIONS)
        refuted[owner[wrong]] = True
        open_ &= ~refuted[owner]
        # give up on boxes whose open part spreads; they stay NOT_CONFIRMED (pending below)
        spread = np.bincount(owner[open_], minlength=n) > PER_BOX // 2
        given_up |= spread
        open_ &= ~spread[owner]
        cur_lo, cur_hi, cur_v, owner = cur_lo[open_], cur_hi[open_], cur_v[open_], owner[open_]
        if len(owner) == 0 or r == rounds or 2 * len(owner) > max_pending:
            break
        cur_lo, cur_hi, parent = _halves(cur_lo, cur_hi, k.reach)
        cur_v, owner = cur_v[parent], owner[parent]
    pending = given_up.copy()
    pending[owner] = True
    status[~pending] = CONFIRMED
    status[refuted] = REFUTED
    return status
