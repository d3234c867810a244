"""Hypothesis properties of the two remaining predicates: off the characteristic surfaces, and joint-cell counts.

(W and the det A sign have theirs in tests/paving/test_predicates.py.)  Each property draws a
labelled box or voxel of the shared small chain (workspace depth 7, joint grid 2**6,
regions depth 7) and a point in it, and re-derives the label without the paving:

* a box labelled "in an aspect and off S_c" lies in a piece whose joint cell is known:
  g(X), computed in arb at 128 bits, must fall in voxels of that very cell only, and an
  independent certified solve at (a rational point of) g(X) must return as many
  solutions as the cell's count, one of them X itself, with the aspect's det A sign;
* a voxel of a certified cell: a certified solve anywhere in the closed voxel (faces
  included) gives the cell's count and its split between the aspects.

Examples are derandomized, so a run is reproducible; shrinking reports the smallest
failing box or voxel.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from flint import arb, ctx
from hypothesis import given, settings, strategies as st

from intervalkin.kinematics.formulas import inverse_kinematics_arb
from intervalkin.paving.labels import Label
from intervalkin.solve.dkp import solve

ASPECT_SIGN = {"WA1": 1, "WA2": -1}
PROPERTY = settings(max_examples=200, deadline=None, derandomize=True, database=None)


@pytest.fixture(scope="module")
def off_sc_boxes(regions_chain):
    """Indices of the boxes certified in an aspect and off S_c, with that aspect (by name)."""
    _, ra = regions_chain
    p = ra.paving
    idx, names = [], []
    for name in ASPECT_SIGN:
        sel = np.flatnonzero((p.labels[name] == Label.INSIDE) & (p.labels["off_Sc"] == Label.INSIDE))
        idx.append(sel)
        names += [name] * sel.size
    idx = np.concatenate(idx)
    assert idx.size > 1000 and set(names) == set(ASPECT_SIGN)
    return idx, names


def _rational_in(ball) -> Fraction:
    """An exact rational inside an arb ball (its midpoint, exactly)."""
    return Fraction(ball.mid().str(40, radius=False))


@PROPERTY
@given(k=st.integers(0, 10**9), t=st.tuples(*[st.floats(0.0, 1.0)] * 3))
def test_off_sc_box_maps_into_one_cell_of_its_count(regions_chain, off_sc_boxes, paper_geometry, k, t):
    """X in a box labelled (aspect, off S_c): g(X) lies in the piece's cell only, and q = g(X) has that many
    certified solutions, X among them with the aspect's sign.

    Would catch an off-S_c label given to a box whose image meets the enclosure of g(S)
    (g(X) would reach a marked voxel or another cell), a piece attached to the wrong
    cell, or a box labelled in the wrong aspect.
    """
    jp, ra = regions_chain
    p = ra.paving
    idx, names = off_sc_boxes
    i = int(idx[k % idx.size])
    aspect = names[k % idx.size]
    assert ra.piece[i] >= 0
    cid = int(ra.piece_cell[ra.piece[i]])
    assert cid >= 0
    X = p.lo[i] + np.array(t) * (p.hi[i] - p.lo[i])
    with ctx.workprec(128):
        rho = inverse_kinematics_arb(paper_geometry, *(arb(float(v)) for v in X))
        lo = np.array([[float(r.lower()) for r in rho]])
        hi = np.array([[float(r.upper()) for r in rho]])
        q = tuple(_rational_in(r) for r in rho)
    ilo, ihi, inside = jp.index_ranges(lo, hi)
    assert inside[0]
    block = jp.cell[ilo[0, 0]:ihi[0, 0] + 1, ilo[0, 1]:ihi[0, 1] + 1, ilo[0, 2]:ihi[0, 2] + 1]
    assert np.all(block == cid), (i, X, np.unique(block))
    cell = jp.cells[cid]
    if cell.count < 0:  # an unsolved cell claims no count
        return
    res = solve(paper_geometry, q)
    assert res.complete
    assert res.count == cell.count
    near = [s for s in res.solutions if np.max(np.abs(s.midpoint - X)) < 1e-8]
    assert len(near) == 1 and near[0].det_sign == ASPECT_SIGN[aspect]


@pytest.fixture(scope="module")
def solved_cells(regions_chain):
    jp, _ = regions_chain
    cells = [c for c in jp.cells if c.count >= 0]
    assert {c.count for c in cells} >= {0, 2, 4, 6}
    return cells


_OFFSET = st.one_of(st.sampled_from([Fraction(0), Fraction(1), Fraction(1, 2)]),
                    st.fractions(min_value=0, max_value=1, max_denominator=1000))


@PROPERTY
@given(k=st.integers(0, 10**9), v=st.integers(0, 10**9), offset=st.tuples(_OFFSET, _OFFSET, _OFFSET))
def test_cell_count_holds_in_every_closed_voxel(regions_chain, solved_cells, paper_geometry, k, v, offset):
    """Any exact q in a closed voxel of a certified cell has exactly the cell's count, split as the cell says.

    Cells are drawn uniformly (small cells as often as big ones), voxels uniformly in the
    cell, and points on voxel faces and corners as well as inside.  Would catch a voxel
    left unmarked although g(S) crosses it (a count change inside a "cell"), two cells
    merged across the marked layer, or a cell whose witness solve was misread.
    """
    jp, _ = regions_chain
    cell = solved_cells[k % len(solved_cells)]
    vox = np.argwhere(jp.cell == cell.id)
    assert len(vox) == cell.n_voxels
    ijk = vox[v % len(vox)]
    q = tuple(jp.rho_min[i] + (int(ijk[i]) + offset[i]) * jp.step[i] for i in range(3))
    res = solve(paper_geometry, q)
    assert res.complete, res.completeness_reason
    n1 = sum(1 for s in res.solutions if s.det_sign > 0)
    assert (res.count, n1, res.count - n1) == (cell.count, cell.n_wa1, cell.n_wa2), (cell.id, q)
