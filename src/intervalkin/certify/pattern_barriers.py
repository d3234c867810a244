"""Pattern barriers: cells with solutions told apart by where their solutions sit on the circle.

Two cells with the same signature that meet only where two sheets of g(S) cross cannot be told apart
by their count: every face near the crossing holds points of both.  What differs is *where* their
solutions are: on one side of the crossing the pair of roots that a first fold creates is present
and the second fold's pair absent, on the other side the reverse.  A pattern barrier records that.

For a cell C with c solutions it is a set of joint boxes (the *region*), for each box R a set P_R of
patterns (:mod:`intervalkin.recheck.arc_pattern`: multisets of the arcs between proved cuts of R that
hold the solutions), and face rectangles covering the region's boundary, such that

* on every rectangle shared by two region boxes R, R' (and on any 2-D intersection of two), the face
  relation links patterns of P_R only to patterns of P_R' and back;
* on every boundary rectangle of a region box R, the relation holds no pattern of P_R;
* C's witness has its pattern in P_R of the box holding it, and the witness of every other cell of
  the signature has, in every region box holding it, a pattern outside that box's set.

Then the points of the region off g(S) whose pattern (seen from any box holding them) lies in that
box's set form an open and closed subset of the joint box minus g(S); it holds C's witness and no
other witness, so those lie in other components (proofs/lemma-pattern-barrier.md).  ``intervalkin
verify`` re-proves all of it from the files (:mod:`intervalkin.recheck.separation_file`).

How the region is found (effort, not soundness): a flood over the leaves of the joint paving from the
witness's (leaf, pattern), following the face relations both ways until nothing new is reached.  Before it
crosses a face of a clear box of a cell with another count, it asks whether split count ranges prove the
face free of its count (the lemma's fact 4): large clear boxes have arcs too coarse to say so.  A face
starts with the product of its boxes' own pattern sets (fact 5) and is ranged only when that product would
carry a pattern across it, once no face with a final relation moves anything: the flood first runs through
the faces that need no range (between boxes labelled clear with its count, allowing one pattern each), and
most faces it would have ranged then have both sides reached.  It stops, and the cell stays library-proved
only, when it reaches another witness's (leaf, pattern) or would range more than :data:`FACE_BUDGET` faces.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.recheck.arc_pattern import (FIELDS, BoxArcs, box_arcs, face_relations, own_patterns,
                                             pattern_of_angles, prune_relations)
from intervalkin.recheck.reduced_equation import reduced_constants

__all__ = ["FACE_BUDGET", "RIVAL_BOXES", "PatternBarrier", "flood", "solution_pattern", "merged_paving", "centre"]

#: Faces a flood may range (about 2 ms each on the paper's paving, plus the boxes' arcs, about 6 ms each).
FACE_BUDGET = 20000
#: Boxes of other cells of the signature a flood may reach before it is given up (a successful flood on the paper's
#: manipulator reaches none; one that leaks reaches hundreds).
RIVAL_BOXES = 8


@dataclass(frozen=True)
class PatternBarrier:
    """The region (leaves, their boxes and pattern sets) and boundary faces of one cell's pattern barrier.

    ``patterns[i]`` is the sorted list of patterns of region box i; barrier face j lies on region box
    ``barrier_box[j]`` and inside the box [outer_lo[j], outer_hi[j]] beyond it."""

    leaves: np.ndarray
    region_lo: np.ndarray
    region_hi: np.ndarray
    patterns: tuple[tuple[tuple[int, ...], ...], ...]
    barrier_lo: np.ndarray
    barrier_hi: np.ndarray
    barrier_box: np.ndarray
    outer_lo: np.ndarray
    outer_hi: np.ndarray


def solution_pattern(arcs: BoxArcs, row: int, witness: dict) -> tuple[int, ...] | None:
    """The pattern, in box ``row`` of ``arcs``, of a witness object's solution list (None: a solution's phi
    interval meets a cut)."""
    phi = [(float(s["box"][2][0]), float(s["box"][2][1])) for s in witness["solutions"]]
    return pattern_of_angles(arcs.signs[row], np.array([p[0] for p in phi]), np.array([p[1] for p in phi]))


def flood(geometry: Geometry, lo: np.ndarray, hi: np.ndarray, a: np.ndarray, b: np.ndarray, count: int,
          start: tuple[int, tuple], forbidden: dict[int, set],
          rivals: np.ndarray | None = None, budget: int = FACE_BUDGET,
          walls: np.ndarray | None = None, same: np.ndarray | None = None) -> tuple[PatternBarrier | None, str, int]:
    """The pattern barrier grown from ``start`` = (leaf, pattern) over boxes [lo, hi] with face contacts (a, b),
    or None; why not; the number of faces related.  ``forbidden``: leaf -> patterns that must not be reached
    (other witnesses).
    ``rivals``: boxes of other cells of the signature; a flood that gives patterns to more than :data:`RIVAL_BOXES`
    of them is leaking into another cell and is given up (a choice of effort: the lemma does not need it).
    ``walls`` (n,) bool: boxes (a clear box of a cell with another count, say) whose faces the flood crosses only
    where split count ranges do not prove the face free of ``count`` solutions
    (:func:`~intervalkin.recheck.arc_pattern.prune_relations`); a face costs its count ranges again when tested.
    ``same`` (n,) bool: boxes the library labels clear with ``count`` solutions.  A face between two of them whose
    own pattern sets (:func:`~intervalkin.recheck.arc_pattern.own_patterns`) are one pattern each takes that pair
    as its relation without ranging the face (the pair is all the lemma's fact 5 allows; the labels only say
    where ranging would not make it smaller), and a face whose own sets leave no pair gets the empty relation."""
    k = reduced_constants(geometry)
    rivals = np.zeros(0, dtype=np.int64) if rivals is None else rivals
    n = len(lo)
    ends = np.concatenate([a, b])
    other = np.concatenate([b, a])
    face = np.concatenate([np.arange(a.size)] * 2)
    at = np.argsort(ends, kind="stable")
    ends, other, face = ends[at], other[at], face[at]
    ptr = np.searchsorted(ends, np.arange(n + 1))
    row = np.full(n, -1, dtype=np.int64)
    owns: list[frozenset] = []  # per table row: the patterns of `count` its own arcs allow
    same = np.zeros(n, dtype=bool) if same is None else same
    rel: dict[int, set] = {}  # faces whose relation is final: ranged, or needing no range (see _relations)
    cand: dict[int, set] = {}  # faces holding only the product of their boxes' own sets, not yet ranged
    found: dict[int, set] = {}
    leaf0, pat0 = start
    found[leaf0] = {pat0}
    frontier = [leaf0]
    table = None
    ranged = 0
    # faces of wall boxes whose count ranges are not yet tested: tested only when the flood would cross them
    untested = np.zeros(a.size, dtype=bool) if walls is None else walls[a] | walls[b]
    while frontier:
        fl = np.array(sorted(frontier), dtype=np.int64)
        inc = np.concatenate([np.arange(ptr[x], ptr[x + 1]) for x in fl])
        need = np.unique(np.concatenate([fl, other[inc]]))
        need = need[row[need] < 0]
        if need.size:
            row[need] = np.arange(need.size) + (0 if table is None else table.signs.shape[0])
            fresh = box_arcs(k, lo[need], hi[need])
            table = fresh if table is None else _stack([table, fresh])
            owns += own_patterns(fresh, count)
        new = np.unique(face[inc])
        new = new[[f not in rel and f not in cand for f in new.tolist()]] if new.size else new
        if new.size:
            final, product = _relations(a[new], b[new], new, row, owns, same)
            rel.update(final)
            cand.update(product)
        # a face without its range is crossed only once nothing else moves: by then the boxes on both sides
        # have often been reached through faces needing none, and it needs none either
        nxt, ask, queue, moved = set(), set(), set(), False
        for x in fl.tolist():
            mine = found.setdefault(x, set())
            for j in range(ptr[x], ptr[x + 1]):
                f, y = int(face[j]), int(other[j])
                theirs = found.setdefault(y, set())
                first = a[f] == x
                crossing = [((pa, pb) if first else (pb, pa)) for pa, pb in (rel[f] if f in rel else cand[f])]
                crossing = [(u, v) for u, v in crossing if (u in mine) != (v in theirs)]
                if crossing and (f not in rel or untested[f]):
                    (ask if f in rel else queue).add(f)  # all at once, below; x comes back to cross it
                    nxt.add(x)
                    continue
                for u, v in crossing:
                    theirs.add(v)
                    mine.add(u)
                    nxt.update((x, y))
                    moved = True
        if queue and not moved:
            if ranged + len(queue) > budget:
                return None, f"more than {budget} faces to relate", ranged
            f = np.array(sorted(queue), dtype=np.int64)
            rel.update(_ranged(k, lo, hi, a[f], b[f], f, row, owns, table, count))
            for t in f.tolist():
                del cand[t]
            ranged += f.size
        if ask and not moved:
            f = np.array(sorted(ask), dtype=np.int64)
            f_lo, f_hi = np.maximum(lo[a[f]], lo[b[f]]), np.minimum(hi[a[f]], hi[b[f]])
            got = prune_relations(k, f_lo, f_hi, [rel[t] for t in f.tolist()], count, np.arange(f.size))
            rel.update(zip(f.tolist(), got))
            untested[f] = False
        reached = [x for x in rivals.tolist() if found.get(x)] if rivals.size else []
        if len(reached) > RIVAL_BOXES:
            # where: the place a finer paving (or a model of the wall between the cells) would be needed
            at_lo, at_hi = lo[reached].min(axis=0), hi[reached].max(axis=0)
            return None, ("its patterns reach boxes of another cell of its signature in "
                          f"[{', '.join(f'{v:.3f}' for v in at_lo)}] x [{', '.join(f'{v:.3f}' for v in at_hi)}] "
                          "(the face relations there do not tell the two apart)"), ranged
        for leaf, pats in forbidden.items():
            if found.get(leaf, set()) & pats:
                return None, "its patterns reach another cell's witness (a finer paving would be needed)", ranged
        frontier = sorted(nxt)
    leaves = np.array(sorted(x for x, p in found.items() if p), dtype=np.int64)
    inside = np.zeros(n, dtype=bool)
    inside[leaves] = True
    region_row = np.full(n, -1, dtype=np.int64)
    region_row[leaves] = np.arange(leaves.size)
    edge = np.array(sorted(f for f in (*rel, *cand) if inside[a[f]] != inside[b[f]]), dtype=np.int64)
    inner_end = np.where(inside[a[edge]], a[edge], b[edge]) if edge.size else edge
    outer_end = np.where(inside[a[edge]], b[edge], a[edge]) if edge.size else edge
    return PatternBarrier(
        leaves, lo[leaves], hi[leaves], tuple(tuple(sorted(found[x])) for x in leaves.tolist()),
        np.maximum(lo[a[edge]], lo[b[edge]]), np.minimum(hi[a[edge]], hi[b[edge]]), region_row[inner_end],
        lo[outer_end], hi[outer_end]), "", ranged


def _relations(fa: np.ndarray, fb: np.ndarray, faces: np.ndarray, row: np.ndarray, owns: list[frozenset],
               same: np.ndarray) -> tuple[dict[int, set], dict[int, set]]:
    """(relations needing no range, the others' products) of faces ``faces`` between boxes fa[i] and fb[i].  A face
    whose boxes' own pattern sets leave no pair has the empty relation; one between two boxes labelled clear with
    the flood's count (``same``) whose own sets are one pattern each has that pair (ranging could only empty it,
    and a face of two such boxes holds points of the count).  Each relation is within the product (fact 5 of the
    lemma), so the labels bear on the flood's effort only."""
    final, product = {}, {}
    for f, x, y in zip(faces.tolist(), fa.tolist(), fb.tolist()):
        pa, pb = owns[row[x]], owns[row[y]]
        if not pa or not pb:
            final[f] = set()
        elif len(pa) == 1 and len(pb) == 1 and same[x] and same[y]:
            final[f] = {(next(iter(pa)), next(iter(pb)))}
        else:
            product[f] = {(u, v) for u in pa for v in pb}
    return final, product


def _ranged(k, lo: np.ndarray, hi: np.ndarray, fa: np.ndarray, fb: np.ndarray, faces: np.ndarray, row: np.ndarray,
            owns: list[frozenset], table: BoxArcs, count: int) -> dict[int, set]:
    """The relations of faces ``faces`` ranged over each face (:func:`face_relations`), within the products of their
    boxes' own pattern sets."""
    f_lo, f_hi = np.maximum(lo[fa], lo[fb]), np.minimum(hi[fa], hi[fb])
    got = face_relations(k, f_lo, f_hi, table.take(row[fa]), table.take(row[fb]), count)
    out = {}
    for f, x, y, g in zip(faces.tolist(), fa.tolist(), fb.tolist(), got):
        pa, pb = owns[row[x]], owns[row[y]]
        out[f] = {(u, v) for u, v in g if u in pa and v in pb}
    return out


def merged_paving(level: np.ndarray, ijk: np.ndarray, label: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Coarsen a paving: eight sibling leaves with one label >= 0 (a clear leaf's cell) become their parent, as long
    as that goes.  Returns (level, ijk, label) of the new leaves and, per old leaf, its new leaf.  Inside a cell
    the flood then relates a few large boxes instead of many small ones (any boxes do: the lemma asks nothing of
    them but to tile)."""
    level, ijk, label = level.astype(np.int64), ijk.astype(np.int64), label.astype(np.int64)
    owner = np.arange(level.size)
    for lev in range(int(level.max()), 0, -1):
        at = np.flatnonzero((level == lev) & (label >= 0))
        if at.size < 8:
            continue
        parent = ijk[at] >> 1
        key = np.stack([parent[:, 0], parent[:, 1], parent[:, 2], label[at]], axis=1)
        uniq, inv, cnt = np.unique(key, axis=0, return_inverse=True, return_counts=True)
        inv = inv.ravel()
        full = cnt[inv] == 8  # all eight children are leaves of this level with the same cell
        if not full.any():
            continue
        merged = at[full]
        group = inv[full]
        first = np.unique(group, return_index=True)[1]
        keep_rows = merged[first]  # one child stands for the parent
        new_id = np.full(uniq.shape[0], -1, dtype=np.int64)
        new_id[group[first]] = keep_rows
        level[keep_rows] -= 1
        ijk[keep_rows] >>= 1
        gone = np.setdiff1d(merged, keep_rows)
        owner_of = np.arange(level.size)
        owner_of[merged] = new_id[group]
        owner = owner_of[owner]
        level[gone] = -1  # dropped below; -2 keeps them out of later merges
        label[gone] = -2
    alive = level >= 0
    new_index = np.cumsum(alive) - 1
    return level[alive], ijk[alive], label[alive], new_index[owner]


def _stack(parts: list[BoxArcs]) -> BoxArcs:
    return BoxArcs(*(np.concatenate([getattr(p, f) for p in parts]) for f in FIELDS))


def centre(lo: np.ndarray, hi: np.ndarray, leaf: int) -> tuple[Fraction, Fraction, Fraction]:
    """The float centre of box ``leaf``, as exact rationals (a witness point)."""
    return tuple(Fraction(float(v)) for v in 0.5 * (lo[leaf] + hi[leaf]))
