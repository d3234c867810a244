"""The open places of a joint paving (space.joint_places): face-connected groups of leaves not certified."""

from __future__ import annotations

import numpy as np
import pytest

from intervalkin.solve.window_fold import CLEAR, FOLD
from intervalkin.space.joint_places import REASONS, open_places


def _grid(depth: int):
    n = 2 ** depth
    ijk = np.array([(i, j, k) for i in range(n) for j in range(n) for k in range(n)], dtype=np.int64)
    lo = ijk / n
    return np.full(len(ijk), depth), ijk, lo, lo + 1.0 / n


def test_two_groups_apart_are_two_places():
    level, ijk, lo, hi = _grid(2)
    open_leaf = np.zeros(len(ijk), dtype=bool)
    # an L of three boxes at one corner, one box at the opposite corner, one box touching the L by an edge only
    for t in [(0, 0, 0), (1, 0, 0), (1, 1, 0), (3, 3, 3), (2, 2, 0)]:
        open_leaf[np.flatnonzero((ijk == t).all(axis=1))] = True
    no_model = open_leaf.copy()
    no_model[np.flatnonzero((ijk == (3, 3, 3)).all(axis=1))] = False
    domain = np.array([[0.0, 1.0]] * 3)
    reason = np.where(no_model, REASONS.index("no_model"), REASONS.index("cusp_window"))
    n, places = open_places(level, ijk, lo, hi, open_leaf, no_model, domain, np.where(open_leaf, reason, -1))
    assert n == 3  # face connection only: (2, 2, 0) touches (1, 1, 0) along an edge
    assert [p.leaves for p in places] == [3, 1, 1]
    assert places[0].lo == (0.0, 0.0, 0.0) and places[0].hi == (0.5, 0.5, 0.25)
    assert sum(p.without_model for p in places) == 4 and all(p.on_face for p in places)
    assert places[0].why == (("no_model", 3, 3 / 64),)
    assert [p.to_json()["why"] for p in places[1:]] == [{"no_model": {"leaves": 1, "volume": 1 / 64}},
                                                         {"cusp_window": {"leaves": 1, "volume": 1 / 64}}]


def test_places_cover_the_open_leaves_of_a_paving(fold_paving):
    block = fold_paving.open_places()
    places = block["places"]
    vol = [q["volume"] for q in places["largest"]]
    assert places["count"] >= len(vol) > 0 and vol == sorted(vol, reverse=True)
    # the listed places hold at most the undecided volume, and the largest ones most of it
    assert sum(vol) <= block["joint_volume"] * (1 + 1e-9)
    assert places["volume_without_model"] <= block["joint_volume"] * (1 + 1e-9)
    assert sum(q["leaves"] for q in places["largest"]) >= 1


def test_every_open_leaf_has_its_reason(fold_paving):
    """The reasons count every open leaf once: their totals are the undecided volume, each listed place's reasons
    add up to its leaves and volume, and no leaf is left without a known reason."""
    places = fold_paving.open_places()["places"]
    by = places["by_reason"]
    assert "other" not in by and set(by) <= set(REASONS)
    assert sum(v["volume"] for v in by.values()) == pytest.approx(fold_paving.open_places()["joint_volume"], rel=1e-9)
    for q in places["largest"]:
        assert sum(v["leaves"] for v in q["why"].values()) == q["leaves"]
        assert sum(v["volume"] for v in q["why"].values()) == pytest.approx(q["volume"], rel=1e-9)
        assert q["why"].get("no_model", {}).get("leaves", 0) == q["without_model"]


def test_window_reasons_follow_the_windows(fold_paving):
    """A leaf's reason, re-derived window by window from its model: a cusp window (odd, degree 3, proved box-wide),
    a window proved only at points, two pair windows or more, or one pair window that is not a window fold."""
    w = fold_paving.windows
    why = w.why_not_pieced(len(fold_paving.cell))
    m = w.models
    seen = set()
    for row, leaf in enumerate(w.leaf.tolist()):
        first, num = m.windows_of(np.array([row]))
        kinds = []
        for j in range(int(first[0]), int(first[0] + num[0])):
            e = m.end_signs[j]
            if e[0] == 0 or e[1] == 0 or m.d_sign[j] == 0:
                kinds.append("points")
            elif e[0] == e[1]:
                kinds.append("pair")
            elif m.degree[j] == 3:
                kinds.append("cusp")
        if not m.ok[row] or w.folds.kind[row] in (CLEAR, FOLD):
            expected = -1
        elif "cusp" in kinds:
            expected = 0
        elif "points" in kinds:
            expected = 1
        else:
            expected = 2 if kinds.count("pair") > 1 else 3
            assert kinds.count("pair") >= 1
        assert why[leaf] == expected, (leaf, kinds, why[leaf])
        seen.add(expected)
    assert {0, 1, 2, 3} <= seen  # every reason occurs on this paving


def test_the_npz_gives_every_open_leaf_its_place_and_reason(fold_paving):
    """Every place is listed in pavings/joint.npz, not only the largest in summary.json: open_place and open_reason
    are set exactly on the open leaves, and place k of the columns is the k-th place of the summary's list."""
    cols = fold_paving.columns()
    place, reason = cols["open_place"], cols["open_reason"]
    assert np.array_equal(place >= 0, reason >= 0)
    places = fold_paving.open_places()["places"]
    assert place.max() + 1 == places["count"]
    for q in places["largest"][:5]:
        mine = place == q["place"]
        assert mine.sum() == q["leaves"]
        assert cols["lo"][mine].min(axis=0).tolist() == q["lo"] and cols["hi"][mine].max(axis=0).tolist() == q["hi"]
        counts = np.bincount(reason[mine], minlength=len(REASONS))
        assert {REASONS[i]: int(counts[i]) for i in np.flatnonzero(counts)} == {k: v["leaves"]
                                                                              for k, v in q["why"].items()}
