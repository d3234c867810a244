"""Patterns of solutions over arcs of orientations: proved cut points, arc ranges, face relations.

A *cut* of a joint box R is one of the :data:`GRID` fixed angles c_j at which f(c_j; r) (the reduced
equation, :mod:`intervalkin.recheck.reduced_equation`) has a proved strict sign for every r in R^2: no
solution at any point of R has orientation c_j.  The cuts of R split the circle into *arcs*, each named
by the grid index of the cut it starts from (-1 for the whole circle when R has no cut).  At a point q of
R off g(S) the *pattern* of q is the multiset of the arcs holding its solutions, written as the sorted
tuple of their start indices (one entry per solution).  The pattern is locally constant on R minus g(S):
off g(S) the solutions move continuously (all are regular) and none crosses a cut.

On a face rectangle F shared by boxes R and R' (or any box F inside both), the union of the cuts of R, of
R' and of F itself refines both arc systems.  :func:`face_relations` proves, for each refined arc, a range
of its number of solutions at every point of F (:func:`~intervalkin.recheck.count_range.arc_ranges`) and,
where D != 0 is proved on the whole arc, its parity: off g(S) every solution there is a simple root of f
and every root of f there is a solution, so the number of solutions has the parity of [the signs of f at
the two cuts differ] (proofs/lemma-pattern-barrier.md).  The vectors of refined counts that satisfy
every range and parity and sum to the count c are the only ones a point of F off g(S) with c solutions
can have; each maps to one pattern of R and one of R' (summing the refined arcs inside each arc).  The
set of these pairs is the *relation* of the face: a point of F off g(S) with c solutions has, for some
pair (x, x') of it, pattern x seen from R and x' seen from R'.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from intervalkin.recheck.arith import PI_HI, PI_LO
from intervalkin.recheck.count_range import GRID, NO_BOUND, PIECES, arc_ranges, cut_angles, cut_signs, r_box
from intervalkin.recheck.reduced_equation import ReducedConstants, d_sign, derivative_enclosures

__all__ = ["GRID", "WHOLE", "MAX_COUNT", "cut_angles", "cut_signs", "arc_starts", "ArcTable", "arc_table",
           "BoxArcs", "box_arcs", "own_patterns", "face_relations", "count_bounds", "split_excludes", "prune_relations",
           "pattern_of_angles", "pack", "unpack"]

#: The start index of the one arc of a box without cuts (the whole circle).
WHOLE = -1
#: Solutions at most (the sextic): the width of a pattern row.
MAX_COUNT = 6
#: Pieces each arc starts from in arc_ranges, in a box's arcs and over a face (the whole circle:
#: count_range.PIECES).
ARC_PIECES = 2
#: Halvings of a piece of a face's own arc ranges (a box's arcs take count_range.DEPTH, 7).  Next to a fold's
#: near-double root seven are not enough: the range keeps an upper bound of 4 to 6 where the arc holds no
#: solution (a thin cell of the second design) and the flood crosses there.  Only the arcs neither box decides
#: are ranged over the face, so the deeper bisection costs little there; in every box's arcs it would cost a
#: third more.
FACE_DEPTH = 9
#: Parts per axis of a face whose count ranges may prove that it holds no point of the count
#: (:func:`split_excludes`), tried in this order.  The whole face (1) proved none that 2 x 2 did not, in the
#: floods of the paper's depth-5 paving and of the second design.
SPLITS = (2, 4)
#: Boxes (or faces) whose arcs (or relations) are computed at once: the interval evaluations hold about 64 grid
#: angles and their bisection pieces per row, so a batch of 67 000 boxes (a 4-solution cell's barrier) took
#: 13.7 GB in one piece.
BLOCK = 2048


def arc_starts(mask: np.ndarray) -> np.ndarray:
    """(n, grid) int64: for each grid index j, the start of the arc of the box holding the grid cell
    (c_j, c_j+1); :data:`WHOLE` for a box without cuts.  ``mask`` (n, grid) bool: the cuts."""
    mask = np.atleast_2d(mask)
    n, grid = mask.shape
    idx = np.where(mask, np.arange(grid)[None, :], -1)
    last = np.maximum.accumulate(idx, axis=1)
    # before the first cut the cell belongs to the arc that wraps from the last cut
    wrap = idx.max(axis=1)
    return np.where(last >= 0, last, wrap[:, None]).astype(np.int64)


@dataclass(frozen=True)
class ArcTable:
    """The arcs of a batch of boxes: arc i belongs to box ``owner[i]``, starts at grid index ``start[i]`` and
    ends at ``end[i]`` (both :data:`WHOLE` for a box without cuts); at every point of the box its number of
    solutions lies in [lo[i], hi[i]]; ``parity[i]`` is that number mod 2 at points off g(S), -1 if unknown."""

    owner: np.ndarray
    start: np.ndarray
    end: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    parity: np.ndarray


def arc_table(k: ReducedConstants, q_lo: np.ndarray, q_hi: np.ndarray, signs: np.ndarray,
              grid: int = GRID) -> ArcTable:
    """The arcs of each box [q_lo[i], q_hi[i]] cut at the nonzero entries of ``signs`` (n, grid), which must be
    the proved signs of f at the cuts over that box (or over a larger one)."""
    q_lo, q_hi = np.atleast_2d(q_lo), np.atleast_2d(q_hi)
    r_lo, r_hi = r_box(q_lo, q_hi)
    ang = cut_angles(grid)
    mask = signs != 0
    owner, start = np.nonzero(mask)  # row-major: by owner, then start
    n_cuts = mask.sum(axis=1)
    first = np.r_[0, np.cumsum(n_cuts)[:-1]]
    nxt = np.arange(owner.size) + 1
    last = first + n_cuts - 1
    has = n_cuts > 0
    nxt[last[has]] = first[has]
    end = start[nxt] if owner.size else start
    wraps = end <= start
    lo = np.zeros(owner.size, dtype=np.int64)
    hi = np.zeros(owner.size, dtype=np.int64)
    d_ok = np.ones(owner.size, dtype=bool)
    # most arcs are one grid step where f keeps one sign: no root, no solution, even parity (one cheap enclosure
    # of f, its first two Taylor coefficients, instead of a range); the seam step is taken as its two halves
    step = np.flatnonzero(end == (start + 1) % grid)
    seam = wraps[step]
    e_arc = np.concatenate([step, step[seam]])
    e_a = np.concatenate([ang[start[step]], np.full(int(seam.sum()), -PI_HI)])
    e_b = np.concatenate([np.where(seam, PI_HI, ang[end[step]]), ang[end[step[seam]]]])
    f_lo, f_hi = derivative_enclosures(k, r_lo[owner[e_arc]], r_hi[owner[e_arc]], e_a, e_b, 1)[0]
    signed = np.ones(owner.size, dtype=bool)
    np.logical_and.at(signed, e_arc, (f_lo > 0) | (f_hi < 0))
    free = np.zeros(owner.size, dtype=bool)
    free[step] = signed[step]
    # the other arcs: ranges (a wrapping arc is [c_s, pi] and [-pi, c_e])
    rest = np.flatnonzero(~free)
    r_wrap = wraps[rest]
    p_arc = np.concatenate([rest, rest[r_wrap]])
    p_a = np.concatenate([ang[start[rest]], np.full(int(r_wrap.sum()), -np.pi)])
    p_b = np.concatenate([np.where(r_wrap, np.pi, ang[end[rest]]), ang[end[rest[r_wrap]]]])
    rng = arc_ranges(k, r_lo, r_hi, owner[p_arc], p_a, p_b, ARC_PIECES)
    np.add.at(lo, p_arc, rng.lo)
    np.add.at(hi, p_arc, rng.hi)
    d_lo = np.where(p_a <= -PI_LO, -PI_HI, p_a)
    d_hi = np.where(p_b >= PI_LO, PI_HI, p_b)
    np.logical_and.at(d_ok, p_arc, d_sign(k, d_lo, d_hi) != 0)
    s = signs[owner, start].astype(np.int64), signs[owner, end].astype(np.int64)
    parity = np.where(d_ok, (s[0] != s[1]).astype(np.int64), -1)
    parity[free] = 0
    # boxes without a cut: one arc, the whole circle, no parity
    none = np.flatnonzero(~has)
    if none.size:
        w = arc_ranges(k, r_lo, r_hi, none, np.full(none.size, -np.pi), np.full(none.size, np.pi), PIECES)
        owner = np.concatenate([owner, none])
        start = np.concatenate([start, np.full(none.size, WHOLE)])
        end = np.concatenate([end, np.full(none.size, WHOLE)])
        lo, hi = np.concatenate([lo, w.lo]), np.concatenate([hi, w.hi])
        parity = np.concatenate([parity, np.full(none.size, -1)])
        at = np.argsort(owner, kind="stable")
        owner, start, end, lo, hi, parity = (v[at] for v in (owner, start, end, lo, hi, parity))
    return ArcTable(owner.astype(np.int64), start.astype(np.int64), end.astype(np.int64), lo, hi, parity)


#: The array fields of :class:`BoxArcs`, in order.
FIELDS = ("signs", "end", "lo", "hi", "parity", "whole_lo", "whole_hi")


@dataclass(frozen=True)
class BoxArcs:
    """The arcs of a batch of boxes, dense over the grid: for box i and a cut j of it (``signs[i, j] != 0``),
    the arc starting at j ends at ``end[i, j]`` and holds between ``lo[i, j]`` and ``hi[i, j]`` solutions at
    every point of the box, with parity ``parity[i, j]`` off g(S) (-1: unknown); entries at non-cuts are
    unused.  ``whole_lo``, ``whole_hi`` (n,): the range over the whole circle of a box without cuts."""

    signs: np.ndarray
    end: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    parity: np.ndarray
    whole_lo: np.ndarray
    whole_hi: np.ndarray

    def take(self, rows: np.ndarray) -> "BoxArcs":
        return BoxArcs(*(getattr(self, f)[rows] for f in FIELDS))


def box_arcs(k: ReducedConstants, q_lo: np.ndarray, q_hi: np.ndarray, grid: int = GRID) -> BoxArcs:
    """The cuts and arcs of each joint box [q_lo[i], q_hi[i]] (every candidate angle with a proved sign is a cut).

    Each box's arcs depend on that box alone: long batches are taken in blocks of :data:`BLOCK` boxes, the same
    results in a bounded memory."""
    q_lo, q_hi = np.atleast_2d(q_lo), np.atleast_2d(q_hi)
    n = q_lo.shape[0]
    if n > BLOCK:
        parts = [box_arcs(k, q_lo[i:i + BLOCK], q_hi[i:i + BLOCK], grid) for i in range(0, n, BLOCK)]
        return BoxArcs(*(np.concatenate([getattr(x, f) for x in parts]) for f in FIELDS))
    signs = cut_signs(k, q_lo, q_hi, grid)
    t = arc_table(k, q_lo, q_hi, signs, grid)
    end, lo, hi, parity = (np.full((n, grid), -9, dtype=np.int64) for _ in range(4))
    cut = t.start >= 0
    for dense, col in ((end, t.end), (lo, t.lo), (hi, t.hi), (parity, t.parity)):
        dense[t.owner[cut], t.start[cut]] = col[cut]
    whole_lo, whole_hi = np.zeros(n, dtype=np.int64), np.full(n, NO_BOUND, dtype=np.int64)
    whole_lo[t.owner[~cut]], whole_hi[t.owner[~cut]] = t.lo[~cut], t.hi[~cut]
    return BoxArcs(signs, end, lo, hi, parity, whole_lo, whole_hi)


def _vectors(lo: np.ndarray, hi: np.ndarray, parity: np.ndarray, count: int) -> list[tuple[int, ...]]:
    """Every integer vector v with lo <= v <= hi, v_i = parity_i mod 2 where known, summing to ``count``."""
    hi = np.minimum(hi, count)
    if int(lo.sum()) > count or np.any(lo > hi):
        return []
    if np.any((hi == lo) & (parity >= 0) & (lo % 2 != parity)):
        return []
    free = np.flatnonzero(hi > lo)
    rest = count - int(lo.sum())
    choices = [[d for d in range(0, int(hi[i] - lo[i]) + 1) if parity[i] < 0 or (lo[i] + d) % 2 == parity[i]]
               for i in free.tolist()]
    out = []
    for combo in itertools.product(*choices):
        if sum(combo) != rest:
            continue
        v = lo.copy()
        v[free] += np.array(combo, dtype=np.int64)
        out.append(tuple(int(x) for x in v))
    return out


def own_patterns(arcs: BoxArcs, count: int) -> list[frozenset[tuple[int, ...]]]:
    """Per box of ``arcs``: every pattern its own arcs allow a point of it off g(S) with ``count`` solutions (the
    vectors of solutions per arc within the arcs' ranges and parities, summing to ``count``; for a box without
    cuts, the whole circle's pattern when its range holds ``count``).

    The relation of any face of two boxes lies in the product of their sets (proofs/lemma-pattern-barrier.md,
    fact 5): a point of the face is a point of both closed boxes, where their ranges hold.  A face whose product is
    empty, or holds no pair that a barrier's pattern sets would tear, needs no relation of its own."""
    out = []
    for i in range(arcs.signs.shape[0]):
        st = np.flatnonzero(arcs.signs[i] != 0)
        if st.size == 0:
            whole = arcs.whole_lo[i] <= count <= arcs.whole_hi[i]
            out.append(frozenset({(WHOLE,) * count} if whole else ()))
            continue
        vec = _vectors(arcs.lo[i, st], arcs.hi[i, st], arcs.parity[i, st], count)
        out.append(frozenset(tuple(np.repeat(st, v).tolist()) for v in vec))
    return out


def _side(x: BoxArcs, starts: np.ndarray, face: np.ndarray, start: np.ndarray, end: np.ndarray):
    """Bounds one box gives a refined arc (start, end) of its face: the box's arc holding it bounds it above;
    when the two are the same arc, its range and parity hold as they are."""
    has = (x.signs[face] != 0).any(axis=1)
    s = starts[face, start]
    s0 = np.maximum(s, 0)
    same = has & (s == start) & (x.end[face, s0] == end)
    hi = np.where(has, x.hi[face, s0], x.whole_hi[face])
    lo = np.where(same, x.lo[face, s0], 0)
    parity = np.where(same, x.parity[face, s0], -1)
    return lo, hi, parity


def face_relations(k: ReducedConstants, f_lo: np.ndarray, f_hi: np.ndarray, a: BoxArcs, b: BoxArcs, count: int,
                   grid: int = GRID) -> list[set[tuple[tuple, tuple]]]:
    """For each face box F_i = [f_lo[i], f_hi[i]] inside the boxes whose arcs are row i of ``a`` and of ``b``: the
    set of pairs (pattern seen from a's box, pattern seen from b's box) that a point of F_i off g(S) with
    ``count`` solutions may have (module docstring).  Patterns are sorted tuples of arc starts.

    The refined arcs are those of the union of both boxes' cuts.  A refined arc's range is the meet of what
    each box proves (its own arc's range when the arcs coincide, else the upper bound of the arc holding it)
    and, where that is not exact, of :func:`~intervalkin.recheck.count_range.arc_ranges` over F_i.  Faces are
    taken in blocks of :data:`BLOCK` (each face's relation depends on its own row alone)."""
    f_lo, f_hi = np.atleast_2d(f_lo), np.atleast_2d(f_hi)
    m = f_lo.shape[0]
    if m > BLOCK:
        out: list[set[tuple[tuple, tuple]]] = []
        for i in range(0, m, BLOCK):
            rows = np.arange(i, min(m, i + BLOCK))
            out += face_relations(k, f_lo[rows], f_hi[rows], a.take(rows), b.take(rows), count, grid)
        return out
    r_lo, r_hi = r_box(f_lo, f_hi)
    ang = cut_angles(grid)
    signs = np.where(a.signs != 0, a.signs, b.signs)
    mask = signs != 0
    face, start = np.nonzero(mask)
    n_cuts = mask.sum(axis=1)
    first = np.r_[0, np.cumsum(n_cuts)[:-1]]
    nxt = np.arange(face.size) + 1
    has = n_cuts > 0
    nxt[(first + n_cuts - 1)[has]] = first[has]
    end = start[nxt] if face.size else start
    lo_a, hi_a, par_a = _side(a, arc_starts(a.signs != 0), face, start, end)
    lo_b, hi_b, par_b = _side(b, arc_starts(b.signs != 0), face, start, end)
    lo, hi = np.maximum(lo_a, lo_b), np.minimum(hi_a, hi_b)
    parity = np.where(par_a >= 0, par_a, par_b)
    # arcs neither box decides: ranges over the face itself (a wrapping arc in two pieces)
    look = np.flatnonzero(lo < hi)
    if look.size:
        wraps = end[look] <= start[look]
        p_arc = np.concatenate([look, look[wraps]])
        p_a = np.concatenate([ang[start[look]], np.full(int(wraps.sum()), -np.pi)])
        p_b = np.concatenate([np.where(wraps, np.pi, ang[end[look]]), ang[end[look][wraps]]])
        rng = arc_ranges(k, r_lo, r_hi, face[p_arc], p_a, p_b, ARC_PIECES, FACE_DEPTH)
        f_lo_c, f_hi_c = np.zeros(face.size, dtype=np.int64), np.zeros(face.size, dtype=np.int64)
        np.add.at(f_lo_c, p_arc, rng.lo)
        np.add.at(f_hi_c, p_arc, rng.hi)
        lo[look], hi[look] = np.maximum(lo[look], f_lo_c[look]), np.minimum(hi[look], f_hi_c[look])
        d_ok = np.ones(face.size, dtype=bool)
        d_lo = np.where(p_a <= -PI_LO, -PI_HI, p_a)
        d_hi = np.where(p_b >= PI_LO, PI_HI, p_b)
        np.logical_and.at(d_ok, p_arc, d_sign(k, d_lo, d_hi) != 0)
        par_f = (signs[face, start] != signs[face, end]).astype(np.int64)
        parity[look] = np.where((parity[look] < 0) & d_ok[look], par_f[look], parity[look])
    # faces where neither box has a cut: the whole circle
    none = np.flatnonzero(~has)
    w_lo, w_hi = np.maximum(a.whole_lo, b.whole_lo), np.minimum(a.whole_hi, b.whole_hi)
    if none.size:
        vague = none[w_lo[none] < w_hi[none]]
        if vague.size:
            w = arc_ranges(k, r_lo, r_hi, vague, np.full(vague.size, -np.pi), np.full(vague.size, np.pi), PIECES)
            w_lo[vague], w_hi[vague] = np.maximum(w_lo[vague], w.lo), np.minimum(w_hi[vague], w.hi)
    to_a, to_b = arc_starts(a.signs != 0), arc_starts(b.signs != 0)
    bounds = np.searchsorted(face, np.arange(m + 1))
    out = []
    for i in range(m):
        if not has[i]:
            ok = w_lo[i] <= count <= w_hi[i]
            out.append({((WHOLE,) * count, (WHOLE,) * count)} if ok else set())
            continue
        sl = slice(bounds[i], bounds[i + 1])
        st = start[sl]
        pairs = set()
        for v in _vectors(lo[sl], hi[sl], parity[sl], count):
            units = np.repeat(st, v)
            pairs.add((tuple(sorted(_map(to_a[i], units))), tuple(sorted(_map(to_b[i], units)))))
        out.append(pairs)
    return out


def count_bounds(arcs: BoxArcs) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi) per box: its number of solutions at every point, the sums of its arcs' ranges (no solution sits at
    a cut, so the arcs share them out), or the whole circle's range for a box without cuts.  Tighter than one
    range over the whole circle next to a fold, where the arcs bisect the roots apart one by one."""
    cut = arcs.signs != 0
    lo = np.where(cut, arcs.lo, 0).sum(axis=1)
    hi = np.where(cut, np.minimum(arcs.hi, NO_BOUND), 0).sum(axis=1)
    none = ~cut.any(axis=1)
    return np.where(none, arcs.whole_lo, lo), np.where(none, arcs.whole_hi, hi)


def split_excludes(k: ReducedConstants, f_lo: np.ndarray, f_hi: np.ndarray, count: int,
                   splits: tuple[int, ...] = SPLITS) -> np.ndarray:
    """(m,) bool: PROVED that no point of box [f_lo[i], f_hi[i]] (a face rectangle or a box) has ``count``
    solutions: for some s of ``splits``, the box cut into s equal parts along each axis of positive width has
    the count range of every part (:func:`count_bounds`: the sum of its arcs' ranges, ``lemma-count-range.md``)
    excluding ``count``.  The parts share their float end points and the outer ones end at the box's own, so
    they cover it exactly.  Such a face's relation is empty (proofs/lemma-pattern-barrier.md, fact 4): a face of
    a large box of a cell with another count, whose arcs are too coarse to say so, is walled this way."""
    f_lo, f_hi = np.atleast_2d(f_lo), np.atleast_2d(f_hi)
    m = f_lo.shape[0]
    out = np.zeros(m, dtype=bool)
    free = f_hi > f_lo
    for s in splits:
        for shape in np.unique(free[~out], axis=0):
            rows = np.flatnonzero(~out & np.all(free == shape, axis=1))
            if rows.size == 0:
                continue
            parts = [s if shape[d] else 1 for d in range(3)]
            edges = []
            for d in range(3):
                t = np.arange(parts[d] + 1) / parts[d]
                e = f_lo[rows, d, None] + (f_hi[rows, d] - f_lo[rows, d])[:, None] * t[None, :]
                e[:, 0], e[:, -1] = f_lo[rows, d], f_hi[rows, d]
                edges.append(np.maximum.accumulate(np.minimum(e, f_hi[rows, d, None]), axis=1))
            idx = np.stack(np.meshgrid(*(np.arange(p) for p in parts), indexing="ij"), axis=-1).reshape(-1, 3)
            p_lo = np.stack([edges[d][:, idx[:, d]] for d in range(3)], axis=-1).reshape(-1, 3)
            p_hi = np.stack([edges[d][:, idx[:, d] + 1] for d in range(3)], axis=-1).reshape(-1, 3)
            owner = np.repeat(np.arange(rows.size), idx.shape[0])
            lo_n, hi_n = count_bounds(box_arcs(k, p_lo, p_hi))
            hit = np.ones(rows.size, dtype=bool)
            np.logical_and.at(hit, owner, (count < lo_n) | (count > hi_n))
            out[rows[hit]] = True
    return out


def prune_relations(k: ReducedConstants, f_lo: np.ndarray, f_hi: np.ndarray, relations: list[set], count: int,
                    which: np.ndarray) -> list[set]:
    """``relations`` with those of the faces ``which`` (indices) emptied where :func:`split_excludes` proves the
    face holds no point of ``count`` solutions; the others as they are.  The builder asks for the faces its
    flood should not cross, the checker for those a claim needs walled; both prove the same way."""
    which = np.asarray(which, dtype=np.int64)
    which = which[[bool(relations[i]) for i in which.tolist()]] if which.size else which
    out = list(relations)
    if which.size:
        for i in which[split_excludes(k, f_lo[which], f_hi[which], count)].tolist():
            out[i] = set()
    return out


def _map(starts_of: np.ndarray, units: np.ndarray) -> list[int]:
    """The arcs (of a box with arc_starts row ``starts_of``) holding the refined arcs starting at ``units``."""
    return [int(starts_of[u]) if u >= 0 else WHOLE for u in units.tolist()]


def pattern_of_angles(signs: np.ndarray, phi_lo: np.ndarray, phi_hi: np.ndarray, grid: int = GRID) -> tuple | None:
    """The pattern, in a box with cut signs ``signs`` (grid,), of solutions whose orientations lie in the
    intervals [phi_lo[i], phi_hi[i]] (taken modulo 2 pi; each inside (-pi, pi] after the shift); None when
    an interval meets a cut angle (its arc is not decided)."""
    ang = cut_angles(grid)
    cuts = np.flatnonzero(signs != 0)
    out = []
    for a, b in zip(np.asarray(phi_lo, dtype=np.float64).tolist(), np.asarray(phi_hi, dtype=np.float64).tolist()):
        if cuts.size == 0:
            out.append(WHOLE)
            continue
        if not (-PI_LO < a <= b < PI_LO):
            return None
        below = cuts[ang[cuts] < a]
        above = cuts[ang[cuts] > b]
        if below.size + above.size != cuts.size:
            return None  # a cut angle lies in [a, b]
        out.append(int(below[-1]) if below.size else int(cuts[-1]))
    return tuple(sorted(out))


def pack(patterns: list[tuple]) -> np.ndarray:
    """(m, MAX_COUNT) int16 rows, a pattern's sorted starts padded with -2."""
    out = np.full((len(patterns), MAX_COUNT), -2, dtype=np.int16)
    for i, p in enumerate(patterns):
        out[i, :len(p)] = p
    return out


def unpack(rows: np.ndarray) -> list[tuple]:
    return [tuple(int(v) for v in r if v != -2) for r in np.asarray(rows)]
