"""Window patterns: the pieces of a window-modelled leaf told apart by where their roots are.

A window model of a leaf L (:mod:`intervalkin.solve.window_model`) cuts the circle of
orientations at points where the sign of f is proved for all of L; between them, arcs whose
roots are fixed on L and *windows* where roots may merge.  Windows joined by inner cuts whose
sign is only proved at points (sub-windows) are taken together: a *super-window* is a maximal
run of them, and its two outer cuts have signs proved over L.

At a point q of L off g(S) every solution is non-singular, so each moves continuously with q
and never crosses a cut where f != 0 over L (f vanishes at a solution).  The number of
solutions in each super-window is therefore locally constant on L minus g(S), and so is the
*pattern*, the vector of those numbers.  The set of points of L off g(S) with a given pattern is
open and closed in L minus g(S): a union of its connected pieces.  Two sets with the same total
count but different patterns (near a transversal crossing of two sheets of g(S): two roots in
one window, or two in the other) are told apart, though neither is proved connected
(proofs/lemma-separation.md).

Codes: a pattern is stored as sum over super-windows s of count_s * 8^rank_s, rank_s the
position of s among its leaf's super-windows (counts below 8: a window holds at most 3 roots,
a super-window at most 7 by construction of the codes; more is refused).

Neighbours (:func:`compatible`): the orientation phi is the same coordinate in every leaf, so at a
point q of a face shared by leaves L and L' every solution lies in one *unit* of each model: a
super-window (holding the pattern's number) or an arc off the windows that holds one fixed root
(the rest of the circle holds none, on the whole leaf).  A solution in a unit U' of L' lies in a
unit of L whose arc meets U'.  Hence, for patterns k of L and k' of L' both held at q,

    k'(U') <= sum of k(U) over the units U of L that meet U',

and the same with L and L' exchanged.  A pair of patterns that breaks one of these inequalities
is never held at one point: no path crosses the face from the one to the other.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import PI_HI
from intervalkin.solve.window_count import window_root_counts
from intervalkin.solve.window_model import WindowModels

__all__ = ["WindowPatterns", "window_patterns", "pattern_at", "digits", "unit_overlaps", "unit_counts", "compatible",
           "exclusive", "row_of", "NONE", "EVERY"]

#: Base of the pattern codes (one digit per super-window).
BASE = 8
#: Boxes that may hold more patterns than this get none (they stay one node of the separation graph).
MAX_PATTERNS = 256
#: Roots of f(phi; r) on the circle at most: a trigonometric polynomial of degree 3 that is not identically
#: zero (a window model proves a derivative or the value nonzero at every point of its box) has at most 6.
MAX_ROOTS = 6
#: Boxes whose super-windows' choices multiply past this are not enumerated (the rows before pruning).
MAX_ENUMERATED = 1 << 14
#: Super-windows of a box with patterns, at most (8**20 < 2**63: a code is an exact int64).
MAX_DIGITS = 20


@dataclass(frozen=True, eq=False)
class WindowPatterns:
    """The possible patterns of the boxes of a :class:`WindowModels` (those with ``ok``).

    super_of : (w,) the super-window of each window; rank : (s,) the rank of each super-window in
    its box; box : (k,) the box of each pattern row; code : (k,) its code; count : (k,) its total
    count (roots off the windows plus the pattern's); width : the super-windows of the boxes with rows
    (at most :data:`MAX_DIGITS`), the number of digits of a code.
    """

    super_of: np.ndarray
    rank: np.ndarray
    box: np.ndarray
    code: np.ndarray
    count: np.ndarray
    width: int = 1


def _window_sets(models: WindowModels) -> np.ndarray:
    """(w,) int64 bit masks of the root counts each window can hold on its whole box."""
    ends = models.end_signs.astype(np.int64)
    # parity from the end signs only where D keeps one sign: at a zero of D the roots of f and the
    # solutions need not match one for one (proofs/lemma-window-patterns.md)
    firm = (ends != 0).all(axis=1) & (models.d_sign != 0)
    even = firm & (ends[:, 0] == ends[:, 1])
    odd = firm & ~even
    deg = models.degree.astype(np.int64)
    every = np.left_shift(1, deg + 1) - 1  # 0 .. degree
    return np.where(even, every & 0b0101_0101, np.where(odd, every & 0b1010_1010, every))


def _super_windows(models: WindowModels) -> np.ndarray:
    """(w,) super-window id of each window: windows linked by a cut whose sign is proved only at points."""
    w = len(models.degree)
    if w == 0:
        return np.zeros(0, dtype=np.int64)
    pw = models.piece_window
    first = np.searchsorted(pw, np.arange(w), side="left")
    last = np.searchsorted(pw, np.arange(w), side="right") - 1
    start, stop = models.piece_lo[first], models.piece_hi[last]
    box = models.window_box
    # an inner cut is the stop of one window and the start of the next (the seam +-PI_HI is one cut)
    key_stop = np.where(np.abs(stop) == PI_HI, -PI_HI, stop)
    key_start = np.where(np.abs(start) == PI_HI, -PI_HI, start)
    inner = np.flatnonzero(models.end_signs[:, 1] == 0)
    a_keys = np.column_stack([box.astype(np.float64), key_start])
    order = np.lexsort((a_keys[:, 1], a_keys[:, 0]))
    sorted_keys = a_keys[order]
    probe = np.column_stack([box[inner].astype(np.float64), key_stop[inner]])
    # exact match of (box, phi) by a structured view
    view = np.ascontiguousarray(sorted_keys).view([("b", "f8"), ("p", "f8")]).ravel()
    pv = np.ascontiguousarray(probe).view([("b", "f8"), ("p", "f8")]).ravel()
    pos = np.searchsorted(view, pv)
    ok = pos < len(view)
    ok[ok] = view[pos[ok]] == pv[ok]
    if not ok.all():
        raise ValueError("window model: an inner cut of a sub-window has no following sub-window")
    nxt = order[pos]
    graph = coo_matrix((np.ones(inner.size), (inner, nxt)), shape=(w, w))
    return connected_components(graph, directed=False)[1].astype(np.int64)


def window_patterns(models: WindowModels) -> WindowPatterns:
    """Every pattern each modelled box may hold: the product of its super-windows' possible counts, less
    the combinations with more than :data:`MAX_ROOTS` roots in all (no point of the box has them).

    Boxes not modelled, with a super-window that might hold more than 7 roots, with more than
    :data:`MAX_ENUMERATED` combinations, or with more than :data:`MAX_PATTERNS` patterns left, get no rows.
    """
    sup = _super_windows(models)
    nsup = int(sup.max()) + 1 if sup.size else 0
    sets = _window_sets(models)
    # the Minkowski sum of the members' sets, as bit masks (16 bits: a super-window over 7 is refused below)
    ssets = np.ones(nsup, dtype=np.int64)
    order = np.argsort(sup, kind="stable")
    wrank = np.empty(len(sup), dtype=np.int64)
    wrank[order] = np.arange(len(sup)) - np.searchsorted(sup[order], sup[order], side="left")
    for r in range(int(wrank.max()) + 1 if len(sup) else 0):
        at = np.flatnonzero(wrank == r)
        grown = np.zeros(at.size, dtype=np.int64)
        for bit in range(4):
            grown |= np.where((sets[at] >> bit) & 1 == 1, ssets[sup[at]] << bit, 0)
        # counts of 16 or more only ever make a super-window "wide": keep that fact, not the bits
        ssets[sup[at]] = (grown & 0xFFFF) | np.where(grown >> 16 != 0, 1 << 15, 0)
    sbox = np.zeros(nsup, dtype=np.int64)
    sbox[sup] = models.window_box
    order = np.argsort(sbox, kind="stable")
    rank = np.empty(nsup, dtype=np.int64)
    rank[order] = np.arange(nsup) - np.searchsorted(sbox[order], sbox[order], side="left")
    wide = np.zeros(len(models.ok), dtype=bool)  # a super-window that might hold 8 roots or more: no digit for it
    wide[models.window_box[(ssets[sup] >> BASE) != 0]] = True
    ssets &= (1 << BASE) - 1
    # the combinations are the product of the super-windows' choices; the rows kept after pruning are
    # bounded below, since pairs of the patterns of two crowded neighbours would fill the memory
    choices = sum((ssets >> k) & 1 for k in range(BASE))
    log_rows = np.zeros(len(models.ok))
    np.add.at(log_rows, sbox, np.log2(np.maximum(choices, 1)))
    crowded = log_rows > np.log2(MAX_ENUMERATED) + 1e-9
    crowded[sbox[rank >= MAX_DIGITS]] = True  # a code holds MAX_DIGITS digits in an int64
    ok = np.flatnonzero(models.ok & ~wide & ~crowded)
    kept = np.isin(sbox, ok)
    width = int(rank[kept].max()) + 1 if kept.any() else 1
    box, code, count = ok.copy(), np.zeros(ok.size, dtype=np.int64), models.off[ok, 0].astype(np.int64)
    for r in range(width):
        at = np.flatnonzero(rank == r)
        mask_of = np.zeros(len(models.ok), dtype=np.int64)
        has = np.zeros(len(models.ok), dtype=bool)
        mask_of[sbox[at]], has[sbox[at]] = ssets[at], True
        rows_b, rows_c, rows_n = [box[~has[box]]], [code[~has[box]]], [count[~has[box]]]
        for c in range(8):
            take = has[box] & ((mask_of[box] >> c) & 1 == 1)
            rows_b.append(box[take])
            rows_c.append(code[take] + c * BASE ** r)
            rows_n.append(count[take] + c)
        box, code, count = np.concatenate(rows_b), np.concatenate(rows_c), np.concatenate(rows_n)
        possible = count <= MAX_ROOTS  # digits only add roots: a row past the bound stays past it
        box, code, count = box[possible], code[possible], count[possible]
    many = np.bincount(box, minlength=len(models.ok)) > MAX_PATTERNS
    box, code, count = box[~many[box]], code[~many[box]], count[~many[box]]
    order = np.lexsort((code, box))
    return WindowPatterns(sup, rank, box[order], code[order], count[order], width)


def pattern_at(geometry: Geometry, models: WindowModels, patterns: WindowPatterns, rows: np.ndarray,
               points: np.ndarray) -> np.ndarray:
    """(m,) int64: the certified pattern code at joint vectors ``points`` of boxes ``rows``; -1 where undecided."""
    rows = np.asarray(rows, dtype=np.int64)
    out = np.full(len(rows), -1, dtype=np.int64)
    if len(rows) == 0:
        return out
    counts = window_root_counts(geometry, models, rows, points)
    rank = patterns.rank[patterns.super_of[counts.win]]
    digit = counts.roots[:, 0].astype(np.int64) * BASE ** np.minimum(rank, MAX_DIGITS - 1)
    code = np.zeros(counts.live.size, dtype=np.int64)
    np.add.at(code, counts.pt, digit)  # in integers: a float sum would round codes past 2**53
    # a box with no patterns (one with a digit past MAX_DIGITS among them) has no code either
    held = np.zeros(len(models.ok), dtype=bool)
    held[patterns.box] = True
    good = counts.decided() & held[rows[counts.live]]
    out[counts.live[good]] = code[good]
    return out


def digits(patterns: WindowPatterns, code: np.ndarray) -> np.ndarray:
    """(m, K) int64: the count in each super-window (by rank) of the pattern codes ``code``."""
    return (np.asarray(code, dtype=np.int64)[:, None] // BASE ** np.arange(patterns.width)) % BASE


def _arcs(start: np.ndarray, stop: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(k, 2) lo and hi of arcs from ``start`` to ``stop`` in circle order, as at most two closed intervals of
    [-PI_HI, PI_HI] (NaN: none); an arc with stop <= start runs across phi = pi (all the way round if equal)."""
    wraps = stop <= start
    lo = np.column_stack([start, np.where(wraps, -PI_HI, np.nan)])
    hi = np.column_stack([np.where(wraps, PI_HI, stop), np.where(wraps, stop, np.nan)])
    return lo, hi


def _units(models: WindowModels, patterns: WindowPatterns) -> tuple[np.ndarray, ...]:
    """The arcs that hold roots, sorted by box: windows (unit: their super-window's rank) and fixed-root
    arcs (unit: K + their position in the box).  Returns box, unit, lo (k, 2), hi (k, 2), and (n,) the number
    of fixed-root arcs of each box.  Only the boxes with patterns: the others' ranks may pass the width."""
    width = patterns.width
    w = len(models.degree)
    pw = models.piece_window
    first = np.searchsorted(pw, np.arange(w), side="left")
    last = np.searchsorted(pw, np.arange(w), side="right") - 1
    wlo, whi = _arcs(models.piece_lo[first], models.piece_hi[last])
    rb = models.root_box
    pos = np.arange(rb.size) - np.searchsorted(rb, rb, side="left")
    rlo, rhi = _arcs(models.root_lo, models.root_hi)
    box = np.r_[models.window_box, rb]
    unit = np.r_[patterns.rank[patterns.super_of], width + pos]
    held = np.zeros(len(models.ok), dtype=bool)
    held[patterns.box] = True
    order = np.flatnonzero(held[box])
    order = order[np.argsort(box[order], kind="stable")]
    lo, hi = np.r_[wlo, rlo][order], np.r_[whi, rhi][order]
    return box[order], unit[order], lo, hi, np.bincount(rb, minlength=len(models.ok))


def unit_overlaps(models: WindowModels, patterns: WindowPatterns, box_a: np.ndarray,
                  box_b: np.ndarray) -> np.ndarray:
    """(c, U, U) bool: whether unit i of box_a[c] and unit j of box_b[c] may share an orientation.

    Units: the super-windows (by rank, 0 .. K-1), then the fixed-root arcs (K, K + 1, ...).  Arcs are
    closed, and every arc that reaches the seam phi = +-pi is taken to meet every other that does
    (so an overlap is never missed; a spurious one only weakens :func:`compatible`).
    """
    box_a, box_b = np.asarray(box_a, dtype=np.int64), np.asarray(box_b, dtype=np.int64)
    box, unit, lo, hi, n_roots = _units(models, patterns)
    size = max(int(unit.max()) + 1 if unit.size else 1, patterns.width)  # every super-window digit has a unit
    out = np.zeros((box_a.size, size, size), dtype=bool)
    if box_a.size == 0 or box.size == 0:
        return out
    sa = np.searchsorted(box, box_a, side="left")
    na = np.searchsorted(box, box_a, side="right") - sa
    sb = np.searchsorted(box, box_b, side="left")
    nb = np.searchsorted(box, box_b, side="right") - sb
    c = np.repeat(np.arange(box_a.size), na * nb)  # every (contact, arc of a, arc of b)
    k = np.arange(c.size) - np.repeat(np.cumsum(na * nb) - na * nb, na * nb)
    ua = sa[c] + k // np.maximum(nb[c], 1)
    ub = sb[c] + k % np.maximum(nb[c], 1)
    meet = np.zeros(c.size, dtype=bool)
    for i in (0, 1):
        for j in (0, 1):
            meet |= np.maximum(lo[ua, i], lo[ub, j]) <= np.minimum(hi[ua, i], hi[ub, j])  # NaN compares False
    seam_a = (np.nanmax(hi[ua], axis=1) >= PI_HI) | (np.nanmin(lo[ua], axis=1) <= -PI_HI)
    seam_b = (np.nanmax(hi[ub], axis=1) >= PI_HI) | (np.nanmin(lo[ub], axis=1) <= -PI_HI)
    meet |= seam_a & seam_b
    out[c[meet], unit[ua[meet]], unit[ub[meet]]] = True
    return out


def unit_counts(models: WindowModels, patterns: WindowPatterns, row: np.ndarray, size: int) -> np.ndarray:
    """(m, size) int64: the roots in each unit of the box of pattern rows ``row`` under that pattern."""
    d = digits(patterns, patterns.code[row])
    width = d.shape[1]
    n_roots = np.bincount(models.root_box, minlength=len(models.ok))[patterns.box[row]]
    if size < width:
        raise ValueError(f"unit_counts: {size} units cannot hold {width} super-windows")
    out = np.zeros((len(row), size), dtype=np.int64)
    out[:, :width] = d
    out[:, width:] = np.arange(size - width) < n_roots[:, None]
    return out


def compatible(models: WindowModels, patterns: WindowPatterns, row_a: np.ndarray, row_b: np.ndarray,
               overlap: np.ndarray) -> np.ndarray:
    """(m,) bool: pattern rows row_a[i] and row_b[i] of two boxes sharing a face may be held at one point of it.

    ``overlap`` (m, U, U): :func:`unit_overlaps` of the two rows' boxes.  False only where the roots of
    one unit cannot all fit in the units of the other box that meet it (module docstring), which proves
    that the two patterns never meet.
    """
    size = overlap.shape[1]
    ca = unit_counts(models, patterns, row_a, size)
    cb = unit_counts(models, patterns, row_b, size)
    ok = np.ones(len(ca), dtype=bool)
    for u in range(size):  # a unit at a time: no (m, U, U) integer copy
        room_b = (ca * overlap[:, :, u]).sum(axis=1)
        room_a = (cb * overlap[:, u, :]).sum(axis=1)
        ok &= (cb[:, u] <= room_b) & (ca[:, u] <= room_a)
    return ok


def row_of(patterns: WindowPatterns, box: np.ndarray, code: np.ndarray) -> np.ndarray:
    """(m,) the pattern row of (box, code), -1 where ``code`` is negative or not a pattern of the box."""
    box, code = np.asarray(box, dtype=np.int64), np.asarray(code, dtype=np.int64)
    lo = np.searchsorted(patterns.box, box, side="left")
    end = hi = np.searchsorted(patterns.box, box, side="right")
    last = max(patterns.code.size - 1, 0)
    while True:  # binary search on the codes of each box's run (rows sorted by box, then code), all at once
        live = lo < hi
        if not live.any():
            break
        mid = (lo + hi) // 2
        below = live & (patterns.code[np.minimum(mid, last)] < code)
        lo, hi = np.where(below, mid + 1, lo), np.where(live & ~below, mid, hi)
    found = (lo < end) & (code >= 0)
    found[found] = patterns.code[lo[found]] == code[found]
    return np.where(found, lo, -1)


#: In the ``only`` arrays of :func:`exclusive`: this slot holds no point of the count; any pattern of it.
NONE, EVERY = -1, -2


def exclusive(models: WindowModels, patterns: WindowPatterns, box_a: np.ndarray, box_b: np.ndarray,
              count: int, only_a: np.ndarray | None = None, only_b: np.ndarray | None = None) -> np.ndarray:
    """(m,) bool: no point of the face shared by boxes box_a[i] and box_b[i] has ``count`` solutions.

    True when both boxes have patterns (modelled) and no pattern of total ``count`` of the one is
    :func:`compatible` with one of the other: a point with that count holds one such pattern in each box.
    ``only_a`` (m, k): where a box's points with the count can only hold some patterns (a connected piece
    of the box off g(S) holds one), those rows; :data:`NONE` for an unused slot, :data:`EVERY` for a
    slot that may hold any pattern (the default).
    """
    box_a, box_b = np.asarray(box_a, dtype=np.int64), np.asarray(box_b, dtype=np.int64)
    pb = patterns.box
    has = np.zeros(len(models.ok), dtype=bool)
    has[pb] = True
    first_a, n_a = np.searchsorted(pb, box_a, side="left"), np.searchsorted(pb, box_a, side="right")
    first_b, n_b = np.searchsorted(pb, box_b, side="left"), np.searchsorted(pb, box_b, side="right")
    n_a, n_b = n_a - first_a, n_b - first_b
    # every (contact, row of a, row of b), then only the rows with the count that each end allows
    c = np.repeat(np.arange(box_a.size), n_a * n_b)
    k = np.arange(c.size) - np.repeat(np.cumsum(n_a * n_b) - n_a * n_b, n_a * n_b)
    ra = first_a[c] + k // np.maximum(n_b[c], 1)
    rb = first_b[c] + k % np.maximum(n_b[c], 1)
    keep = (patterns.count[ra] == count) & (patterns.count[rb] == count)
    for only, r in ((only_a, ra), (only_b, rb)):
        if only is not None:
            only = np.asarray(only, dtype=np.int64)
            keep &= (only[c] == EVERY).any(axis=1) | (only[c] == r[:, None]).any(axis=1)
    c, ra, rb = c[keep], ra[keep], rb[keep]
    meet = np.zeros(box_a.size, dtype=bool)
    if c.size:
        uniq, inv = np.unique(c, return_inverse=True)
        ov = unit_overlaps(models, patterns, box_a[uniq], box_b[uniq])
        meet[c[compatible(models, patterns, ra, rb, ov[inv])]] = True
    return has[box_a] & has[box_b] & ~meet
