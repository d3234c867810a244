"""Closed cells (space.joint_closure, proofs/lemma-closed-cell.md) on the session's depth-5 paving with windows.

- a small cell with no solution is proved closed, and no other cell is;
- segments from it to points just outside its leaves that carry the same signature pass through a
  point with another count (certified solver): it is not joined to them without crossing g(S);
- mutations: a neighbouring piece relabelled to another cell, a neighbouring fold box without its
  model: each opens the cell;
- the fold boxes' monotone directions (signs of w) hold along random lines, and reversed ones fail
  (a reversal is a wrong input the closure check itself could not see).
"""

from __future__ import annotations

import dataclasses
from fractions import Fraction

import numpy as np
import pytest

import intervalkin.space.joint_closure as jc
from intervalkin.solve.dkp import solve
from intervalkin.space.joint_closure import closed_cells
from tests.solve.shared import split_of


@pytest.fixture(scope="module")
def closure(fold_paving, paper_geometry):
    return closed_cells(fold_paving, paper_geometry)


def _closed_zero_cell(fold_paving, closure) -> int:
    sig = {c.id: c.signature for c in fold_paving.cells + fold_paving.fragments}
    zero = [c for c in closure.closed if sig[c] == (0, 0, 0)]
    assert zero, closure.open_contacts
    return zero[0]


def _neighbours(fold_paving, cid):
    cells, kind = jc.piece_cells(fold_paving)
    p = fold_paving.paving
    from intervalkin.paving.adjacency import shares_face
    e = shares_face(p.level, p.ijk, int(p.level.max()), periodic=(False, False, False))
    mine = (cells == cid).any(axis=1)
    pair = e[:, mine[e[0]] ^ mine[e[1]]]
    inside = np.where(mine[pair[0]], pair[0], pair[1])
    outside = np.where(mine[pair[0]], pair[1], pair[0])
    return cells, kind, inside, outside


def test_a_small_zero_cell_is_closed(fold_paving, paper_geometry, closure):
    cid = _closed_zero_cell(fold_paving, closure)
    assert all(closure.open_contacts[c] for c in closure.open_contacts if c not in closure.closed)
    big = max(fold_paving.cells, key=lambda c: c.volume)
    assert big.id not in closure.closed and closure.open_contacts[big.id]
    # the segment from its witness to the witness of every other cell with no solution passes through
    # points with solutions (certified solver): nothing joins them along it
    cells = {c.id: c for c in fold_paving.cells + fold_paving.fragments}
    a = np.array([float(v) for v in cells[cid].witness])
    others = [c for c in cells.values() if c.id != cid and c.signature == (0, 0, 0)]
    assert others
    for c in others:
        b = np.array([float(v) for v in c.witness])
        path = [split_of(solve(paper_geometry, [Fraction(float(v)) for v in a + t * (b - a)]))
                for t in np.linspace(0.05, 0.95, 19)]
        assert any(s != (0, 0, 0) for s in path), (a, b)
    # points of the leaves just outside the cell: those without solutions are not joined to it along the
    # segment to its witness either
    _, _, inside, outside = _neighbours(fold_paving, cid)
    p = fold_paving.paving
    rng = np.random.default_rng(3)
    out = np.unique(outside)[:60]
    pts = p.lo[out] + rng.uniform(0.05, 0.95, (len(out), 3)) * (p.hi[out] - p.lo[out])
    sig = [split_of(solve(paper_geometry, [Fraction(float(v)) for v in q])) for q in pts]
    assert len(sig) >= 20
    for q, s in zip(pts, sig):
        if s == (0, 0, 0):
            path = [split_of(solve(paper_geometry, [Fraction(float(v)) for v in q + t * (a - q)]))
                    for t in np.linspace(0.05, 0.95, 19)]
            assert any(x != (0, 0, 0) for x in path), q


def test_a_piece_put_in_another_cell_opens_it(fold_paving, paper_geometry, closure):
    cid = _closed_zero_cell(fold_paving, closure)
    other = next(c.id for c in fold_paving.cells if c.id != cid and c.signature == (0, 0, 0))
    cells, kind, inside, outside = _neighbours(fold_paving, cid)
    # a fold box beside the cell: its piece in the cell is said to be in another cell
    t = np.flatnonzero(np.isin(fold_paving.pieces.box, inside) & (fold_paving.piece_cell.reshape(-1, 2) == cid).any(axis=1))
    assert t.size
    pc = fold_paving.piece_cell.reshape(-1, 2).copy()
    pc[t[0]][pc[t[0]] == cid] = other
    bad = dataclasses.replace(fold_paving, piece_cell=pc.ravel())
    got = closed_cells(bad, paper_geometry)
    assert cid not in got.closed and other not in got.closed
    assert "two cells meet" in got.open_contacts[cid]


def test_an_incomplete_neighbour_opens_it(fold_paving, paper_geometry, closure, monkeypatch):
    cid = _closed_zero_cell(fold_paving, closure)
    cells, kind, inside, outside = _neighbours(fold_paving, cid)
    victim = outside[kind[outside] == 3][0]
    real = jc.piece_cells

    def stripped(jp):
        c, k = real(jp)
        k = k.copy()
        k[victim] = 0
        return c, k

    monkeypatch.setattr(jc, "piece_cells", stripped)
    got = closed_cells(fold_paving, paper_geometry)
    assert cid not in got.closed and "incomplete leaf" in got.open_contacts[cid]


def _direction_breaks(fold_paving, paper_geometry, directions: np.ndarray, lines: int) -> tuple[int, int]:
    """(lines breaking the rule, lines crossing the sheet): moving along an axis in the direction that keeps the
    piece below the sheet, the side test never goes from below (-1) back to above (+1)."""
    from intervalkin.solve.fold_model import side_of

    rng = np.random.default_rng(8)
    rows = rng.choice(np.flatnonzero((directions != 0).all(axis=1)), lines)
    axis = rng.integers(0, 3, lines)
    box = fold_paving.pieces.box[rows]
    lo, hi = fold_paving.paving.lo[box], fold_paving.paving.hi[box]
    t = np.linspace(0.0, 1.0, 9)
    base = lo + rng.uniform(size=(lines, 3)) * (hi - lo)
    pts = np.repeat(base[:, None, :], len(t), axis=1)
    idx = np.arange(lines)
    pts[idx[:, None], np.arange(len(t))[None, :], axis[:, None]] = (lo[idx, axis][:, None]
                                                                     + t[None, :] * (hi - lo)[idx, axis][:, None])
    side = side_of(paper_geometry, fold_paving.pieces.models, np.repeat(rows, len(t)), pts.reshape(-1, 3))
    side = side.reshape(lines, -1)
    bad = crossing = 0
    for s, r, k in zip(side, rows, axis):
        seq = s[s != 0] if directions[r, k] > 0 else s[s != 0][::-1]
        crossing += len(set(seq)) > 1
        below = np.flatnonzero(seq < 0)
        bad += bool(below.size and np.any(seq[below[0]:] > 0))
    return bad, crossing


def test_fold_directions_hold_along_lines_and_reversed_ones_fail(fold_paving, paper_geometry):
    """The directions that keep the piece below a fold sheet (from the signs of w) hold along random lines;
    reversed, they fail on every line that crosses the sheet."""
    d = jc._fold_directions(fold_paving, paper_geometry)
    assert (d != 0).all(axis=1).mean() > 0.5
    bad, crossing = _direction_breaks(fold_paving, paper_geometry, d, 400)
    assert bad == 0 and crossing >= 20
    bad, crossing = _direction_breaks(fold_paving, paper_geometry, (-d).astype(np.int8), 400)
    assert bad == crossing >= 20
