"""Arcs, patterns and face relations (recheck.arc_pattern) hold the certified solver's solutions.

At random points of random joint boxes of the paper's manipulator and of the second design, the
library's certified solver (a complete solve) places each solution in an arc of the box: the counts
per arc lie in the proved ranges, with the proved parities.  At random points of random faces shared
by two boxes, the pair of patterns the solutions give, seen from each box, is in the face relation.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

import intervalkin.recheck.arc_pattern as ap
from intervalkin.core.geometry import load_geometry
from intervalkin.recheck.reduced_equation import reduced_constants
from intervalkin.solve.dkp import solve
from tests.conftest import SECOND_DESIGN


@pytest.fixture(scope="module", params=["paper", "second"])
def geometry(request, paper_geometry):
    return paper_geometry if request.param == "paper" else load_geometry(SECOND_DESIGN)


def _boxes(geometry, seed: int, n: int, widest: float = -0.5):
    rng = np.random.default_rng(seed)
    lo_lim = np.array([float(v) for v in geometry.rho_min])
    hi_lim = np.array([float(v) for v in geometry.rho_max])
    w = 10.0 ** rng.uniform(-2, widest, (n, 3))
    lo = rng.uniform(lo_lim, hi_lim - 2 * w)
    return lo, lo + w, rng


def _solve(geometry, q):
    res = solve(geometry, tuple(Fraction(float(v)) for v in q))
    if not res.complete:
        return None
    return np.array([s.box[2][0] for s in res.solutions]), np.array([s.box[2][1] for s in res.solutions])


def _arc_counts(signs, phi_lo, phi_hi):
    """Solutions per arc start (a dict), or None when one sits too near a cut to be placed."""
    pat = ap.pattern_of_angles(signs, phi_lo, phi_hi)
    if pat is None:
        return None
    out: dict[int, int] = {}
    for s in pat:
        out[s] = out.get(s, 0) + 1
    return out


def _samples(geometry, seed=21, n=40, per_box=3):
    k = reduced_constants(geometry)
    lo, hi, rng = _boxes(geometry, seed, n)
    arcs = ap.box_arcs(k, lo, hi)
    seen = []
    for i in range(n):
        for _ in range(per_box):
            got = _solve(geometry, rng.uniform(lo[i], hi[i]))
            if got is not None:
                seen.append((i, _arc_counts(arcs.signs[i], *got), got[0].size))
    return arcs, seen


def test_arc_ranges_hold_the_solver_counts(geometry):
    arcs, seen = _samples(geometry)
    assert len(seen) > 80
    odd_checked = 0
    for i, counts, total in seen:
        assert counts is not None
        cuts = np.flatnonzero(arcs.signs[i] != 0)
        if cuts.size == 0:
            assert arcs.whole_lo[i] <= total <= arcs.whole_hi[i]
            continue
        for s in cuts.tolist():
            c = counts.get(s, 0)
            assert arcs.lo[i, s] <= c <= arcs.hi[i, s], (i, s, c, arcs.lo[i, s], arcs.hi[i, s])
            if arcs.parity[i, s] >= 0:
                assert c % 2 == arcs.parity[i, s]
                odd_checked += int(arcs.parity[i, s] == 1)
        assert set(counts) <= set(cuts.tolist())
    assert odd_checked > 20  # the parity rule is exercised, in its odd case too


def test_a_wrong_parity_rule_is_caught(paper_geometry):
    """Parities turned round would contradict the solver at the sampled points."""
    arcs, seen = _samples(paper_geometry, seed=22, n=20, per_box=2)
    wrong = 0
    for i, counts, _ in seen:
        for s in np.flatnonzero((arcs.signs[i] != 0) & (arcs.parity[i] >= 0)).tolist():
            wrong += counts.get(s, 0) % 2 != 1 - arcs.parity[i, s]
    assert wrong > 0


def test_face_relations_hold_the_patterns_of_points(geometry):
    k = reduced_constants(geometry)
    lo, hi, rng = _boxes(geometry, 23, 40)
    axis = rng.integers(0, 3, lo.shape[0])
    shift = np.zeros_like(lo)
    shift[np.arange(lo.shape[0]), axis] = (hi - lo)[np.arange(lo.shape[0]), axis]
    lo2, hi2 = lo + shift, hi + shift  # the neighbour across the face x_axis = hi
    f_lo, f_hi = np.maximum(lo, lo2), np.minimum(hi, hi2)
    a, b = ap.box_arcs(k, lo, hi), ap.box_arcs(k, lo2, hi2)
    checked = 0
    for i in range(lo.shape[0]):
        for _ in range(3):
            q = rng.uniform(f_lo[i], f_hi[i])
            got = _solve(geometry, q)
            if got is None:
                continue
            pa, pb = ap.pattern_of_angles(a.signs[i], *got), ap.pattern_of_angles(b.signs[i], *got)
            rel = ap.face_relations(k, f_lo[i][None], f_hi[i][None], a.take(np.array([i])), b.take(np.array([i])),
                                    got[0].size)[0]
            assert (pa, pb) in rel, (i, pa, pb, rel)
            checked += 1
    assert checked > 80


def test_own_patterns_hold_the_solver_patterns(geometry):
    """Fact 5 of the lemma: the pattern the solver's solutions take at a point of a box is among the box's own
    patterns of that count, so a face's relation lies in the product of its boxes' own sets.  Most sampled boxes
    allow one pattern, which is what lets the flood and the checker skip most faces."""
    arcs, seen = _samples(geometry, seed=24, n=30, per_box=2)
    own = {c: ap.own_patterns(arcs, c) for c in range(0, 7, 2)}
    single = 0
    for i, counts, total in seen:
        pattern = tuple(sorted(s for s, c in counts.items() for _ in range(c)))
        if not (arcs.signs[i] != 0).any():
            pattern = (ap.WHOLE,) * total
        assert pattern in own[total][i], (i, pattern, own[total][i])
        single += len(own[total][i]) == 1
        for other in own:
            if other != total and (arcs.signs[i] != 0).any():
                # a count the arcs' sums exclude leaves no pattern
                lo, hi = ap.count_bounds(arcs.take(np.array([i])))
                assert bool(own[other][i]) <= bool(lo[0] <= other <= hi[0])
    assert len(seen) > 40 and single > len(seen) // 2


def test_witness_patterns_need_the_arcs_decided():
    signs = np.zeros(ap.GRID, dtype=np.int8)
    signs[[3, 40]] = 1
    ang = ap.cut_angles()
    assert ap.pattern_of_angles(signs, np.array([ang[10]]), np.array([ang[11]])) == (3,)
    assert ap.pattern_of_angles(signs, np.array([ang[50], 0.0]), np.array([ang[50], 0.0])) == (3, 40)
    assert ap.pattern_of_angles(signs, np.array([ang[2]]), np.array([ang[4]])) is None  # a cut inside
    assert ap.pattern_of_angles(np.zeros(ap.GRID, dtype=np.int8), np.array([1.0]), np.array([1.0])) == (ap.WHOLE,)
    assert ap.unpack(ap.pack([(3, 40), ()])) == [(3, 40), ()]


def _faces(geometry, seed: int, n: int):
    """Random face rectangles (one axis of zero width) of random size, some of them 3-D boxes."""
    lo, hi, rng = _boxes(geometry, seed, n, widest=0.0)
    flat = rng.integers(0, 4, n)  # 3: a box, not a face
    rows = np.flatnonzero(flat < 3)
    hi[rows, flat[rows]] = lo[rows, flat[rows]]
    return lo, hi, rng


def test_split_exclusions_hold_the_solver_counts(geometry):
    """Fact 4 of the lemma: where split_excludes proves a face free of a count, the solver never finds that count
    at random points of it; and the splits prove more than the whole face alone."""
    k = reduced_constants(geometry)
    lo, hi, rng = _faces(geometry, 31, 20)
    excluded = {c: ap.split_excludes(k, lo, hi, c) for c in (0, 2, 4, 6)}
    whole = {c: ap.split_excludes(k, lo, hi, c, splits=(1,)) for c in (0, 2, 4, 6)}
    for c in excluded:
        assert np.all(excluded[c] | ~whole[c])  # splitting never loses what the whole face proves
    assert sum(int(np.sum(excluded[c] & ~whole[c])) for c in excluded) > 0
    checked = 0
    for i in range(lo.shape[0]):
        for _ in range(3):
            got = _solve(geometry, rng.uniform(lo[i], hi[i]))
            if got is None:
                continue
            assert not excluded[got[0].size][i], (i, lo[i], hi[i], got[0].size)
            checked += 1
    assert checked > 40
    assert sum(int(v.sum()) for v in excluded.values()) > 20  # the exclusions are not vacuous


def test_the_split_parts_cover_the_face(paper_geometry, monkeypatch):
    """The parts whose count ranges are computed cover the face: every random point of it lies in one part (in
    the squared leg lengths, where the ranges are computed)."""
    k = reduced_constants(paper_geometry)
    lo, hi, rng = _faces(paper_geometry, 32, 12)
    seen = []
    real = ap.arc_ranges

    def spy(k_, r_lo, r_hi, box, a, b, pieces=1, depth=7):
        seen.append((r_lo.copy(), r_hi.copy()))
        return real(k_, r_lo, r_hi, box, a, b, pieces, depth)

    monkeypatch.setattr(ap, "arc_ranges", spy)
    for i in range(lo.shape[0]):
        seen.clear()
        ap.split_excludes(k, lo[i][None], hi[i][None], 7, splits=(4,))  # 7 is never excluded: every part is kept
        r_lo = np.concatenate([s[0] for s in seen])
        r_hi = np.concatenate([s[1] for s in seen])
        assert r_lo.shape[0] == 4 ** int(np.sum(hi[i] > lo[i]))
        corners = rng.uniform(lo[i], hi[i], (50, 3))
        corners[:4] = [lo[i], hi[i], np.where([1, 0, 1], lo[i], hi[i]), np.where([0, 1, 0], lo[i], hi[i])]
        for q in corners:
            assert np.any(np.all((r_lo <= q * q) & (q * q <= r_hi), axis=1)), (i, q)


def test_a_relation_is_emptied_only_where_proved(paper_geometry):
    k = reduced_constants(paper_geometry)
    lo, hi, _ = _faces(paper_geometry, 33, 16)
    ex = ap.split_excludes(k, lo, hi, 2)
    assert ex.any() and not ex.all()
    rels = [{((1, 2), (1, 2))} for _ in range(lo.shape[0])]
    asked = np.arange(0, lo.shape[0], 2)
    out = ap.prune_relations(k, lo, hi, rels, 2, asked)
    for i in range(lo.shape[0]):
        assert out[i] == (set() if (ex[i] and i % 2 == 0) else rels[i])


def test_a_box_decided_on_every_grid_step_has_arcs(paper_geometry):
    """A face of the paper's joint box far from any solution has a proved sign of f at all 64 cut angles and on
    every grid step between them: its arcs need no range at all (an empty batch of ranges), and hold 0 in all."""
    k = reduced_constants(paper_geometry)
    lo = np.array([[11.378621838068574, 30.01777620911349, 11.492347852607775]])
    hi = np.array([[11.525605478069442, 30.12774828358213, 11.492347852607775]])
    arcs = ap.box_arcs(k, lo, hi)
    assert np.all(arcs.signs != 0)
    low, high = ap.count_bounds(arcs)
    assert low.tolist() == [0] and high.tolist() == [0]
    assert ap.split_excludes(k, lo, hi, 2).all()


def test_arcs_and_relations_in_blocks_are_those_of_each_row(paper_geometry, monkeypatch):
    """Long batches of boxes and faces are taken in blocks (bounded memory): with a block of 7 rows the arcs of
    40 boxes, and the relations of their 40 faces, are exactly those of one batch.  Reversing the blocks' order
    would tie rows to the wrong boxes and fail."""
    k = reduced_constants(paper_geometry)
    lo, hi, _ = _boxes(paper_geometry, 31, 40)
    lo2 = lo.copy()
    lo2[:, 0] = hi[:, 0]
    hi2 = hi.copy()
    hi2[:, 0] = hi[:, 0] + (hi[:, 0] - lo[:, 0])
    f_lo, f_hi = np.maximum(lo, lo2), np.minimum(hi, hi2)
    whole = ap.box_arcs(k, lo, hi), ap.box_arcs(k, lo2, hi2)
    rels = [ap.face_relations(k, f_lo, f_hi, *whole, c) for c in (2, 4)]
    monkeypatch.setattr(ap, "BLOCK", 7)
    blocks = ap.box_arcs(k, lo, hi), ap.box_arcs(k, lo2, hi2)
    for w, b in zip(whole, blocks):
        for f in ap.FIELDS:
            assert np.array_equal(getattr(w, f), getattr(b, f)), f
    assert [ap.face_relations(k, f_lo, f_hi, *blocks, c) for c in (2, 4)] == rels
    assert any(r for r in rels[0] + rels[1])  # some face holds points of the counts: the relations say something
