"""Tests of the octree paving engine: subdivision, labels, adjacency, seam, components."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from intervalkin.core.errors import InputError, ResourceError
from intervalkin.core.geometry import default_geometry
from intervalkin.paving.labels import Label, and_labels, not_label
from intervalkin.paving.tree import box_bounds, pave, pave_multi
from intervalkin.paving.budget import check_depth, estimate_memory_bytes
from intervalkin.paving.adjacency import component_labels, connected_components, shares_face, shares_face_bruteforce
from intervalkin.paving.predicates import pave_workspace, workspace_predicate

GEOM = default_geometry()


@pytest.fixture(scope="module")
def paving5():
    return pave_workspace(GEOM, 5)


def _random_octree(rng, depth, p_split=0.5, seam_split=True):
    """Leaves of a random octree (level, ijk) down to depth."""
    level = np.zeros(1, np.int64)
    ijk = np.zeros((1, 3), np.int64)
    leaves_l, leaves_i = [], []
    off = np.array([[a, b, c] for a in (0, 1) for b in (0, 1) for c in (0, 1)])
    for lev in range(depth + 1):
        cut = rng.random(len(level)) < p_split if lev < depth else np.zeros(len(level), bool)
        if lev == 0 and depth > 0:
            cut[:] = True
        leaves_l.append(level[~cut])
        leaves_i.append(ijk[~cut])
        ijk = (2 * ijk[cut][:, None, :] + off[None]).reshape(-1, 3)
        level = np.full(len(ijk), lev + 1)
    return np.concatenate(leaves_l), np.concatenate(leaves_i)


def test_label_algebra():
    """and_labels is the three-valued conjunction, not_label the negation (full truth tables)."""
    a = np.array([1, 1, 1, 2, 2, 2, 3, 3, 3], np.uint8)
    b = np.array([1, 2, 3, 1, 2, 3, 1, 2, 3], np.uint8)
    assert and_labels(a, b).tolist() == [1, 1, 1, 1, 2, 3, 1, 3, 3]
    assert not_label(np.array([1, 2, 3], np.uint8)).tolist() == [2, 1, 3]


def test_label_flags_intersect_as_sets_of_possible_answers():
    """The encoding the paver relies on (``sharp = inherited & new``): a label is the bit set of the
    answers still possible (OUTSIDE = {fails}, INSIDE = {holds}, BOUNDARY = both), so ``&`` of two sound
    labels of ONE predicate is their intersection, and only INSIDE & OUTSIDE gives CONTRADICTION (0).

    Would catch: a renumbering of Label (e.g. BOUNDARY = 0, or INSIDE = 1 and OUTSIDE = 2 with
    BOUNDARY = 4) under which ``&`` would silently drop a decided label or never flag a contradiction.
    """
    possible = {Label.OUTSIDE: {"fails"}, Label.INSIDE: {"holds"}, Label.BOUNDARY: {"fails", "holds"}}
    for a, sa in possible.items():
        for b, sb in possible.items():
            got = Label(int(a) & int(b))
            if sa & sb:
                assert possible[got] == sa & sb, (a, b, got)
            else:
                assert got == Label.CONTRADICTION, (a, b, got)
    # not_label maps each set of possible answers to the set of their negations
    flip = {"fails": "holds", "holds": "fails"}
    for a, sa in possible.items():
        assert possible[Label(int(not_label(np.array([a], np.uint8))[0]))] == {flip[v] for v in sa}


def test_leaves_tile_the_domain(paving5):
    p = paving5
    assert abs(p.volume().sum() - np.prod(p.domain[:, 1] - p.domain[:, 0])) < 1e-9
    lo, hi = p.fine_coordinates()
    n = 1 << p.depth
    occ = np.zeros((n, n, n), np.int32)
    for a, b in zip(lo, hi):  # small: depth 5
        occ[a[0]:b[0], a[1]:b[1], a[2]:b[2]] += 1
    assert np.all(occ == 1)


def test_a_few_boxes_are_read_without_building_all(paving5):
    """Paving.box(i) gives the rows of Paving.boxes, for one index and for an index array."""
    every = paving5.boxes
    idx = np.array([0, 5, len(paving5) - 1])
    assert np.array_equal(paving5.box(7), every[7]) and paving5.box(7).shape == (3, 2)
    assert np.array_equal(paving5.box(idx), every[idx])


def test_float_bounds_match_integer_coordinates(paving5):
    p = paving5
    lo, hi = box_bounds(p.domain, p.level, p.ijk)
    assert np.array_equal(lo, p.lo) and np.array_equal(hi, p.hi)
    # shared faces are bitwise equal across levels: a fine box's bounds reproduce coarse ones
    lev = p.level.astype(np.int64)
    lo2, hi2 = box_bounds(p.domain, lev + 2, p.ijk * 4)
    _, hi3 = box_bounds(p.domain, lev + 2, p.ijk * 4 + 3)
    assert np.array_equal(lo2, p.lo) and np.array_equal(hi3, p.hi)


def test_children_cover_parent_and_labels_sharpen():
    """Every box split at level l has its 8 children at level l+1, and each child's labels
    are at least as sharp as what the parent had (same flag or a subset of its bits)."""
    pred = workspace_predicate(GEOM)
    dom = np.array([[-32, 32], [-32, 32], [-np.pi, np.pi]], float)
    parent_l = np.full(8, 1)
    parent_ijk = np.array([[a, b, c] for a in (0, 1) for b in (0, 1) for c in (0, 1)])
    plo, phi_ = box_bounds(dom, parent_l, parent_ijk)
    plab = pred(np.stack([plo, phi_], -1))
    off = np.array([[a, b, c] for a in (0, 1) for b in (0, 1) for c in (0, 1)])
    for lev in range(1, 5):
        cl = np.repeat(parent_l + 1, 8)
        cijk = (2 * parent_ijk[:, None] + off[None]).reshape(-1, 3)
        clo, chi = box_bounds(dom, cl, cijk)
        # children cover the parent: their hull is the parent, their volumes add up
        hull_lo = clo.reshape(-1, 8, 3).min(1)
        hull_hi = chi.reshape(-1, 8, 3).max(1)
        assert np.array_equal(hull_lo, plo) and np.array_equal(hull_hi, phi_)
        vol = np.prod(chi - clo, 1).reshape(-1, 8).sum(1)
        assert np.allclose(vol, np.prod(phi_ - plo, 1), rtol=1e-12)
        clab = pred(np.stack([clo, chi], -1))
        inherited = np.repeat(plab, 8)
        assert np.all((clab & inherited) == clab), "a child contradicts or loosens its parent's label"
        keep = clab == Label.BOUNDARY
        keep_idx = np.flatnonzero(keep)[:4000]
        parent_l, parent_ijk, plo, phi_, plab = cl[keep_idx], cijk[keep_idx], clo[keep_idx], chi[keep_idx], clab[keep_idx]


def test_pave_splits_only_undecided():
    """The paver splits a box exactly when its label is BOUNDARY, down to the depth, and keeps the labels.

    Checked leaf by leaf against the predicate itself: each leaf carries the label of its own box; each
    leaf below the root has a parent whose box is undecided (so a decided box is never split); an
    undecided leaf sits at the full depth (so no undecided box is left unsplit above it); decided
    leaves above the full depth exist (the previous check is not vacuous).  Would catch a paver that
    splits every box, stops early, splits decided boxes, or mixes up the labels of siblings.
    """
    dom = np.array([[0.0, 1.0], [0.0, 1.0], [0.0, 1.0]])

    def ball(boxes):  # x^2 + y^2 + z^2 <= 0.5, from the bounds of a function monotone on [0, 1]^3
        lo2 = np.sum(np.where(boxes[..., 0] > 0, boxes[..., 0] ** 2, 0.0), axis=1)
        hi2 = np.sum(boxes[..., 1] ** 2, axis=1)
        lab = np.full(len(boxes), Label.BOUNDARY, np.uint8)
        lab[hi2 < 0.4999] = Label.INSIDE
        lab[lo2 > 0.5001] = Label.OUTSIDE
        return lab

    depth = 5
    p = pave(dom, ball, depth, name="ball")
    lab = p.labels["ball"]
    assert np.array_equal(lab, ball(p.boxes))
    assert np.all(p.level[lab == Label.BOUNDARY] == depth)
    decided_early = (lab != Label.BOUNDARY) & (p.level < depth)
    assert decided_early.sum() > 20 and {Label.INSIDE, Label.OUTSIDE} <= set(lab[decided_early].tolist())
    below_root = p.level > 0
    plo, phi_ = box_bounds(dom, p.level[below_root].astype(np.int64) - 1, p.ijk[below_root] // 2)
    assert np.all(ball(np.stack([plo, phi_], axis=-1)) == Label.BOUNDARY)
    ev = [s["evaluated"]["ball"] for s in p.stats]
    splits = [s["split"] for s in p.stats]
    assert all(ev[i + 1] == 8 * splits[i] for i in range(len(ev) - 1))


@settings(max_examples=60, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10**6), depth=st.integers(1, 4), p_split=st.floats(0.2, 0.8),
       periodic=st.tuples(st.booleans(), st.booleans(), st.booleans()), keep=st.floats(0.5, 1.0))
def test_bulk_adjacency_equals_bruteforce(seed, depth, p_split, periodic, keep):
    """Every wrap of the axes, and part of a tiling (boxes dropped: the lookup across a gap finds nothing),
    against the pairwise test; the pairs come once each, sorted."""
    rng = np.random.default_rng(seed)
    level, ijk = _random_octree(rng, depth, p_split)
    some = rng.random(level.size) < keep
    level, ijk = level[some], ijk[some]
    fast = shares_face(level, ijk, depth, periodic)
    slow = shares_face_bruteforce(level, ijk, depth, periodic)
    assert fast.shape == slow.shape
    assert set(map(tuple, fast.T.tolist())) == set(map(tuple, slow.T.tolist()))
    assert np.all(fast[0] < fast[1]) and np.all(np.diff(fast[0] * max(level.size, 1) + fast[1]) > 0)


def test_adjacency_excludes_edges_and_corners():
    # four level-1 boxes in the x-y plane at k = 0: diagonal pair touches on an edge only
    level = np.ones(8, np.int64)
    ijk = np.array([[a, b, c] for a in (0, 1) for b in (0, 1) for c in (0, 1)])
    e = set(map(tuple, shares_face(level, ijk, 1).T.tolist()))
    idx = {tuple(v): n for n, v in enumerate(ijk.tolist())}
    assert (idx[(0, 0, 0)], idx[(1, 0, 0)]) in e
    assert (min(idx[(0, 0, 0)], idx[(1, 1, 0)]), max(idx[(0, 0, 0)], idx[(1, 1, 0)])) not in e
    assert (idx[(0, 0, 0)], idx[(1, 1, 1)]) not in e
    # each box has 3 face neighbours (phi wraps onto the same neighbour): 8 * 3 / 2 = 12 pairs
    assert len(e) == 12


def test_phi_seam_adjacency_and_component_counted_once():
    depth = 3
    n = 1 << depth
    # a tube along phi at (i, j) = (0, 0), every phi slice present
    ijk = np.array([[0, 0, k] for k in range(n)])
    level = np.full(n, depth)
    e = shares_face(level, ijk, depth)
    pairs = set(map(tuple, e.T.tolist()))
    assert (0, n - 1) in pairs  # the box touching -pi is adjacent to the one touching +pi
    assert len(pairs) == n  # a ring
    without = shares_face(level, ijk, depth, periodic=(False, False, False))
    assert (0, n - 1) not in set(map(tuple, without.T.tolist()))
    # an arc crossing the seam: slices n-2, n-1, 0, 1 present: ONE component
    sel = np.array([0, 1, n - 2, n - 1])
    e2 = shares_face(level[sel], ijk[sel], depth)
    comp = component_labels(4, e2, np.ones(4, bool))
    assert comp.max() == 0
    comp_np = component_labels(4, shares_face(level[sel], ijk[sel], depth, periodic=(False,) * 3), np.ones(4, bool))
    assert comp_np.max() == 1


def test_seam_in_real_paving(paving5):
    p = paving5
    e = shares_face(p.level, p.ijk, p.depth)
    top = np.flatnonzero(p.hi[:, 2] == p.domain[2, 1])
    bottom = set(np.flatnonzero(p.lo[:, 2] == p.domain[2, 0]).tolist())
    pairs = e.T
    seam = [(a, b) for a, b in pairs.tolist() if (a in bottom and b in set(top.tolist())) or (b in bottom and a in set(top.tolist()))]
    assert len(seam) > 0
    # seam pairs overlap in x and y
    for a, b in seam[:200]:
        assert min(p.hi[a, 0], p.hi[b, 0]) > max(p.lo[a, 0], p.lo[b, 0])
        assert min(p.hi[a, 1], p.hi[b, 1]) > max(p.lo[a, 1], p.lo[b, 1])


@settings(max_examples=10, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10**6))
def test_bulk_components_equal_networkx(seed):
    rng = np.random.default_rng(seed)
    level, ijk = _random_octree(rng, 3, 0.6)
    e = shares_face(level, ijk, 3)
    mask = rng.random(len(level)) < 0.5
    comp = component_labels(len(level), e, mask)
    ours = {frozenset(np.flatnonzero(comp == c).tolist()) for c in range(comp.max() + 1)}
    theirs = set(connected_components(len(level), e, mask))
    assert ours == theirs


def test_depth_validation():
    with pytest.raises(InputError):
        check_depth(0)
    with pytest.raises(InputError):
        check_depth(99)
    with pytest.raises(InputError):
        check_depth(2.5)
    assert check_depth(3) == 3
    assert estimate_memory_bytes(9) > 3 * estimate_memory_bytes(8)


def test_depth_refused_when_memory_short(monkeypatch):
    from intervalkin.paving import budget

    monkeypatch.setattr(budget, "available_memory_bytes", lambda: 1e8)
    with pytest.raises(ResourceError, match="exceeds available"):
        budget.check_depth(6)


def test_bad_domain():
    with pytest.raises(InputError):
        pave_multi(np.zeros((3, 2)), [("a", lambda b: np.full(len(b), 3, np.uint8))], 2)


def test_locate_boxes_matches_brute_force(paper_geometry):
    """The key lookup finds exactly the leaf that contains a small query box, or -1."""
    from intervalkin.paving.predicates import pave_workspace

    p = pave_workspace(paper_geometry, 5)
    rng = np.random.default_rng(3)
    pts = np.column_stack([rng.uniform(-32, 32, 500), rng.uniform(-32, 32, 500), rng.uniform(-3.14, 3.14, 500)])
    # include points on box faces, where no leaf contains a box around them
    pts[:50] = p.lo[rng.integers(len(p), size=50)]
    q = np.stack([pts - 1e-9, pts + 1e-9], axis=-1)
    idx = p.locate_boxes(q)
    for k in range(len(q)):
        holders = np.flatnonzero(np.all((p.lo <= q[k, :, 0]) & (q[k, :, 1] <= p.hi), axis=1))
        if idx[k] >= 0:
            assert idx[k] in holders
        else:
            assert holders.size == 0


def test_conjunct_parts_are_kept_and_labels_unchanged(monkeypatch):
    """W as three legs: the paver asks a child only for the legs its parent left open, and the labels
    are those of the paver that re-evaluates all three legs on every box."""
    from intervalkin.paving import predicates

    asked = []
    real = predicates.WorkspacePredicate.conjunct_labels

    def spy(self, boxes, todo):
        asked.append((len(todo), int(todo.sum())))
        return real(self, boxes, todo)

    monkeypatch.setattr(predicates.WorkspacePredicate, "conjunct_labels", spy)
    kept = pave_workspace(GEOM, 6)
    monkeypatch.setattr(predicates.WorkspacePredicate, "conjuncts", 0)
    plain = pave_workspace(GEOM, 6)
    assert len(kept) == len(plain) and all(np.array_equal(kept.labels[n], plain.labels[n]) for n in plain.labels)
    boxes, legs = np.sum(asked, axis=0)
    assert legs < 0.6 * 3 * boxes, "children re-evaluated the legs their parents had decided"
