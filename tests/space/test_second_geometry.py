"""A second manipulator, examples/second_design_0246.toml (issue 14): the same analysis, no code change.

- the witnesses written in the file's header have the stated counts and aspect
  splits (certified solves), and together show 0, 2, 4 and 6 solutions;
- each witness lies in a clear cell of the direct joint paving (depth 5) whose
  certified count is the stated one, so its count holds on a neighbourhood;
- that paving finds cells of 0, 2, 4 and 6 solutions, and a 6-solution cell of more than 5 % of the box;
- seeded random joint vectors that the paving places in a cell get the cell's
  count and split from an independent certified solve;
- the whole chain (pipeline.analyse) runs on it and its counts keep their bounds;
- its aspects are exactly 4: each sign's part of W has two components, joined inside
  by retractions and cut apart by OUT boxes (tests/checker/test_aspects.py re-proves it).
"""

from __future__ import annotations

import re
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from intervalkin.core.geometry import load_geometry
from intervalkin.core.status import Count
from intervalkin.paving.adjacency import component_labels
from intervalkin.pipeline import analyse
from intervalkin.solve.dkp import solve
from intervalkin.space.aspect_topology import SINK, face_pairs
from intervalkin.space.joint_paving import pave_joint_space

EXAMPLE = Path(__file__).parents[2] / "examples" / "second_design_0246.toml"
_WITNESS = re.compile(r"^# witness (\d+) \((\d+) WA1, (\d+) WA2\): ([\d.]+), ([\d.]+), ([\d.]+)$")


def _witnesses() -> list[tuple[tuple[int, int, int], tuple[Fraction, Fraction, Fraction]]]:
    """((count, n_wa1, n_wa2), exact joint vector) for each witness line of the header."""
    out = []
    for line in EXAMPLE.read_text().splitlines():
        m = _WITNESS.match(line)
        if m:
            out.append((tuple(int(v) for v in m.group(1, 2, 3)), tuple(Fraction(v) for v in m.group(4, 5, 6))))
    return out


def _signature(res) -> tuple[int, int, int]:
    n1 = sum(1 for s in res.solutions if s.aspect == "WA1")
    return res.count, n1, res.count - n1


@pytest.fixture(scope="module")
def geometry():
    return load_geometry(EXAMPLE)


@pytest.fixture(scope="module")
def joint5(geometry):
    return pave_joint_space(geometry, 5, join_levels=1, model_levels=1)


def test_the_witnesses_have_the_stated_counts(geometry):
    wit = _witnesses()
    assert {sig[0] for sig, _ in wit} == {0, 2, 4, 6}
    assert sum(1 for sig, _ in wit if sig[0] == 6) >= 3
    for sig, q in wit:
        res = solve(geometry, q)
        assert res.complete, (q, res.completeness_reason)
        assert all(s.status == "unique" for s in res.solutions)
        assert _signature(res) == sig, q


def test_the_witnesses_lie_in_cells_of_their_count(geometry, joint5):
    wit = _witnesses()
    ids = joint5.cell_of(np.array([[float(v) for v in q] for _, q in wit]))
    by_id = {c.id: c for c in joint5.cells}
    for (sig, q), cid in zip(wit, ids):
        assert cid >= 0, q
        assert by_id[int(cid)].signature == sig, q


def test_the_paving_finds_cells_of_0_2_4_and_6_solutions(geometry, joint5):
    # the module's depth-5 paving: a depth-4 paving of its own (join levels, windows) cost 44 s more a run
    jp = joint5
    assert {c.count for c in jp.cells} >= {0, 2, 4, 6}
    assert all(c.count == c.n_wa1 + c.n_wa2 for c in jp.cells)
    # the largest 6-solution cell is not a sliver: more than 5 % of the joint box
    total = float(np.prod([float(hi - lo) for lo, hi in zip(geometry.rho_min, geometry.rho_max)]))
    assert max(c.volume for c in jp.cells if c.count == 6) > 0.05 * total


def test_random_points_in_cells_get_the_cell_count(geometry, joint5):
    rng = np.random.default_rng(14)
    qs = [tuple(Fraction(int(rng.integers(1000, 3201)), 100) for _ in range(3)) for _ in range(100)]
    ids = joint5.cell_of(np.array([[float(v) for v in q] for q in qs]))
    by_id = {c.id: c for c in joint5.cells}
    placed, wrong, seen = 0, [], set()
    for q, cid in zip(qs, ids):
        if cid < 0:
            continue
        res = solve(geometry, q)
        assert res.complete, (q, res.completeness_reason)
        placed += 1
        seen.add(res.count)
        if _signature(res) != by_id[int(cid)].signature:
            wrong.append((q, _signature(res), by_id[int(cid)].signature))
    assert wrong == []
    assert placed >= 30
    assert seen >= {2, 4, 6}


def test_the_chain_runs_and_keeps_its_bounds(geometry):
    a = analyse(geometry, depth=4)
    counts = a.counts()
    for name in ("aspects", "basic_regions", "uniqueness_domains"):
        c = getattr(counts, name)
        assert c.found >= c.lower, name
        assert c.upper is None or c.found <= c.upper, name
    assert counts.aspects.lower >= 2
    # a 6-solution cell with 3 solutions of each aspect: at least 3 + 3 uniqueness domains
    assert counts.uniqueness_domains.lower >= 6
    assert counts.basic_regions.lower >= 6
    assert {c.count for c in a.cells.cells} >= {0, 2, 4, 6}


def test_the_aspects_are_exactly_four(second_aspect_topology):
    """Each sign: a closed cover, two groups of sinks, each in its own piece of the non-OUT boxes, so
    exactly two components; the count (found 2 by opposite signs) is raised and proved: 4 aspects.
    The two groups of a sign are far apart (no thin neck, nothing at the phi seam): their sink boxes
    are more than 5 apart in (x, y, 20 phi), phi taken modulo 2 pi."""
    for cover in second_aspect_topology.covers:
        assert cover.closed and cover.exact
        assert cover.groups == cover.separated == 2
        depth = int(cover.level.max())
        group = component_labels(len(cover.level), face_pairs(cover.level, cover.ijk, depth)[2], cover.kind == SINK)
        boxes = cover.boxes()
        a, b = boxes[group == 0][:, None], boxes[group == 1][None]
        gap = [np.maximum(0, np.maximum(a[..., k, 0] - b[..., k, 1], b[..., k, 0] - a[..., k, 1])) for k in range(3)]
        span = np.maximum(a[..., 2, 1], b[..., 2, 1]) - np.minimum(a[..., 2, 0], b[..., 2, 0])
        gap[2] = np.minimum(gap[2], np.maximum(0, 2 * np.pi - span))  # around the seam
        assert np.sqrt(gap[0] ** 2 + gap[1] ** 2 + (20 * gap[2]) ** 2).min() > 5
    c = second_aspect_topology.count(Count(2, 2, None, False, "opposite signs"))
    assert (c.found, c.lower, c.upper, c.exact) == (4, 4, 4, True)
    assert "cutting" in c.why
