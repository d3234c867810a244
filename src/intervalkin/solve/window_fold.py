"""Window folds: joint boxes whose window model proves one monotone sheet of g(S), or none.

A window model (:mod:`intervalkin.solve.window_model`, proofs/lemma-window-model.md)
of a joint box R cuts the circle of orientations into arcs whose roots are the same
on all of R and *windows* where roots may merge.  Classify each window by its degree
d (2 or 3: at most d roots with multiplicity) and the end signs of f:

* *constant*: d = 2 and the end signs differ: exactly one simple root for every
  r in R^2 (odd parity, at most two), whose det A sign follows from the direction in
  which f crosses zero and the sign of D on the window;
* *pair*: the end signs agree (s = the common sign): 0 or 2 roots.  With
  u(r) = min over the window of s f(phi; r), the window holds two simple roots where
  u < 0, none where u > 0, and a double root (a point of g(S)) where u = 0;
* *cusp*: d = 3 and the end signs differ: one or three roots (a cusp edge may pass); a window
  whose end signs or sign of D are not proved for the whole box is treated like one (open).

R is a *window-clear* box when it has no pair and no cusp window: every root is simple
on all of R, so R lies off g(S) and its signature is the same everywhere.  R is a
*window fold* when it has exactly one pair window, no cusp window, and the sign of
s df/dr_l is certified over R^2 x window for l = 1, 2, 3.  Then u is strictly
monotone in each rho_l (r_l = rho_l^2, rho_l > 0) with known directions, g(S) meets R
exactly in {u = 0}, and R minus g(S) is two pieces, each connected or empty:

* piece 0, {u > 0}: the window holds no root; it holds the corner where u is largest
  if it is not empty;
* piece 1, {u < 0}: the window holds two roots (one solution in each aspect: the two
  roots have opposite f' and the same sign of D); it holds the corner where u is smallest.

A point of piece 1 moves, one coordinate at a time, towards the corner where u is
smallest without leaving {u < 0}; so piece 1 is connected, and so is its trace on every
face of R or on any axis-aligned rectangle in R (the same argument inside it).  Likewise
piece 0 (proofs/lemma-window-fold.md).  *Two-axis* folds: when the slope is certified
for two axes only, it is checked along the third on two edges of R, and the pieces retract to
those edges (statement 4' of the lemma).  A point is placed in a piece by its window count,
certified at the point (:func:`intervalkin.solve.window_count.window_signature`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from intervalkin.core.errors import InputError
from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import sign_label
from intervalkin.core.workers import Workers
from intervalkin.solve.simple_roots import ReducedBoxes
from intervalkin.solve.window_count import window_signature
from intervalkin.solve.root_directions import piece_direction_signs, with_singular_signs
from intervalkin.solve.window_model import DET_SIGN, WindowModels

__all__ = ["OPEN", "CLEAR", "FOLD", "PAIR", "STEADY", "WHY_NOT", "WindowFolds", "window_folds", "why_not_pieced",
           "fold_piece", "extreme_corners", "base_signature", "window_kinds", "pair_windows", "pair_slopes",
           "pair_direction_signs", "agreed_signs", "window_parts", "critical_pieces", "pair_critical"]

#: Kinds of window-modelled boxes.
OPEN, CLEAR, FOLD = 0, 1, 2
#: Boxes from which pair_direction_signs splits its work between processes.
MIN_PARALLEL_BOXES = 400
#: pair_direction_signs(at_roots=True) for a window whose status no point of the box changes (every direction keeps it).
STEADY = 2
#: What the two roots of a pair window add to a signature (count, n_wa1, n_wa2).
PAIR = np.array([2, 1, 1], dtype=np.int64)
#: Why a modelled box is neither window-clear nor a window fold, most telling first (:func:`why_not_pieced`):
#: a cusp window (one or three roots: a cusp edge of g(S) may pass), a window whose end signs or sign of D
#: are proved only at points, two pair windows or more (sheets of g(S) that may cross), one pair window whose
#: slope signs are not certified (a sheet that may turn within the box).
WHY_NOT = ("cusp_window", "window_at_points", "pair_windows", "slope_not_certified")
#: Halvings of the critical pieces of a pair window before its slope signs are read.
CRITICAL_HALVINGS = 1


@dataclass(frozen=True, eq=False)
class WindowFolds:
    """The window-clear boxes and window folds among window-modelled boxes (rows of a :class:`WindowModels`).

    kind : (n,) int8, :data:`CLEAR`, :data:`FOLD` or :data:`OPEN` (not modelled, or a cusp
        window, or several pair windows, or a slope sign not certified).
    window : (n,) int64, the pair window of a fold (an index into the models' windows), -1 elsewhere.
    rising : (n, 3) int8, for a fold: +1 where u grows with rho_l over the whole box, -1 where it
        falls; 0 elsewhere, and on the free axis of a two-axis fold.
    edge_rising : (n, 2) int8, for a two-axis fold: the same sign along its free axis a on the edge
        E_low (the other two coordinates at their ends towards -rising) and on the edge E_high
        (towards +rising); 0 elsewhere.
    signature : (n, 2, 3) int64, (count, n_wa1, n_wa2) of piece 0 (the pair window empty) and of
        piece 1 (two roots in it) of a fold; of the whole box (piece 0) of a clear box; -1 elsewhere.
    """

    kind: np.ndarray
    window: np.ndarray
    rising: np.ndarray
    signature: np.ndarray
    edge_rising: np.ndarray

    def __len__(self) -> int:
        return len(self.kind)

    def take(self, rows: np.ndarray, renumber: np.ndarray) -> "WindowFolds":
        """Rows ``rows``, their window indices mapped by ``renumber`` (WindowModels.window_renumber)."""
        w = self.window[rows]
        return WindowFolds(self.kind[rows], np.where(w >= 0, renumber[np.maximum(w, 0)], -1), self.rising[rows],
                           self.signature[rows], self.edge_rising[rows])

    def concat(self, other: "WindowFolds", windows: int) -> "WindowFolds":
        """These rows followed by ``other``'s, whose window indices are shifted by ``windows``."""
        shifted = np.where(other.window >= 0, other.window + windows, -1)
        return WindowFolds(*(np.concatenate([a, b]) for a, b in (
            (self.kind, other.kind), (self.window, shifted), (self.rising, other.rising),
            (self.signature, other.signature), (self.edge_rising, other.edge_rising))))


def window_folds(geometry: Geometry, models: WindowModels, halvings: int = CRITICAL_HALVINGS) -> WindowFolds:
    """Classify the boxes of ``models`` and prove the slope signs of their pair windows (vectorised).

    The slopes are needed only where the window's interior minimum of s f can sit: on the
    *critical* pieces, where neither s f > 0 nor df/dphi != 0 is certified over R^2 x piece;
    those are halved ``halvings`` times to tighten them.
    """
    n = len(models.ok)
    ends = models.end_signs.astype(np.int64)
    firm, even, cusp, _ = window_kinds(models)
    cusp = ~firm | cusp  # decided only at points: treated like a cusp window
    box = models.window_box
    n_pair = np.bincount(box, weights=even, minlength=n)
    n_cusp = np.bincount(box, weights=cusp, minlength=n)
    base = base_signature(models)
    kind = np.full(n, OPEN, dtype=np.int8)
    clear = models.ok & (n_pair == 0) & (n_cusp == 0)
    kind[clear] = CLEAR
    candidate = models.ok & (n_pair == 1) & (n_cusp == 0)
    window = np.full(n, -1, dtype=np.int64)
    pair_w = np.flatnonzero(even & candidate[box])
    window[box[pair_w]] = pair_w
    rising = np.zeros((n, 3), dtype=np.int8)
    if pair_w.size:
        rising[box[pair_w]] = pair_slopes(geometry, models, np.flatnonzero(candidate), halvings)[pair_w]
    edge_rising = np.zeros((n, 2), dtype=np.int8)
    two = np.flatnonzero(candidate & (np.count_nonzero(rising, axis=1) == 2))
    if two.size:
        edge_rising[two] = _edge_slopes(geometry, models, two, rising[two], window[two], ends[:, 0], halvings)
    fold = candidate & ((rising != 0).all(axis=1) | (edge_rising != 0).all(axis=1))
    kind[fold] = FOLD
    edge_rising[~fold] = 0
    window[~fold] = -1
    rising[~fold] = 0
    signature = np.full((n, 2, 3), -1, dtype=np.int64)
    signature[clear, 0] = base[clear]
    signature[fold, 0] = base[fold]
    signature[fold, 1] = base[fold] + PAIR
    return WindowFolds(kind, window, rising, signature, edge_rising)


def base_signature(models: WindowModels) -> np.ndarray:
    """(n, 3) the part of each box's signature (count, n_wa1, n_wa2) that is the same at all its points: the roots
    off the windows and the one root of each window of degree 2 whose end signs differ (box-wide end signs and
    sign of D); meaningful for modelled boxes."""
    n = len(models.ok)
    ends = models.end_signs.astype(np.int64)
    constant = window_kinds(models)[3]
    det_pos = constant & ((DET_SIGN * models.d_sign.astype(np.int64) * np.where(ends[:, 0] < 0, 1, -1)) > 0)
    box = models.window_box
    base = models.off.copy()
    base[:, 0] += np.bincount(box, weights=constant, minlength=n).astype(np.int64)
    base[:, 1] += np.bincount(box, weights=det_pos, minlength=n).astype(np.int64)
    base[:, 2] += np.bincount(box, weights=constant & ~det_pos, minlength=n).astype(np.int64)
    return base


def pair_windows(models: WindowModels) -> np.ndarray:
    """(w,) bool: the pair windows (end signs equal and sign of D, both proved over the whole box: 0 or 2 roots)."""
    return window_kinds(models)[1]


def pair_slopes(geometry: Geometry, models: WindowModels, rows: np.ndarray,
                halvings: int = CRITICAL_HALVINGS) -> np.ndarray:
    """(w, 3) int8 per window of ``models``: for the pair windows of boxes ``rows``, the certified sign of
    s df/dr_l (s the common end sign) over R^2 x the window's critical pieces, that is the direction in
    which u = min s f over the window grows along rho_l (0: not certified); 0 for the other windows."""
    signs, free = pair_direction_signs(geometry, models, rows, np.eye(3), halvings)
    signs[free] = 1  # u > 0 on the whole box: every direction keeps it
    return signs


def window_kinds(models: WindowModels) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(firm, pair, cusp, constant) per window: end signs and sign of D proved over the whole box (a window that
    is not firm is decided only at points); a firm window with equal end signs (0 or 2 roots); a firm window of
    degree 3 with end signs that differ (1 or 3 roots); a firm window of degree 2 with end signs that differ
    (exactly one root)."""
    ends = models.end_signs.astype(np.int64)
    firm = (ends != 0).all(axis=1) & (models.d_sign != 0)
    even = firm & (ends[:, 0] == ends[:, 1])
    return firm, even, firm & (models.degree == 3) & ~even, firm & (models.degree == 2) & ~even


def why_not_pieced(models: WindowModels, folds: WindowFolds) -> np.ndarray:
    """(n,) int8 per box of ``models``: the index in :data:`WHY_NOT` of the first reason its pieces are not proved
    connected, -1 for window-clear boxes, window folds and boxes without a model.  The classes follow the windows'
    kinds as :func:`window_folds` reads them (a label for reports, not a claim)."""
    n = len(models.ok)
    firm, even, cusp, _ = window_kinds(models)
    box = models.window_box
    count = [np.bincount(box, weights=w, minlength=n) > t for w, t in ((cusp, 0), (~firm, 0), (even, 1), (even, 0))]
    out = np.full(n, -1, dtype=np.int8)
    for code in range(len(WHY_NOT) - 1, -1, -1):  # the first reason wins
        out[count[code]] = code
    out[~models.ok | np.isin(folds.kind, (CLEAR, FOLD))] = -1
    return out


def critical_pieces(data: ReducedBoxes, owner_of_window: np.ndarray, s: np.ndarray, pw: np.ndarray, lo: np.ndarray,
              hi: np.ndarray, halvings: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The critical pieces (pw, lo, hi) of pair windows: where neither s f > 0 nor df/dphi != 0 is proved over
    R^2 x piece (the window's minimum of s f can only sit there), halved ``halvings`` times."""
    for round_ in range(halvings + 1):
        owner = owner_of_window[pw]
        crit = sign_label(data.enclosure(owner, lo, hi, 1)) == 0
        if round_:  # a window's own pieces are the ones where f may vanish: s f > 0 shows only on halves
            crit[crit] = sign_label(data.enclosure(owner[crit], lo[crit], hi[crit], 0))[...] * s[pw[crit]] <= 0
        pw, lo, hi = pw[crit], lo[crit], hi[crit]
        if round_ < halvings:
            mid = np.minimum(np.maximum(0.5 * lo + 0.5 * hi, lo), hi)
            pw, lo, hi = np.r_[pw, pw], np.r_[lo, mid], np.r_[mid, hi]
    return pw, lo, hi


def _slopes(data: ReducedBoxes, owner_of_window: np.ndarray, s: np.ndarray, w: int, pw: np.ndarray,
            lo: np.ndarray, hi: np.ndarray, halvings: int) -> np.ndarray:
    """(w, 3) int8 per window: the certified sign of s d f / d r_l on its critical pieces (0: not certified).

    A window with no critical piece left has u > 0 on all of R (no root): every direction is
    valid for it, and +1 is returned.
    """
    pw, lo, hi = critical_pieces(data, owner_of_window, s, pw, lo, hi, halvings)
    out = np.ones((w, 3), dtype=np.int8)
    owner = owner_of_window[pw]
    for axis in range(3):
        sg = sign_label(data.r_slope(owner, lo, hi, axis)).astype(np.int64) * s[pw]
        low = np.full(w, 2, dtype=np.int64)
        high = np.full(w, -2, dtype=np.int64)
        np.minimum.at(low, pw, sg)
        np.maximum.at(high, pw, sg)
        out[:, axis] = np.where(low == 2, 1, np.where((low == high) & (low != 0), low, 0))
    return out


def pair_direction_signs(geometry: Geometry, models: WindowModels, rows: np.ndarray, directions: np.ndarray,
                         halvings: int = CRITICAL_HALVINGS, at_roots: bool = False,
                         workers: Workers | None = None) -> tuple[np.ndarray, np.ndarray]:
    """For the pair windows of boxes ``rows`` and each direction e (c, 3) in rho: ((w, c) int8, the certified
    sign of s D_e f = s sum_l e_l 2 rho_l df/dr_l on the window's critical pieces over R, that is the direction
    in which u = min s f moves along e (0: not certified); (w,) bool, windows with no critical piece (u > 0 on
    the whole box)).  Other windows: 0 and False.  df/dr_l is the intersection of the Taylor form's enclosure
    and :func:`~intervalkin.solve.window_split.aligned_r_slopes` (tighter near the zeros of D).

    ``at_roots``: the sign only at the roots of f on the critical pieces, which is all the retraction needs (u
    changes sign only through u = 0, where its minimum is a double root; proofs/lemma-joint-retraction.md): where
    the whole-piece form gives none, the sign at the roots of
    :func:`~intervalkin.solve.root_directions.root_direction_signs`; critical pieces proved to hold no root (or whose
    two forms disagree, which they could not at a root) then say nothing, and a window whose critical pieces all
    hold none gets :data:`STEADY` for every direction (u does not vanish on the box, so its status is the same at
    every point of it).  The window folds need the sign at every point of the critical pieces (u monotone), so
    it is off for them.

    With ``at_roots`` a critical piece also says nothing where no point of it is a double root of f (u vanishes
    only at one: :mod:`~intervalkin.solve.root_directions`, the two branches of f near a zero of D, and s pinned
    at the double roots), and where the root bound leaves a direction open, the sign at the double roots alone
    fills it (:func:`~intervalkin.solve.root_directions.double_root_signs`); the singular poses read what is still
    open (:func:`~.root_directions.with_singular_signs`, gap pieces too: a double root is the only one, s f'' > 0).

    ``workers``: boxes are cut into parts computed at once (each window's signs come from its own box alone)."""
    w = len(models.degree)
    rows = np.asarray(rows, dtype=np.int64)
    directions = np.asarray(directions, dtype=np.float64)
    if workers is not None and workers.count > 1 and rows.size >= MIN_PARALLEL_BOXES:
        return _pair_direction_parts(geometry, models, rows, directions, halvings, at_roots, workers)
    out = np.zeros((w, len(directions)), dtype=np.int8)
    even = pair_windows(models) & np.isin(models.window_box, rows)
    if not even.any():
        return out, np.zeros(w, dtype=bool)
    data, s, pw, lo, hi, owner = pair_critical(geometry, models, rows, even, halvings)
    signs, quiet = piece_direction_signs(geometry, models.boxes[rows], data, owner, lo, hi, directions, at_roots)
    free = even & (np.bincount(pw, minlength=w) == 0)
    if at_roots:  # what the elimination's forms leave open, from the singular poses (quiet pieces need nothing)
        with_singular_signs(geometry, models.boxes[rows], owner, lo, hi, directions, signs, quiet, np.arange(pw.size),
                            curvature=s[pw].astype(np.int8), gap=True)
    out[:] = agreed_signs(pw, signs, s[pw], quiet, w)
    # no root on any critical piece: u never vanishes on the box, whichever its sign (either pattern keeps)
    out[even & ~free & (np.bincount(pw, weights=~quiet, minlength=w) == 0)] = STEADY
    return out, free


def pair_critical(geometry: Geometry, models: WindowModels, rows: np.ndarray, even: np.ndarray, halvings: int):
    """(the ReducedBoxes of boxes ``rows``, the end signs s, and the critical pieces pw, lo, hi of the windows
    ``even`` with their owners, rows of ``data``): what the direction signs of pair windows are read on."""
    on = np.isin(models.piece_window, np.flatnonzero(even))
    row = np.full(len(models.ok), -1, dtype=np.int64)
    row[rows] = np.arange(rows.size)
    data = ReducedBoxes(geometry, models.boxes[rows])
    s = models.end_signs[:, 0].astype(np.int64)
    pw, lo, hi = critical_pieces(data, row[models.window_box], s, models.piece_window[on], models.piece_lo[on],
                                 models.piece_hi[on], halvings)
    return data, s, pw, lo, hi, row[models.window_box][pw]


def agreed_signs(window: np.ndarray, signs: np.ndarray, factor: np.ndarray, quiet: np.ndarray, w: int) -> np.ndarray:
    """(w, c) int8: for each of ``w`` windows and each direction, the sign that ``factor`` times ``signs`` (pieces
    (m, c), of window ``window`` (m,)) has on every piece of the window that is not ``quiet``, where that is
    +-1 on all of them; 0 elsewhere, and for windows with no such piece."""
    out = np.zeros((w, signs.shape[1]), dtype=np.int8)
    held = np.flatnonzero(~quiet)
    held = held[np.argsort(window[held], kind="stable")]
    win, start = np.unique(window[held], return_index=True)
    if win.size:
        sg = signs[held] * np.asarray(factor, dtype=np.int8)[held][:, None]
        low, high = np.minimum.reduceat(sg, start, axis=0), np.maximum.reduceat(sg, start, axis=0)
        out[win] = np.where((low == high) & (np.abs(low) == 1), low, 0)
    return out


def window_parts(fn, geometry: Geometry, models: WindowModels, rows: np.ndarray, workers: Workers,
                 *args) -> list[tuple[np.ndarray, tuple]]:
    """``fn(geometry, part_models, all_their_rows, *args)`` for parts of the boxes ``rows`` on the workers (each
    window's result comes from its own box alone, so the arrays are the same bit for bit): (the windows of
    ``models`` each part holds, in the order :meth:`take` keeps them; its result) per part."""
    rows = np.unique(rows)  # take() wants increasing rows; every window is then in exactly one part
    parts = [rows[a:b] for a, b in workers.parts(rows.size, least=MIN_PARALLEL_BOXES)]
    got = workers.run(fn, [(geometry, models.take(part), np.arange(part.size)) + tuple(args) for part in parts])
    return [(np.flatnonzero(models.window_renumber(part) >= 0), res) for part, res in zip(parts, got)]


def _pair_direction_parts(geometry: Geometry, models: WindowModels, rows: np.ndarray, directions: np.ndarray,
                          halvings: int, at_roots: bool, workers: Workers) -> tuple[np.ndarray, np.ndarray]:
    """:func:`pair_direction_signs` with the boxes ``rows`` cut into parts, one call each on their models alone."""
    w = len(models.degree)
    out = np.zeros((w, len(directions)), dtype=np.int8)
    free = np.zeros(w, dtype=bool)
    for at, (signs, part_free) in window_parts(pair_direction_signs, geometry, models, rows, workers, directions,
                                               halvings, at_roots):
        out[at] = signs
        free[at] = part_free
    return out, free


def _edge_slopes(geometry: Geometry, models: WindowModels, rows: np.ndarray, rising: np.ndarray, window: np.ndarray,
                 s: np.ndarray, halvings: int) -> np.ndarray:
    """(k, 2) int8: for boxes ``rows`` with one uncertified axis a, the certified sign of s df/dr_a over the
    critical pieces of the pair window on the edges E_low and E_high (0: not certified)."""
    box = models.boxes[rows]
    free = np.argmin(np.abs(rising), axis=1)
    k = len(rows)
    out = np.zeros((k, 2), dtype=np.int8)
    for end, toward in enumerate((-1, 1)):
        edge = box.copy()
        pin = np.where(rising * toward > 0, box[:, :, 1], box[:, :, 0])  # the end of each axis in that direction
        fixed = np.arange(3)[None, :] != free[:, None]
        edge[:, :, 0] = np.where(fixed, pin, box[:, :, 0])
        edge[:, :, 1] = np.where(fixed, pin, box[:, :, 1])
        owner = np.full(len(models.degree), -1, dtype=np.int64)
        owner[window] = np.arange(k)
        on = np.isin(models.piece_window, window)
        signs = _slopes(ReducedBoxes(geometry, edge), owner, s, len(models.degree), models.piece_window[on],
                        models.piece_lo[on], models.piece_hi[on], halvings)
        out[:, end] = signs[window, free]
    return out


def fold_piece(geometry: Geometry, models: WindowModels, folds: WindowFolds, rows: np.ndarray,
               points: np.ndarray) -> np.ndarray:
    """(m,) int8: the piece of each point (m, 3) of box ``rows`` (m,): 0 or 1 for a fold, 0 for a clear box;
    -1 where the point's window count is not decided (on or very near g(S)) or the box is open.

    Certified: a fold's piece is read from the count proved at the point; a clear box is off g(S).
    """
    rows = np.asarray(rows, dtype=np.int64)
    q = np.asarray(points, dtype=np.float64)
    if q.ndim != 2 or q.shape[1] != 3 or rows.shape != (len(q),):
        raise InputError(f"points: expected shape (m, 3) and rows (m,), got {q.shape} and {rows.shape}")
    out = np.full(len(rows), -1, dtype=np.int8)
    kind = folds.kind[rows]
    box = models.boxes[rows]
    inside = ((box[:, :, 0] <= q) & (q <= box[:, :, 1])).all(axis=1)
    if not inside.all():
        raise InputError("points: every point must lie in its box models.boxes[rows]")
    out[kind == CLEAR] = 0
    at = np.flatnonzero(kind == FOLD)
    if at.size:
        count = window_signature(geometry, models, rows[at], q[at])[:, 0]
        extra = count - folds.signature[rows[at], 0, 0]
        out[at] = np.where(count < 0, -1, np.where(extra == 0, 0, np.where(extra == 2, 1, -1)))
    return out


def extreme_corners(lo: np.ndarray, hi: np.ndarray, rising: np.ndarray,
                    edge_rising: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(corner where u is smallest, corner where it is largest) of boxes or faces lo, hi (m, 3), for folds
    with directions ``rising`` (m, 3) and, for two-axis folds, ``edge_rising`` (m, 2) on their free axis:
    piece 1 holds the first if it is not empty, piece 0 the second (on a face of a two-axis fold they
    are only points to try)."""
    rising = np.asarray(rising)
    low_dir, high_dir = rising.copy(), rising.copy()
    if edge_rising is not None:
        free = rising == 0
        low_dir = np.where(free, np.asarray(edge_rising)[:, :1], low_dir)
        high_dir = np.where(free, np.asarray(edge_rising)[:, 1:], high_dir)
    return np.where(low_dir > 0, lo, hi), np.where(high_dir > 0, hi, lo)
