"""Basic regions and uniqueness domains: labels checked in arb, solutions separated as Theorem 1 says."""

from __future__ import annotations

from fractions import Fraction

import networkx as nx
import numpy as np
import pytest
from flint import arb, ctx

from intervalkin.core.errors import InputError
from intervalkin.kinematics.formulas import det_a_arb, inverse_kinematics_arb
from intervalkin.solve.dkp import solve
from intervalkin.paving.labels import Label
from intervalkin.space.basic_region import label_pose
from intervalkin.space.uniqueness_domain import uniqueness_domains



@pytest.fixture(scope="module")
def chain(regions_chain):
    return regions_chain



def _random_point_of_cell(jp, cid, rng) -> tuple:
    """An exact joint vector inside a random voxel of cell ``cid`` (same draws as before: voxel, then offsets)."""
    vox = np.argwhere(jp.cell == cid)
    v = vox[rng.integers(len(vox))]
    return tuple(jp.rho_min[i] + (int(v[i]) + Fraction(int(rng.integers(1, 99)), 100)) * jp.step[i] for i in range(3))

def test_region_boxes_hold_their_labels_in_arb(chain, paper_geometry):
    """Points of region boxes: det A has the aspect's sign, the legs are within limits, g(X) is in the cell."""
    jp, ra = chain
    p = ra.paving
    rng = np.random.default_rng(4)
    idx = np.flatnonzero(ra.region >= 0)
    pick = rng.choice(idx, size=min(400, idx.size), replace=False)
    old = ctx.prec
    ctx.prec = 128
    try:
        for i in pick:
            r = ra.regions[ra.region[i]]
            t = rng.uniform(0, 1, 3)
            X = p.lo[i] + t * (p.hi[i] - p.lo[i])
            x, y, phi = (arb(float(v)) for v in X)
            d = det_a_arb(paper_geometry, x, y, phi)
            assert (d > 0) if r.aspect == "WA1" else (d < 0)
            rho = inverse_kinematics_arb(paper_geometry, x, y, phi)
            assert all(v > 10 and v < 32 for v in rho)
            lo = np.array([[float(v.lower()) for v in rho]])
            hi = np.array([[float(v.upper()) for v in rho]])
            ilo, ihi, _ = jp.index_ranges(lo, hi)
            block = jp.cell[ilo[0, 0]:ihi[0, 0] + 1, ilo[0, 1]:ihi[0, 1] + 1, ilo[0, 2]:ihi[0, 2] + 1]
            assert np.all(block == r.cell)
    finally:
        ctx.prec = old


def test_pieces_are_connected_and_partition_the_certified_boxes(chain):
    jp, ra = chain
    p = ra.paving
    certified = np.zeros(len(p), bool)
    for a in ("WA1", "WA2"):
        certified |= (p.labels[a] == Label.INSIDE) & (p.labels["off_Sc"] == Label.INSIDE)
    assert np.array_equal(certified, ra.piece >= 0)
    g = nx.Graph()
    g.add_edges_from(ra.edges.T.tolist())
    rng = np.random.default_rng(0)
    for pid in rng.choice(ra.piece.max() + 1, size=min(30, ra.piece.max() + 1), replace=False):
        members = np.flatnonzero(ra.piece == pid).tolist()
        sub = g.subgraph(members).copy()
        sub.add_nodes_from(members)
        assert nx.is_connected(sub)
    # no face between two different pieces (they would be one component)
    u, v = ra.edges
    both = (ra.piece[u] >= 0) & (ra.piece[v] >= 0)
    assert np.all(ra.piece[u[both]] == ra.piece[v[both]])


def test_solutions_of_random_joint_vectors_are_separated(chain, paper_geometry):
    """Property (Theorem 1, Theorem 2): solutions of one q lie in distinct regions and domains."""
    jp, ra = chain
    p = ra.paving
    rng = np.random.default_rng(8)
    realized = sorted({r.cell for r in ra.regions})
    labelled = 0
    for _ in range(200):
        cid = realized[rng.integers(len(realized))]
        q = _random_point_of_cell(jp, cid, rng)
        res = solve(paper_geometry, q)
        assert res.complete
        regions, domains = [], []
        # the leaf holding each solution box, or -1 (paving/test_tree.py checks this lookup against brute force)
        holders = p.locate_boxes(np.array([s.box for s in res.solutions]))
        for s, i in zip(res.solutions, holders):
            if i >= 0 and ra.region[i] >= 0:
                r = ra.regions[ra.region[i]]
                assert r.cell == cid
                assert (r.aspect == "WA1") == (s.det_sign > 0)
                regions.append(r.id)
            if i >= 0 and ra.domain[i] >= 0:
                domains.append(int(ra.domain[i]))
        assert len(regions) == len(set(regions))
        assert len(domains) == len(set(domains))
        labelled += len(regions)
    assert labelled > 100


def test_witnesses_are_confirmed_by_an_independent_solve(chain, paper_geometry):
    jp, ra = chain
    p = ra.paving
    assert ra.witnesses
    for w in ra.witnesses:
        res = solve(paper_geometry, w.rho)
        assert res.complete
        sign = 1 if w.aspect == "WA1" else -1
        found = []
        for s in res.solutions:
            if s.det_sign != sign:
                continue
            i = p.locate_boxes(np.asarray(s.box)[None])[0]
            pieces = {int(ra.piece[i])} if i >= 0 and ra.piece[i] >= 0 else set()
            found.extend(pieces)
        assert set(w.pieces) <= set(found)
        assert len(set(w.pieces)) == len(w.pieces)


def test_uniqueness_domains_respect_theorem_2(chain):
    jp, ra = chain
    by_id = {r.id: r for r in ra.regions}
    for grp in ra.domains:
        cells = [by_id[i].cell for i in grp]
        assert len(cells) == len(set(cells))
        assert len({by_id[i].aspect for i in grp}) == 1
    assert sorted(i for grp in ra.domains for i in grp) == sorted(i for i, r in by_id.items() if r.n_boxes > 0)
    assert len(ra.domains) >= ra.domains_lower_bound
    # the paper's bound: at least the largest number of solutions (6)
    assert ra.domains_lower_bound >= 6


def test_uniqueness_domains_on_a_small_graph():
    """Hand-made: two cells with 2 regions each per aspect, a path graph: 2 groups are enough."""
    from intervalkin.space.basic_region import BasicRegion

    regs = [BasicRegion(i, "WA1", c, s, 4, 1, 1.0, 1) for i, (c, s) in enumerate([(0, 0), (0, 1), (1, 0), (1, 1)])]
    groups, bound = uniqueness_domains(regs, {(0, 2), (1, 3)})
    assert bound == 2 and sorted(groups) == [(0, 2), (1, 3)]
    groups, _ = uniqueness_domains(regs, {(0, 1), (2, 3)})  # no valid pairing: each alone
    assert len(groups) == 4


def test_label_pose_reports_what_the_paving_certifies(chain, paper_geometry):
    """label_pose on Table 1's six certified solutions, on points of region boxes and off the workspace.

    * each of the six solutions is in W and in the aspect of its certified det A sign
      (decided at this depth), and its region / domain are exactly those of the paving
      box holding it (None only when that box has none);
    * a point drawn inside a box with a basic region gets that region, its aspect and its domain;
    * B1 on A1 (rho_1 = 0) is certainly outside W; a pose beyond the paved domain is refused.

    Would catch a lookup that returns the label of a neighbouring box, drops the aspect, or
    answers "undecided" where the paving has decided.
    """
    jp, ra = chain
    p = ra.paving
    table1 = solve(paper_geometry, [Fraction("14.98"), Fraction("15.38"), Fraction("12.0")])
    assert table1.complete and table1.count == 6

    def own(i, column):
        return int(column[i]) if column[i] >= 0 else None

    for s in table1.solutions:
        pose = [repr(float(v)) for v in s.midpoint]
        lab = label_pose(ra, pose)
        assert lab.in_workspace is True and lab.aspect == s.aspect, (pose, lab)
        i = p.locate_boxes(np.asarray(s.box)[None])[0]
        assert i >= 0
        assert (lab.basic_region, lab.uniqueness_domain) == (own(i, ra.region), own(i, ra.domain))
    rng = np.random.default_rng(12)
    for i in rng.choice(np.flatnonzero(ra.region >= 0), size=40, replace=False):
        X = p.lo[i] + rng.uniform(0.1, 0.9, 3) * (p.hi[i] - p.lo[i])
        lab = label_pose(ra, [repr(float(v)) for v in X])
        r = ra.regions[ra.region[i]]
        assert (lab.basic_region, lab.aspect, lab.uniqueness_domain) == (r.id, r.aspect, own(i, ra.domain))
    out = label_pose(ra, ("0", "0", "0.5"))
    assert out.in_workspace is False and out.aspect is None and out.boxes > 0
    with pytest.raises(InputError, match="outside the paved domain"):  # issue 15: an error, not "undecided"
        label_pose(ra, ("40", "40", "0"))


# --------------------------------------------------------------------------------------
# Sheets by certified continuation (proofs/lemma-sheet-continuation.md)
# --------------------------------------------------------------------------------------
def test_nearly_every_piece_has_its_sheet(chain):
    """Continuation names the sheet of almost every piece, by count and by volume."""
    jp, ra = chain
    vol = ra.paving.volume()
    has = ra.piece >= 0
    n_pieces = int(ra.piece.max()) + 1
    piece_vol = np.bincount(ra.piece[has], weights=vol[has], minlength=n_pieces)
    assigned = np.zeros(n_pieces, dtype=bool)
    assigned[ra.piece[has & (ra.region >= 0)]] = True
    assert assigned.mean() > 0.8
    assert piece_vol[assigned].sum() > 0.9 * piece_vol.sum()
    for c in ra.consistency:
        assert c["sheets_with_boxes"] <= c["expected"]


def test_sheets_of_pieces_match_the_solutions_of_their_cell(chain, paper_geometry):
    """A piece holding a certified solution of some q in its cell is in the sheet of that solution.

    Independent of the continuation: the solutions of q, sorted by the region of
    the piece they land in, must be in pairwise different sheets (one per sheet).
    """
    jp, ra = chain
    p = ra.paving
    rng = np.random.default_rng(11)
    checked = 0
    multi = [r.cell for r in ra.regions if r.sheet >= 1]
    for _ in range(60):
        cid = multi[rng.integers(len(multi))]
        q = _random_point_of_cell(jp, cid, rng)
        res = solve(paper_geometry, q)
        assert res.complete
        for sign, name in ((1, "WA1"), (-1, "WA2")):
            sheets = []
            for s in res.solutions:
                if s.det_sign != sign:
                    continue
                box = np.asarray(s.box)
                i = p.locate_boxes(box[None])[0]
                if i >= 0 and ra.region[i] >= 0:
                    r = ra.regions[ra.region[i]]
                    assert r.cell == cid and r.aspect == name
                    sheets.append(r.sheet)
            assert len(sheets) == len(set(sheets))
            checked += len(sheets)
    assert checked > 50
