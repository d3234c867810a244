"""Fold models of joint boxes (solve.fold_model) and their pieces (space.joint_pieces).

- points placed below or above the sheet of a fold box have the certified count of
  that piece's cell (independent complete solves at exact points), and the two pieces
  of one box differ by exactly two solutions (a fold);
- swapping the sides (a wrong model) is caught by that comparison;
- singular poses whose joint vector falls in a fold box lie in the model's pose box,
  and the sheet height there is inside the enclosed height;
- piece edges join only sets whose certified counts agree.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from intervalkin.core.interval import PI_LO
from intervalkin.kinematics.formulas import approx_det_a, approx_inverse_kinematics
from intervalkin.solve.dkp import solve
from intervalkin.solve.fold_model import side_of
from intervalkin.solve.fold_side import placed_side
from tests.solve.shared import split_of


@pytest.fixture(scope="module")
def folds(fold_models_5):
    """``pave_joint_space(paper_geometry, 5, join_levels=0, fold=True, model_levels=1)`` (tests/conftest.py)."""
    jp = fold_models_5
    assert jp.pieces is not None and len(jp.pieces) >= 100, "depth 5 gives a few hundred fold boxes"
    return jp


def _random_points(jp, rows, rng, per_box):
    lo, hi = jp.paving.lo[jp.pieces.box[rows]], jp.paving.hi[jp.pieces.box[rows]]
    t = np.repeat(rows, per_box)
    u = rng.random((len(t), 3))
    q = np.repeat(lo, per_box, axis=0) + u * np.repeat(hi - lo, per_box, axis=0)
    return t, q


def _placed_solves(jp, geometry, rng, boxes=40, per_box=5):
    rows = rng.choice(len(jp.pieces), size=min(boxes, len(jp.pieces)), replace=False)
    t, q = _random_points(jp, rows, rng, per_box)
    side = side_of(geometry, jp.pieces.models, t, q)
    out = []
    for row, point, s in zip(t, q, side):
        if s == 0:
            continue
        out.append((int(row), int(s), split_of(solve(geometry, [Fraction(float(v)) for v in point]))))
    return out


def test_points_of_a_piece_have_the_piece_count(folds, paper_geometry):
    rng = np.random.default_rng(3)
    placed = _placed_solves(folds, paper_geometry, rng)
    assert len(placed) >= 150, "the side test places nearly every random point"
    cells = {c.id: c for c in folds.cells}
    pc = folds.piece_cell.reshape(-1, 2)
    compared = 0
    for row, s, split in placed:
        cid = int(pc[row, int(s > 0)])
        if cid >= 0 and cells[cid].count >= 0:
            assert cells[cid].signature == split, (row, s, split, cells[cid])
            compared += 1
    assert compared >= 50


def test_the_two_pieces_differ_by_two_solutions(folds, paper_geometry):
    rng = np.random.default_rng(4)
    by_box: dict[int, dict[int, set]] = {}
    for row, s, split in _placed_solves(folds, paper_geometry, rng, boxes=30, per_box=8):
        by_box.setdefault(row, {}).setdefault(s, set()).add(split)
    both = 0
    for sides in by_box.values():
        for splits in sides.values():
            assert len(splits) == 1, sides  # one piece, one count
        if len(sides) == 2:
            (a,), (b,) = sides[-1], sides[1]
            assert abs(a[0] - b[0]) == 2 and abs(a[1] - b[1]) == 1 and abs(a[2] - b[2]) == 1, sides
            both += 1
    assert both >= 5


def test_a_wrong_side_is_caught(folds, paper_geometry):
    """Mutation: a model whose sides were swapped disagrees with the certified solves."""
    rng = np.random.default_rng(3)
    cells = {c.id: c for c in folds.cells}
    pc = folds.piece_cell.reshape(-1, 2)
    wrong = 0
    for row, s, split in _placed_solves(folds, paper_geometry, rng, boxes=20):
        cid = int(pc[row, int(s < 0)])  # the other piece
        if cid >= 0 and cells[cid].count >= 0:
            wrong += cells[cid].signature != split
    assert wrong >= 10


def test_points_placed_by_the_tight_test_are_on_their_side(folds, paper_geometry):
    """The tight side test (the preconditioner taken again over the shrunk pose box) places points the quick
    one leaves undecided; checked against independent complete solves: in each box every point placed below
    has one signature, every point placed above another, two solutions apart.  Swapping the sides the tight
    test adds mixes them and fails."""
    rng = np.random.default_rng(8)
    rows = rng.choice(len(folds.pieces), size=min(120, len(folds.pieces)), replace=False)
    t, q = _random_points(folds, rows, rng, 12)
    quick = side_of(paper_geometry, folds.pieces.models, t, q)
    side = placed_side(paper_geometry, folds.pieces.models, t, q)
    assert np.all((quick == 0) | (quick == side))  # the tight test only adds placements
    tight = (quick == 0) & (side != 0)
    assert tight.sum() >= 30, int(tight.sum())
    seen: dict[tuple[int, int], set] = {}
    for row in np.unique(t[tight]):
        at = np.flatnonzero(t == row)
        at = at[side[at] != 0]
        if not ((side[at] < 0).any() and (side[at] > 0).any()):
            continue
        for i in at[:6]:
            split = split_of(solve(paper_geometry, [Fraction(float(v)) for v in q[i]]))
            seen.setdefault((int(row), int(side[i])), set()).add(split)
    boxes = {row for row, _ in seen if (row, -1) in seen and (row, 1) in seen}
    assert len(boxes) >= 5, len(boxes)
    for row in boxes:
        below, above = seen[(row, -1)], seen[(row, 1)]
        assert len(below) == 1 and len(above) == 1, (row, below, above)
        (b,), (a,) = below, above
        assert abs(a[0] - b[0]) == 2, (row, b, a)


def _singular_poses(geometry, boxes, rng, per_box):
    """Float poses within 1e-12 of a sign change of det A along y, drawn in the given pose boxes (m, 3, 2)."""
    out = []
    for P in boxes:
        for _ in range(per_box):
            x, phi = rng.uniform(P[0, 0], P[0, 1]), rng.uniform(P[2, 0], P[2, 1])
            ys = np.linspace(P[1, 0], P[1, 1], 41)
            det = approx_det_a(geometry, np.stack([np.full_like(ys, x), ys, np.full_like(ys, phi)], axis=1))
            for c in np.flatnonzero(np.sign(det[:-1]) * np.sign(det[1:]) < 0):
                a, b, da = ys[c], ys[c + 1], det[c]
                for _ in range(50):
                    m = 0.5 * (a + b)
                    dm = approx_det_a(geometry, np.array([[x, m, phi]]))[0]
                    a, b, da = (m, b, dm) if np.sign(dm) == np.sign(da) else (a, m, da)
                out.append((x, 0.5 * (a + b), phi))
    return np.array(out)


def test_model_pose_box_holds_every_singular_pose_of_the_box(folds, paper_geometry):
    rng = np.random.default_rng(8)
    models = folds.pieces.models
    X = _singular_poses(paper_geometry, models.pose[rng.choice(len(models), 60, replace=False)], rng, 10)
    q = approx_inverse_kinematics(paper_geometry, X)
    leaf = folds.paving.locate_boxes(np.stack([q, q], axis=-1))
    row = np.full(len(folds.cell), -1)
    row[folds.pieces.box] = np.arange(len(folds.pieces))
    hits = 0
    for x, v, lf in zip(X, q, leaf):
        if lf < 0 or row[lf] < 0:
            continue
        t = row[lf]
        P = models.pose[t]
        phis = x[2] + 2 * PI_LO * np.array([-1, 0, 1])
        tol = 1e-9
        inside_xy = P[0, 0] - tol <= x[0] <= P[0, 1] + tol and P[1, 0] - tol <= x[1] <= P[1, 1] + tol
        inside_phi = np.any((P[2, 0] - tol <= phis) & (phis <= P[2, 1] + tol))
        assert inside_xy and inside_phi, (x, P)
        k = models.axis[t]
        assert models.height.lo[t] - 1e-6 <= v[k] <= models.height.hi[t] + 1e-6
        hits += 1
    assert hits >= 20


def test_piece_edges_join_sets_of_one_count(folds):
    """Every edge of the piece graph joins two nodes of one cell (or two pieces joined to no clear box, -1)."""
    n = len(folds.cell)
    node_cell = np.concatenate([folds.cell, folds.piece_cell])
    a, b = folds.pieces.edges
    assert a.size > 0
    assert np.all(node_cell[a] == node_cell[b])
    assert np.count_nonzero(node_cell[a] >= 0) > a.size // 4
    assert np.all(a < n + 2 * len(folds.pieces)) and np.all(b >= n)  # sorted pairs: the larger end is a piece


def test_lines_along_the_axis_cross_the_sheet_at_most_once(folds, paper_geometry):
    """The graph claim: along a line of a fold box parallel to its axis k, the certified count
    changes at most once, from the count below the sheet to the count above it."""
    rng = np.random.default_rng(12)
    models = folds.pieces.models
    rows = rng.choice(len(models), size=12, replace=False)
    crossings = 0
    for t in rows:
        lo, hi = folds.paving.lo[folds.pieces.box[t]], folds.paving.hi[folds.pieces.box[t]]
        k = int(models.axis[t])
        for _ in range(2):
            base = lo + rng.random(3) * (hi - lo)
            zs = np.linspace(lo[k], hi[k], 17)
            q = np.repeat(base[None], len(zs), axis=0)
            q[:, k] = zs
            side = side_of(paper_geometry, models, np.full(len(zs), t), q)
            splits = [split_of(solve(paper_geometry, [Fraction(float(v)) for v in p])) for p in q]
            changes = sum(1 for a, b in zip(splits, splits[1:]) if a != b)
            assert changes <= 1, (t, k, splits)
            crossings += changes
            placed = [(s, sp) for s, sp in zip(side, splits) if s != 0]
            assert all(s1 <= s2 for (s1, _), (s2, _) in zip(placed, placed[1:])), side  # below, then above
            for s in (-1, 1):
                assert len({sp for si, sp in placed if si == s}) <= 1, (t, side, splits)
    assert crossings >= 3
