"""Certified trajectories between Table 1's solutions 2, 3, 6 (one aspect), re-checked in arb."""

from __future__ import annotations

import json
import math
from fractions import Fraction

import numpy as np
import pytest
from flint import arb, ctx

from intervalkin.kinematics.formulas import approx_inverse_kinematics, det_a_arb, inverse_kinematics_arb
from intervalkin.app.cli import main
from intervalkin.solve.dkp import parse_joint_vector, solve
from intervalkin.space.trajectory import NoPathError, trajectory
from intervalkin.space.segment import certify_segment

from ..conftest import small_chain

RHO = ["14.98", "15.38", "12.0"]
PAIRS = [(2, 3), (2, 6), (3, 6)]
#: 50 decimal digits and then some
PREC = 200


@pytest.fixture(scope="module")
def chain(paper_geometry):
    """A small but complete chain: workspace paving, joint cells, regions (depth 6)."""
    return small_chain(paper_geometry, 6, 6, 6, max_solves=200)


@pytest.fixture(scope="module")
def paths(paper_geometry, chain):
    jp, ra = chain
    return {pair: trajectory(paper_geometry, RHO, *pair, analysis=ra, joint=jp) for pair in PAIRS}


@pytest.fixture(scope="module")
def solutions(paper_geometry):
    return solve(paper_geometry, parse_joint_vector(paper_geometry, RHO)).solutions


def _arb_box(lo: float, hi: float):
    return arb(lo).union(arb(hi))


def _point_on_segment(seg, t: Fraction):
    """P(t) = A + t (B - A) in arb, A and B the end enclosures as balls, t exact."""
    tt = arb(t.numerator) / t.denominator
    out = []
    for j in range(3):
        a = _arb_box(*seg.start[j])
        b = _arb_box(*seg.end[j])
        out.append(a + tt * (b - a))
    return out


def _ok_in_arb(geometry, x, y, phi, sign: int) -> bool:
    d = det_a_arb(geometry, x, y, phi)
    if not ((d > 0) if sign > 0 else (d < 0)):
        return False
    return all(r >= 10 and r <= 32 for r in inverse_kinematics_arb(geometry, x, y, phi))


# --------------------------------------------------------------------------------------
def test_table1_pairs_are_certified(paths):
    for pair, tr in paths.items():
        assert tr.aspect == "WA1" and tr.sign == 1, pair
        assert tr.certified, (pair, tr.reason)
        assert len(tr.segments) == len(tr.waypoints) - 1
        assert tr.raw_waypoints >= len(tr.waypoints)
        for s in tr.segments:
            assert s.pieces[0, 0] == 0.0 and s.pieces[-1, 1] == 1.0
            assert np.all(s.pieces[1:, 0] == s.pieces[:-1, 1])


def test_endpoints_are_the_solutions(paths, solutions):
    """The motion starts and ends at the exact solutions: its end enclosures are theirs (phi + 2 pi k)."""
    for (i, j), tr in paths.items():
        a, b = np.asarray(solutions[i - 1].box), np.asarray(solutions[j - 1].box)
        assert np.array_equal(tr.segments[0].start, a)
        assert np.all(a[:, 0] <= tr.waypoints[0]) and np.all(tr.waypoints[0] <= a[:, 1])
        end = tr.segments[-1].end
        shift = 2 * math.pi * tr.phi_turns
        assert np.array_equal(end[:2], b[:2])
        assert end[2, 0] <= b[2, 0] + shift + 1e-12 and b[2, 1] + shift - 1e-12 <= end[2, 1]
        assert end[2, 1] - end[2, 0] < 1e-8
        last = tr.waypoints[-1]
        assert np.all(end[:, 0] <= last) and np.all(last <= end[:, 1])


def test_segments_rechecked_in_arb_at_sampled_points(paths, paper_geometry):
    """det A > 0 and 10 <= rho_i <= 32 at many points of every segment, at 200 bits."""
    rng = np.random.default_rng(8)
    old = ctx.prec
    ctx.prec = PREC
    try:
        for pair, tr in paths.items():
            for seg in tr.segments:
                ts = {Fraction(k, 64) for k in range(65)}
                ts |= {Fraction(int(v), 1 << 30) for v in rng.integers(0, 1 << 30, 40)}
                ts |= {Fraction(float(v)) for v in seg.pieces[:, 0]}
                for t in ts:
                    x, y, phi = _point_on_segment(seg, t)
                    assert _ok_in_arb(paper_geometry, x, y, phi, tr.sign), (pair, float(t))
    finally:
        ctx.prec = old


def test_certificate_reverified_in_arb(paths, paper_geometry):
    """Each certified piece, enclosed as an arb box, re-proved by arb evaluation (bisecting if loose)."""
    old = ctx.prec
    ctx.prec = 128
    try:
        for pair, tr in paths.items():
            cert = tr.certificate()
            assert cert["det_sign"] == 1
            for seg_doc, seg in zip(cert["segments"], tr.segments):
                pieces = [(Fraction(float.fromhex(a)), Fraction(float.fromhex(b))) for a, b in seg_doc["pieces"]]
                assert pieces[0][0] == 0 and pieces[-1][1] == 1
                assert all(p[1] == q[0] for p, q in zip(pieces, pieces[1:]))
                todo = [(t0, t1, 0) for t0, t1 in pieces]
                while todo:
                    t0, t1, level = todo.pop()
                    p0, p1 = _point_on_segment(seg, t0), _point_on_segment(seg, t1)
                    x, y, phi = (u.union(v) for u, v in zip(p0, p1))
                    if _ok_in_arb(paper_geometry, x, y, phi, tr.sign):
                        continue
                    assert level < 12, (pair, float(t0), float(t1))
                    tm = (t0 + t1) / 2
                    todo += [(t0, tm, level + 1), (tm, t1, level + 1)]
    finally:
        ctx.prec = old


def test_a_path_crosses_the_phi_seam(paths):
    """2 -> 6 is reached through phi = -pi: the unwrapped waypoints leave (-pi, pi], and it is certified."""
    tr = paths[(2, 6)]
    assert tr.phi_turns != 0
    assert np.any(np.abs(tr.waypoints[:, 2]) > math.pi)
    assert np.all(np.abs(np.diff(tr.waypoints[:, 2])) < math.pi)
    assert tr.certified


def test_joint_image_pieces_map_into_their_cells(paths, chain, paper_geometry):
    """The cells reported along the path hold the arb images of points of their pieces."""
    from intervalkin.space.trajectory import _cells_along

    jp, _ = chain
    rng = np.random.default_rng(3)
    old = ctx.prec
    ctx.prec = PREC
    try:
        for tr in paths.values():
            for seg in tr.segments:
                t0, cells = _cells_along(paper_geometry, jp, seg)
                ends = np.append(t0[1:], 1.0)
                for k in np.flatnonzero(cells >= 0)[:40]:
                    t = Fraction(float(t0[k] + rng.uniform() * (ends[k] - t0[k])))
                    x, y, phi = _point_on_segment(seg, t)
                    rho = inverse_kinematics_arb(paper_geometry, x, y, phi)
                    lo = np.array([[float(r.lower()) for r in rho]])
                    hi = np.array([[float(r.upper()) for r in rho]])
                    ilo, ihi, _ = jp.index_ranges(lo, hi)
                    block = jp.cell[ilo[0, 0]:ihi[0, 0] + 1, ilo[0, 1]:ihi[0, 1] + 1, ilo[0, 2]:ihi[0, 2] + 1]
                    assert np.all(block == cells[k])
    finally:
        ctx.prec = old


def test_paths_pass_through_a_two_solution_cell(paths):
    """The paper's remark (section 5.2): the image goes through a domain with only 2 solutions.

    At this small depth the joint-space layer is thick, so it is shown for 2 -> 3 and 2 -> 6
    (3 -> 6 too at depth 7: see the slow test)."""
    for pair in ((2, 3), (2, 6)):
        tr = paths[pair]
        assert tr.through_two_solution_cell, (pair, tr.joint_cells)
        assert all(c["count"] in (2, 4, 6) for c in tr.joint_cells if c["cell"] >= 0)
    for tr in paths.values():
        assert tr.basic_regions is not None and len(tr.basic_regions) >= 1


@pytest.mark.slow
def test_all_three_paths_meet_a_two_solution_cell_at_depth_7(paper_geometry, regions_chain):
    # regions_chain (tests/conftest.py) is small_chain(paper_geometry, 7, 6, 7, max_solves=200), built once a session
    jp, ra = regions_chain
    for pair in PAIRS:
        tr = trajectory(paper_geometry, RHO, *pair, analysis=ra, joint=jp)
        assert tr.certified and tr.through_two_solution_cell, (pair, tr.joint_cells)


def test_different_aspects_have_no_path(paper_geometry, capsys):
    with pytest.raises(NoPathError, match=r"solutions 1 and 2 are in different aspects \(det A signs -, \+\)"):
        trajectory(paper_geometry, RHO, 1, 2, depth=4)
    code = main(["trajectory", "--rho", *RHO, "--from", "1", "--to", "2", "--json"])
    out, err = capsys.readouterr()
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and "different aspects" in err


def test_bad_requests_are_input_errors(paper_geometry):
    from intervalkin.core.errors import InputError

    with pytest.raises(InputError, match="^i_to: expected a solution number in 1..6"):  # the parameter, not the flag
        trajectory(paper_geometry, RHO, 2, 7, depth=4)
    with pytest.raises(InputError, match="^i_from: "):
        trajectory(paper_geometry, RHO, 0, 2, depth=4)
    with pytest.raises(InputError, match="same|both"):
        trajectory(paper_geometry, RHO, 3, 3, depth=4)
    with pytest.raises(InputError, match="rho_1"):
        trajectory(paper_geometry, ["9", "15", "12"], 1, 2, depth=4)


def test_certifier_refuses_a_straight_segment_through_the_singularity(paper_geometry, solutions):
    """Straight from solution 2 to 3: arb finds det A < 0 on it, and the certifier says no."""
    a, b = np.asarray(solutions[1].box), np.asarray(solutions[2].box)
    old = ctx.prec
    ctx.prec = PREC
    try:
        from intervalkin.space.segment import SegmentCertificate

        seg = SegmentCertificate(a, b, 1, np.zeros((0, 2)), False)
        negative = []
        for k in range(1, 200):
            x, y, phi = _point_on_segment(seg, Fraction(k, 200))
            if det_a_arb(paper_geometry, x, y, phi) < 0:
                negative.append(k)
        assert negative, "the straight segment 2 -> 3 should cross det A = 0"
    finally:
        ctx.prec = old
    cert = certify_segment(paper_geometry, a, b, +1)
    assert not cert.certified
    assert "wrong sign" in cert.reason or "not proved" in cert.reason


def test_certifier_refuses_a_segment_leaving_the_joint_limits(paper_geometry, solutions):
    """Straight from solution 3 to 6 keeps det A > 0 (float look) but a leg drops below 10: refused."""
    a, b = np.asarray(solutions[2].box), np.asarray(solutions[5].box)
    t = np.linspace(0, 1, 401)[:, None]
    pts = 0.5 * (a[:, 0] + a[:, 1]) + t * (0.5 * (b[:, 0] + b[:, 1]) - 0.5 * (a[:, 0] + a[:, 1]))
    k = int(np.argmin(approx_inverse_kinematics(paper_geometry, pts).min(axis=1)))
    old = ctx.prec
    ctx.prec = PREC
    try:
        x, y, phi = (arb(float(v)) for v in pts[k])
        assert any(r < 10 for r in inverse_kinematics_arb(paper_geometry, x, y, phi))
    finally:
        ctx.prec = old
    cert = certify_segment(paper_geometry, a, b, +1)
    assert not cert.certified


def test_certify_segment_inside_one_box(paper_geometry):
    c = certify_segment(paper_geometry, [-14.9, 1.6, 0.25], [-14.0, 1.0, 0.3], +1)
    assert c.certified and c.boxes().shape == (len(c.pieces), 3, 2)
    # the same segment cannot be WA2
    assert not certify_segment(paper_geometry, [-14.9, 1.6, 0.25], [-14.0, 1.0, 0.3], -1).certified


def test_json_object_and_outputs(paths, paper_geometry, chain, tmp_path):
    from intervalkin.app.animation import write_trajectory

    jp, ra = chain
    tr = paths[(2, 3)]
    doc = tr.to_json()
    for key in ("rho", "from", "to", "aspect", "waypoints", "basic_regions", "certified"):
        assert key in doc
    assert doc["from"] == 2 and doc["to"] == 3 and doc["aspect"] == "WA1" and doc["certified"] is True
    assert all(len(w) == 3 for w in doc["waypoints"])
    json.dumps(doc, allow_nan=False)
    written = write_trajectory(tr, paper_geometry, tmp_path, paving=ra.paving, joint=jp)
    names = {p.name for p in written}
    assert {"trajectory.json", "trajectory_workspace_3d.png", "trajectory_workspace_xy.png",
            "trajectory_joint.png"} <= names
    assert "trajectory_animation.gif" in names or any(n.startswith("frame_") for n in names)
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temp files left
    back = json.loads((tmp_path / "trajectory.json").read_text())
    assert back["certificate"]["segments"][0]["certified"] is True


def test_the_box_path_is_a_shortest_one(paper_geometry, chain, solutions):
    """The search between two of Table 1's solutions returns a chain of face-adjacent boxes of the aspect whose
    length (centre to centre, the search's metric) is the one scipy's Dijkstra finds for a graph built here
    (the path is read back from predecessors: a wrong step breaks the chain or lengthens it)."""
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import dijkstra

    from intervalkin.paving.labels import Label
    from intervalkin.space.path_search import _point_box_distance, metric_length, path_distance, shortest_box_path

    _, ra = chain
    paving, edges = ra.paving, ra.edges
    L = metric_length(paper_geometry)
    start, goal = (np.array([float(v) for v in solutions[k].midpoint]) for k in (1, 2))
    path = shortest_box_path(paving, edges, "WA1", start, goal, L)
    assert path is not None and len(path) > 2
    inside = paving.labels["WA1"] == Label.INSIDE
    assert inside[path].all()
    pairs = {(int(a), int(b)) for a, b in edges.T} | {(int(b), int(a)) for a, b in edges.T}
    assert all((int(a), int(b)) in pairs for a, b in zip(path[:-1], path[1:]))
    centre = 0.5 * (paving.lo + paving.hi)
    length = float(path_distance(centre[path[:-1]], centre[path[1:]], L).sum())
    # the same graph for Dijkstra: the aspect's boxes, face contacts weighted by the same metric
    nodes = np.flatnonzero(inside)
    local = np.full(len(paving), -1)
    local[nodes] = np.arange(nodes.size)
    e = edges[:, inside[edges[0]] & inside[edges[1]]]
    key = np.unique(np.minimum(local[e[0]], local[e[1]]) * nodes.size + np.maximum(local[e[0]], local[e[1]]))
    u, v = key // nodes.size, key % nodes.size
    w = path_distance(centre[nodes[u]], centre[nodes[v]], L)
    graph = csr_matrix((w, (u, v)), shape=(nodes.size, nodes.size))
    ends = local[path[[0, -1]]]
    best = dijkstra(graph, directed=False, indices=ends[0])[ends[1]]
    assert abs(length - best) <= 1e-9 * max(1.0, best), (length, best)
    # the ends are the boxes nearest the two poses
    for pose, box in ((start, path[0]), (goal, path[-1])):
        gap = _point_box_distance(pose, paving.lo[nodes], paving.hi[nodes], L)
        assert gap[local[box]] == gap.min()
