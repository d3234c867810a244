"""Covers of the aspects: tiling, ranks, separations, and exact counts (2 on the paper's manipulator)."""

from __future__ import annotations

import numpy as np

from pathlib import Path

import pytest

from intervalkin.core.geometry import load_geometry
from intervalkin.core.status import Count, Status
from intervalkin.paving.adjacency import component_labels, shares_face, touching_pairs, touching_pairs_bruteforce
from intervalkin.paving.tree import split_boxes
from intervalkin.space.aspect_retraction import DIRECTIONS, exit_faces
from intervalkin.space.aspect_topology import (
    LEFT,
    OUT,
    RET,
    SINK,
    AspectTopology,
    face_pairs,
    prove_aspects,
    resolve_cover,
    separations,
)

DATA = Path(__file__).parents[1] / "data"


def test_the_paper_has_exactly_two_aspects(aspect_topology):
    """Both signs close: no LEFT box, sinks present; the count becomes exact."""
    assert aspect_topology.upper == 2
    for cover in aspect_topology.covers:
        assert cover.connected and not cover.empty and not cover.leftovers()
        assert cover.exact and cover.components_at_least == cover.components_at_most == 1
        assert cover.fragments > 1  # the IN boxes alone are fragmented: the retractions join them
    found = Count(2, 2, None, False, "signs")
    c = aspect_topology.count(found)
    assert (c.found, c.lower, c.upper, c.exact, c.status) == (2, 2, 2, True, Status.CERTIFIED)


def test_a_process_proves_a_geometrys_covers_once_and_no_caller_can_change_them(aspect_topology, paper_geometry):
    """prove_aspects keeps its result per geometry: a later analysis gets the same covers, not a new proof, and
    an attempt to write into them fails instead of changing what the other analyses read."""
    again = prove_aspects(paper_geometry)
    assert again is prove_aspects(paper_geometry) and again.upper == 2
    for cover in again.covers:
        for a in (cover.level, cover.ijk, cover.kind, cover.direction, cover.rank):
            with pytest.raises(ValueError):
                a[0] = a[0]
    # only an equal geometry shares the proof: the same numbers under another name are proved again (about 5 s)
    from dataclasses import replace
    other = replace(paper_geometry, name="a copy under another name")
    assert prove_aspects(other) is not again


def test_each_cover_tiles_the_domain(aspect_topology):
    """Integer volumes add up to the domain and no two boxes overlap (the checker's rule, in numpy)."""
    for cover in aspect_topology.covers:
        depth = int(cover.level.max())
        assert int(np.sum(8 ** (depth - cover.level.astype(np.int64)))) == 8 ** depth
        fine = cover.ijk << (depth - cover.level)[:, None]
        keys = set(map(tuple, np.column_stack([cover.level, cover.ijk]).tolist()))
        assert len(keys) == len(cover.level)
        for lev, i, j, k in list(keys)[:3000]:
            assert not any((lev - u, i >> u, j >> u, k >> u) in keys for u in range(1, lev + 1))
        assert fine.min() >= 0


def test_ranks_point_downhill_and_sinks_are_one_component(aspect_topology):
    """Every box across an exit face of a RET box is OUT, a sink, or of lower rank; the sinks are one set."""
    for cover in aspect_topology.covers:
        depth = int(cover.level.max())
        pairs, border, edges = face_pairs(cover.level, cover.ijk, depth)
        ret = cover.kind == RET
        faces = exit_faces(cover.direction)
        a, b, f = pairs
        sel = ret[a] & faces[a, f]
        ok = (cover.kind[b[sel]] == OUT) | (cover.kind[b[sel]] == SINK) | \
             ((cover.kind[b[sel]] == RET) & (cover.rank[b[sel]] < cover.rank[a[sel]]))
        assert np.all(ok)
        assert not np.any(border[ret] & faces[ret])
        sinks = component_labels(len(cover.level), edges, cover.kind == SINK)
        assert sinks.max() == 0
        assert np.all(np.any(cover.direction[ret] != 0, axis=1))


def test_face_pairs_agree_with_the_face_adjacency():
    """Every face-adjacent pair appears once from each side, across opposite faces (phi seam included)."""
    level = np.array([1, 1, 1, 1, 2, 2, 2, 2, 1, 1, 1, 1], dtype=np.int64)
    ijk = np.array([[0, 0, 0], [0, 0, 1], [0, 1, 0], [0, 1, 1], [2, 0, 0], [3, 0, 0], [2, 1, 0], [3, 1, 0],
                    [1, 0, 1], [1, 1, 0], [1, 1, 1], [1, 0, 0]])
    keep = level == 1
    keep[4:8] = True
    keep[11] = False  # [1, 0, 0] at level 1 is covered by the four level-2 boxes
    level, ijk = level[keep], ijk[keep]
    # complete the tiling: the level-2 boxes cover x in [1/2, 1], y in [0, 1/2], phi in [0, 1/4]
    extra = np.array([[2, 0, 1], [3, 0, 1], [2, 1, 1], [3, 1, 1]])
    level, ijk = np.concatenate([level, [2] * 4]), np.concatenate([ijk, extra])
    assert int(np.sum(8 ** (2 - level))) == 64
    pairs, border, edges = face_pairs(level, ijk, 2)
    und = {tuple(sorted(p)) for p in pairs[:2].T.tolist()}
    assert und == set(map(tuple, shares_face(level, ijk, 2).T.tolist()))
    opposite = {(a, b, f) for a, b, f in pairs.T.tolist()}
    assert all((b, a, f ^ 1) in opposite for a, b, f in opposite)


def test_an_open_cover_gives_no_upper_bound(aspect_topology):
    """A LEFT box anywhere: no upper bound, the count stays a lower bound and says where it is open."""
    cover = aspect_topology.covers[1]
    kind = cover.kind.copy()
    kind[np.flatnonzero(kind == RET)[0]] = LEFT
    import dataclasses
    broken = AspectTopology((aspect_topology.covers[0], dataclasses.replace(cover, kind=kind)))
    assert broken.upper is None
    c = broken.count(Count(2, 2, None, False, "signs"))
    assert c.upper is None and not c.exact and "1 boxes undecided" in c.why
    assert len(broken.covers[1].leftovers()) == 1


def test_the_lower_bound_is_the_checkers_whatever_the_regions_witness(aspect_topology):
    """Per sign, the larger of a witness in ``found`` and the closed cover's separated pieces (the checker's
    ``count_bound``): the paper's covers each hold sinks, so 2 aspects are proved even when the regions paving has no
    certified box of either sign (depth 3 found 0, and ``verify`` refused the count as below its certificates); an
    open cover's sinks add nothing (it has no claim), and one witness of an unknown sign counts as the weaker one."""
    import dataclasses

    from intervalkin.checker.claims import count_bound

    facts = [{"aspect_sign": c.sign, "components_at_least": c.separated} for c in aspect_topology.covers]
    for witnessed in (0, 1, 2):
        found = Count(witnessed, witnessed, None, False, "signs")
        signs = [{"signs": {1, -1}}] if witnessed == 2 else []
        assert aspect_topology.lower(found) == 2 == count_bound("aspects", facts + signs)
        c = aspect_topology.count(found)
        assert c.found == c.lower == c.upper == 2 and c.exact
        assert ("opposite certified signs" in c.why) == (witnessed == 2) and ("sinks of the closed covers" in c.why) == (witnessed < 2)
    cover = aspect_topology.covers[1]
    kind = cover.kind.copy()
    kind[np.flatnonzero(kind == RET)[0]] = LEFT
    open_one = AspectTopology((aspect_topology.covers[0], dataclasses.replace(cover, kind=kind)))
    assert open_one.lower(Count(0, 0, None, False, "signs")) == 1
    assert open_one.lower(Count(2, 2, None, False, "signs")) == 2
    two = dataclasses.replace(aspect_topology.covers[0], separated=2)
    assert AspectTopology((two, aspect_topology.covers[1])).lower(Count(1, 1, None, False, "signs")) == 3


def test_directions_are_integer_and_nonzero():
    assert DIRECTIONS.dtype.kind == "i" and np.all(np.any(DIRECTIONS != 0, axis=1))
    assert len({tuple(d) for d in DIRECTIONS.tolist()}) == len(DIRECTIONS)


def test_a_fragment_no_chain_reaches_becomes_another_group_of_sinks():
    """Two IN boxes separated by boxes that retract nowhere: with one group the second stays LEFT; with two
    groups allowed it becomes a second group of sinks (the bound is then 2 for this sign, not 1)."""
    level = np.full(64, 2, dtype=np.int64)
    ijk = np.array([[i, j, k] for i in range(4) for j in range(4) for k in range(4)], dtype=np.int64)
    out = np.zeros(64, dtype=bool)
    inside = np.zeros(64, dtype=bool)
    first, second = 0, 2 * 16  # (0, 0, 0) and (2, 0, 0)
    inside[[first, second]] = True
    ok = np.zeros((64, len(DIRECTIONS) + 3), dtype=bool)
    faces = np.zeros((64, 3, 6), dtype=bool)
    vol = np.ones(64)
    kind, rank, choice, fragments, edges, groups = resolve_cover(level, ijk, 2, out, inside, ok, faces, vol)
    assert fragments == 2 and groups == 1
    assert sorted(kind[[first, second]].tolist()) == [SINK, LEFT]
    kind, rank, choice, fragments, edges, groups = resolve_cover(level, ijk, 2, out, inside, ok, faces, vol, 2)
    assert groups == 2 and kind[first] == kind[second] == SINK
    assert np.all(kind[~inside] == LEFT)


def _random_tiling(rng, rounds: int = 4):
    level, ijk = np.zeros(1, dtype=np.int64), np.zeros((1, 3), dtype=np.int64)
    for r in range(rounds):
        cut = (rng.random(len(level)) < 0.5) | (r == 0)
        cl, cijk = split_boxes(level[cut], ijk[cut])
        level, ijk = np.concatenate([level[~cut], cl]), np.concatenate([ijk[~cut], cijk])
    return level, ijk


def test_touching_pairs_agree_with_brute_force():
    """Closed boxes meeting at a face, an edge or a corner (phi wraps), with and without a mask, on random
    octree tilings: the Z-order lookup finds exactly the pairs of the O(n^2) reference."""
    rng = np.random.default_rng(14)
    for _ in range(5):
        level, ijk = _random_tiling(rng)
        depth = int(level.max())
        ref = set(map(tuple, touching_pairs_bruteforce(level, ijk, depth).T.tolist()))
        assert set(map(tuple, touching_pairs(level, ijk, depth).T.tolist())) == ref
        mask = rng.random(len(level)) < 0.6
        got = set(map(tuple, touching_pairs(level, ijk, depth, mask).T.tolist()))
        assert got == {p for p in ref if mask[p[0]] and mask[p[1]]}
        faces = set(map(tuple, shares_face(level, ijk, depth).T.tolist()))
        assert faces <= ref


def test_separations_count_pieces_not_face_groups():
    """Two sink cells meeting only along an edge are two face groups but one piece (their closed union is
    connected); a layer of OUT cells between them makes two pieces; across the phi seam they meet again."""
    level = np.full(64, 2, dtype=np.int64)
    ijk = np.array([[i, j, k] for i in range(4) for j in range(4) for k in range(4)], dtype=np.int64)
    at = {tuple(c): n for n, c in enumerate(ijk.tolist())}
    edges = shares_face(level, ijk, 2)

    def run(out_cells, sink_cells):
        out = np.zeros(64, dtype=bool)
        out[[at[c] for c in out_cells]] = True
        sink = np.zeros(64, dtype=bool)
        sink[[at[c] for c in sink_cells]] = True
        piece, group, separated, _ = separations(level, ijk, 2, out, sink, edges)
        return int(group.max()) + 1, separated

    everything_else = [c for c in at if c not in ((1, 1, 1), (2, 2, 1))]
    assert run(everything_else, [(1, 1, 1), (2, 2, 1)]) == (2, 1)  # an edge: one piece
    far = [c for c in at if c not in ((0, 0, 1), (3, 3, 1))]
    assert run(far, [(0, 0, 1), (3, 3, 1)]) == (2, 2)  # OUT cells between: two pieces
    seam = [c for c in at if c not in ((1, 1, 0), (2, 2, 3))]
    assert run(seam, [(1, 1, 0), (2, 2, 3)]) == (2, 1)  # phi = hi is phi = lo: an edge across the seam


@pytest.mark.parametrize("name, groups", [("offset_right.toml", (1, 2)), ("concurrent_legs.toml", (1, 1))])
def test_the_test_geometries_close_with_exact_counts(name, groups):
    """offset_right: WA2 has two components, cut apart by OUT boxes (3 aspects); concurrent_legs: its
    thin corners (nearly dependent gradients) close with fine directions and combinations (2 aspects)."""
    topo = prove_aspects(load_geometry(DATA / name))
    for cover, k in zip(topo.covers, groups):
        assert cover.closed and cover.exact and cover.groups == cover.separated == k
    c = topo.count(Count(2, 2, None, False, "signs"))
    assert (c.found, c.lower, c.upper, c.exact) == (sum(groups),) * 3 + (True,)
