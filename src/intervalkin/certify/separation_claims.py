"""Separation certificates: count barriers that put two joint cells of one signature in different components.

A *count barrier* for a cell C with c solutions is a finite set S of closed joint boxes (the
*region*) and a set of closed face rectangles (the *barrier*) such that

* the boundary of S inside the open joint box lies in the union of the barrier rectangles;
* no point of any barrier rectangle has exactly c solutions (proved by
  :func:`intervalkin.recheck.count_range.excludes_count`);
* a witness of C lies in the interior of a box of S, and a witness of every other cell of
  C's signature lies outside S.

A path off g(S) from C's witness to another witness keeps c solutions at every point
(lemma-constant-count-off-gS.md); leaving S, it would cross the boundary of S at a point with c
solutions, on a barrier rectangle.  So the witnesses lie in different components of the joint
box minus g(S) (proofs/lemma-count-barrier.md).  ``intervalkin verify`` re-proves every
barrier rectangle and the covering of the boundary from the files alone
(:mod:`intervalkin.recheck.separation_file`).

How a region is found (a choice of effort, not of soundness): the leaves of the joint paving that
may hold c solutions (:func:`~intervalkin.space.joint_separation.possible_counts`), joined through
shared faces, form components; C's component, if it holds no leaf of another cell of its
signature, is the first region.  Its boundary faces are tested; the leaf beyond each face whose
count is not excluded is added (the barrier moves away from g(S), where the roots of the reduced
equation are better apart), for at most :data:`GROW_ROUNDS` rounds.  Patterns of window models
are not used: cells told apart only by the patterns of their solutions (the transversal
crossings of two sheets) get no count barrier, and stay library-proved.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from intervalkin.certify.pattern_barriers import PatternBarrier, centre, flood, merged_paving, solution_pattern
from intervalkin.certify.solve_claims import witness_end
from intervalkin.core.geometry import Geometry
from intervalkin.core.workers import Beside, Workers, default_workers
from intervalkin.paving.adjacency import shares_face
from intervalkin.paving.tree import box_bounds
from intervalkin.recheck.arc_pattern import MAX_COUNT, box_arcs, pack
from intervalkin.recheck.count_range import excludes_count, supported
from intervalkin.recheck.reduced_equation import reduced_constants
from intervalkin.space.joint_closure import piece_cells
from intervalkin.space.joint_separation import ANY, possible_counts

__all__ = ["PATTERN_BUDGET", "pattern_barriers", "GROW_ROUNDS", "FACE_BUDGET", "TOTAL_FACE_BUDGET", "SHRINK", "SAMPLE",
           "MAX_FAIL_SHARE",
           "CountBarrier", "count_barriers", "separation_claims"]

#: Rounds of moving failed faces outward before a region is given up.
GROW_ROUNDS = 8
#: Face rectangles tested per region at most, and for all regions of one paving (each costs about 1.5 ms of
#: count ranges per core): the paper's three barriers test about 7000 in all, 4000 for the largest.
FACE_BUDGET = 8000
TOTAL_FACE_BUDGET = 20000
#: A growth round must leave at most this share of the failed faces of the round before.
SHRINK = 0.6
#: Faces of a region's first boundary tested first, and the share of them that may fail.
SAMPLE, MAX_FAIL_SHARE = 200, 0.35
#: Faces worth sending to a second process at once.
MIN_PART = 400
#: Faces the pattern barriers' floods may range for all of one paving, by default (``--barrier-faces``; a face
#: needs a range only where its boxes' own patterns would carry the flood across it): the second design's first
#: barrier ranges 9761, the paper's 3042; a 4-solution cell of limits [10.5, 32] 115 320 (about 9 minutes).
PATTERN_BUDGET = 16000
#: Faces a flood ranges per box of its cell, at least: the floods that closed ranged 9 and 15 (a region holds its
#: whole cell and spreads to about five times its boxes).  A cell past the budget at this rate is not tried.
FACES_PER_BOX = 12
#: The npz columns of ``certificates/joint_separation.npz``.
_COLUMNS = ("region_lo", "region_hi", "region_claim", "barrier_lo", "barrier_hi", "barrier_claim", "barrier_box",
            "barrier_outer_lo", "barrier_outer_hi", "pattern_box", "pattern_rows")


@dataclass(frozen=True)
class CountBarrier:
    """A region (closed boxes) holding ``cell``'s leaves and a barrier of faces with no point of ``count``
    solutions covering its boundary; ``others`` the cells of the same signature left outside."""

    cell: int
    signature: tuple[int, int, int]
    others: tuple[int, ...]
    region_lo: np.ndarray
    region_hi: np.ndarray
    barrier_lo: np.ndarray
    barrier_hi: np.ndarray
    witness: tuple[Fraction, Fraction, Fraction]
    other_witnesses: tuple[tuple[Fraction, Fraction, Fraction], ...]


def count_barriers(jp, geometry: Geometry, face_budget: int = FACE_BUDGET,
                   workers: Workers | None = None) -> tuple[list[CountBarrier], list[dict]]:
    """Count barriers for the cells of ``jp`` (a :class:`~intervalkin.space.joint_paving.JointSpacePaving`):
    for each signature held by two cells or more, one barrier per cell but the one with the largest
    region (enough to tell every pair apart), where one is found; and what was left out, with why."""
    if not supported(geometry):
        return [], [{"what": "count barriers", "why": "|p_i| = |A_i - A_1| for legs 2 and 3: count ranges refused"}]
    p = jp.paving
    n = len(p.lo)
    a, b = shares_face(p.level, p.ijk, int(p.level.max()), periodic=(False, False, False))
    counts = possible_counts(jp)
    cells = piece_cells(jp)[0]
    barriers, omitted = [], []
    total, spent = TOTAL_FACE_BUDGET, 0
    by_sig: dict[tuple, list] = {}
    for c in jp.cells:
        if c.signature[0] >= 0 and np.any(jp.cell == c.id):
            by_sig.setdefault(c.signature, []).append(c)
    for sig, mine in sorted(by_sig.items()):
        if len(mine) < 2:
            continue
        count = sig[0]
        admit = (counts == ANY) | ((counts >> count) & 1 == 1)
        keep = admit[a] & admit[b]
        comp = connected_components(coo_matrix((np.ones(int(keep.sum()), dtype=np.int8), (a[keep], b[keep])),
                                               shape=(n, n)), directed=False)[1]
        leaves = {c.id: np.flatnonzero((cells == c.id).any(axis=1)) for c in mine}
        size = {c.id: int(np.sum(comp == comp[leaves[c.id][0]])) for c in mine}
        order = sorted(mine, key=lambda c: size[c.id])
        for c in order[:-1]:
            others = [o for o in mine if o.id != c.id]
            found, why, used = _grow(geometry, p, a, b, comp == comp[leaves[c.id][0]], count,
                                     np.concatenate([leaves[o.id] for o in others]),
                                     min(face_budget, total - spent), workers)
            spent += used
            if found is None:
                omitted.append({"what": f"count barrier of cell {c.id} ({count} solutions)", "why": why})
                continue
            region, faces = found
            clear = lambda cid: int(np.flatnonzero(jp.cell == cid)[0])  # noqa: E731 - a clear leaf of the cell
            barriers.append(CountBarrier(
                c.id, tuple(int(v) for v in sig), tuple(o.id for o in others), p.lo[region], p.hi[region],
                np.maximum(p.lo[a[faces]], p.lo[b[faces]]), np.minimum(p.hi[a[faces]], p.hi[b[faces]]),
                centre(p.lo, p.hi, clear(c.id)), tuple(centre(p.lo, p.hi, clear(o.id)) for o in others)))
    return barriers, omitted


def _grow(geometry: Geometry, p, a: np.ndarray, b: np.ndarray, region: np.ndarray, count: int,
          forbidden: np.ndarray, budget: int,
          workers: Workers | None) -> tuple[tuple[np.ndarray, np.ndarray] | None, str, int]:
    """(region leaves, boundary contacts) once every boundary face excludes ``count``, or None; why not; and the
    number of faces tested (at most ``budget``).  Growth stops when a round leaves more than
    :data:`SHRINK` times the failed faces of the round before: the barrier is then not moving away from g(S)
    but along it (two cells of the count meeting at a crossing of two sheets)."""
    region = region.copy()
    proved: dict[int, bool] = {}
    before = None
    for k in range(GROW_ROUNDS + 1):
        if region[forbidden].any():
            return None, ("its region reaches another cell of its signature (a finer paving, or the patterns of "
                          "window models, would be needed)"), len(proved)
        edge = np.flatnonzero(region[a] ^ region[b])
        todo = np.array([e for e in edge.tolist() if e not in proved], dtype=np.int64)
        if len(proved) + todo.size > budget:
            return None, f"more than {budget} faces to test", len(proved)
        if k == 0 and todo.size > 2 * SAMPLE:
            # an even sample of the first boundary first: a region whose barrier is far from closing is given up cheaply
            pick = todo[np.linspace(0, todo.size - 1, SAMPLE).astype(np.int64)]
            lo = np.maximum(p.lo[a[pick]], p.lo[b[pick]])
            hi = np.minimum(p.hi[a[pick]], p.hi[b[pick]])
            ok = excludes_count(geometry, lo, hi, count, workers)
            proved.update(zip(pick.tolist(), ok.tolist()))
            if (~ok).mean() > MAX_FAIL_SHARE:
                return None, (f"{(~ok).mean():.0%} of a sample of its boundary faces hold points of {count} solutions "
                              "or are not decided"), len(proved)
            todo = np.array([e for e in todo.tolist() if e not in proved], dtype=np.int64)
        if todo.size:
            lo = np.maximum(p.lo[a[todo]], p.lo[b[todo]])
            hi = np.minimum(p.hi[a[todo]], p.hi[b[todo]])
            proved.update(zip(todo.tolist(), excludes_count(geometry, lo, hi, count, workers).tolist()))
        fail = np.array([e for e in edge.tolist() if not proved[e]], dtype=np.int64)
        if fail.size == 0:
            return (np.flatnonzero(region), edge), "", len(proved)
        if before is not None and fail.size > SHRINK * before:
            return None, (f"faces with {count} solutions not excluded: {before} then {fail.size} after round {k} "
                          "(the barrier runs along g(S), not away from it)"), len(proved)
        before = fail.size
        region[np.where(region[a[fail]], b[fail], a[fail])] = True
    return None, f"faces with {count} solutions not excluded after {GROW_ROUNDS} rounds", len(proved)


def pattern_barriers(jp, geometry: Geometry, precision: int = 128,
                     budget: int = PATTERN_BUDGET) -> tuple[list[tuple[dict, list[dict], PatternBarrier]], list[dict]]:
    """Pattern barriers (:mod:`intervalkin.certify.pattern_barriers`) for the cells with solutions whose signature
    two cells or more share: for a signature with k cells, barriers are tried cell by cell, smallest first, until
    k - 1 are found (enough to tell every pair apart) or ``budget`` faces are ranged in all.  Returns (witness,
    other witnesses (with ``cell``), barrier, cell, signature) per barrier and what was left out."""
    p = jp.paving
    out, omitted = [], []
    if not supported(geometry):
        return out, omitted
    if getattr(jp, "windows", None) is None:
        # a preview paving (no window models: g(S) not resolved near its folds and crossings), where the library
        # attempts no separations either; a flood there would spend its budget and close nothing
        return out, [{"what": "pattern barriers", "why": "the joint paving has no window models (a preview)"}]
    by_sig: dict[tuple, list] = {}
    for c in jp.cells:
        if c.signature[0] > 0 and np.any(jp.cell == c.id):
            by_sig.setdefault(c.signature, []).append(c)
    groups = [(sig, mine) for sig, mine in sorted(by_sig.items()) if len(mine) > 1]
    if not groups:
        return out, omitted
    # the flood runs on the paving with sibling clear leaves of one cell merged (fewer, larger boxes)
    level, ijk, label, owner = merged_paving(p.level, p.ijk, jp.cell)
    every = tuple(jp.cells) + tuple(getattr(jp, "fragments", ()))
    count_of = np.full(max(int(label.max()), max((c.id for c in every), default=0)) + 1, -1, dtype=np.int64)
    for c in every:
        count_of[c.id] = c.signature[0]
    clear_count = np.where(label >= 0, count_of[np.maximum(label, 0)], -1)
    lo, hi = box_bounds(p.domain, level, ijk)
    a, b = shares_face(level, ijk, int(level.max()), periodic=(False, False, False))
    k = reduced_constants(geometry)
    spent = 0
    for sig, mine in groups:
        leaf = {c.id: int(np.flatnonzero(jp.cell == c.id)[0]) for c in mine}  # a clear leaf: its centre is inside
        node = {cid: int(owner[x]) for cid, x in leaf.items()}
        ends, pats = {}, {}
        arcs = box_arcs(k, lo[list(node.values())], hi[list(node.values())])
        for i, c in enumerate(mine):
            got, why = witness_end(geometry, centre(p.lo, p.hi, leaf[c.id]), precision)
            if got is None or (got["count"], got["n_wa1"], got["n_wa2"]) != tuple(sig):
                omitted.append({"what": f"pattern barrier of cell {c.id}",
                                "why": why or "its witness's signature differs"})
                continue
            ends[c.id], pats[c.id] = got, solution_pattern(arcs, i, got)
        # the smallest cells first: a region holds its whole cell, and k - 1 barriers tell k cells apart
        boxes = {c.id: np.unique(owner[jp.cell == c.id]).size for c in mine}
        ready = sorted((c for c in mine if pats.get(c.id) is not None), key=lambda c: boxes[c.id])
        made = 0
        for c in ready:
            if made == len(mine) - 1:
                break
            if spent >= budget:
                omitted.append({"what": f"pattern barrier of cell {c.id} ({sig[0]} solutions)",
                                "why": f"no face budget left ({spent} ranged of --barrier-faces {budget})"})
                continue
            others = [o for o in mine if o.id != c.id]
            if any(o.id not in ends or pats[o.id] is None for o in others):
                omitted.append({"what": f"pattern barrier of cell {c.id}",
                                "why": "another cell's witness has no pattern"})
                continue
            if boxes[c.id] * FACES_PER_BOX > budget - spent:
                # the region holds the whole cell, and each box brings at least FACES_PER_BOX faces: it cannot close
                omitted.append({"what": f"pattern barrier of cell {c.id} ({sig[0]} solutions)",
                                "why": f"the cell alone is {boxes[c.id]} boxes of the paving, past the face budget "
                                       f"left ({budget - spent} of --barrier-faces {budget})"})
                continue
            forbidden = {node[o.id]: {pats[o.id]} for o in others}
            rivals = np.unique(owner[np.isin(jp.cell, [o.id for o in others])])
            # a clear box of another count is walled where its count ranges say so: its arcs may be too coarse to
            walls = (clear_count >= 0) & (clear_count != sig[0])
            bar, why, used = flood(geometry, lo, hi, a, b, sig[0], (node[c.id], pats[c.id]), forbidden, rivals,
                                   budget=budget - spent, walls=walls,
                                   same=clear_count == sig[0])
            spent += used
            if bar is None:
                omitted.append({"what": f"pattern barrier of cell {c.id} ({sig[0]} solutions)", "why": why})
                continue
            made += 1
            out.append((ends[c.id], [dict(ends[o.id], cell=int(o.id)) for o in others], bar, c.id, tuple(sig)))
    return out, omitted


def separation_claims(geometry: Geometry, jp, precision: int = 128, patterned: Beside | None = None,
                      budget: int = PATTERN_BUDGET) -> tuple[list[dict], dict, list[dict]]:
    """(claims, npz arrays, omitted) of ``certificates/joint_separation.json`` and ``.npz``.

    Claim j: ``cell``, ``signature``, ``witness`` and ``others`` (each a witness object with its
    complete solution list, as in a ``joint_cell`` claim, plus ``cell``), ``region`` (j itself: the
    rows of the npz whose ``region_claim`` / ``barrier_claim`` is j).  A count barrier's barrier rows
    have ``barrier_box`` -1; a pattern barrier (``"kind": "pattern"``) ties each barrier row to the region
    row it lies on (``barrier_box``, an index into all region rows) and to the box beyond it
    (``barrier_outer_lo`` / ``_hi``), and lists the pattern set of each region row (``pattern_box``, rows of
    ``pattern_rows``: sorted arc starts padded with -2).

    ``patterned``: :func:`pattern_barriers` of the same paving, already started in a second process (a
    :class:`~intervalkin.core.workers.Beside`), so that its serial flood runs while this process does the rest;
    otherwise they are made here, with ``budget`` ranged faces in all."""
    with Workers(default_workers(), min_items=MIN_PART) as workers:
        barriers, omitted = count_barriers(jp, geometry, workers=workers)
    made, left = patterned.result() if patterned is not None else pattern_barriers(jp, geometry, precision, budget)
    omitted += left
    claims: list[dict] = []
    arrays = {k: [] for k in _COLUMNS}
    rows = 0

    def add(region, barrier, box, outer, patterns, j):
        nonlocal rows
        for name, value in (("region", region), ("barrier", barrier)):
            arrays[f"{name}_lo"].append(value[0])
            arrays[f"{name}_hi"].append(value[1])
            arrays[f"{name}_claim"].append(np.full(len(value[0]), j, dtype=np.int64))
        arrays["barrier_box"].append(np.where(box >= 0, box + rows, -1).astype(np.int64))
        arrays["barrier_outer_lo"].append(outer[0])
        arrays["barrier_outer_hi"].append(outer[1])
        for i, pats in enumerate(patterns):
            arrays["pattern_box"].append(np.full(len(pats), rows + i, dtype=np.int64))
            arrays["pattern_rows"].append(pack(list(pats)))
        rows += len(region[0])

    for bar in barriers:
        ends = [witness_end(geometry, q, precision) for q in (bar.witness, *bar.other_witnesses)]
        bad = next((why for got, why in ends if got is None), None)
        if bad is not None:
            omitted.append({"what": f"count barrier of cell {bar.cell}", "why": bad})
            continue
        if any((e["count"], e["n_wa1"], e["n_wa2"]) != bar.signature for e, _ in ends):
            omitted.append({"what": f"count barrier of cell {bar.cell}", "why": "a witness's signature differs"})
            continue
        j = len(claims)
        claims.append({
            "id": f"cell-{bar.cell}",
            "cell": bar.cell,
            "signature": list(bar.signature),
            "witness": ends[0][0],
            "others": [dict(e, cell=int(o)) for (e, _), o in zip(ends[1:], bar.others)],
            "region": j,
            "statement": (f"joint cell {bar.cell} ({bar.signature[0]} solutions, {bar.signature[1]} in WA1) lies in "
                          f"another component of the joint box minus g(S) than cells "
                          f"{', '.join(map(str, bar.others))}: {len(bar.region_lo)} boxes around its witness, whose "
                          f"boundary is covered by {len(bar.barrier_lo)} face rectangles with no point of "
                          f"{bar.signature[0]} solutions"),
        })
        add((bar.region_lo, bar.region_hi), (bar.barrier_lo, bar.barrier_hi), np.full(len(bar.barrier_lo), -1),
            (bar.barrier_lo, bar.barrier_hi), [], j)
    for witness, others, bar, cell, sig in made:
        j = len(claims)
        claims.append({
            "id": f"cell-{cell}",
            "kind": "pattern",
            "cell": int(cell),
            "signature": list(sig),
            "witness": witness,
            "others": others,
            "region": j,
            "statement": (f"joint cell {cell} ({sig[0]} solutions, {sig[1]} in WA1) lies in another component of the "
                          f"joint box minus g(S) than cells {', '.join(str(o['cell']) for o in others)}: "
                          f"{len(bar.region_lo)} boxes around its witness with the patterns its solutions may take "
                          f"there, whose boundary is covered by {len(bar.barrier_lo)} face rectangles where none of "
                          "those patterns occurs"),
        })
        add((bar.region_lo, bar.region_hi), (bar.barrier_lo, bar.barrier_hi), bar.barrier_box,
            (bar.outer_lo, bar.outer_hi), bar.patterns, j)
    shapes = {"pattern_rows": (0, MAX_COUNT)}
    out = {k: (np.concatenate(v) if v else np.zeros(shapes.get(k, (0, 3) if k.endswith(("lo", "hi")) else 0)))
           for k, v in arrays.items()}
    for k in out:
        if k.endswith(("claim", "box")):
            out[k] = out[k].astype(np.int64)
    out["pattern_rows"] = out["pattern_rows"].astype(np.int16)
    return claims, out, omitted
