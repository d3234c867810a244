"""Refuted contacts (space.joint_refutation, proofs/lemma-refuted-contact.md) on the session's depth-5 paving.

- soundness: at random points of the faces of contacts the refuter cuts for a count, the certified solver
  never finds that count (and a refuter made to believe the opposite of what the models say is caught);
- halves: a leaf whose own window model fails is modelled by its eight halves, and what they cut is
  checked the same way;
- the rounds only ever split groups: with rounds the groups refine those found without them.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

import intervalkin.space.joint_refutation as jr
import intervalkin.space.joint_separation as js
from intervalkin.solve.dkp import solve
from intervalkin.space.joint_refutation import Refuter

COUNTS = (0, 2, 4, 6)


@pytest.fixture(scope="module")
def graph(fold_paving, paper_geometry):
    return js._Graph(fold_paving, paper_geometry)


def _contacts(graph, rng, size):
    """Random leaf-leaf contacts near g(S): both ends without a clear cell (fold boxes, window leaves, open)."""
    a, b = graph.a, graph.b
    near = (graph.cells[a, 0] < 0) | (graph.cells[a, 1] >= 0) | (graph.cells[a, 1] == js.UNKNOWN)
    near &= (graph.cells[b, 0] < 0) | (graph.cells[b, 1] >= 0) | (graph.cells[b, 1] == js.UNKNOWN)
    pick = rng.choice(np.flatnonzero(near), size, replace=False)
    return a[pick], b[pick]


def _counts_on_faces(geometry, paving, a, b, rng, per):
    """Certified solution counts at ``per`` random points of each shared face (None where a solve is open)."""
    lo = np.maximum(paving.lo[a], paving.lo[b])
    hi = np.minimum(paving.hi[a], paving.hi[b])
    out = []
    for x, y in zip(lo, hi):
        seen = []
        for q in x + rng.uniform(0.0, 1.0, (per, 3)) * (y - x):
            r = solve(geometry, [Fraction(float(v)) for v in q])
            seen.append(r.count if r.complete else None)
        out.append(seen)
    return out


def _cut_for(refuter, graph, a, b, count):
    s = (count, count // 2, count // 2)
    whole = np.array([True, False])
    may = np.where(graph.has_model[:, None], graph.may(s) | (graph.sig[:, :, 0] == count), whole)
    return refuter.cut(a, b, count, (graph.points[a], graph.points[b]), (may[a], may[b]))


def test_cut_contacts_carry_no_point_of_the_count(graph, fold_paving, paper_geometry):
    rng = np.random.default_rng(31)
    a, b = _contacts(graph, rng, 600)
    refuter = Refuter(paper_geometry, fold_paving.paving.lo, fold_paving.paving.hi)
    checked = 0
    for count in COUNTS:
        cut = np.flatnonzero(_cut_for(refuter, graph, a, b, count))
        assert cut.size > 0, count
        sample = rng.choice(cut, min(cut.size, 12), replace=False)
        for seen in _counts_on_faces(paper_geometry, fold_paving.paving, a[sample], b[sample], rng, 3):
            for n in seen:
                if n is not None:
                    checked += 1
                    assert n != count, (count, seen)
    assert checked >= 100


def test_a_refuter_that_trusts_the_wrong_patterns_is_caught(graph, fold_paving, paper_geometry, monkeypatch):
    # the opposite verdict on every modelled pair: the same face sampling must then find the count
    real = jr.exclusive

    def backwards(models, patterns, box_a, box_b, count, only_a=None, only_b=None):
        return ~real(models, patterns, box_a, box_b, count)

    monkeypatch.setattr(jr, "exclusive", backwards)
    rng = np.random.default_rng(32)
    a, b = _contacts(graph, rng, 300)
    refuter = Refuter(paper_geometry, fold_paving.paving.lo, fold_paving.paving.hi)
    wrong = 0
    for count in (2, 4):
        cut = np.flatnonzero(_cut_for(refuter, graph, a, b, count))
        sample = rng.choice(cut, min(cut.size, 15), replace=False)
        for seen in _counts_on_faces(paper_geometry, fold_paving.paving, a[sample], b[sample], rng, 2):
            wrong += sum(n == count for n in seen)
    assert wrong > 0


def test_halves_stand_for_leaves_whose_model_fails(graph, fold_paving, paper_geometry):
    rng = np.random.default_rng(33)
    refuter = Refuter(paper_geometry, fold_paving.paving.lo, fold_paving.paving.hi)
    # leaves with neither a complete model nor pattern nodes (no window model, or too many patterns): the
    # ones most likely to need halves
    bare = np.flatnonzero(~graph.has_model & ~graph.pat.is_p & (fold_paving.cell < 0))
    ends = np.isin(graph.a, bare) | np.isin(graph.b, bare)
    pick = rng.choice(np.flatnonzero(ends), min(int(ends.sum()), 400), replace=False)
    a, b = graph.a[pick], graph.b[pick]
    checked = 0
    for count in COUNTS:
        cut = _cut_for(refuter, graph, a, b, count)
        halves = refuter._halves[np.searchsorted(refuter._leaf, a)] | refuter._halves[np.searchsorted(refuter._leaf, b)]
        sample = np.flatnonzero(cut & halves)[:8]
        for seen in _counts_on_faces(paper_geometry, fold_paving.paving, a[sample], b[sample], rng, 3):
            for n in seen:
                if n is not None:
                    checked += 1
                    assert n != count
    assert refuter._halves.any()
    # a half's box lies in its leaf, and the eight of a leaf tile it
    k = np.flatnonzero(refuter._halves)[0]
    row, leaf = refuter._row[k], refuter._leaf[k]
    boxes = refuter._models.boxes[row:row + 8]
    assert np.all(boxes[:, :, 0] >= fold_paving.paving.lo[leaf]) and np.all(boxes[:, :, 1] <= fold_paving.paving.hi[leaf])
    assert np.isclose(np.prod(boxes[:, :, 1] - boxes[:, :, 0], axis=1).sum(),
                      np.prod(fold_paving.paving.hi[leaf] - fold_paving.paving.lo[leaf]))
    assert checked >= 10  # cuts made by halves were found and checked


def test_rounds_only_split_groups(fold_paving, paper_geometry):
    none = js.separated_cells(fold_paving, paper_geometry, rounds=0)
    some = js.separated_cells(fold_paving, paper_geometry, rounds=3)
    assert set(none.groups) == set(some.groups)
    for s, groups in some.groups.items():
        coarse = [set(g) for g in none.groups[s]]
        for g in groups:
            assert any(set(g) <= c for c in coarse), (s, g, coarse)
    assert some.components_at_least() >= none.components_at_least()


def test_a_piece_holds_the_one_pattern_its_probe_found(graph, fold_paving, paper_geometry):
    # fold boxes with two pieces of certified counts: the pattern given to each piece (from its point, or from
    # a probe of its count) is the pattern at every point of the leaf with that count
    from intervalkin.space.joint_patterns import pattern_at

    rng = np.random.default_rng(34)
    two = np.flatnonzero((graph.sig[:, :, 0] >= 0).all(axis=1) & (graph.sig[:, 0, 0] != graph.sig[:, 1, 0]))
    leaves = rng.choice(two, 150, replace=False)
    refuter = Refuter(paper_geometry, fold_paving.paving.lo, fold_paving.paving.hi)
    refuter._model(np.unique(leaves))
    i = np.searchsorted(refuter._leaf, leaves)
    whole = ~refuter._halves[i]
    leaves, rows = leaves[whole], refuter._row[i[whole]]
    pts = np.full((leaves.size, 2, 3), np.nan)  # no witness: every pattern comes from a probe
    rows_of_piece = refuter._piece_rows(leaves, rows, pts, np.ones((leaves.size, 2), dtype=bool),
                                        graph.sig[leaves, :, 0])
    assert (rows_of_piece >= 0).sum() > 100
    p = fold_paving.paving
    checked = 0
    for leaf, row, given in zip(leaves[:60], rows[:60], rows_of_piece[:60]):
        q = p.lo[leaf] + rng.uniform(0.02, 0.98, (6, 3)) * (p.hi[leaf] - p.lo[leaf])
        code = pattern_at(paper_geometry, refuter._models, refuter._patterns, np.full(6, row), q)
        for x, c in zip(q, code):
            if c < 0:
                continue
            n = solve(paper_geometry, [Fraction(float(v)) for v in x])
            if not n.complete:
                continue
            for slot in (0, 1):
                if given[slot] >= 0 and graph.sig[leaf, slot, 0] == n.count:
                    checked += 1
                    assert refuter._patterns.code[given[slot]] == c, (leaf, slot, n.count)
    assert checked >= 60


def test_models_the_paving_made_are_reused_and_change_no_cut(graph, fold_paving, paper_geometry):
    # a box's window model depends on the box alone, so a refuter handed the paving's models must cut exactly
    # what one that makes every model itself cuts; the models it took must be the paving's rows
    rng = np.random.default_rng(8)
    a, b = _contacts(graph, rng, 300)
    w = fold_paving.windows
    fresh = Refuter(paper_geometry, fold_paving.paving.lo, fold_paving.paving.hi)
    reuse = Refuter(paper_geometry, fold_paving.paving.lo, fold_paving.paving.hi, (w.leaf, w.models))
    for count in COUNTS:
        assert np.array_equal(_cut_for(fresh, graph, a, b, count), _cut_for(reuse, graph, a, b, count))
    took = np.intersect1d(reuse._leaf[~reuse._halves], w.leaf)
    assert took.size > 20
    rows = reuse._row[np.searchsorted(reuse._leaf, took)]
    assert np.array_equal(reuse._models.boxes[rows], w.models.boxes[np.searchsorted(w.leaf, took)])
    assert np.array_equal(reuse._models.off[rows], w.models.off[np.searchsorted(w.leaf, took)])
