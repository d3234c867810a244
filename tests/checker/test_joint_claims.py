"""The checker on ``joint_fold_model`` and ``joint_join`` claims: honest claims verify, falsified ones are refused.

The claims come from the depth-5 fold paving of the paper's manipulator (``fold_paving`` in
tests/conftest.py).  Each falsification is one a faulty library could make: a pose box that
misses the sheet, the wrong axis, a criterion that does not hold, the sides of a fold box
swapped, a link point or a witness moved into the other piece, a chain through an undecided
box, and two cells of different counts joined.  Single claims are re-checked with
:func:`intervalkin.checker.check_claim` (the fold models a join refers to are verified first).
"""

from __future__ import annotations

import copy
import json
import re
from fractions import Fraction

import numpy as np
import pytest
from flint import arb, ctx
from hypothesis import given, settings
from hypothesis import strategies as st

from intervalkin import checker
from intervalkin.certify.writer import write_certificates
from intervalkin.checker import check_claim
from intervalkin.checker.claims import run_check
from intervalkin.checker.joint_models import in_joint_box, read_joint_box, read_joint_point
from intervalkin.checker.joint_torus import torus_search
from intervalkin.checker.model import ArbModel
from intervalkin.core.exact import exact_text
from intervalkin.core.geometry import load_geometry
from intervalkin.kinematics.formulas import approx_inverse_kinematics
from intervalkin.paving.labels import Label
from intervalkin.solve.dkp import solve
from intervalkin.solve.fold_model import side_of
from intervalkin.solve.fold_side import placed_side
from tests.conftest import DATA
from tests.solve.shared import box_across_singular_image, concurrent_legs_box, first_det_change

MODELS = "joint_fold_model.json"


@pytest.fixture(scope="module")
def written(tmp_path_factory, paper_geometry, fold_paving):
    out = tmp_path_factory.mktemp("joint-claims")
    write_certificates(out, paper_geometry, joint_cells=fold_paving, separations=False)
    return out


def _load(d, name):
    return json.loads((d / name).read_text())


@pytest.fixture(scope="module")
def models(written):
    return _load(written, MODELS)["claims"]


@pytest.fixture(scope="module")
def joins(written):
    return _load(written, "joint_join.json")["claims"]


@pytest.fixture(scope="module")
def facts(paper_geometry, models):
    """The checker's facts of every verified model, as verify_directory hands them to the joins."""
    return {f"{MODELS}#{c['id']}": run_check(paper_geometry, "joint_fold_model", c, 128)[1] for c in models}


def _refused_model(geometry, claim) -> str:
    ok, why = check_claim(geometry, "joint_fold_model", claim)
    assert not ok, "a falsified fold model was accepted"
    return why


def _refused_join(geometry, claim, facts) -> str:
    ok, why = check_claim(geometry, "joint_join", claim, claim.get("precision", 128), verified=facts)
    assert not ok, "a falsified join was accepted"
    return why


def _box_ends(node, models_by_id):
    return read_joint_box(node["clear"] if "clear" in node else models_by_id[node["fold"]]["box"])


# --------------------------------------------------------------------------------------
# Honest claims
# --------------------------------------------------------------------------------------
def test_written_claims_verify(written, models, joins):
    results = checker.verify_directory(written)
    assert results and all(r.verified for r in results), [r.line() for r in results if not r.verified]
    assert {r.kind for r in results} == {"joint_fold_model", "joint_join"}
    assert 10 <= len(models) <= 64 and 10 <= len(joins) <= 64
    index = _load(written, "index.json")
    assert any("cap" in om["why"] for om in index["omitted"]), "the joins left out are said to be left out"
    used = {n["fold"] for j in joins for n in j["nodes"] if "fold" in n}
    assert used == {c["id"] for c in models}, "exactly the models the joins use are written"


def test_models_are_the_library_models(paper_geometry, fold_paving, models):
    """Each claim restates the library's model of its leaf; its witnesses sit where the library places them."""
    pc = fold_paving.pieces
    row = {int(b): t for t, b in enumerate(pc.box)}
    for c in models:
        t = row[int(c["id"].split("-")[1])]
        assert c["axis"] == int(pc.models.axis[t])
        assert np.array_equal(np.array(c["pose"]), pc.models.pose[t])
        leaf = pc.box[t]
        box = read_joint_box(c["box"])
        assert [(float(a), float(b)) for a, b in box] == list(map(tuple, np.stack(
            [fold_paving.paving.lo[leaf], fold_paving.paving.hi[leaf]], -1).tolist()))
        for name, want in (("below", -1), ("above", 1)):
            if name in c["witnesses"]:
                q = np.array([[float(v) for v in read_joint_point(c["witnesses"][name], name)]])
                assert placed_side(paper_geometry, pc.models, np.array([t]), q)[0] == want


def test_points_only_the_tight_side_test_places_are_re_proved(paper_geometry, fold_paving, monkeypatch):
    """Points of fold boxes the library places only with its tight side test (the preconditioner taken again
    over the shrunk pose box) are placed on the same side by the checker's side test (arb, its own Krawczyk
    proof of the box); some need its fresh steps: without them it leaves them open, and a witness there would be
    refused."""
    import intervalkin.checker.joint_models as jm

    pc, pav = fold_paving.pieces, fold_paving.paving
    rng = np.random.default_rng(9)
    t = np.repeat(np.arange(len(pc)), 4)
    q = pav.lo[pc.box[t]] + rng.random((len(t), 3)) * (pav.hi[pc.box[t]] - pav.lo[pc.box[t]])
    quick = side_of(paper_geometry, pc.models, t, q)
    side = placed_side(paper_geometry, pc.models, t, q)
    only = np.flatnonzero((quick == 0) & (side != 0))
    model = ArbModel(paper_geometry)
    placed = needed = 0
    for row in rng.permutation(np.unique(t[only]))[:60]:
        i = only[t[only] == row][0]
        b = pc.box[row]
        box = tuple((Fraction(float(pav.lo[b, a])), Fraction(float(pav.hi[b, a]))) for a in range(3))
        pose = tuple((float(pc.models.pose[row, a, 0]), float(pc.models.pose[row, a, 1])) for a in range(3))
        try:
            proof = jm.FoldProof(model, box, int(pc.models.axis[row]), pose)
        except jm.Refused:  # the checker's own Krawczyk proof of this box does not pass: no claim is written
            continue
        point = [Fraction(float(v)) for v in q[i]]
        assert proof.side(point) == side[i], (row, point)
        monkeypatch.setattr(jm, "FRESH_STEPS", 0)
        needed += proof.side(point) == 0
        monkeypatch.setattr(jm, "FRESH_STEPS", 3)
        placed += 1
    assert placed >= 30 and needed >= 3, (placed, needed)


def test_edge_heights_criterion_verifies_where_it_holds(paper_geometry, models):
    """The third criterion of the lemma is re-proved where it holds, and refused along the sheet's own axis."""
    accepted = 0
    for c in models[:20]:
        for b in (a for a in range(3) if a != c["axis"]):
            ok, _ = check_claim(paper_geometry, "joint_fold_model", dict(c, criterion={"name": "edge_heights",
                                                                                       "along": b}))
            accepted += ok
    assert accepted >= 1, "some models of the depth-5 paving satisfy the edge criterion"
    c = dict(models[0], criterion={"name": "edge_heights", "along": models[0]["axis"]})
    assert "parameter axis" in _refused_model(paper_geometry, c)


# --------------------------------------------------------------------------------------
# Wrong local models
# --------------------------------------------------------------------------------------
def test_pose_box_shrunk_off_the_sheet_is_refused(paper_geometry, models):
    """A corner eighth of the pose box, and the pose box with 40 % cut from one side: neither holds the sheet."""
    for c in models[:6]:
        pose = np.array(c["pose"])
        w = pose[:, 1] - pose[:, 0]
        corner = np.stack([pose[:, 0], pose[:, 0] + w / 2], -1)
        why = _refused_model(paper_geometry, dict(c, pose=corner.tolist()))
        assert "Krawczyk" in why or "pose box" in why, why
        for a in range(3):
            cut = pose.copy()
            cut[a, 1] = cut[a, 0] + 0.6 * w[a]
            _refused_model(paper_geometry, dict(c, pose=cut.tolist()))


def test_cover_refuses_a_pose_box_away_from_the_singular_poses(paper_geometry, models):
    """The cover step alone: the pose box moved by its own width misses the singular poses of the box
    (refused); moved by 2 pi in phi it still holds them (every quantity is 2 pi-periodic)."""
    ctx.prec = 128
    model = ArbModel(paper_geometry)
    c = models[0]
    box, pose = read_joint_box(c["box"]), np.array(c["pose"])
    assert torus_search(model, box, pose.tolist())[0]
    away = pose.copy()
    away[0] += 1.5 * (pose[0, 1] - pose[0, 0])
    ok, why = torus_search(model, box, away.tolist())
    assert not ok and "undecided" in why
    turned = pose.copy()
    turned[2] += 2 * np.pi
    turned[2, 0], turned[2, 1] = np.nextafter(turned[2, 0], -np.inf), np.nextafter(turned[2, 1], np.inf)
    assert torus_search(model, box, turned.tolist())[0]


def _graph_along(geometry, claim, k) -> bool:
    """Whether the sheet may well be a graph along axis k too: the normal (rho_l w_l) has certified signs in
    all three components on the claim's pose box, or the library's float Krawczyk inclusion holds for k."""
    from intervalkin.core.interval import Interval
    from intervalkin.kinematics.enclosures import det_a_gradient_interval, jacobian_interval
    from intervalkin.solve.fold_model import krawczyk_image, normal_signs, preconditioned

    X = np.array([[float(Fraction(v)) for v in side] for side in claim["pose"]])[None]
    R = np.array([[float(Fraction(v)) for v in side] for side in claim["box"]])[None]
    if np.all(normal_signs(geometry, X) != 0):
        return True
    i, j = [a for a in range(3) if a != k]
    Y, C = preconditioned((jacobian_interval(geometry, X), det_a_gradient_interval(geometry, X)), k)
    K = krawczyk_image(geometry, X, k, Interval(R[:, [i, j], 0], R[:, [i, j], 1]), Y, C)
    return bool(np.all(np.isfinite(K)) and np.all(K[..., 0] > X[..., 0]) and np.all(K[..., 1] < X[..., 1]))


def test_changed_axis_is_refused(paper_geometry, fold_paving, models):
    """A claim whose axis is changed is proved again from scratch: refused, unless the sheet is a graph
    along that axis as well (the library keeps the first axis that passes in its own rounds, on a
    pose box that may have shrunk since; the checker proves the changed claim on the box written)."""
    tried = refused = 0
    for c in models:
        for k in range(c["axis"]):
            changed = dict(c, axis=k)
            ok, _ = check_claim(paper_geometry, "joint_fold_model", changed)
            tried += 1
            refused += not ok
            assert not ok or _graph_along(paper_geometry, changed, k), ("accepted, not a graph along", k, c["id"])
    assert tried >= 5 and refused >= 0.8 * tried, (refused, tried)


def test_criterion_that_does_not_hold_is_refused(paper_geometry, models):
    c = next(c for c in models if c["criterion"]["name"] != "height_inside")
    assert "height_inside" in _refused_model(paper_geometry, dict(c, criterion={"name": "height_inside"}))


def test_swapped_sides_are_refused(paper_geometry, models):
    c = next(c for c in models if set(c["witnesses"]) == {"below", "above"})
    swapped = dict(c, witnesses={"below": c["witnesses"]["above"], "above": c["witnesses"]["below"]})
    assert "not proved below" in _refused_model(paper_geometry, swapped)


# --------------------------------------------------------------------------------------
# False joins
# --------------------------------------------------------------------------------------
def test_the_joins_verify_one_by_one(paper_geometry, joins, facts):
    for j in joins[:8]:
        ok, why = check_claim(paper_geometry, "joint_join", j, j["precision"], verified=facts)
        assert ok, why
    # without its models a join proves nothing
    ok, why = check_claim(paper_geometry, "joint_join", joins[0], joins[0]["precision"], verified={})
    assert not ok and "not a verified claim" in why


def test_link_point_moved_into_the_other_piece_is_refused(paper_geometry, models, joins, facts):
    """A link moved along its shared face to a point the checker places in the other piece."""
    by_id = {c["id"]: c for c in models}
    for j in joins:
        for t, link in enumerate(j["links"]):
            for at in (t, t + 1):
                node = j["nodes"][at]
                if "fold" not in node:
                    continue
                proof = facts[f"{MODELS}#{node['fold']}"]["fold"]
                a, b = _box_ends(j["nodes"][t], by_id), _box_ends(j["nodes"][t + 1], by_id)
                lo = [max(x[0], y[0]) for x, y in zip(a, b)]
                hi = [min(x[1], y[1]) for x, y in zip(a, b)]
                for f in np.linspace(0.02, 0.98, 9):
                    for g in np.linspace(0.02, 0.98, 9):
                        fr = iter((Fraction(f), Fraction(g)))
                        q = [lo[x] if lo[x] == hi[x] else lo[x] + next(fr) * (hi[x] - lo[x]) for x in range(3)]
                        if proof.side(q) == -node["side"]:
                            bad = copy.deepcopy(j)
                            bad["links"][t] = [exact_text(v) for v in q]
                            why = _refused_join(paper_geometry, bad, facts)
                            assert "the sheet of fold model" in why, why
                            return
    pytest.fail("no link of the written joins lies on a face that the sheet crosses")


def test_witness_moved_into_the_other_piece_is_refused(paper_geometry, models, joins, facts):
    by_id = {c["id"]: c for c in models}
    j = next(j for j in joins if "fold" in j["nodes"][-1]
             and set(by_id[j["nodes"][-1]["fold"]]["witnesses"]) == {"below", "above"})
    node = j["nodes"][-1]
    other = by_id[node["fold"]]["witnesses"]["above" if node["side"] < 0 else "below"]
    bad = copy.deepcopy(j)
    bad["ends"][1]["witness"] = other
    assert "end 1 witness: not proved" in _refused_join(paper_geometry, bad, facts)


def test_flipped_side_of_a_piece_is_refused(paper_geometry, joins, facts):
    j = copy.deepcopy(joins[0])
    t = next(t for t, n in enumerate(j["nodes"]) if "fold" in n)
    j["nodes"][t]["side"] *= -1
    assert "the sheet of fold model" in _refused_join(paper_geometry, j, facts)


def test_chain_through_an_undecided_box_is_refused(paper_geometry, models, joins, facts):
    """A fold piece replaced by its whole box called clear.  Its two witnesses (both verified, on the two
    sides) have different counts, so the box meets g(S): the torus search cannot clear it."""
    by_id = {c["id"]: c for c in models}
    for j in joins:
        for t, n in enumerate(j["nodes"]):
            if "fold" in n and set(by_id[n["fold"]]["witnesses"]) == {"below", "above"}:
                w = by_id[n["fold"]]["witnesses"]
                counts = {solve(paper_geometry, read_joint_point(w[s], s)).count for s in w}
                assert len(counts) == 2
                bad = copy.deepcopy(j)
                bad["nodes"][t] = {"clear": by_id[n["fold"]]["box"]}
                assert "not proved off g(S)" in _refused_join(paper_geometry, bad, facts)
                return
    pytest.fail("no written join uses a fold box with both witnesses")


def test_two_cells_of_different_counts_joined_are_refused(paper_geometry, joins, facts):
    a = joins[0]
    b = next(j for j in joins if j["ends"][0]["count"] != a["ends"][0]["count"])
    bad = copy.deepcopy(a)
    bad["ends"][1] = copy.deepcopy(b["ends"][1])
    assert "different counts" in _refused_join(paper_geometry, bad, facts)
    # the same, with the declared count copied over: the witness is not in the last node, or its solve differs
    bad["ends"][1].update({k: a["ends"][1][k] for k in ("count", "n_wa1", "n_wa2")})
    why = _refused_join(paper_geometry, bad, facts)
    assert "not inside the box" in why or "not proved" in why or "solutions" in why, why


def test_a_join_on_a_falsified_model_fails_in_the_folder(tmp_path, written, models, joins):
    """verify_directory: a model made false fails, and so does every join that uses it."""
    for name in ("index.json", MODELS, "joint_join.json"):
        (tmp_path / name).write_text((written / name).read_text())
    doc = _load(tmp_path, MODELS)
    victim = doc["claims"][0]
    pose = np.array(victim["pose"])
    victim["pose"] = np.stack([pose[:, 0], (pose[:, 0] + pose[:, 1]) / 2], -1).tolist()
    (tmp_path / MODELS).write_text(json.dumps(doc))
    results = {(r.file, r.claim): r for r in checker.verify_directory(tmp_path)}
    assert not results[(MODELS, victim["id"])].verified
    users = [j["id"] for j in joins if any(n.get("fold") == victim["id"] for n in j["nodes"])]
    assert users
    for jid in users:
        r = results[("joint_join.json", jid)]
        assert not r.verified and "not a verified claim" in r.message
    assert sum(r.verified for r in results.values()) == len(results) - 1 - len(users)


def test_malformed_claims_are_refused_not_crashed_on(paper_geometry, models, joins, facts):
    j = joins[0]
    for bad in (dict(j, nodes="x"), dict(j, links=j["links"][:-1]), dict(j, ends=j["ends"][:1]),
                dict(j, nodes=[dict(j["nodes"][0], clear=[["1", "2"]])] + j["nodes"][1:]),
                dict(j, links=[[1.5, 2, 3]] + j["links"][1:])):
        _refused_join(paper_geometry, bad, facts)
    fold = next(t for t, n in enumerate(j["nodes"]) if "fold" in n)
    bad = copy.deepcopy(j)
    bad["nodes"][fold]["side"] = True
    assert "side must be" in _refused_join(paper_geometry, bad, facts)
    c = models[0]
    for bad in (dict(c, axis=3), dict(c, box=c["box"][:2]), dict(c, pose=[[1, 0]] * 3), dict(c, criterion="x"),
                dict(c, witnesses=[]), {k: v for k, v in c.items() if k != "pose"}):
        _refused_model(paper_geometry, bad)


# --------------------------------------------------------------------------------------
# The checker's clear test and side test against the library and exact solves
# --------------------------------------------------------------------------------------
def _fr_box(box):
    return tuple((Fraction(float(a)), Fraction(float(b))) for a, b in box)


def test_clear_test_refuses_boxes_that_meet_g_s(paper_geometry):
    ctx.prec = 128
    assert not torus_search(ArbModel(paper_geometry), _fr_box(box_across_singular_image(paper_geometry)[0]))[0]
    g = load_geometry(DATA / "concurrent_legs.toml")
    for width in (1e-2, 1e-4):
        assert not torus_search(ArbModel(g), _fr_box(concurrent_legs_box(width)[0]))[0]


@settings(max_examples=20, deadline=None)
@given(st.floats(-20, 25), st.floats(-3.1, 3.1), st.sampled_from([1e-3, 0.05]))
def test_boxes_around_singular_images_are_never_clear(x, phi, width):
    """A singular pose bracketed in arb (det A changes sign along y), its joint vector boxed: never clear."""
    from intervalkin.core.geometry import default_geometry

    g = default_geometry()
    ys = np.linspace(-25.0, 25.0, 401)
    c = first_det_change(g, x, phi, ys)
    if c is None:
        return
    a, b = ys[c], ys[c + 1]
    ctx.prec = 128
    model = ArbModel(g)
    da, db = model.det(arb(x), arb(a), arb(phi)), model.det(arb(x), arb(b), arb(phi))
    if not ((da < 0 and db > 0) or (da > 0 and db < 0)):
        return
    rho = approx_inverse_kinematics(g, np.array([[x, a, phi], [x, b, phi]]))
    lo, hi = rho.min(axis=0) - width, rho.max(axis=0) + width
    if lo.min() <= 1.0:
        return
    box = tuple((Fraction(float(u)), Fraction(float(v))) for u, v in zip(lo, hi))
    assert not torus_search(model, box, budget=5000)[0], (x, phi, box)


def test_library_clear_boxes_are_re_proved(paper_geometry, fold_paving):
    """Clear leaves of both kinds, re-proved by the checker's torus search: those the library cleared by its own
    torus search, and those it cleared by Krawczyk exclusion (``voided``), which the checker re-proves with its
    own exclusion of small cells (proofs/lemma-clear-joint-box.md, point 5)."""
    pav = fold_paving.paving
    clear = pav.labels["clear"] == Label.INSIDE
    voided = np.flatnonzero(fold_paving.voided)
    assert voided.size >= 100 and clear[voided].all()
    searched = np.flatnonzero(clear & ~fold_paving.voided)
    ctx.prec = 128
    model = ArbModel(paper_geometry)
    rng = np.random.default_rng(3)
    for i in np.concatenate([rng.choice(searched, 20, replace=False), rng.choice(voided, 40, replace=False)]):
        ok, why = torus_search(model, _fr_box(np.stack([pav.lo[i], pav.hi[i]], -1)))
        assert ok, (i, why)


def test_side_test_agrees_with_the_library_and_with_solves(paper_geometry, fold_paving, models, facts):
    """Random exact points of the written fold boxes: the checker's side equals the library's where both
    decide, and points placed on one side have the solution count of that side's witness."""
    pc = fold_paving.pieces
    row = {int(b): t for t, b in enumerate(pc.box)}
    rng = np.random.default_rng(5)
    agreed = counted = 0
    for c in models[:12]:
        proof = facts[f"{MODELS}#{c['id']}"]["fold"]
        box = proof.box
        t = row[int(c["id"].split("-")[1])]
        wit_count = {}
        for name, s in (("below", -1), ("above", 1)):
            if name in c["witnesses"]:
                wit_count[s] = solve(paper_geometry, read_joint_point(c["witnesses"][name], name)).count
        for _ in range(4):
            q = [lo + Fraction(int(rng.integers(1, 999)), 1000) * (hi - lo) for lo, hi in box]
            assert in_joint_box(q, box)
            mine = proof.side(q)
            lib = placed_side(paper_geometry, pc.models, np.array([t]), np.array([[float(v) for v in q]]))[0]
            if mine and lib:
                assert mine == lib
                agreed += 1
            if mine in wit_count:
                res = solve(paper_geometry, q)
                assert res.complete and res.count == wit_count[mine], (q, mine, res.count, wit_count)
                counted += 1
    assert agreed >= 30 and counted >= 15


def test_component_joins_link_clear_components(paper_geometry, fold_models_5):
    """Without join levels, cells of the paper's manipulator are several face-connected groups of clear boxes
    that only fold pieces join (with the local models, fold and voided boxes along g(S); 28 groups beyond the
    first of each cell at depth 5): the writer plans one component join per group beyond the first of each
    cell, and the two written come first, end in clear boxes of two different groups of one cell, and verify."""
    from intervalkin.certify.joint_claims import joint_claims
    from intervalkin.paving.adjacency import component_labels, shares_face

    jsp = fold_models_5  # pave_joint_space(paper_geometry, 5, 0, fold=True, model_levels=1), tests/conftest.py
    models, joins, omitted = joint_claims(paper_geometry, jsp, max_joins=2, max_models=8)
    pav = jsp.paving
    clear = jsp.cell >= 0
    comp = component_labels(len(pav), shares_face(pav.level, pav.ijk, int(pav.level.max()), (False,) * 3), clear)
    extra = sum(np.unique(comp[clear & (jsp.cell == c)]).size - 1 for c in np.unique(jsp.cell[clear]))
    planned = re.search(r"(\d+) joining clear components", omitted[-1]["what"])
    assert len(joins) == 2 and planned and int(planned.group(1)) == extra >= 2, (extra, omitted[-1])
    leaf_of = {tuple((float(a), float(b)) for a, b in zip(pav.lo[i], pav.hi[i])): i for i in np.flatnonzero(clear)}
    facts = {f"{MODELS}#{c['id']}": run_check(paper_geometry, "joint_fold_model", c, 128)[1] for c in models}
    for j in joins:
        ends = [j["nodes"][0], j["nodes"][-1]]
        assert all("clear" in n for n in ends)
        leaves = [leaf_of[tuple((float(a), float(b)) for a, b in read_joint_box(n["clear"]))] for n in ends]
        assert jsp.cell[leaves[0]] == jsp.cell[leaves[1]] and comp[leaves[0]] != comp[leaves[1]]
        ok, why = check_claim(paper_geometry, "joint_join", j, j["precision"], verified=facts)
        assert ok, why
