"""The independent checker on ``aspect_connected`` claims: the real claims verify, falsified ones are refused.

Each tampering is one a faulty library could produce: a retraction along the wrong direction,
a box called a sink (a false join of fragments, or of two groups of sinks of the second design
that are different components), a retracting box listed before the boxes it retracts onto (a
cycle), a box left out (a hole where a piece of an aspect could hide), a wall of boxes called
OUT (a false separation), a combination with the wrong weights, a domain too small, and counts
declared exact without the covers.  The arb proofs run box by
box after the cheap combinatorial steps, so the tamperings are placed where they fail fast.
"""

from __future__ import annotations

import copy

import numpy as np
import pytest
from flint import arb, ctx

from intervalkin.certify.aspect_claims import aspect_connected_claims
from intervalkin.checker import check_claim
import networkx as nx

from intervalkin.checker.aspect_tiling import sink_groups
from intervalkin.checker.aspects import _box, pieces_holding_sinks, retracts
from intervalkin.checker.labels import holds_on_box
from intervalkin.checker.claims import check_count, count_bound, count_upper
from intervalkin.checker.model import ArbModel, balls
from intervalkin.checker.parse import Refused
from intervalkin.checker.taylor import centred_enclosure, seeded, slope_enclosure, value_enclosure
from intervalkin.space.aspect_retraction import classify_boxes, constraint_values
from intervalkin.paving.adjacency import component_labels
from intervalkin.space.aspect_topology import SINK, face_pairs


@pytest.fixture(scope="module")
def claims(aspect_topology):
    got, omitted = aspect_connected_claims(aspect_topology)
    assert not omitted and [c["id"] for c in got] == ["WA1", "WA2"]
    return got


@pytest.fixture(scope="module")
def second_claims(second_aspect_topology):
    got, omitted = aspect_connected_claims(second_aspect_topology)
    assert not omitted and [c["id"] for c in got] == ["WA1", "WA2"]
    return got


def _refused(geometry, claim) -> str:
    ok, why = check_claim(geometry, "aspect_connected", claim)
    assert not ok
    return why


def test_the_claims_of_the_paper_verify(paper_geometry, claims):
    for claim in claims:
        ok, why = check_claim(paper_geometry, "aspect_connected", claim)
        assert ok, why
        assert "nonempty and connected" in why


def _first_ret(claim) -> int:
    return next(k for k, row in enumerate(claim["boxes"]) if row[4] >= 0)


def test_a_false_retraction_is_refused(paper_geometry, claims):
    """The last retracting row (highest rank: nothing retracts onto it, and every box is listed before it)
    given the reverse of its direction: only the arb step can refuse it, and it does."""
    claim = copy.deepcopy(claims[0])
    model = ArbModel(paper_geometry)
    domain = [[float.fromhex(lo), float.fromhex(hi)] for lo, hi in claim["domain"]]
    row = next(r for r in reversed(claim["boxes"]) if r[4] >= 0 and not _retracts_reversed(model, domain, claim, r))
    a, b, c = claim["directions"][row[4]]
    claim["directions"].append([-a, -b, -c])
    row[4] = len(claim["directions"]) - 1
    claim["boxes"].remove(row)
    claim["boxes"].append(row)
    assert "not proved retracting" in _refused(paper_geometry, claim)


def _retracts_reversed(model, domain, claim, row) -> bool:
    a, b, c = claim["directions"][row[4]]
    with ctx.workprec(128):
        e = [arb(-a), arb(-b), arb(-c) / claim["phi_divisor"]]
        return retracts(model, _box(domain, tuple(row[:4])), 1, e)


def test_reversed_directions_fail_in_arb(paper_geometry, claims):
    """The arb test itself: on many RET boxes the reversed direction is refused (would catch a slope whose
    sign is ignored), while the stated one passes on sub-boxes covering the box."""
    claim = claims[0]
    model = ArbModel(paper_geometry)
    domain = [[float.fromhex(lo), float.fromhex(hi)] for lo, hi in claim["domain"]]
    rows = [r for r in claim["boxes"] if r[4] >= 0][:300]
    refused = sum(not _retracts_reversed(model, domain, claim, r) for r in rows)
    assert refused > 100
    with ctx.workprec(128):
        for r in rows[:40]:
            a, b, c = claim["directions"][r[4]]
            e = [arb(a), arb(b), arb(c) / claim["phi_divisor"]]
            assert holds_on_box(_box(domain, tuple(r[:4])), lambda s: retracts(model, s, 1, e))


def test_a_false_join_is_refused(paper_geometry, claims, aspect_topology):
    """A box beside the sinks but not inside the aspect declared a sink (a join through a place outside
    the aspect, or through its undecided layer), listed first."""
    cover = aspect_topology.covers[0]
    pairs, _, _ = face_pairs(cover.level, cover.ijk, int(cover.level.max()))
    near = pairs[1][(cover.kind[pairs[0]] == SINK) & (cover.kind[pairs[1]] != SINK)]
    c = classify_boxes(paper_geometry, cover.boxes(np.isin(np.arange(len(cover.kind)), near)), 1)
    target = np.unique(near)[~c.inside][0]
    key = [int(cover.level[target])] + cover.ijk[target].tolist()
    claim = copy.deepcopy(claims[0])
    row = next(r for r in claim["boxes"] if r[:4] == key)
    claim["boxes"].remove(row)
    claim["boxes"].insert(0, key + [-2])
    assert "not proved inside WA1" in _refused(paper_geometry, claim)


def test_a_cycle_a_hole_and_a_small_domain_are_refused(paper_geometry, claims):
    """The highest-rank row moved before the first retracting row: a box it retracts onto now comes after
    it (the order no longer makes the chains acyclic).  A row left out: the boxes no longer tile the
    domain.  A domain cut short: W may leave it."""
    claim = copy.deepcopy(claims[1])
    rows = claim["boxes"]
    rows.insert(_first_ret(claim), rows.pop())
    assert "neither OUT, a sink nor an earlier" in _refused(paper_geometry, claim)
    hole = copy.deepcopy(claims[1])
    hole["boxes"].pop(3)
    assert "do not tile" in _refused(paper_geometry, hole)
    small = copy.deepcopy(claims[1])
    small["domain"][0][1] = (float.fromhex(small["domain"][0][1]) - 1).hex()
    assert "A1 -+ rho_max_1" in _refused(paper_geometry, small)


def test_counts_exact_only_with_both_signs_connected():
    """count_upper needs a verified cover for each sign; exact needs the declared bounds to meet."""
    both = [{"signs": {1, -1}}, {"aspect_sign": 1, "components_at_most": 1}, {"aspect_sign": -1, "components_at_most": 1}]
    assert count_upper("aspects", both) == 2
    assert count_upper("aspects", both[:2]) is None
    assert count_upper("basic_regions", both) is None
    verified = {f"f#{k}": f for k, f in enumerate(both)}
    claim = {"name": "aspects", "lower_bound": 2, "upper_bound": 2, "found": 2, "exact": True,
             "support": list(verified)}
    msg, facts = check_count(claim, verified)
    assert "exactly 2" in msg and facts["upper_bound"] == 2
    with pytest.raises(Refused, match="not backed"):
        check_count(claim, {k: v for k, v in verified.items() if k != "f#2"})
    with pytest.raises(Refused, match="exact is False"):
        check_count({**claim, "exact": False}, verified)
    with pytest.raises(Refused, match="above the 2"):
        check_count({**claim, "found": 3}, verified)


def test_taylor_forms_enclose_and_tighten(paper_geometry):
    """The Taylor forms contain the values (and slopes) at sampled points of the box, and the value form is
    much narrower than the natural one on this box of level 7 (where the natural one has no sign)."""
    model = ArbModel(paper_geometry)
    b = ((11.5, 12.0), (-20.0, -19.5), (0.8344855486097891, 0.8835729338221294))
    with ctx.workprec(128):
        box = balls(b)
        v = value_enclosure(model.det, box)
        assert v.rad() < model.det(*box).rad() / 2
        e = [arb(16), arb(0), arb(1) / 16]
        s = slope_enclosure(model.det, box, e)
        for t in (0.0, 0.3, 0.7, 1.0):
            p = [arb(lo + t * (hi - lo)) for lo, hi in b]
            assert v.overlaps(model.det(*p))
            at = model.det(*seeded(p, (e,)))
            assert s.overlaps(at.d[0])


def test_jets_agree_with_differences_and_with_one_pair_at_a_time(paper_geometry, rng):
    """The jets' derivatives of det A match central differences in arb at random poses (step 1e-12: error about
    1e-22, far inside the 1e-15 asked); a jet of six pairs gives the same balls, bit for bit, as six jets of one
    pair each (what the enclosures' docstring promises); the centred form encloses det A at points of its box."""
    pairs = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))
    unit = [[arb(int(i == k)) for i in range(3)] for k in range(3)]
    with ctx.workprec(128):
        model = ArbModel(paper_geometry)  # its constants at this precision: the differences divide by h
        h = arb(10) ** -12
        for x, y, phi in zip(rng.uniform(-20, 20, 12), rng.uniform(-20, 20, 12), rng.uniform(-3, 3, 12)):
            p = [arb(x), arb(y), arb(phi)]
            jet = model.det(*seeded(p, unit, pairs))

            def at(*steps):
                return model.det(*[q + sum((u[k] for u in steps), arb(0)) * h for k, q in enumerate(p)])
            for k in range(3):
                diff = (at(unit[k]) - at([-v for v in unit[k]])) / (2 * h)
                assert abs(float((jet.d[k] - diff).mid())) < 1e-15 * (1 + abs(float(diff.mid())))
            for (j, k), dd in zip(pairs, jet.dd):
                uj, uk = unit[j], unit[k]
                mj, mk = [-v for v in uj], [-v for v in uk]
                diff = (at(uj, uk) - at(uj, mk) - at(mj, uk) + at(mj, mk)) / (4 * h * h)
                assert abs(float((dd - diff).mid())) < 1e-6 * (1 + abs(float(diff.mid())))  # h^2 in the division
                alone = model.det(*seeded(p, unit, ((j, k),))).dd[0]
                assert alone.mid() == dd.mid() and alone.rad() == dd.rad()
        b = ((11.5, 12.0), (-20.0, -19.5), (0.8344855486097891, 0.8835729338221294))
        c = centred_enclosure(model.det, balls(b))
        for t in (0.0, 0.5, 1.0):
            assert c.overlaps(model.det(*[arb(lo + t * (hi - lo)) for lo, hi in b]))


def test_the_second_design_has_exactly_four_aspects(second_geometry, second_claims):
    """Each sign: two groups of sinks, each in its own piece of the non-OUT boxes (re-proved in arb, the pieces
    recomputed from the rows): exactly two components; with the opposite signs, the count is 4 from below
    and from above."""
    facts = [{"signs": {1, -1}}]
    for claim in second_claims:
        ok, why = check_claim(second_geometry, "aspect_connected", claim)
        assert ok, why
        assert "exactly 2 components" in why
        keys = {tuple(r[:4]) for r in claim["boxes"]}
        rows = [(tuple(r[:4]), r[4]) for r in claim["boxes"]]
        assert pieces_holding_sinks(keys, rows) == 2
        facts.append({"aspect_sign": 1 if claim["aspect"] == "WA1" else -1, "components_at_most": 2,
                      "components_at_least": 2})
    assert count_bound("aspects", facts) == count_upper("aspects", facts) == 4
    assert count_bound("aspects", facts[:1]) == 2  # the signs alone prove 2


def _join_path(cover, claim):
    """Rows (level, i, j, k) of a shortest face path of boxes from one group of sinks to the other."""
    depth = int(cover.level.max())
    edges = face_pairs(cover.level, cover.ijk, depth)[2]
    group = component_labels(len(cover.level), edges, cover.kind == SINK)
    g = nx.Graph()
    g.add_edges_from(edges.T.tolist())
    g.add_edges_from(("A", int(v)) for v in np.flatnonzero(group == 0))
    g.add_edges_from(("B", int(v)) for v in np.flatnonzero(group == 1))
    path = [v for v in nx.shortest_path(g, "A", "B")[2:-2]]
    return [[int(cover.level[v])] + cover.ijk[v].tolist() for v in path]


def test_a_false_join_of_two_groups_of_sinks_is_refused(second_geometry, second_claims, second_aspect_topology):
    """The boxes of a shortest face path between the two groups of sinks of WA1 called sinks: the rows alone
    now show one group (a join of two different components), and the arb step refuses a box of the path."""
    claim = copy.deepcopy(second_claims[0])
    path = _join_path(second_aspect_topology.covers[0], claim)
    assert len(path) > 3
    on_path = {tuple(p) for p in path}
    rows = [r for r in claim["boxes"] if tuple(r[:4]) not in on_path]
    claim["boxes"] = [p + [-2] for p in path] + rows
    keys = {tuple(r[:4]) for r in claim["boxes"]}
    sinks = [tuple(r[:4]) for r in claim["boxes"] if r[4] == -2]
    deepest = max(r[0] for r in claim["boxes"])
    assert sink_groups(keys, sinks, deepest) == 1  # combinatorially joined
    assert "not proved inside WA1" in _refused(second_geometry, claim)


def test_a_false_separation_is_refused(paper_geometry, claims):
    """Every box meeting phi = 0 or phi = pi called OUT: two walls cut the paper's WA1 into two pieces that
    both hold sinks (a false proof of a second component); the arb step refuses a box of the walls."""
    claim = copy.deepcopy(claims[0])
    domain = [[float.fromhex(lo), float.fromhex(hi)] for lo, hi in claim["domain"]]

    def on_wall(r):
        lo, hi = _box(domain, tuple(r[:4]))[2]
        return any(lo <= w <= hi for w in (0.0, float(np.pi)))

    wall = [r for r in claim["boxes"] if on_wall(r) and r[4] != -1]
    rest = [r for r in claim["boxes"] if not (on_wall(r) and r[4] != -1)]
    claim["boxes"] = [r[:4] + [-1] for r in wall] + rest
    keys = {tuple(r[:4]) for r in claim["boxes"]}
    assert pieces_holding_sinks(keys, [(tuple(r[:4]), r[4]) for r in claim["boxes"]]) == 2
    assert "not proved free of WA1" in _refused(paper_geometry, claim)


def test_a_combination_with_wrong_weights_is_refused(paper_geometry, claims):
    """OUT rows proved by a combination given, instead, the weight of one constraint that is satisfied on the
    whole box (so the sum is positive there): refused, whichever constraint it is."""
    claim0 = claims[0]
    assert claim0["combinations"]
    domain = [[float.fromhex(lo), float.fromhex(hi)] for lo, hi in claim0["domain"]]
    rows = [r for r in claim0["boxes"] if r[4] <= -3][:3]
    boxes = np.array([_box(domain, tuple(r[:4])) for r in rows])
    values = constraint_values(paper_geometry, boxes, 1)
    for row, low in zip(rows, values.lo):
        j = int(np.argmax(low))
        assert low[j] > 0
        claim = copy.deepcopy(claim0)
        claim["combinations"].append([int(k == j) for k in range(7)])
        mutated = row[:4] + [-3 - (len(claim["combinations"]) - 1)]
        claim["boxes"] = [mutated] + [r for r in claim["boxes"] if r[:4] != row[:4]]
        assert "by the combination" in _refused(paper_geometry, claim)
