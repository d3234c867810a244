"""Separations (space.joint_separation, proofs/lemma-separation.md) on the session's depth-5 paving with windows.

- what the leaves may hold: at random points of leaves, the count from the certified solver is one the
  leaf admits (complete models: a piece's signature; window models: a bit of the count mask);
- cut contacts: at points of a rectangle on which a piece's trace is said to be empty, the certified
  signature is never that piece's;
- the result: cells with no solution are split into several groups, every closed cell is a group of its
  own, and two cells of one group are never both closed;
- mutations: leaves that may hold anything merge every signature's groups into one; a cell leaf given
  another signature is caught as a soundness bug.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

import intervalkin.space.joint_separation as js
from intervalkin.paving.adjacency import shares_face
from intervalkin.solve.dkp import solve
from intervalkin.space.joint_closure import closed_cells, decided_traces
from intervalkin.space.joint_separation import ANY, NO_PIECE, UNKNOWN, separated_cells
from tests.solve.shared import split_of


@pytest.fixture(scope="module")
def separation(fold_paving, paper_geometry):
    return separated_cells(fold_paving, paper_geometry)


def _certified_splits(geometry, points):
    out = []
    for q in points:
        res = solve(geometry, [Fraction(float(v)) for v in q])
        out.append(split_of(res) if res.complete else None)
    return out


def test_leaves_hold_only_what_they_admit(fold_paving, paper_geometry):
    sig = js.leaf_signatures(fold_paving)
    counts = js.possible_counts(fold_paving)
    p = fold_paving.paving
    rng = np.random.default_rng(11)
    modelled = (sig[:, :, 0] != NO_PIECE).any(axis=1)
    two = np.flatnonzero((sig[:, :, 0] >= 0).all(axis=1))
    masked = np.flatnonzero(~modelled & (counts != ANY))
    assert two.size > 100 and masked.size > 100
    leaves = np.r_[rng.choice(two, 60, replace=False), rng.choice(masked, 60, replace=False)]
    pts = p.lo[leaves] + rng.uniform(0.02, 0.98, (len(leaves), 3)) * (p.hi[leaves] - p.lo[leaves])
    seen = 0
    for leaf, s in zip(leaves, _certified_splits(paper_geometry, pts)):
        if s is None:
            continue  # on or very near g(S)
        seen += 1
        if modelled[leaf]:
            assert any(tuple(x) == s or x[0] == UNKNOWN for x in sig[leaf]), (leaf, s, sig[leaf])
        else:
            assert (int(counts[leaf]) >> s[0]) & 1, (leaf, s, bin(int(counts[leaf])))
    assert seen >= 90


def test_a_cut_contact_carries_no_point_of_the_piece(fold_paving, paper_geometry):
    p = fold_paving.paving
    sig = js.leaf_signatures(fold_paving)
    a, b = shares_face(p.level, p.ijk, int(p.level.max()), periodic=(False, False, False))
    two = (sig[:, :, 0] >= 0).all(axis=1)
    pick = np.flatnonzero(two[a])[:40000]
    leaf, other = a[pick], b[pick]
    flo, fhi = np.maximum(p.lo[leaf], p.lo[other]), np.minimum(p.hi[leaf], p.hi[other])
    trace, points = decided_traces(fold_paving, paper_geometry, leaf, flo, fhi)
    empty = np.argwhere(trace == 0)
    assert len(empty) > 100
    rng = np.random.default_rng(12)
    rows = empty[rng.choice(len(empty), 50, replace=False)]
    checked = 0
    for r, slot in rows:
        pts = flo[r] + rng.uniform(0.0, 1.0, (3, 3)) * (fhi[r] - flo[r])
        for s in _certified_splits(paper_geometry, pts):
            if s is not None:
                checked += 1
                assert s != tuple(sig[leaf[r], slot]), (leaf[r], slot, s)
    assert checked >= 100


def test_separations_split_the_zero_cells_and_agree_with_closure(fold_paving, paper_geometry, separation):
    zero = separation.groups[(0, 0, 0)]
    assert len(zero) >= 2
    cells = {c.id for c in fold_paving.cells + fold_paving.fragments}
    assert {c for groups in separation.groups.values() for g in groups for c in g} == cells
    closed = set(closed_cells(fold_paving, paper_geometry).closed)
    assert closed
    for groups in separation.groups.values():
        for g in groups:
            assert not closed & set(g) or len(g) == 1, (g, closed)
    assert separation.components_at_least() == sum(len(g) for g in separation.groups.values())
    assert separation.basic_regions_at_least() == sum(len(g) * s[0] for s, g in separation.groups.items())
    js_json = separation.to_json()
    assert js_json["components_at_least"] == separation.components_at_least()


def test_a_tube_of_leaves_that_may_hold_anything_joins_two_groups(fold_paving, paper_geometry, separation,
                                                                  monkeypatch):
    a, b = separation.groups[(0, 0, 0)][:2]
    wit = {c.id: np.array([float(v) for v in c.witness]) for c in fold_paving.cells + fold_paving.fragments}
    p, q = wit[a[0]], wit[b[0]]
    lo, hi = fold_paving.paving.lo, fold_paving.paving.hi
    # leaves within 0.4 of the segment between the two witnesses (box-to-segment distance, sampled finely)
    t = np.linspace(0.0, 1.0, 400)[:, None]
    tube = np.zeros(len(lo), dtype=bool)
    for x in p + t * (q - p):
        gap = np.maximum(0.0, np.maximum(lo - x, x - hi))
        tube |= np.sqrt((gap ** 2).sum(axis=1)) < 0.4
    real_sig, real_counts = js.leaf_signatures, js.possible_counts

    def blind_sig(jp):
        sig = real_sig(jp).copy()
        sig[tube] = NO_PIECE
        return sig

    def blind_counts(jp):
        counts = real_counts(jp).copy()
        counts[tube] = ANY
        return counts

    monkeypatch.setattr(js, "leaf_signatures", blind_sig)
    monkeypatch.setattr(js, "possible_counts", blind_counts)
    # no refutation rounds: those would model the tube's leaves afresh (tests/space/test_joint_refutation.py)
    got = separated_cells(fold_paving, paper_geometry, rounds=0)
    assert any(a[0] in g and b[0] in g for g in got.groups[(0, 0, 0)]), got.groups


def test_a_cell_leaf_with_another_signature_is_a_soundness_bug(fold_paving, paper_geometry, monkeypatch):
    real = js.leaf_signatures
    big = max(fold_paving.cells, key=lambda c: c.volume)
    leaf = np.flatnonzero(fold_paving.cell == big.id)[0]

    def wrong(jp):
        sig = real(jp).copy()
        sig[leaf, 0] = (big.count + 2, big.n_wa1 + 1, big.n_wa2 + 1)
        return sig

    monkeypatch.setattr(js, "leaf_signatures", wrong)
    with pytest.raises(AssertionError, match="soundness bug"):
        separated_cells(fold_paving, paper_geometry)
