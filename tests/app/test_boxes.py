"""Labelled box sets: merging keeps every point's label, painting keeps the caller's order, surfaces close."""

from __future__ import annotations

import numpy as np
import pytest

from intervalkin.app.boxes import fine_bounds, lattice_points, merge_boxes, rasterise
from intervalkin.app.surfaces import grid_geometry, label_surfaces


def _paint(lo, hi, key, n):
    """Reference painter: one Python loop per box (slow and obvious)."""
    grid = np.full((n, n, n), -1, dtype=np.int64)
    for a, b, k in zip(lo, hi, key):
        assert np.all(grid[a[0]:b[0], a[1]:b[1], a[2]:b[2]] == -1), "boxes overlap"
        grid[a[0]:b[0], a[1]:b[1], a[2]:b[2]] = k
    return grid


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_merge_keeps_every_cell_and_its_key(seed):
    """Voxels of a random 3-label grid, merged: the cuboids paint back exactly the same grid, with fewer boxes.

    Would catch a merge across different keys, across a gap, or across unequal cross-sections.
    """
    rng = np.random.default_rng(seed)
    n = 8
    labels = rng.integers(-1, 3, size=(n, n, n))
    labels[:4, :4, :] = 1  # a block that must merge
    idx = np.argwhere(labels >= 0)
    key = labels[tuple(idx.T)]
    m_lo, m_hi, m_key = merge_boxes(idx, idx + 1, key)
    assert len(m_key) < len(key)
    assert np.array_equal(_paint(m_lo, m_hi, m_key, n), np.where(labels >= 0, labels, -1))


def test_merge_handles_octree_boxes_of_several_levels():
    """A level-1 box beside eight level-2 boxes of the same key: one cuboid of the union."""
    level = np.array([1] + [2] * 8)
    ijk = np.array([[0, 0, 0]] + [[2 + a, b, c] for a in (0, 1) for b in (0, 1) for c in (0, 1)])
    lo, hi = fine_bounds(level, ijk, 2)
    m_lo, m_hi, m_key = merge_boxes(lo, hi, np.zeros(9, dtype=np.int64))
    assert m_lo.tolist() == [[0, 0, 0]] and m_hi.tolist() == [[4, 2, 2]] and m_key.tolist() == [0]


def test_rasterise_keeps_the_callers_order_and_widens_thin_boxes():
    """Later boxes win where they meet a grid cell; a box thinner than a grid cell paints the whole cell."""
    lo = np.array([[0, 0, 0], [1, 0, 0]])
    hi = np.array([[4, 4, 4], [2, 1, 1]])  # the second box is inside the first, one fine cell
    g = rasterise(lo, hi, np.array([5, 7]), depth=2, bits=1)
    assert g.shape == (2, 2, 2) and g[0, 0, 0] == 7 and np.all(g.ravel()[1:] == 5)
    g = rasterise(lo[::-1], hi[::-1], np.array([7, 5]), depth=2, bits=1)
    assert np.all(g == 5)


def test_lattice_points_share_corners():
    """Two face-adjacent boxes share four corners; points sit on the domain's lattice."""
    lo = np.array([[0, 0, 0], [1, 0, 0]])
    pts, conn = lattice_points(lo, lo + 1, 2, np.array([[0.0, 4.0], [0.0, 4.0], [-2.0, 2.0]]))
    assert len(pts) == 12 and conn.shape == (2, 8)
    assert np.array_equal(pts[conn[0]].min(axis=0), [0, 0, -2]) and np.array_equal(pts[conn[1]].max(axis=0), [2, 1, -1])


def test_surface_encloses_the_labelled_cells():
    """The marching-cubes surface of a 2x2x2 block lies on the block's faces (a closed cube)."""
    grid = np.full((4, 4, 4), -1)
    grid[1:3, 1:3, 1:3] = 3
    origin, spacing = grid_geometry(np.array([[0.0, 4.0]] * 3), 2)
    s = label_surfaces(grid, [3, 9], origin, spacing)
    assert s[9].is_empty()
    v = s[3].vertices
    assert s[3].n_faces > 0 and np.isclose(v.min(), 1.0) and np.isclose(v.max(), 3.0)  # on the cell faces
    # closed: every edge is shared by exactly two triangles
    f = s[3].faces
    edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert np.all(counts == 2)
