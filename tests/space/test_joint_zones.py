"""Zones paved more finely (space.joint_zones) and the leaves between joined cells (Separation.between).

- a zone holds exactly the leaves inside its boxes (against the boxes' float bounds), and refuses levels
  and positions out of range;
- a paving with a zone (no join levels, which follow the cells): inside it the undecided leaves are finer,
  outside it the leaves are those of the paving without it; sampled points of the zone's clear leaves have
  the count of their cell (certified solver);
- a finer paving is kept only when it loses or merges no cell and proves more components apart;
- the leaves between two cells of one group hold a chain of face contacts from the one to the other
  (the shortest chains lie in them), and nothing is between when every group holds one cell.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from intervalkin.core.errors import InputError
from intervalkin.paving.adjacency import shares_face
from intervalkin.solve.dkp import solve
from intervalkin.space.joint_closure import piece_cells
from intervalkin.space.joint_paving import pave_joint_space
from intervalkin.space.joint_separation import separated_cells
from intervalkin.space.joint_zones import MAX_ZONE_LEVELS, RefinementZone

DEPTH = 4


def test_a_zone_holds_the_leaves_inside_its_boxes(rng):
    level = rng.integers(DEPTH - 1, DEPTH + 4, size=4000)
    ijk = rng.integers(0, 1 << 20, size=(4000, 3)) % (1 << level)[:, None]
    zone = RefinementZone(DEPTH, rng.integers(0, 1 << DEPTH, size=(40, 3)), 2)
    held = zone.holds(level, ijk)
    # brute force on the unit cube: the leaf's centre lies in one of the zone's boxes (a leaf above the zone's
    # level straddles several boxes and is never held)
    centre = (ijk + 0.5) / (1 << level)[:, None]
    box = np.floor(centre * (1 << DEPTH)).astype(np.int64)
    inside = (box[:, None, :] == zone.cells[None]).all(axis=2).any(axis=1) & (level >= DEPTH)
    assert np.array_equal(held, inside) and held.any() and not held.all()


def test_a_zone_refuses_levels_and_positions_out_of_range():
    with pytest.raises(InputError, match="zone levels"):
        RefinementZone(DEPTH, np.zeros((1, 3)), MAX_ZONE_LEVELS + 1)
    with pytest.raises(InputError, match="zone cells"):
        RefinementZone(DEPTH, np.array([[0, 0, 1 << DEPTH]]), 1)


@pytest.fixture(scope="module")
def plain(paper_geometry):
    return pave_joint_space(paper_geometry, DEPTH, 0, fold=True, model_levels=1)


@pytest.fixture(scope="module")
def zoned(paper_geometry, plain):
    p = plain.paving
    undecided = np.flatnonzero(plain.cell < 0)
    pick = undecided[:: max(1, undecided.size // 12)]
    zone = RefinementZone.of_leaves(p.level[pick], p.ijk[pick], DEPTH, 2)
    return zone, pave_joint_space(paper_geometry, DEPTH, 0, fold=True, model_levels=1, zone=zone)


def _keys(p, mask):
    return {(int(lv), *map(int, c)) for lv, c in zip(p.level[mask], p.ijk[mask])}


def test_a_zone_splits_its_undecided_leaves_and_leaves_the_rest_alone(plain, zoned):
    zone, finer = zoned
    a, b = plain.paving, finer.paving
    out_a, out_b = ~zone.holds(a.level, a.ijk), ~zone.holds(b.level, b.ijk)
    assert _keys(a, out_a) == _keys(b, out_b)
    in_a, in_b = ~out_a & (plain.cell < 0), ~out_b & (finer.cell < 0)
    assert in_a.any() and b.level[in_b].min() >= a.level[in_a].min() + 1
    assert b.level.max() >= a.level.max() + 1
    # the volume proved clear inside the zone never shrinks
    vol = lambda p, m: float(np.prod(p.hi[m] - p.lo[m], axis=1).sum())  # noqa: E731
    assert vol(b, ~out_b & (finer.cell >= 0)) >= vol(a, ~out_a & (plain.cell >= 0)) - 1e-9


def test_the_zone_s_clear_leaves_have_their_cell_s_count(paper_geometry, zoned, rng):
    zone, finer = zoned
    p = finer.paving
    mine = np.flatnonzero(zone.holds(p.level, p.ijk) & (finer.cell >= 0) & (p.level > DEPTH))
    assert mine.size > 20
    every = {c.id: c.signature for c in finer.cells + finer.fragments}
    for i in rng.choice(mine, size=20, replace=False):
        x = p.lo[i] + rng.random(3) * (p.hi[i] - p.lo[i])
        got = solve(paper_geometry, [Fraction(float(v)) for v in x])
        assert got.complete and len(got.solutions) == every[int(finer.cell[i])][0]


def test_the_leaves_between_two_joined_cells_hold_a_chain_from_one_to_the_other(paper_geometry, plain):
    sep = separated_cells(plain, paper_geometry)  # no window models: no refutation, groups stay coarse
    groups = [g for gs in sep.groups.values() for g in gs
              if len([c for c in g if c < len(plain.cells)]) > 1]
    assert groups and sep.between.size
    p = plain.paving
    a, b = shares_face(p.level, p.ijk, int(p.level.max()), periodic=(False, False, False))
    keep = np.zeros(len(p.level), dtype=bool)
    keep[sep.between] = True
    on = keep[a] & keep[b]
    comp = connected_components(coo_matrix((np.ones(on.sum()), (a[on], b[on])), shape=(len(keep),) * 2),
                                directed=False)[1]
    of_cell = piece_cells(plain)[0]
    for g in groups:
        first, second = [c for c in g if c < len(plain.cells)][:2]
        ends = [np.intersect1d(np.flatnonzero((of_cell == c).any(axis=1)), sep.between) for c in (first, second)]
        assert ends[0].size and ends[1].size
        assert np.intersect1d(comp[ends[0]], comp[ends[1]]).size, (first, second)


def test_old_cells_are_kept_by_witness_and_signature(paper_geometry, plain):
    import dataclasses

    from intervalkin.space.joint_topology import _old_cells_kept

    assert _old_cells_kept(paper_geometry, plain, plain)
    other = dataclasses.replace(plain.cells[0], count=plain.cells[0].count + 2)
    assert not _old_cells_kept(paper_geometry, plain, dataclasses.replace(plain, cells=(other,) + plain.cells[1:]))
    assert not _old_cells_kept(paper_geometry, plain, dataclasses.replace(plain, cells=plain.cells[:-1]))
    # a cell found only by the finer paving loses none of the old ones
    assert _old_cells_kept(paper_geometry, dataclasses.replace(plain, cells=plain.cells[:-1]), plain)
    # two old cells whose witnesses fall in one new cell were merged
    merged = np.where(plain.cell == 1, 0, plain.cell)
    assert not _old_cells_kept(paper_geometry, plain, dataclasses.replace(plain, cell=merged))


class _Fake:
    """A stand-in paving: its cells' signatures, the separation it would give, windows on."""

    def __init__(self, groups, between=(), cells=("a",)):
        from intervalkin.space.joint_separation import Separation

        self.windows = object()
        self.cells = cells
        self.paving = type("P", (), {"level": np.full(64, DEPTH), "ijk": np.zeros((64, 3), dtype=np.int64),
                                     "lo": np.zeros((64, 3)), "hi": np.ones((64, 3))})()
        self.separation = Separation(groups, between=np.asarray(between, dtype=np.int64))


@pytest.mark.parametrize("same, proves_more, kept", [(True, True, True), (True, False, False), (False, True, False)])
def test_a_finer_paving_is_kept_only_when_it_keeps_the_cells_and_proves_more(monkeypatch, same, proves_more, kept):
    import intervalkin.space.joint_topology as jt

    first = _Fake({(4, 2, 2): ((1, 3),)}, between=[0, 1])
    finer = _Fake({(4, 2, 2): ((1,), (3,)) if proves_more else ((1, 3),)})
    zones = []
    monkeypatch.setattr(jt, "pave_joint_space", lambda *a, zone=None, **k: zones.append(zone) or finer)
    monkeypatch.setattr(jt, "separated_cells", lambda jp, g: jp.separation)
    monkeypatch.setattr(jt, "_old_cells_kept", lambda g, a, b: same)
    cells, sep = jt.refine_separations(None, first, first.separation, DEPTH, 0)
    assert (cells is finer) == kept and len(sep.zone_passes) == 1 and sep.zone_passes[0]["kept"] == kept
    assert zones[0].depth == DEPTH and zones[0].levels == jt.ZONE_LEVELS and len(zones[0].cells) == 1
    assert sep.components_at_least() == (2 if kept else 1)


def test_no_pass_when_nothing_is_between(monkeypatch):
    import intervalkin.space.joint_topology as jt

    first = _Fake({(4, 2, 2): ((1,), (3,))})
    monkeypatch.setattr(jt, "pave_joint_space", lambda *a, **k: pytest.fail("paved again with nothing between"))
    cells, sep = jt.refine_separations(None, first, first.separation, DEPTH, 0)
    assert cells is first and sep.zone_passes == ()


@pytest.mark.parametrize("replaced", [False, True])
def test_the_topology_s_retraction_and_separations_are_those_of_the_paving_it_returns(monkeypatch, paper_geometry,
                                                                                      plain, zoned, replaced):
    """pave_joint_topology computes the separations beside the first paving's retraction when asked to retract: the
    retraction it returns is the one of the paving it returns (made again when a zone pass replaced the first), and
    the separations are those of the first paving when no pass ran; by default it returns the same paving and
    separations with no retraction.  The small pavings of this module stand for the topology's (the
    plumbing is the same; the retraction's window nodes have their own tests)."""
    from intervalkin.space import joint_topology
    from intervalkin.space.joint_retraction import retract_joint_paving

    finer = zoned[1]
    monkeypatch.setattr(joint_topology, "pave_joint_space", lambda *a, **k: plain)
    # no pass, or a pass that keeps a finer paving (here another paving stands for it)
    monkeypatch.setattr(joint_topology, "refine_separations",
                        lambda g, cells, sep, *a, **k: (finer, separated_cells(finer, g)) if replaced else (cells, sep))
    unretracted = joint_topology.pave_joint_topology(paper_geometry, DEPTH, 0)  # the default: no retraction
    cells, closure, separation = joint_topology.pave_joint_topology(paper_geometry, DEPTH, 0, retract=True)
    final = finer if replaced else plain
    assert cells.paving is final.paving and unretracted[0].paving is final.paving
    assert separation == separated_cells(final, paper_geometry) == unretracted[2]
    assert unretracted[0].retraction is None and "retraction" not in unretracted[0].open_places()
    want = retract_joint_paving(final, paper_geometry)
    got = cells.retraction
    assert got.leaf.size == want.leaf.size and np.array_equal(got.leaf, want.leaf)
    assert np.array_equal(got.rank, want.rank) and np.array_equal(got.signature, want.signature)
