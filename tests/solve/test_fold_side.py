"""The side of the extra pair and the empty pieces of fold boxes (solve.fold_side), against certified solves.

On the depth-5 fold paving of the paper's manipulator (``fold_paving``):
- where a side s is proved, a point placed below the sheet and one placed above (side test)
  have certified signatures differing by exactly s (2, 1, 1);
- where a piece is proved empty, no point of a grid over the box is placed in it;
- mutation: with the sides negated, the same comparison fails.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from intervalkin.solve.dkp import solve
from intervalkin.solve.fold_model import side_of
from intervalkin.solve.fold_side import PAIR, pair_sides
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
