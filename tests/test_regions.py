"""Basic regions and uniqueness domains: labels checked in arb, solutions separated as Theorem 1 says."""

from __future__ import annotations

from fractions import Fraction

import networkx as nx
import numpy as np
import pytest
from flint import arb, ctx

from intervalkin.kinematics.formulas import det_a_arb, inverse_kinematics_arb
from intervalkin.solve.continuation import _newton, compare_mod_2pi, krawczyk_segment, new_tracks, track
from intervalkin.solve.dkp import solve
from intervalkin.paving.labels import Label
from intervalkin.space.basic_region import label_pose
from intervalkin.space.uniqueness_domain import uniqueness_domains

from .conftest import small_chain


@pytest.fixture(scope="module")
def chain(paper_geometry):
    return small_chain(paper_geometry, 7, 6, 7, max_solves=200)


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
        vox = np.argwhere(jp.cell == cid)
        v = vox[rng.integers(len(vox))]
        q = tuple(jp.rho_min[i] + (int(v[i]) + Fraction(int(rng.integers(1, 99)), 100)) * jp.step[i] for i in range(3))
        res = solve(paper_geometry, q)
        assert res.complete
        regions, domains = [], []
        for s in res.solutions:
            box = np.asarray(s.box)
            inside = np.flatnonzero(np.all((p.lo <= box[:, 0]) & (box[:, 1] <= p.hi), axis=1))
            reg = {int(ra.region[i]) for i in inside if ra.region[i] >= 0}
            dom = {int(ra.domain[i]) for i in inside if ra.domain[i] >= 0}
            if reg:
                assert len(reg) == 1
                r = ra.regions[reg.pop()]
                assert r.cell == cid
                assert (r.aspect == "WA1") == (s.det_sign > 0)
                regions.append(r.id)
            if dom:
                domains.append(dom.pop())
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
            box = np.asarray(s.box)
            inside = np.flatnonzero(np.all((p.lo <= box[:, 0]) & (box[:, 1] <= p.hi), axis=1))
            pieces = {int(ra.piece[i]) for i in inside if ra.piece[i] >= 0}
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


def test_label_of_table1_solutions(chain):
    jp, ra = chain
    rows = {2: ("-5.495660815453", "-13.935498276039", "-0.047331369367"),
            3: ("-14.896128100173", "1.582961661963", "0.245309530992"),
            6: ("14.673943655735", "-3.012603124926", "2.132904365129")}
    seen = []
    for k, pose in rows.items():
        lab = label_pose(ra, pose)
        assert lab["aspect"] in ("WA1", "undecided")
        if lab["uniqueness_domain"] != "undecided":
            seen.append(lab["uniqueness_domain"])
    assert len(seen) == len(set(seen))
    out = label_pose(ra, ("40", "40", "0"))
    assert out["boxes"] == 0 or out["in_workspace"] in ("no", "undecided")


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
        vox = np.argwhere(jp.cell == cid)
        v = vox[rng.integers(len(vox))]
        q = tuple(jp.rho_min[i] + (int(v[i]) + Fraction(int(rng.integers(1, 99)), 100)) * jp.step[i] for i in range(3))
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


def _fold_segment(geometry):
    """A singular pose X_s of W, q_s = g(X_s), and a joint step dq that crosses g(S) there.

    Along q_s + s dq the two solutions near X_s exist for s < 0 and merge at s = 0.
    """
    from intervalkin.kinematics.formulas import approx_det_a, approx_inverse_kinematics, approx_jacobian

    xs = np.linspace(-30, 30, 6001)
    P = np.stack([xs, np.full_like(xs, -10.0), np.full_like(xs, 0.3)], axis=1)
    d = approx_det_a(geometry, P)
    for i in np.flatnonzero(np.sign(d[:-1]) != np.sign(d[1:])):
        a, b = P[i].copy(), P[i + 1].copy()
        for _ in range(60):
            mid = 0.5 * (a + b)
            if np.sign(approx_det_a(geometry, mid[None])[0]) == np.sign(approx_det_a(geometry, a[None])[0]):
                a = mid
            else:
                b = mid
        x_s = 0.5 * (a + b)
        q_s = approx_inverse_kinematics(geometry, x_s[None])[0]
        if np.all((q_s > 12) & (q_s < 30)):
            break
    else:  # pragma: no cover
        pytest.fail("no singular pose on the search line")
    u, _, _ = np.linalg.svd(approx_jacobian(geometry, x_s[None])[0])
    dq = u[:, 2] / (2 * q_s)  # moves rho^2 along the left null vector of A: across the fold
    dq = 0.02 * dq / np.linalg.norm(dq)
    return x_s, q_s, dq


def test_parameter_krawczyk_refuses_steps_across_a_fold(paper_geometry):
    """Krawczyk over [t0, t1] holding the fold is refused; tracking stops before it, never past it."""
    from intervalkin.core.interval import Interval

    x_s, q_s, dq = _fold_segment(paper_geometry)
    side = None
    for s in (-1.0, 1.0):
        p, conv = _newton(paper_geometry, x_s[None] + 0.05, (q_s + s * dq)[None], iters=40)
        if conv[0] and np.max(np.abs(p[0] - x_s)) < 2.0:
            side, start = s, p[0]
    assert side is not None
    qa = Interval.point((q_s + side * dq)[None])
    qb = Interval.point((q_s - side * dq)[None])  # q(1/2) = q_s is on g(S)
    # any box around the singular pose, over a parameter range holding t = 1/2: refused
    for r in (1e-3, 1e-2, 0.1, 1.0):
        lo, hi = x_s[None] - r, x_s[None] + r
        ok, _, _ = krawczyk_segment(paper_geometry, lo, hi, qa, qb, np.array([0.4]), np.array([0.6]))
        assert not ok[0]
    # from the side with solutions, across the fold: the track must give up
    z = np.stack([start - 1e-9, start + 1e-9])
    tr = track(paper_geometry, new_tracks(qa, qb, start[None], z[0][None], z[1][None]))
    assert tr.status[0] == -1 and tr.t[0] < 0.5
    # the same solution tracked to just before the fold: certified, and it ends near the fold
    near = Interval.point((q_s + side * 0.1 * dq)[None])
    tr = track(paper_geometry, new_tracks(qa, near, start[None], z[0][None], z[1][None]))
    assert tr.status[0] == 1
    assert np.all(tr.x_lo[0] <= tr.p[0]) and np.all(tr.p[0] <= tr.x_hi[0])


def test_tracked_box_holds_the_certified_solution_at_the_end(paper_geometry):
    """Tracks between two exact joint vectors end in boxes holding exactly the solver's solutions there."""
    from intervalkin.core.interval import Interval

    qa = (Fraction(15), Fraction(20), Fraction(18))
    qb = (Fraction(31, 2), Fraction(39, 2), Fraction(18))
    ra, rb = solve(paper_geometry, qa), solve(paper_geometry, qb)
    assert ra.complete and rb.complete and len(ra.solutions) == len(rb.solutions)
    m = len(ra.solutions)
    A = Interval.point(np.tile([float(v) for v in qa], (m, 1)))
    B = Interval.point(np.tile([float(v) for v in qb], (m, 1)))
    boxes = np.array([np.asarray(s.box) for s in ra.solutions])
    tr = track(paper_geometry, new_tracks(A, B, boxes.mean(axis=2), boxes[:, :, 0], boxes[:, :, 1]))
    assert np.all(tr.status == 1)
    ends = np.array([np.asarray(s.box) for s in rb.solutions])
    seen = []
    for i in range(m):
        inside, apart = compare_mod_2pi(np.repeat(tr.x_lo[i:i + 1], m, 0), np.repeat(tr.x_hi[i:i + 1], m, 0),
                                          ends[:, :, 0], ends[:, :, 1])
        assert inside.sum() == 1 and apart.sum() == m - 1  # each track ends on exactly one solution
        j = int(np.flatnonzero(inside)[0])
        assert ra.solutions[i].det_sign == rb.solutions[j].det_sign  # no fold on the way: same aspect
        seen.append(j)
    assert sorted(seen) == list(range(m))
