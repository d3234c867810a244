"""The open places of a joint paving (space.joint_places): face-connected groups of leaves not certified."""

from __future__ import annotations

import numpy as np

from intervalkin.space.joint_places import open_places


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
    n, places = open_places(level, ijk, lo, hi, open_leaf, no_model, domain)
    assert n == 3  # face connection only: (2, 2, 0) touches (1, 1, 0) along an edge
    assert [p.leaves for p in places] == [3, 1, 1]
    assert places[0].lo == (0.0, 0.0, 0.0) and places[0].hi == (0.5, 0.5, 0.25)
    assert sum(p.without_model for p in places) == 4 and all(p.on_face for p in places)


def test_places_cover_the_open_leaves_of_a_paving(fold_paving):
    block = fold_paving.open_places()
    places = block["places"]
    vol = [q["volume"] for q in places["largest"]]
    assert places["count"] >= len(vol) > 0 and vol == sorted(vol, reverse=True)
    # the listed places hold at most the undecided volume, and the largest ones most of it
    assert sum(vol) <= block["joint_volume"] * (1 + 1e-9)
    assert places["volume_without_model"] <= block["joint_volume"] * (1 + 1e-9)
    assert sum(q["leaves"] for q in places["largest"]) >= 1
