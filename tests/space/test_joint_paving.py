"""The direct joint-space paving (space.joint_paving): clear boxes, cells, certified counts.

- every cell's count and aspect split hold at random exact points of random boxes
  of the cell (independent certified solves): a wrong clear label or a wrong
  component would show as a different count;
- cells are unions of face-adjacent clear boxes: components recomputed with
  networkx from a brute-force adjacency agree;
- the boxes tile the joint box; the npz columns have the documented shapes;
- joining paths run through undecided boxes between cells of one signature only;
- the large cells and their certified counts are the same at two depths.
"""

from __future__ import annotations

from fractions import Fraction

import networkx as nx
import numpy as np
import pytest

from intervalkin.paving.adjacency import shares_face_bruteforce
from intervalkin.paving.labels import Label
from intervalkin.solve.dkp import solve
from intervalkin.space.joint_cells import JointSpaceCell, joining_paths
from intervalkin.space.joint_paving import joint_domain, pave_joint_space


@pytest.fixture(scope="module")
def joint4(joint_paving_4):
    """``pave_joint_space(paper_geometry, 4)`` (tests/conftest.py, shared with app/test_figures.py)."""
    return joint_paving_4


def test_counts_hold_inside_the_cells(joint4, paper_geometry):
    rng = np.random.default_rng(5)
    p = joint4.paving
    checked = 0
    for c in joint4.cells:
        assert c.count >= 0 and c.count == c.n_wa1 + c.n_wa2 and c.count % 2 == 0
        members = np.flatnonzero(joint4.cell == c.id)
        for k in rng.choice(members, size=min(2, len(members)), replace=False):
            q = [Fraction(float(p.lo[k, i])) + Fraction(int(rng.integers(0, 101)), 100)
                 * (Fraction(float(p.hi[k, i])) - Fraction(float(p.lo[k, i]))) for i in range(3)]
            res = solve(paper_geometry, q)
            assert res.complete, (q, res.completeness_reason)
            n1 = sum(1 for s in res.solutions if s.aspect == "WA1")
            assert (res.count, n1, res.count - n1) == (c.count, c.n_wa1, c.n_wa2), (c, q)
            checked += 1
    assert checked >= 10


def test_cells_are_components_of_clear_boxes(joint4):
    p = joint4.paving
    clear = np.flatnonzero(p.labels["clear"] == Label.INSIDE)
    sub = clear[:400]  # brute force on a sample: O(n^2)
    edges = shares_face_bruteforce(p.level[sub], p.ijk[sub], p.depth, periodic=(False, False, False))
    G = nx.Graph()
    G.add_nodes_from(range(len(sub)))
    G.add_edges_from(edges.T.tolist())
    for comp in nx.connected_components(G):
        assert len({int(joint4.cell[sub[i]]) for i in comp}) == 1
    assert np.all(joint4.cell[p.labels["clear"] != Label.INSIDE] == -1)
    assert np.all(joint4.cell[clear] >= 0)


def test_boxes_tile_the_joint_box(joint4, paper_geometry):
    dom = joint_domain(paper_geometry)
    total = float(np.prod(dom[:, 1] - dom[:, 0]))
    assert joint4.paving.volume().sum() == pytest.approx(total, rel=1e-12)
    assert 0.1 < joint4.certified_share() < 1.0
    cols = joint4.columns()
    n = len(joint4.paving)
    assert cols["lo"].shape == (n, 3) and cols["cell"].shape == (n,)
    assert set(np.unique(cols["count"][cols["cell"] < 0])) == {-1}


def _cell(i: int, sig: tuple[int, int, int]) -> JointSpaceCell:
    return JointSpaceCell(i, 1, 1.0, *sig, (Fraction(0), Fraction(0), Fraction(0)))


def test_joining_paths_follow_undecided_chains_between_equal_cells():
    # a row of boxes: cell 0 | three undecided | cell 1 | cell 2, with a side branch 6-7 off box 2
    cell = np.array([0, -1, -1, -1, 1, 2, -1, -1])
    edges = np.array([[0, 1, 2, 3, 4, 2, 6], [1, 2, 3, 4, 5, 6, 7]])
    same = joining_paths(edges, cell, [_cell(0, (4, 2, 2)), _cell(1, (4, 2, 2)), _cell(2, (6, 3, 3))])
    assert same.tolist() == [False, True, True, True, False, False, False, False]
    other = joining_paths(edges, cell, [_cell(0, (4, 2, 2)), _cell(1, (2, 1, 1)), _cell(2, (6, 3, 3))])
    assert not other.any()


def test_large_cells_are_the_same_one_level_finer(paper_geometry):
    """Cells holding >= 1 % of the joint box: the same certified signatures at depths 5 and 6.

    Smaller cells are not compared: slivers along the faces rho_i = 10 appear as the
    boxes get thinner (proofs and closing note of issue 13: the count is not yet exact).
    """
    coarse = pave_joint_space(paper_geometry, 5, fold=False)
    finer = pave_joint_space(paper_geometry, 6, fold=False)
    total = float(np.prod(np.diff(joint_domain(paper_geometry), axis=1)))

    def big(jp):
        return sorted(c.signature for c in jp.cells if c.volume >= 0.01 * total)

    assert big(coarse) == big(finer)
    assert len(big(finer)) >= 4
    # each large cell of the coarser paving lies inside a cell of the finer one with the same signature
    for c in coarse.cells:
        if c.volume >= 0.01 * total:
            cid = finer.cell_of(np.array([[float(v) for v in c.witness]]))[0]
            assert cid >= 0 and finer.cells[[x.id for x in finer.cells].index(cid)].signature == c.signature


def test_face_levels_refine_only_boxes_on_the_faces(paper_geometry):
    """face_levels: undecided boxes touching a face of the joint box go deeper; nothing else changes."""
    base = pave_joint_space(paper_geometry, 4, join_levels=0, fold=False)
    jp = pave_joint_space(paper_geometry, 4, join_levels=0, face_levels=2, fold=False)
    dom = joint_domain(paper_geometry)
    p = jp.paving
    deep = p.level > 4
    assert deep.any() and p.level.max() == 6
    # a deep box lies in a depth-4 box on a face: within 1/16 of the range from it
    step = (dom[:, 1] - dom[:, 0]) / 16
    touch = ((p.lo <= dom[:, 0] + step) | (p.hi >= dom[:, 1] - step)).any(axis=1)
    assert np.all(touch[deep])
    assert p.volume().sum() == pytest.approx(base.paving.volume().sum(), rel=1e-12)
    assert jp.certified_share() > base.certified_share() - 1e-9
