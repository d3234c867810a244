"""Count and pattern barriers: built on a joint paving of the paper's manipulator, re-proved from the files,
and refused when the files are made false.

The paving is the depth-5 paving with window models of ``tests/conftest.py`` (``fold_paving``).  Every
mutation below breaks exactly one hypothesis of proofs/lemma-count-barrier.md or
proofs/lemma-pattern-barrier.md and must be refused.
"""

from __future__ import annotations

import json
from fractions import Fraction

import numpy as np
import pytest

from intervalkin.certify.separation_claims import separation_claims
from intervalkin.checker.parse import Refused
from intervalkin.core.errors import CertificateFormatError
from intervalkin.core.files import write_json
from intervalkin.recheck.arc_pattern import box_arcs, pattern_of_angles, unpack
from intervalkin.recheck.reduced_equation import reduced_constants
from intervalkin.recheck.separation_file import ARRAYS, CLAIMS, check_pattern_separation, check_separation, \
    recheck_separations
from intervalkin.solve.dkp import solve


#: The pattern floods' face budget for ``every``: cell 10's barrier ranges about 900 faces; the default 16000 would
#: then spend about 70 s on cell 7's flood, which leaks, before the other 4-solution cells are left out by the budget
#: (the budget rule and the leak have their own tests below).
BUDGET = 3000


@pytest.fixture(scope="module")
def every(fold_paving, paper_geometry):
    return separation_claims(paper_geometry, fold_paving, budget=BUDGET)


@pytest.fixture(scope="module")
def built(every):
    """The count barriers (the first claims of the file)."""
    claims, arrays, omitted = every
    return [c for c in claims if c.get("kind", "count") == "count"], arrays, omitted


def _pattern_parts(arrays, j):
    """(region, patterns per region box, barrier, barrier's region box (local), outer boxes) of claim j."""
    rows = arrays["region_claim"] == j
    index = np.flatnonzero(rows)
    local = np.full(rows.size, -1)
    local[index] = np.arange(index.size)
    walls = arrays["barrier_claim"] == j
    patterns = [set() for _ in index]
    mine = rows[arrays["pattern_box"]]
    for r, pat in zip(local[arrays["pattern_box"][mine]], unpack(arrays["pattern_rows"][mine])):
        patterns[r].add(pat)
    return ((arrays["region_lo"][rows], arrays["region_hi"][rows]), patterns,
            (arrays["barrier_lo"][walls], arrays["barrier_hi"][walls]), local[arrays["barrier_box"][walls]],
            (arrays["barrier_outer_lo"][walls], arrays["barrier_outer_hi"][walls]))


@pytest.fixture(scope="module")
def patterned(every):
    claims, arrays, _ = every
    j = next(j for j, c in enumerate(claims) if c.get("kind") == "pattern")
    return claims[j], _pattern_parts(arrays, j)


def _parts(arrays, j):
    r, w = arrays["region_claim"] == j, arrays["barrier_claim"] == j
    return (arrays["region_lo"][r], arrays["region_hi"][r]), (arrays["barrier_lo"][w], arrays["barrier_hi"][w])


def test_the_barriers_of_the_paper_paving_verify(built, paper_geometry):
    claims, arrays, omitted = built
    # the four cells without solutions: three count barriers tell them all apart; the cells with solutions meet
    # at transversal crossings of two sheets, where only the patterns of their solutions tell them apart
    assert len(claims) == 3 and {c["signature"][0] for c in claims} == {0}
    assert any("another cell of its signature" in o["why"] for o in omitted)
    rng = np.random.default_rng(5)
    for j, claim in enumerate(claims):
        region, barrier = _parts(arrays, j)
        msg, facts = check_separation(paper_geometry, claim, region, barrier)
        assert facts["cell"] == claim["cell"] and len(facts["others"]) == 3
        # the barrier is what the lemma needs it to be: sampled, it never holds a point of the count
        for i in rng.choice(len(barrier[0]), 40, replace=False):
            q = tuple(Fraction(float(v)) for v in rng.uniform(barrier[0][i], barrier[1][i]))
            res = solve(paper_geometry, q)
            assert not res.complete or len(res.solutions) != claim["signature"][0]


def test_a_missing_barrier_face_is_refused(built, paper_geometry):
    claims, arrays, _ = built
    region, barrier = _parts(arrays, 0)
    with pytest.raises(Refused, match="lie on no barrier box"):
        check_separation(paper_geometry, claims[0], region, (barrier[0][1:], barrier[1][1:]))


def test_a_region_box_taken_away_is_refused(built, paper_geometry):
    """Without one of its inner boxes the region has a hole whose walls carry no barrier."""
    claims, arrays, _ = built
    region, barrier = _parts(arrays, 1)
    lo, hi = region
    inner = [i for i in range(len(lo)) if not np.any(np.isin(lo[i], barrier[0]))]
    drop = inner[len(inner) // 2]
    keep = np.arange(len(lo)) != drop
    with pytest.raises(Refused):
        check_separation(paper_geometry, claims[1], (lo[keep], hi[keep]), barrier)


def test_a_barrier_face_with_points_of_the_count_is_refused(built, paper_geometry):
    claims, arrays, _ = built
    region, barrier = _parts(arrays, 0)
    x = np.array([float(Fraction(v)) for v in claims[0]["witness"]["witness"]])
    inside = (np.vstack([barrier[0], x - 1e-3]), np.vstack([barrier[1], x + 1e-3]))
    with pytest.raises(Refused, match="not proved free of 0 solutions"):
        check_separation(paper_geometry, claims[0], region, inside)


def test_a_witness_outside_the_region_is_refused(built, paper_geometry):
    claims, arrays, _ = built
    region, barrier = _parts(arrays, 0)
    swapped = dict(claims[0], witness=claims[0]["others"][0], others=[claims[0]["witness"]])
    with pytest.raises(Refused, match="not inside a box of the region"):
        check_separation(paper_geometry, swapped, region, barrier)


def test_another_cell_inside_the_region_is_refused(built, paper_geometry):
    claims, arrays, _ = built
    region, barrier = _parts(arrays, 0)
    same = dict(claims[0], others=[claims[0]["witness"]])
    with pytest.raises(Refused, match="may lie in the region"):
        check_separation(paper_geometry, same, region, barrier)


def test_a_false_signature_is_refused(built, paper_geometry):
    claims, arrays, _ = built
    region, barrier = _parts(arrays, 0)
    with pytest.raises(Refused, match="not the claimed signature"):
        check_separation(paper_geometry, dict(claims[0], signature=[2, 1, 1]), region, barrier)


def test_the_pattern_barrier_verifies(patterned, paper_geometry, monkeypatch):
    """The cell with 2 solutions next to the big one (they meet where two sheets cross) has a pattern barrier;
    sampled on its barrier faces, the solver's solutions never show a pattern of the region box's set.  Some of
    its walls are faces of clear boxes of another count that only split count ranges close (fact 4 of the
    lemma): the checker asks those proofs only of faces the claim would otherwise fail on, and uses some."""
    import intervalkin.recheck.separation_file as sf
    claim, (region, patterns, barrier, box, outer) = patterned
    assert claim["signature"][0] == 2
    emptied = []
    real = sf.prune_relations

    def spy(k, f_lo, f_hi, rels, count, which):
        out = real(k, f_lo, f_hi, rels, count, which)
        emptied.extend(int(i) for i in which if rels[i] and not out[i])
        return out

    monkeypatch.setattr(sf, "prune_relations", spy)
    msg, facts = check_pattern_separation(paper_geometry, claim, region, patterns, barrier, box, outer)
    assert emptied  # without these proofs the claim would be refused
    assert facts["cell"] == claim["cell"] and "shared faces (" in msg
    k = reduced_constants(paper_geometry)
    arcs = box_arcs(k, *region)
    rng = np.random.default_rng(7)
    seen = 0
    for t in rng.choice(len(barrier[0]), 150, replace=False):
        q = rng.uniform(barrier[0][t], barrier[1][t])
        res = solve(paper_geometry, tuple(Fraction(float(v)) for v in q))
        if not res.complete or len(res.solutions) != 2:
            continue
        phi = np.array([s.box[2][0] for s in res.solutions]), np.array([s.box[2][1] for s in res.solutions])
        assert pattern_of_angles(arcs.signs[box[t]], *phi) not in patterns[box[t]]
        seen += 1
    assert seen > 5  # the faces do hold points of the count: only the patterns tell them apart


def test_a_pattern_barrier_without_a_face_is_refused(patterned, paper_geometry):
    claim, (region, patterns, barrier, box, outer) = patterned
    cut = lambda v: (v[0][1:], v[1][1:])  # noqa: E731
    with pytest.raises(Refused, match="lie on no barrier box"):
        check_pattern_separation(paper_geometry, claim, region, patterns, cut(barrier), box[1:], cut(outer))


def test_a_pattern_dropped_from_a_box_is_refused(patterned, paper_geometry):
    """Emptying the set of a box inside the region breaks the consistency on its faces (or the witness)."""
    claim, (region, patterns, barrier, box, outer) = patterned
    inner = [i for i in range(len(patterns)) if i not in set(box.tolist()) and patterns[i]]
    changed = list(patterns)
    changed[inner[len(inner) // 2]] = set()
    with pytest.raises(Refused, match="shared face|witness"):
        check_pattern_separation(paper_geometry, claim, region, changed, barrier, box, outer)


def test_the_other_pattern_added_is_refused(patterned, paper_geometry):
    """A barrier box's region box given every pattern its face relation allows is no longer walled off."""
    claim, (region, patterns, barrier, box, outer) = patterned
    k = reduced_constants(paper_geometry)
    from intervalkin.recheck.arc_pattern import face_relations
    arcs = box_arcs(k, *region)
    rels = face_relations(k, barrier[0], barrier[1], arcs.take(box), box_arcs(k, *outer), claim["signature"][0])
    t = next(t for t, rel in enumerate(rels) if rel)  # a barrier face that may hold points of the count
    changed = list(patterns)
    changed[box[t]] = set(patterns[box[t]]) | {u for u, _ in rels[t]}
    with pytest.raises(Refused):
        check_pattern_separation(paper_geometry, claim, region, changed, barrier, box, outer)


def test_a_swapped_pattern_witness_is_refused(patterned, paper_geometry):
    claim, (region, patterns, barrier, box, outer) = patterned
    swapped = dict(claim, witness=claim["others"][0], others=[claim["witness"]])
    with pytest.raises(Refused, match="witness"):
        check_pattern_separation(paper_geometry, swapped, region, patterns, barrier, box, outer)


def test_the_face_budget_bounds_the_pattern_floods(fold_paving, paper_geometry, every):
    """--barrier-faces is the floods' budget for the whole paving: with none left no cell is tried, and each cell
    left out says so; with BUDGET the paper paving's barrier is made (``every``)."""
    from intervalkin.certify.separation_claims import pattern_barriers

    made, omitted = pattern_barriers(fold_paving, paper_geometry, budget=0)
    assert made == [] and omitted
    assert all("--barrier-faces 0" in o["why"] for o in omitted if "boxes of the paving" in o["why"])
    assert any("--barrier-faces 0" in o["why"] for o in omitted)
    assert any(c.get("kind") == "pattern" for c in every[0])


def test_the_folder_is_read_and_a_corrupt_file_is_a_format_error(built, paper_geometry, tmp_path):
    claims, arrays, _ = built
    cert = tmp_path / "certificates"
    write_json(cert / "index.json", {"geometry_toml": paper_geometry.to_toml()})
    write_json(tmp_path / CLAIMS, {"claims": claims[:1]})
    keep = {k: v for k, v in arrays.items()}
    walls = keep["barrier_claim"] == 0
    for k in ("barrier_box", "barrier_outer_lo", "barrier_outer_hi"):
        keep[k] = keep[k][walls]
    keep["pattern_box"], keep["pattern_rows"] = keep["pattern_box"][:0], keep["pattern_rows"][:0]
    for name in ("region", "barrier"):
        rows = keep[f"{name}_claim"] == 0
        for col in ("lo", "hi", "claim"):
            keep[f"{name}_{col}"] = keep[f"{name}_{col}"][rows]
    np.savez(tmp_path / ARRAYS, **keep)
    results = recheck_separations(tmp_path)
    assert len(results) == 1 and results[0].verified and results[0].kind == "joint_separation"
    assert recheck_separations(cert)[0].verified  # the certificates folder itself is accepted too
    (tmp_path / ARRAYS).write_bytes(b"not an npz")
    with pytest.raises(CertificateFormatError, match="cannot read"):
        recheck_separations(tmp_path)
    assert recheck_separations(tmp_path / "nothing") == []
    json.loads((tmp_path / CLAIMS).read_text())


def test_the_summary_bound_of_the_barriers_is_checked(built, paper_geometry, tmp_path):
    """verify adds one verdict on summary.json's basic_regions.barriers_at_least: the counts claim's bound plus n
    per separated cell of n solutions, over the claims it verified; a higher stated number fails."""
    from intervalkin.recheck.separation_file import barrier_bound

    def at(*q):
        return {"witness": [str(v) for v in q]}

    a, b, c, d = at(11, 12, 13), at(14, 15, 16), at("17.5", 18, 19), at(20, 21, 22)
    claims = [{"signature": [2, 1, 1], "cell": 9, "witness": a, "others": [b]},
              {"signature": [4, 2, 2], "cell": 3, "witness": c, "others": [a, d]},
              {"signature": [4, 2, 2], "cell": 3, "witness": c, "others": [a, d]},
              {"signature": [0, 0, 0], "cell": 7, "witness": d, "others": [a]}]
    assert barrier_bound(12, claims, [True, True, True, True]) == 12 + 2 + 4  # the repeated claim counted once
    assert barrier_bound(12, claims, [False, True, True, True]) == 16
    # one claim per cell of a signature proves its cells apart, no more: 2 cells of 2 solutions, not 3
    both = [{"signature": [2, 1, 1], "cell": 0, "witness": a, "others": [b]},
            {"signature": [2, 1, 1], "cell": 9, "witness": b, "others": [a]}]
    assert barrier_bound(12, both, [True, True]) == 14
    # a witness renamed as another cell is still one point
    renamed = [{"signature": [2, 1, 1], "cell": 0, "witness": a, "others": [b]},
               {"signature": [2, 1, 1], "cell": 5, "witness": a, "others": [b]}]
    assert barrier_bound(12, renamed, [True, True]) == 14
    # three cells, each told from the two others by one claim each: a triangle, 3 components
    tri = [{"signature": [4, 2, 2], "cell": i, "witness": w, "others": o}
           for i, (w, o) in enumerate(((a, [b, c]), (b, [c])))]
    assert barrier_bound(12, tri, [True, True]) == 12 + 4 * 2
    c, arrays, _ = built
    write_json(tmp_path / "certificates" / "index.json", {"geometry_toml": paper_geometry.to_toml()})
    write_json(tmp_path / "certificates" / "counts.json", {"claims": [{"name": "basic_regions", "lower_bound": 12}]})
    write_json(tmp_path / CLAIMS, {"claims": c[:1]})
    keep = dict(arrays)
    walls, rows = keep["barrier_claim"] == 0, keep["region_claim"] == 0
    for k in ("barrier_box", "barrier_outer_lo", "barrier_outer_hi", "barrier_lo", "barrier_hi", "barrier_claim"):
        keep[k] = keep[k][walls]
    for k in ("region_lo", "region_hi", "region_claim"):
        keep[k] = keep[k][rows]
    keep["pattern_box"], keep["pattern_rows"] = keep["pattern_box"][:0], keep["pattern_rows"][:0]
    np.savez(tmp_path / ARRAYS, **keep)
    for stated, ok in ((12, True), (13, False)):
        write_json(tmp_path / "summary.json", {"basic_regions": {"barriers_at_least": stated}})
        last = recheck_separations(tmp_path)[-1]
        assert last.kind == "barrier_bound" and last.verified is ok, last.line()
    # a bound stated from barriers with the barrier file gone is refused, not passed over
    (tmp_path / CLAIMS).unlink()
    write_json(tmp_path / "summary.json", {"basic_regions": {"barriers_at_least": 14}})
    got = recheck_separations(tmp_path)
    assert [r.kind for r in got] == ["barrier_bound"] and not got[0].verified, got[0].line()


def test_a_folder_with_a_pattern_barrier_verifies_and_a_torn_tie_is_refused(every, paper_geometry, tmp_path):
    """The whole file as the builder writes it (count and pattern claims in one npz) is re-proved claim by claim;
    a pattern barrier whose wall rows point to no region box of the claim is refused, not a crash."""
    claims, arrays, _ = every
    write_json(tmp_path / "certificates" / "index.json", {"geometry_toml": paper_geometry.to_toml()})
    write_json(tmp_path / CLAIMS, {"claims": claims})
    np.savez(tmp_path / ARRAYS, **arrays)
    results = recheck_separations(tmp_path)
    assert len(results) == len(claims) and all(r.verified for r in results), [r.line() for r in results]
    j = next(j for j, c in enumerate(claims) if c.get("kind") == "pattern")
    torn = dict(arrays)
    torn["barrier_box"] = np.where(arrays["barrier_claim"] == j, -1, arrays["barrier_box"])
    np.savez(tmp_path / ARRAYS, **torn)
    got = recheck_separations(tmp_path)[j]
    assert not got.verified and "barrier_box" in got.message



def test_a_leaking_flood_names_where_it_leaks(fold_paving, paper_geometry, monkeypatch):
    """A flood given up because its patterns reach another cell's boxes says where (the boxes it reached), the
    place a finer paving would be needed: here a clear leaf's neighbour of the same cell is called a rival."""
    import intervalkin.certify.pattern_barriers as pb
    from intervalkin.paving.adjacency import shares_face
    from intervalkin.paving.tree import box_bounds
    from intervalkin.recheck.arc_pattern import own_patterns

    p, cell = fold_paving.paving, fold_paving.cell
    lo, hi = box_bounds(p.domain, p.level, p.ijk)
    a, b = shares_face(p.level, p.ijk, int(p.level.max()), periodic=(False, False, False))
    k = reduced_constants(paper_geometry)
    counts = {c.id: c.signature[0] for c in fold_paving.cells}
    pair = next((x, y) for x, y in zip(a.tolist(), b.tolist())
                if cell[x] >= 0 and cell[x] == cell[y] and counts[int(cell[x])] > 0
                and len(own_patterns(box_arcs(k, lo[[x]], hi[[x]]), counts[int(cell[x])])[0]) == 1)
    x, y = pair
    count = counts[int(cell[x])]
    start = (x, next(iter(own_patterns(box_arcs(k, lo[[x]], hi[[x]]), count)[0])))
    monkeypatch.setattr(pb, "RIVAL_BOXES", 0)
    bar, why, _ = pb.flood(paper_geometry, lo, hi, a, b, count, start, {}, np.array([y]), budget=1000)
    assert bar is None and "another cell of its signature in [" in why
    assert f"[{lo[y][0]:.3f}, {lo[y][1]:.3f}, {lo[y][2]:.3f}] x [{hi[y][0]:.3f}" in why, why
