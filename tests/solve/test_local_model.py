"""Local models of undecided joint boxes (solve.local_model) and the exclusion that clears boxes.

- no singular pose has its joint vector in a box proved clear, by the torus search or by
  Krawczyk exclusion (singular poses sampled over the whole workspace, bisected on det A);
- random points of a box proved clear by exclusion all have one certified count;
- the grouping of live torus cells joins touching cells only, across the seam too;
- mutation: a hull that misses part of its group's cells (the ordering bug once made this)
  voids boxes that the singular poses show are not clear.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from intervalkin.core.interval import PI_HI
from intervalkin.kinematics.formulas import approx_inverse_kinematics
from intervalkin.solve.dkp import solve
from intervalkin.solve.local_model import cluster_cells
from intervalkin.space.joint_paving import pave_joint_space
from tests.solve.shared import det_zeros_along_y, split_of


@pytest.fixture(scope="module")
def modelled(fold_models_5):
    """``pave_joint_space(paper_geometry, 5, join_levels=0, fold=True, model_levels=1)`` (tests/conftest.py)."""
    jp = fold_models_5
    assert np.count_nonzero(jp.voided) >= 200, "depth 5 proves a few hundred boxes clear by exclusion"
    return jp


def _singular_joint_vectors(geometry, rng, n_lines):
    """Joint vectors of poses within 1e-12 of det A = 0: sign changes of det A along y, bisected."""
    x = rng.uniform(-15, 35, n_lines)
    phi = rng.uniform(-np.pi, np.pi, n_lines)
    line, a, b = det_zeros_along_y(geometry, x, phi, np.linspace(-15, 35, 401))
    return approx_inverse_kinematics(geometry, np.stack([x[line], 0.5 * (a + b), phi[line]], axis=1))


def test_no_singular_pose_lands_in_a_clear_box(modelled, paper_geometry):
    rng = np.random.default_rng(21)
    q = _singular_joint_vectors(paper_geometry, rng, 20000)
    dom = modelled.paving.domain
    q = q[((q > dom[:, 0] + 1e-6) & (q < dom[:, 1] - 1e-6)).all(axis=1)]
    assert len(q) >= 4000
    # shrink each box by a hair: a float singular pose may sit 1e-12 across a face
    lo, hi = modelled.paving.lo + 1e-9, modelled.paving.hi - 1e-9
    leaf = modelled.paving.locate_boxes(np.stack([q, q], axis=-1))
    hit = leaf[leaf >= 0]
    strictly = ((q[leaf >= 0] > lo[hit]) & (q[leaf >= 0] < hi[hit])).all(axis=1)
    assert not np.any((modelled.cell[hit] >= 0) & strictly), "a singular joint vector in a clear box"
    # the test reaches the exclusion: many singular points lie within one box width of a voided box
    v = np.flatnonzero(modelled.voided)
    w = modelled.paving.hi[v] - modelled.paving.lo[v]
    vlo, vhi = modelled.paving.lo[v] - w, modelled.paving.hi[v] + w
    near = sum(int(((p > vlo) & (p < vhi)).all(axis=1).any()) for p in q)
    assert near >= 200, near


def test_points_of_a_voided_box_share_one_count(modelled, paper_geometry):
    rng = np.random.default_rng(5)
    boxes = np.flatnonzero(modelled.voided)
    for b in rng.choice(boxes, size=25, replace=False):
        lo, hi = modelled.paving.lo[b], modelled.paving.hi[b]
        pts = np.vstack([lo, hi, lo + rng.random((4, 3)) * (hi - lo)])
        splits = {split_of(solve(paper_geometry, [Fraction(float(v)) for v in p])) for p in pts}
        assert len(splits) == 1, (b, lo, hi, splits)


def test_cells_touching_across_the_seam_are_one_group():
    a = [-PI_HI, -3.0, -0.5, 0.5]
    b = [3.0, PI_HI, -0.2, 0.2]     # touches a across theta = +-pi
    c = [0.0, 0.5, 0.0, 0.5]        # apart from both
    d = [0.5, 0.9, 0.5, 0.8]        # touches c at a corner
    e = [-1.0, -0.5, 3.0, PI_HI]    # the second box's only cell
    owner = np.array([0, 0, 0, 0, 1])
    g = cluster_cells(owner, np.array([a, b, c, d, e], dtype=float))
    assert g[0] == g[1] and g[2] == g[3] and g[0] != g[2]
    assert g[4] not in g[:4] and np.all(np.diff(g[np.argsort(owner, kind="stable")][[0, 2, 4]]) > 0)


def test_a_hull_missing_cells_is_caught(paper_geometry, monkeypatch):
    """Mutation: hulls built from half of each group's cells void boxes that are not clear; singular
    poses land in them, or two certified solves of one cell disagree."""
    import intervalkin.solve.local_model as lm

    real = lm.pose_hulls

    def careless(geometry, boxes, owner, cells):
        rng = np.random.default_rng(0)
        keep = rng.random(len(owner)) < 0.5
        keep[np.r_[True, owner[1:] != owner[:-1]]] = True  # every group keeps one cell
        return real(geometry, boxes, owner[keep], cells[keep])

    monkeypatch.setattr(lm, "pose_hulls", careless)
    try:
        jp = pave_joint_space(paper_geometry, 5, join_levels=0, fold=True, model_levels=1)
    except AssertionError as e:  # or the cells' own check trips: two solves of one cell disagree
        assert "different counts" in str(e)
        return
    q = _singular_joint_vectors(paper_geometry, np.random.default_rng(21), 20000)
    dom = jp.paving.domain
    q = q[((q > dom[:, 0] + 1e-6) & (q < dom[:, 1] - 1e-6)).all(axis=1)]
    lo, hi = jp.paving.lo + 1e-9, jp.paving.hi - 1e-9
    leaf = jp.paving.locate_boxes(np.stack([q, q], axis=-1))
    hit = leaf[leaf >= 0]
    strictly = ((q[leaf >= 0] > lo[hit]) & (q[leaf >= 0] < hi[hit])).all(axis=1)
    assert np.any((jp.cell[hit] >= 0) & strictly)
