"""The open layer's retraction into the cells (space.joint_retraction, proofs/lemma-joint-retraction.md)."""

from __future__ import annotations

from fractions import Fraction
from types import SimpleNamespace

import mpmath
import numpy as np
import pytest

from intervalkin.solve.dkp import solve
from intervalkin.solve.window_split import d_zeros
from intervalkin.space.joint_retraction import LEFT, RET, SINK, SOURCES, retract_joint_paving
from intervalkin.space.retraction_ranks import retraction_ranks
from tests.solve.test_window_model import _d_mp, _mp_value
from tests.solve.test_window_plane import _s_mp


@pytest.fixture(scope="module")
def corner_geometry():
    """The paper's manipulator on the part [21, 32] x [15.5, 26.5] x [10, 21] of its joint box."""
    from dataclasses import replace

    from intervalkin.core.geometry import default_geometry

    return replace(default_geometry(), rho_min=(Fraction(21), Fraction(31, 2), Fraction(10)),
                   rho_max=(Fraction(32), Fraction(53, 2), Fraction(21)))


@pytest.fixture(scope="module")
def corner_paving(corner_geometry):
    """That part paved as the shared ``fold_paving`` is (fold and window models, one model and one join level) at
    depth 4, so with leaves of the same size (11/16 = 22/32).  Of the eighth-volume parts of the joint box it holds
    the most leaves with cusp sides (420 of the whole box's 1707 on ``fold_paving``) beside the 6-solution cell,
    crossings and zeros of D, so every kind of retraction node in numbers the property tests can sample; its
    paving and retraction take about 45 s on one core, where the whole box's retraction alone took about 110 s.
    Read only."""
    from intervalkin.space.joint_paving import pave_joint_space

    return pave_joint_space(corner_geometry, 4, 1, fold=True, model_levels=1, windows=True)


@pytest.fixture(scope="module")
def retraction(corner_paving, corner_geometry):
    return retract_joint_paving(corner_paving, corner_geometry)


def _signature(geometry, point) -> tuple[int, int, int] | None:
    """The signature at an exact point from an independent certified solve, None where it does not complete."""
    res = solve(geometry, [Fraction(float(x)) for x in point])
    if not res.complete or any(s.status != "unique" or s.det_sign == 0 for s in res.solutions):
        return None
    n1 = sum(s.det_sign > 0 for s in res.solutions)
    return len(res.solutions), n1, len(res.solutions) - n1


def test_every_leaf_has_a_node_and_sinks_lie_in_counted_cells(corner_paving, retraction):
    r = retraction
    assert np.all(np.diff(r.leaf) >= 0)
    assert np.array_equal(np.unique(r.leaf), np.arange(len(corner_paving.cell)))
    sink = r.kind == SINK
    assert sink.any() and np.all(r.cell[sink] >= 0) and np.all(r.cell[sink] < len(corner_paving.cells))
    assert np.all(r.cell[~sink] == -1) and np.all(r.rank[sink] == 0)
    # a sink's signature is its cell's
    sigs = np.array([c.signature for c in corner_paving.cells])
    assert np.array_equal(r.signature[sink], sigs[r.cell[sink]])
    # every source of node occurs on this paving, and LEFT nodes never get a rank
    assert set(np.unique(r.source)) == set(range(len(SOURCES)))
    assert np.all(r.rank[r.kind == LEFT] == -1)
    # f has at most 6 roots: a node claiming more would be an empty set posing as a blocker
    assert r.signature[:, 0].max() <= 6
    assert not r.closed()  # pair patterns and cusp sides without a way: no upper bound at this depth


def test_ranks_follow_the_rule_across_each_exit_face(corner_paving, retraction):
    """Re-derived from the float boxes: every leaf sharing a 2-D piece of a resolved node's exit face holds no LEFT
    node, and its nodes of the same signature are sinks or of lower rank (but for those on the other side of the
    node's own plane of double roots, which its path never reaches)."""
    r, p = retraction, corner_paving.paving
    lo, hi = p.lo, p.hi
    resolved = np.flatnonzero((r.kind == RET) & (r.rank > 0))
    assert resolved.size > 100
    rng = np.random.default_rng(5)
    start = np.searchsorted(r.leaf, np.arange(len(lo) + 1))
    for node in rng.choice(resolved, 300, replace=False):
        assert r.option_node[r.exit[node]] == node  # the exit is one of the node's options
        a = r.leaf[node]
        for f in np.flatnonzero(r.option_faces[r.exit[node]]):
            ax, side = divmod(int(f), 2)
            plane = hi[a, ax] if side else lo[a, ax]
            assert p.domain[ax, 0] < plane < p.domain[ax, 1]  # not on the border
            touch = (lo[:, ax] == plane) if side else (hi[:, ax] == plane)
            for o in [o for o in range(3) if o != ax]:
                touch &= (np.minimum(hi[:, o], hi[a, o]) > np.maximum(lo[:, o], lo[a, o]))
            across = np.flatnonzero(touch)
            assert across.size >= 1
            for b in across:
                q = np.arange(start[b], start[b + 1])
                assert not np.any(r.kind[q] == LEFT)
                same = q[(r.signature[q] == r.signature[node]).all(axis=1)
                         & ((r.side[q] == 0) | (r.side[q] != -r.side[node]))]  # not across its own plane
                assert np.all((r.rank[same] >= 0) & (r.rank[same] < r.rank[node]))


def test_resolved_nodes_keep_their_signature_along_the_exit(corner_paving, retraction, corner_geometry):
    """Property test against independent certified solves: a point of a resolved node (of a signature no other node
    of its leaf has) keeps the node's signature on the segment along the exit direction up to the face: fold
    pieces, window pieces, pair patterns, cusp sides that leave along a segment (only pairs dying on the
    one-root side, only born on the three-root side), and cusp patterns (both kinds of window kept at once)."""
    r, p = retraction, corner_paving.paving
    rng = np.random.default_rng(11)
    checked = {name: 0 for name in SOURCES}
    straight = np.zeros(r.leaf.size, dtype=bool)  # nodes that left along a segment (cusp sides may use lifted paths)
    resolved = np.flatnonzero(r.rank > 0)
    straight[resolved] = np.abs(r.option_direction[r.exit[resolved]]).sum(axis=1) > 0
    for source in (1, 2, 3, 4, SOURCES.index("cusp_pattern")):
        nodes = np.flatnonzero((r.source == source) & (r.rank > 0) & straight)
        rng.shuffle(nodes)
        for node in nodes[:150]:
            a = r.leaf[node]
            mates = np.flatnonzero(r.leaf == a)
            if ((r.signature[mates] == r.signature[node]).all(axis=1)).sum() != 1:
                continue
            for _ in range(6):  # a point of the node: one of the node's signature (no other node of the leaf has it)
                x = p.lo[a] + rng.random(3) * (p.hi[a] - p.lo[a])
                if _signature(corner_geometry, x) == tuple(r.signature[node]):
                    break
            else:
                continue
            e = r.option_direction[r.exit[node]]  # a straight retraction: the segment along e up to the box's boundary
            reach = np.min(np.where(e > 0, (p.hi[a] - x) / np.where(e > 0, e, 1), np.inf))
            reach = min(reach, np.min(np.where(e < 0, (p.lo[a] - x) / np.where(e < 0, e, -1), np.inf)))
            assert np.isfinite(reach) and reach >= 0
            for t in (0.25, 0.5, 0.75, 1.0):
                y = np.clip(x + t * reach * e, p.lo[a], p.hi[a])
                got = _signature(corner_geometry, y)
                assert got is None or got == tuple(r.signature[node]), (SOURCES[source], node, y)
            checked[SOURCES[source]] += 1
    assert checked["fold_piece"] >= 10 and checked["window_piece"] >= 2 and checked["pair_pattern"] >= 20, checked
    assert checked["cusp_side"] >= 10, checked  # straight ways of cusp sides (solve.window_cusp.cusp_direction_signs)
    assert checked["cusp_pattern"] >= 10, checked  # a cusp side and pair patterns kept by one segment


def test_fold_pieces_leave_sideways_where_the_sheet_keeps_them(corner_paving, retraction, corner_geometry):
    """Property test against independent certified solves: from a point of a fold piece (its signature, which
    the other piece of the box does not have), the segment along each sideways way (the sheet's slope proved)
    keeps the piece's signature up to the face.  Reversing the slope signs makes it fail."""
    r, p = retraction, corner_paving.paving
    k = corner_paving.pieces.models.axis
    axis_of = np.full(len(p.level), -1)
    axis_of[corner_paving.pieces.box] = k
    opt = np.flatnonzero(r.source[r.option_node] == SOURCES.index("fold_piece"))
    face = np.argmax(r.option_faces[opt], axis=1)
    sideways = opt[face // 2 != axis_of[r.leaf[r.option_node[opt]]]]
    assert sideways.size > 50
    rng = np.random.default_rng(23)
    rng.shuffle(sideways)
    checked = 0
    for o in sideways[:320]:
        node = r.option_node[o]
        a = r.leaf[node]
        for _ in range(8):
            x = p.lo[a] + rng.random(3) * (p.hi[a] - p.lo[a])
            if _signature(corner_geometry, x) == tuple(r.signature[node]):
                break
        else:
            continue
        e = r.option_direction[o]
        ax = int(np.flatnonzero(e)[0])
        end = p.hi[a, ax] if e[ax] > 0 else p.lo[a, ax]
        for t in (0.2, 0.4, 0.6, 0.8, 1.0):
            y = x.copy()
            y[ax] = x[ax] + t * (end - x[ax])
            got = _signature(corner_geometry, y)
            assert got is None or got == tuple(r.signature[node]), (node, x, y)
        checked += 1
        if checked == 30:
            break
    assert checked >= 20, checked


def test_plane_side_nodes_keep_their_side_and_signature_along_the_exit(corner_paving, retraction, corner_geometry):
    """Property test: a point of a resolved node on one side of a plane of double roots (the 50-digit sign of
    s(phi_D; rho^2) at the zero phi_D of D), of the node's signature (no other node of its leaf and side has
    it), keeps its side and its signature along the exit segment up to the face."""
    r, p = retraction, corner_paving.paving
    mpmath.mp.dps = 50
    d_coeff = _d_mp(corner_geometry)
    zeros = [mpmath.findroot(lambda x: _mp_value(d_coeff, x), mpmath.mpf(float(z))) for z in d_zeros(corner_geometry)]
    sided = np.flatnonzero((r.side != 0) & (r.rank > 0))
    assert sided.size >= 10
    rng = np.random.default_rng(17)
    rng.shuffle(sided)
    checked = 0
    for node in sided[:60]:
        a, side = r.leaf[node], int(r.side[node])
        phi_d = zeros[abs(side) - 1]
        mates = (r.leaf == a) & (r.side == side) & (r.signature == r.signature[node]).all(axis=1)
        if mates.sum() != 1:
            continue
        for _ in range(8):
            x = p.lo[a] + rng.random(3) * (p.hi[a] - p.lo[a])
            if (mpmath.sign(_s_mp(corner_geometry, x, phi_d)) == np.sign(side)
                    and _signature(corner_geometry, x) == tuple(r.signature[node])):
                break
        else:
            continue
        e = r.option_direction[r.exit[node]]
        assert np.any(e != 0)  # a straight path: sides are kept only along segments
        reach = np.min(np.where(e > 0, (p.hi[a] - x) / np.where(e > 0, e, 1), np.inf))
        reach = min(reach, np.min(np.where(e < 0, (p.lo[a] - x) / np.where(e < 0, e, -1), np.inf)))
        for t in (0.5, 1.0):
            y = np.clip(x + t * reach * e, p.lo[a], p.hi[a])
            assert mpmath.sign(_s_mp(corner_geometry, y, phi_d)) == np.sign(side), (node, y)
            got = _signature(corner_geometry, y)
            assert got is None or got == tuple(r.signature[node]), (node, y)
        checked += 1
    assert checked >= 5, checked


def _cube(depth: int):
    n = 2 ** depth
    ijk = np.array([(i, j, k) for i in range(n) for j in range(n) for k in range(n)], dtype=np.int64)
    return SimpleNamespace(level=np.full(len(ijk), depth), ijk=ijk, depth=depth)


def _faces(*which):
    out = np.zeros(6, dtype=bool)
    out[list(which)] = True
    return out


def test_the_fixed_point_on_a_small_tiling():
    """A row of boxes along x retracting towards a sink at x = 0 is ranked 1, 2, 3; a LEFT box or a box of
    unknown signature blocks; a face on the border never counts; two boxes retracting into each other stay
    unresolved; a neighbour of another signature does not block."""
    t = _cube(2)
    n = len(t.ijk)
    at = {tuple(v): i for i, v in enumerate(t.ijk)}
    sig = np.ones((n, 3), dtype=np.int64)
    kind = np.full(n, SINK, dtype=np.int8)
    faces = np.zeros((n, 6), dtype=bool)
    row = [at[(i, 0, 0)] for i in range(4)]
    kind[row[1:]] = RET
    faces[row[1:]] = _faces(0)  # towards -x
    # a cycle: (1, 2, 0) retracts +x into (2, 2, 0), which retracts -x back
    c1, c2 = at[(1, 2, 0)], at[(2, 2, 0)]
    kind[[c1, c2]] = RET
    faces[c1], faces[c2] = _faces(1), _faces(0)
    # the border: (0, 3, 3) retracts only through its -x face, which is on the border
    b = at[(0, 3, 3)]
    kind[b] = RET
    faces[b] = _faces(0)
    # a box behind a LEFT leaf, one behind a neighbour of another signature
    left, behind = at[(0, 1, 3)], at[(1, 1, 3)]
    kind[left], sig[left] = LEFT, -1
    kind[behind], faces[behind] = RET, _faces(0)
    other, past = at[(0, 3, 1)], at[(1, 3, 1)]
    kind[other] = RET
    sig[other] = (3, 2, 1)  # never resolved (its only face is on the border) but of another signature
    faces[other] = _faces(0)
    kind[past], faces[past] = RET, _faces(0)
    leaf = np.arange(n)
    opt_node, opt_face = np.nonzero(faces & (kind == RET)[:, None])
    rank, exit_ = retraction_ranks(t, leaf, sig, kind, opt_node, np.eye(6, dtype=bool)[opt_face])
    assert list(rank[row]) == [0, 1, 2, 3]
    assert all(opt_node[exit_[b]] == b and opt_face[exit_[b]] == 0 for b in row[1:])  # through the -x face
    assert rank[c1] == -1 and rank[c2] == -1
    assert rank[b] == -1 and rank[other] == -1
    assert rank[left] == -1 and rank[behind] == -1
    assert rank[past] == 1
    # with the LEFT leaf made a sink of the same signature, the box behind it resolves
    kind[left], sig[left] = SINK, 1
    rank, _ = retraction_ranks(t, leaf, sig, kind, opt_node, np.eye(6, dtype=bool)[opt_face])
    assert rank[behind] == 1
    # an option of two faces needs both: (2, 1, 3) through -x (the resolved (1, 1, 3)) and +x (unresolved (3, 1, 3))
    two = at[(2, 1, 3)]
    kind[two] = RET
    kind[at[(3, 1, 3)]], faces[at[(3, 1, 3)]] = RET, _faces(1)  # its only face on the border
    both = np.array([[True, True, False, False, False, False]])
    rank, _ = retraction_ranks(t, leaf, sig, kind, np.r_[opt_node, two], np.r_[np.eye(6, dtype=bool)[opt_face], both])
    assert rank[at[(1, 1, 3)]] == 1 and rank[two] == -1
    # the cycle's two boxes on opposite sides of one plane of double roots do not wait for each other; on sides
    # of two different planes they do
    side = np.zeros(n, dtype=np.int8)
    for s1, s2, resolved in ((1, -1, True), (-2, 2, True), (1, 2, False), (1, 1, False)):
        side[c1], side[c2] = s1, s2
        rank, _ = retraction_ranks(t, leaf, sig, kind, opt_node, np.eye(6, dtype=bool)[opt_face], side)
        assert (rank[c1] == 1 and rank[c2] == 1) if resolved else (rank[c1] == -1 and rank[c2] == -1)


def test_the_nodes_of_a_leaf_cover_the_signatures_of_its_points(corner_paving, retraction, corner_geometry):
    """Property test against independent certified solves: at sampled points of leaves with cusp sides or
    signature-only nodes (including those read from unions of runs of degree 4 to 6), of leaves with pair
    patterns and of leaves with a cusp window beside pair windows (cusp patterns), the signature is one of the
    leaf's nodes' (a node set that missed it would let a neighbour of that signature retract through the leaf
    without waiting).  Fails if a union's crossing root or its pairs are
    dropped from the signature-only nodes, or its lifted sides are added with the wrong aspects."""
    r, p = retraction, corner_paving.paving
    rng = np.random.default_rng(17)
    start = np.searchsorted(r.leaf, np.arange(len(p.lo) + 1))
    checked = {}
    for source in ("cusp_side", "signature_only", "pair_pattern", "cusp_pattern"):
        leaves = np.unique(r.leaf[r.source == SOURCES.index(source)])
        for a in rng.choice(leaves, min(80, leaves.size), replace=False):
            sigs = {tuple(s) for s in r.signature[start[a]:start[a + 1]]}
            for _ in range(2):
                got = _signature(corner_geometry, p.lo[a] + rng.random(3) * (p.hi[a] - p.lo[a]))
                if got is not None:
                    assert got in sigs, (source, a, got, sorted(sigs))
                    checked[source] = checked.get(source, 0) + 1
    assert all(checked.get(s, 0) >= 60 for s in ("cusp_side", "signature_only", "pair_pattern", "cusp_pattern")), checked


def test_the_summary_reports_the_retraction(corner_paving, retraction):
    from dataclasses import replace

    block = replace(corner_paving, retraction=retraction).open_places()["retraction"]
    assert block["closed"] is False
    assert block["nodes"] == retraction.leaf.size
    assert block["sinks"] + block["resolved"] + block["unresolved"] == block["nodes"]
    assert sum(v["unresolved"] for v in block["by_source"].values()) == block["unresolved"]
    sided = retraction.side != 0
    assert block["plane_sides"]["nodes"] == sided.sum() > 0
    assert block["plane_sides"]["unresolved"] == (sided & (retraction.rank < 0)).sum()
    assert 0 < block["volume_unresolved"] <= corner_paving.paving.volume().sum()
    assert "retraction" not in corner_paving.open_places()


def _window_count(geometry, point, lo: np.ndarray, hi: np.ndarray) -> int | None:
    """The number of solutions at an exact point whose phi lies in one of the pieces [lo_j, hi_j] (mod 2 pi; a
    window's pieces may run across -pi), by an independent certified solve; None where it does not complete."""
    res = solve(geometry, [Fraction(float(x)) for x in point])
    if not res.complete or any(s.status != "unique" for s in res.solutions):
        return None
    phis = [float(np.mean(s.box[2])) for s in res.solutions]
    return sum(any(a <= p + k * 2 * np.pi <= b for k in (-1, 0, 1) for a, b in zip(lo, hi)) for p in phis)


def test_signs_at_the_roots_keep_the_window_status_along_e(corner_paving, corner_geometry):
    """Property test of pair_direction_signs(at_roots=True) (proofs/lemma-joint-retraction.md, pattern nodes): where
    it proves a direction the signs over whole pieces did not, or calls a window STEADY, the number of solutions in
    the window (an independent certified solve) stays the same from a point of the box along e up to its boundary:
    along e where the window is empty and its sign is +1 or it holds two roots and its sign is -1, along -e in the
    other cases, either way where STEADY; for a half of a window cut at phi_D, as long as the walk keeps its side of
    the plane s(phi_D; r) = 0, as the nodes do.  Signs over whole pieces are never changed, only added to."""
    from intervalkin.solve.window_fold import STEADY, pair_direction_signs, pair_windows
    from intervalkin.solve.window_plane import split_at_zeros_of_d
    from intervalkin.solve.window_union import joined_windows
    from intervalkin.space.retraction_nodes import DIRECTIONS

    win = corner_paving.windows
    split = split_at_zeros_of_d(corner_geometry, joined_windows(win.models))
    models = split.models
    # a sample of the boxes with a pair window beside a zero of D, where the signs at the roots tell most
    apart = np.min([np.maximum(np.maximum(models.piece_lo - z, z - models.piece_hi), 0)
                    for z in d_zeros(corner_geometry)], axis=0)  # each piece's distance to the zeros of D
    gap = np.full(len(models.degree), np.inf)
    np.minimum.at(gap, models.piece_window, apart)
    near = np.unique(models.window_box[pair_windows(models) & (gap < 0.1) & models.ok[models.window_box]])
    rng = np.random.default_rng(17)
    rows = np.sort(rng.choice(near, size=min(near.size, 2500), replace=False))
    old, _ = pair_direction_signs(corner_geometry, models, rows, DIRECTIONS, at_roots=False)
    new, _ = pair_direction_signs(corner_geometry, models, rows, DIRECTIONS, at_roots=True)
    assert np.all((old == 0) | (new == old) | (new == STEADY))
    gained = np.flatnonzero(pair_windows(models) & ((old == 0) & (new != 0)).any(axis=1))
    assert gained.size >= 100
    rng.shuffle(gained)
    checked = steady = 0
    for w in gained[:60]:
        box = models.boxes[models.window_box[w]]
        c = rng.choice(np.flatnonzero((old[w] == 0) & (new[w] != 0)))
        x = box[:, 0] + rng.random(3) * (box[:, 1] - box[:, 0])
        own = models.piece_window == w
        pieces = models.piece_lo[own], models.piece_hi[own]
        status = _window_count(corner_geometry, x, *pieces)
        if status is None:
            continue
        assert status in (0, 2)
        way = 1 if new[w, c] == STEADY or (new[w, c] == 1) == (status == 0) else -1
        e = way * DIRECTIONS[c].astype(float)
        reach = min(np.min(np.where(e > 0, (box[:, 1] - x) / np.where(e > 0, e, 1), np.inf)),
                    np.min(np.where(e < 0, (box[:, 0] - x) / np.where(e < 0, e, -1), np.inf)))
        # a half of a window cut at phi_D speaks for its box's points on one side of the plane s(phi_D; r) = 0 (its
        # nodes only move along directions that keep their side): the walk stops where it would cross the plane
        cut = split.plane[models.window_box[w]]
        phi_d = d_zeros(corner_geometry)[cut - 1] if cut else None
        side = mpmath.sign(_s_mp(corner_geometry, x, phi_d)) if cut else 0
        for t in (0.2, 0.4, 0.6, 0.8, 1.0):
            y = np.clip(x + t * reach * e, box[:, 0], box[:, 1])
            if cut and mpmath.sign(_s_mp(corner_geometry, y, phi_d)) != side:
                break
            got = _window_count(corner_geometry, y, *pieces)
            assert got is None or got == status, (w, DIRECTIONS[c], way, t, status, got)
        checked += 1
        steady += bool(new[w, c] == STEADY)
    assert checked >= 40, checked


def test_the_direction_signs_split_between_processes_are_the_serial_ones(corner_paving, corner_geometry, monkeypatch):
    """pair_direction_signs cut into parts for two processes returns exactly the serial arrays (each part runs on its
    boxes' models alone, and the windows are put back where take() found them).  Rows are given unsorted and with a
    box twice, as a caller may."""
    from intervalkin.core.workers import Workers
    from intervalkin.solve import window_fold
    from intervalkin.solve.window_fold import pair_direction_signs, pair_windows
    from intervalkin.solve.window_plane import split_at_zeros_of_d
    from intervalkin.solve.window_union import joined_windows
    from intervalkin.space.retraction_nodes import DIRECTIONS

    models = split_at_zeros_of_d(corner_geometry, joined_windows(corner_paving.windows.models)).models
    boxes = np.unique(models.window_box[pair_windows(models) & models.ok[models.window_box]])
    rng = np.random.default_rng(5)
    rows = rng.choice(boxes, size=min(boxes.size, 300), replace=False)
    rows = np.r_[rows, rows[:1]]
    serial = pair_direction_signs(corner_geometry, models, rows, DIRECTIONS, at_roots=True)
    monkeypatch.setattr(window_fold, "MIN_PARALLEL_BOXES", 40)
    with Workers(2) as workers:
        parts = pair_direction_signs(corner_geometry, models, rows, DIRECTIONS, at_roots=True, workers=workers)
    assert (serial[0] != 0).sum() > 100  # signs were proved, so a misplaced window would show
    for a, b in zip(serial, parts):
        assert a.dtype == b.dtype and np.array_equal(a, b)
