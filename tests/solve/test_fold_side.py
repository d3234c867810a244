"""The side of the extra pair and the empty pieces of fold boxes (solve.fold_side), against certified solves.

On the depth-5 fold paving of the paper's manipulator (``fold_paving``):
- where a side s is proved, a point placed below the sheet and one placed above (side test)
  have certified signatures differing by exactly s (2, 1, 1);
- where a piece is proved empty, no point of a grid over the box is placed in it;
- mutation: with the sides negated, the same comparison fails;
- where a piece is proved empty by parts, the sheet's height found by float Newton at a grid of the
  parameter rectangle lies beyond the box's face on that side, and no grid point is placed in the piece.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from intervalkin.solve.dkp import solve
from intervalkin.solve.fold_model import side_of
from intervalkin.kinematics.formulas import approx_det_a, approx_inverse_kinematics
from intervalkin.solve.fold_side import PAIR, empty_by_parts, pair_sides, placed_side
from tests.solve.shared import split_of

_GRID = np.array([(a, b, c) for a in (0.1, 0.5, 0.9) for b in (0.1, 0.5, 0.9) for c in (0.05, 0.3, 0.7, 0.95)])


@pytest.fixture(scope="module")
def sides(paper_geometry, fold_paving):
    pc = fold_paving.pieces
    R = np.stack([fold_paving.paving.lo[pc.box], fold_paving.paving.hi[pc.box]], axis=-1)
    return R, pair_sides(paper_geometry, R, pc.models)


def _placed(geometry, models, t, R):
    """Grid points of box t and their sides (-1 below, +1 above, 0 not placed)."""
    q = R[t, :, 0] + _GRID * (R[t, :, 1] - R[t, :, 0])
    return q, side_of(geometry, models, np.full(len(q), t), q)


def _mismatches(geometry, models, R, side, rows):
    """(boxes compared, boxes whose two placed points' signatures differ by other than side * PAIR)."""
    compared = bad = 0
    for t in rows:
        q, s = _placed(geometry, models, t, R)
        if not ((s < 0).any() and (s > 0).any()):
            continue
        below = split_of(solve(geometry, [Fraction(float(v)) for v in q[s < 0][0]]))
        above = split_of(solve(geometry, [Fraction(float(v)) for v in q[s > 0][0]]))
        compared += 1
        bad += int(tuple(np.subtract(above, below)) != tuple(int(side[t]) * PAIR))
    return compared, bad


def test_proved_sides_match_certified_solves(paper_geometry, fold_paving, sides):
    R, fs = sides
    assert np.count_nonzero(fs.side) >= 0.8 * len(R), "most fold boxes get a proved side"
    rng = np.random.default_rng(3)
    rows = rng.choice(np.flatnonzero(fs.side != 0), size=40, replace=False)
    compared, bad = _mismatches(paper_geometry, fold_paving.pieces.models, R, fs.side, rows)
    assert bad == 0 and compared >= 25, (compared, bad)


def test_negated_sides_are_caught(paper_geometry, fold_paving, sides):
    R, fs = sides
    rows = np.flatnonzero(fs.side != 0)[:30]
    compared, bad = _mismatches(paper_geometry, fold_paving.pieces.models, R, -fs.side, rows)
    assert compared >= 10 and bad == compared


def test_no_point_is_placed_in_an_empty_piece(paper_geometry, fold_paving, sides):
    R, fs = sides
    rows = np.flatnonzero(fs.empty != 0)
    assert rows.size >= 20, rows.size
    placed = 0
    for t in rows[:200]:
        _, s = _placed(paper_geometry, fold_paving.pieces.models, t, R)
        assert not np.any(s == fs.empty[t]), (t, R[t], fs.empty[t])
        placed += int(np.count_nonzero(s))
    assert placed >= 1000, "the grid points do get placed (in the other piece)"


def _sheet_height(geometry, pose_box, k, p):
    """h(p) = rho_k(X*(p)) by float Newton on (rho_i^2 - p_i^2, rho_j^2 - p_j^2, det A) from the pose box's
    centre, with a finite-difference Jacobian (not certified: an independent check); None if it wanders off."""
    i, j = [a for a in range(3) if a != k]
    X = pose_box.mean(axis=1)

    def E(X):
        rho = approx_inverse_kinematics(geometry, X)
        return np.array([rho[i] ** 2 - p[0] ** 2, rho[j] ** 2 - p[1] ** 2, approx_det_a(geometry, X)])
    for _ in range(12):
        J = np.stack([(E(X + h) - E(X - h)) / 2e-7 for h in np.eye(3) * 1e-7], axis=1)
        step = np.linalg.solve(J, E(X))
        X = X - step
        if np.abs(step).max() < 1e-13:
            break
    if np.abs(E(X)).max() > 1e-8 or np.any(X < pose_box[:, 0] - 1e-9) or np.any(X > pose_box[:, 1] + 1e-9):
        return None
    return approx_inverse_kinematics(geometry, X)[k]


def test_pieces_proved_empty_by_parts_hold_no_sheet_point(paper_geometry, fold_paving, sides):
    """The parts' proof against float Newton: where the piece above is proved empty, h(p) >= hi_k at every point
    of a 5 x 5 grid of the parameter rectangle (corners included), and h(p) <= lo_k where the piece below is; and
    no grid point of the box is placed in it.  It proves pieces the monotone corner rule does not."""
    R, fs = sides
    pc = fold_paving.pieces
    t = np.repeat(np.arange(len(R)), 2)
    piece = np.tile([0, 1], len(R))
    proved = empty_by_parts(paper_geometry, R[t], pc.models.take(t), piece)
    assert proved.sum() >= 40, int(proved.sum())
    new = proved & (fs.empty[t] != np.where(piece == 1, 1, -1))
    assert new.sum() >= 5, int(new.sum())
    rng = np.random.default_rng(12)
    checked = 0
    f = np.linspace(0.0, 1.0, 5)
    for r in rng.permutation(np.flatnonzero(proved))[:24]:
        box, k, side = t[r], int(pc.models.axis[t[r]]), int(piece[r])
        i, j = [a for a in range(3) if a != k]
        for a in f:
            for b in f:
                p = (R[box, i, 0] + a * (R[box, i, 1] - R[box, i, 0]), R[box, j, 0] + b * (R[box, j, 1] - R[box, j, 0]))
                h = _sheet_height(paper_geometry, pc.models.pose[box], k, p)
                if h is None:
                    continue
                assert (h >= R[box, k, 1] - 1e-9) if side else (h <= R[box, k, 0] + 1e-9), (box, side, p, h)
                checked += 1
        q = R[box, :, 0] + _GRID * (R[box, :, 1] - R[box, :, 0])
        placed = placed_side(paper_geometry, pc.models, np.full(len(q), box), q)
        assert not np.any(placed == (1 if side else -1)), (box, side)
    assert checked >= 300, checked
