"""The summary's counts: the separations' basic-region bound is shown beside the certified one, never as it."""

from __future__ import annotations

import copy

from intervalkin.app.summary import add_separation_bound, chain_table

BASE = {
    "aspects": {"count": 2, "found": 2, "lower": 2, "lower_bound": 2, "upper": 2, "exact": True, "why": "covers"},
    "basic_regions": {"count": 22, "found": 22, "lower": 12, "lower_bound": 12, "upper": None, "exact": False,
                      "why": "sum of the cells"},
    "uniqueness_domains": {"count": 6, "found": 6, "lower": 6, "lower_bound": 6, "upper": None, "exact": False,
                           "why": "Theorem 2", "minimal": True},
    "joint_cells": {"cells": [{"count": 2, "volume": 1.0}], "certified_share": 0.99,
                    "separations": {"basic_regions_at_least": 18}},
    "undecided_volume": {"W": 1.0, "WA1": 0.5, "WA2": 0.5},
    "depth": {"workspace": 8, "singular_layer": 9, "joint": 7},
}


def test_a_higher_separation_bound_is_shown_apart_from_the_certified_one():
    s = copy.deepcopy(BASE)
    add_separation_bound(s)
    block = s["basic_regions"]
    assert block["separations_at_least"] == 18
    assert block["lower"] == 12 and block["lower_bound"] == 12  # the certified bound is left alone
    assert "not re-prove" in block["why"]
    table = chain_table(s)
    row = next(line for line in table.splitlines() if line.startswith("basic regions"))
    assert "certified lower bound 12" in row and "at least 18 by separations" in row


def test_no_separation_bound_when_it_adds_nothing():
    for sep in ({"basic_regions_at_least": 12}, None):
        s = copy.deepcopy(BASE)
        s["joint_cells"]["separations"] = sep
        add_separation_bound(s)
        assert "separations_at_least" not in s["basic_regions"]
        assert s["basic_regions"]["why"] == "sum of the cells"


def test_a_separation_bound_that_meets_the_count_says_so_and_stays_a_lower_bound():
    s = copy.deepcopy(BASE)
    s["joint_cells"]["separations"] = {"basic_regions_at_least": 22}
    add_separation_bound(s)
    block = s["basic_regions"]
    assert block["separations_at_least"] == 22 and not block["exact"] and block["upper"] is None
    row = next(line for line in chain_table(s).splitlines() if line.startswith("basic regions"))
    assert "at least 22 by separations" in row and "the count found: no upper bound yet" in row
    assert not row.rstrip().endswith("exact")


def test_the_chain_summary_reads_the_analysis_topology_without_recomputing_it(monkeypatch):
    """The closed cells and separations come with the analysis (computed beside the regions, in the joint
    paving's process); the summary reports those and computes neither again."""
    import intervalkin.app.summary as summary
    from intervalkin.space.joint_closure import closed_cells
    from intervalkin.space.joint_separation import separated_cells

    from .shared import chain

    a = chain(6)
    assert a.closure is not None and a.separation is not None
    assert a.separation.to_json() == separated_cells(a.cells, a.geometry).to_json()
    assert a.closure.to_json() == closed_cells(a.cells, a.geometry).to_json()

    def again(*args, **kwargs):
        raise AssertionError("the summary computed the cells' topology again")

    monkeypatch.setattr(summary, "separated_cells", again)
    monkeypatch.setattr(summary, "closed_cells", again)
    s = summary.chain_summary(a)
    assert s["joint_cells"]["separations"] == a.separation.to_json()
    assert s["joint_cells"]["closed_cells"] == a.closure.to_json()


def test_count_barriers_are_reported_beside_the_separations():
    """Each barrier claim tells its cell from every other cell of its signature: k claims, k + 1 components; the
    other signatures count one component each (their witnesses' splits differ)."""
    from intervalkin.app.summary import add_barrier_certificates

    summary = {"joint_cells": {"separations": {"by_signature": [
        {"signature": [0, 0, 0]}, {"signature": [2, 1, 1]}, {"signature": [4, 2, 2]}]}}}
    summary["basic_regions"] = {"lower_bound": 6, "why": "Theorem 1"}

    def at(*q):
        return {"witness": [str(v) for v in q]}

    w7, w6, w5 = at(11, 11, 11), at(12, 12, 12), at(13, 13, 13)
    claims = [{"cell": 7, "signature": [0, 0, 0], "witness": w7, "others": [w6, w5]},
              {"cell": 6, "signature": [0, 0, 0], "witness": w6, "others": [w7, w5]},
              {"cell": 3, "signature": [4, 2, 2], "kind": "pattern", "witness": at(14, 15, 16),
               "others": [at(17, 18, 19)]}]
    add_barrier_certificates(summary, claims)
    got = summary["joint_cells"]["separations"]["count_barriers"]
    assert [r["components_at_least"] for r in got["by_signature"]] == [3, 2]
    assert got["components_at_least"] == 5 and got["all_components_at_least"] == 3 + 1 + 2
    # 2 components of 4 solutions, 1 of 2: Theorem 1 puts 2 * 4 + 1 * 2 basic regions above them
    assert got["basic_regions_at_least"] == 2 * 4 + 2
    assert got["pattern_barrier_cells"] == [3] and got["count_barrier_cells"] == [6, 7]
    block = summary["basic_regions"]
    assert block["barriers_at_least"] == 10 and "re-proved by" in block["why"]
    # the certified lower bound is the raised one, the claim's own kept beside it
    assert block["lower_bound"] == 10 and block["counts_claim_lower"] == 6 and block["exact"] is False
    empty = {"joint_cells": {"separations": {"by_signature": []}}}
    add_barrier_certificates(empty, [])
    assert "count_barriers" not in empty["joint_cells"]["separations"]


def test_the_report_says_which_separations_the_certificates_hold():
    from intervalkin.app.report_joint import _barrier_text
    from intervalkin.app.summary import add_barrier_certificates

    summary = {"joint_cells": {"separations": {"by_signature": [{"signature": [0, 0, 0]}, {"signature": [2, 1, 1]}]}}}
    sep = summary["joint_cells"]["separations"]
    assert "not yet in the certificates" in _barrier_text(sep)
    add_barrier_certificates(summary, [{"cell": 7, "signature": [0, 0, 0], "witness": {"witness": ["11", "11", "11"]},
                                        "others": [{"witness": ["12", "12", "12"]}, {"witness": ["13", "13", "13"]}]}])
    text = _barrier_text(sep)
    assert "cell 7 from" in text and "at least 3 components" in text and "joint_separation.json" in text
