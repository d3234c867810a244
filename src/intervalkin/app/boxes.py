"""Labelled box sets on a dyadic lattice: merged into fewer cuboids, or painted onto a grid.

Every paving of the package is dyadic: a box of level L with integer coordinates
``ijk`` covers ``[ijk << (d - L), (ijk + 1) << (d - L))`` in units of the leaf
width at the paving's depth d (:meth:`~intervalkin.paving.tree.Paving.fine_coordinates`).
Two operations on such sets serve the exports and the drawings:

* :func:`merge_boxes` joins boxes that carry the same key and abut along an axis
  with the same cross-section into one cuboid.  The union is unchanged, point for
  point: every cuboid is exactly a union of input boxes with one key.  It is what
  makes ``workspace.vtu`` small (the finest level holds most boxes, in long runs).
* :func:`rasterise` paints integer values onto a regular grid of 2**bits cells per
  axis (boxes finer than a grid cell paint the whole cell, so thin sets stay
  visible), the input of marching cubes (:mod:`intervalkin.app.surfaces`).

Both are pictures and files of certified labels, not proofs: the labels come from
the library, and this module only rearranges them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["fine_bounds", "merge_boxes", "rasterise", "lattice_points", "JointBoxes", "joint_boxes", "cell_by_id"]


def fine_bounds(level: np.ndarray, ijk: np.ndarray, depth: int) -> tuple[np.ndarray, np.ndarray]:
    """Integer bounds (n, 3) of dyadic boxes in units of the leaf width at ``depth``: [lo, hi).

    >>> fine_bounds(np.array([1]), np.array([[1, 0, 1]]), 3)
    (array([[4, 0, 4]]), array([[8, 4, 8]]))
    """
    shift = (depth - np.asarray(level, dtype=np.int64))[:, None]
    ijk = np.asarray(ijk, dtype=np.int64)
    return ijk << shift, (ijk + 1) << shift


def _merge_along(lo: np.ndarray, hi: np.ndarray, key: np.ndarray, axis: int):
    """One pass of :func:`merge_boxes` along ``axis``."""
    o1, o2 = [a for a in range(3) if a != axis]
    order = np.lexsort((lo[:, axis], hi[:, o2], lo[:, o2], hi[:, o1], lo[:, o1], key))
    lo, hi, key = lo[order], hi[order], key[order]
    same_group = np.ones(len(key), dtype=bool)
    same_group[0] = False
    for col in (key, lo[:, o1], hi[:, o1], lo[:, o2], hi[:, o2]):
        same_group[1:] &= col[1:] == col[:-1]
    # boxes of one group never overlap, so sorted by their lower bound they abut exactly when
    # one ends where the next begins
    joins = same_group.copy()
    joins[1:] &= hi[:-1, axis] == lo[1:, axis]
    first = np.flatnonzero(~joins)
    last = np.append(first[1:] - 1, len(key) - 1)
    new_lo, new_hi = lo[first].copy(), hi[first].copy()
    new_hi[:, axis] = hi[last, axis]
    return new_lo, new_hi, key[first]


def merge_boxes(lo: np.ndarray, hi: np.ndarray, key: np.ndarray, passes: int = 2):
    """Merge abutting integer boxes of equal key into cuboids, axis by axis; returns (lo, hi, key).

    Parameters
    ----------
    lo, hi : int arrays (n, 3), half-open integer bounds of non-overlapping boxes.
    key : int array (n,), boxes merge only with boxes of the same key.
    passes : sweeps over the three axes (the second finds merges the first made possible).

    The union of the output cuboids of each key equals the union of its input
    boxes (tested).  The output is sorted by lower corner (x, then y, then phi), so
    that neighbours in space are neighbours in the file (it compresses better).
    Cost: O(n log n) per axis and pass.

    >>> lo = np.array([[0, 0, 0], [0, 0, 1], [1, 0, 0], [1, 0, 1]])
    >>> m_lo, m_hi, m_key = merge_boxes(lo, lo + 1, np.array([5, 5, 5, 5]))
    >>> m_lo.tolist(), m_hi.tolist(), m_key.tolist()
    ([[0, 0, 0]], [[2, 1, 2]], [5])
    """
    lo = np.asarray(lo, dtype=np.int64)
    hi = np.asarray(hi, dtype=np.int64)
    key = np.asarray(key, dtype=np.int64)
    if len(key) == 0:
        return lo.reshape(0, 3), hi.reshape(0, 3), key
    for _ in range(passes):
        n = len(key)
        for axis in (0, 1, 2):  # this order leaves the fewest cuboids on the paper's pavings
            lo, hi, key = _merge_along(lo, hi, key, axis)
        if len(key) == n:
            break
    order = np.lexsort((lo[:, 2], lo[:, 1], lo[:, 0]))
    return lo[order], hi[order], key[order]


def rasterise(lo: np.ndarray, hi: np.ndarray, values: np.ndarray, depth: int, bits: int,
              fill: int = -1) -> np.ndarray:
    """Paint ``values`` of integer boxes (fine units at ``depth``) onto a (2**bits)^3 grid.

    Boxes are painted in the order given (later boxes win where they share a grid
    cell), so callers list the set that should show on top last.  A box finer than
    a grid cell paints the whole cell: a thin layer stays at least one cell thick.
    Grid cells that no box meets keep ``fill``.
    """
    if bits > depth:
        raise ValueError(f"bits: expected at most the paving depth {depth}, got {bits}")
    n = 1 << bits
    s = depth - bits
    # who[c] = the last box (in the caller's order) meeting grid cell c, -1 for none
    who = np.full((n, n, n), -1, dtype=np.int64)
    values = np.asarray(values)
    if len(values):
        glo = np.asarray(lo, dtype=np.int64) >> s
        ghi = (np.asarray(hi, dtype=np.int64) + (1 << s) - 1) >> s
        size = ghi - glo
        code = (size[:, 0] << 42) | (size[:, 1] << 21) | size[:, 2]  # one int per box size: a fast unique
        codes, which = np.unique(code, return_inverse=True)
        which = which.reshape(-1)
        flat_who = who.reshape(-1)
        for m, c in enumerate(codes):
            sx, sy, sz = int(c >> 42), int((c >> 21) & ((1 << 21) - 1)), int(c & ((1 << 21) - 1))
            sel = np.flatnonzero(which == m)
            if sx * sy * sz <= 64:
                base = (glo[sel, 0] * n + glo[sel, 1]) * n + glo[sel, 2]
                for dx in range(sx):
                    for dy in range(sy):
                        for dz in range(sz):
                            np.maximum.at(flat_who, base + (dx * n + dy) * n + dz, sel)
            else:
                for i in sel:  # few big boxes (coarse octree levels)
                    block = who[glo[i, 0]:ghi[i, 0], glo[i, 1]:ghi[i, 1], glo[i, 2]:ghi[i, 2]]
                    np.maximum(block, i, out=block)
    grid = np.full((n, n, n), fill, dtype=np.int32)
    hit = who >= 0
    grid[hit] = values[who[hit]]
    return grid


def lattice_points(lo: np.ndarray, hi: np.ndarray, depth: int, domain: np.ndarray):
    """Shared corner points of integer boxes, for hexahedral meshes.

    Returns ``(points, connectivity)``: points (m, 3) float64 at
    ``domain_lo + k * step`` (the domain's upper bound exactly on the last plane,
    as the paving writes box bounds) and connectivity (n, 8) int32 in VTK's
    hexahedron order (bottom face counter-clockwise, then the top face).
    """
    corners_of = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                           [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]])
    lo = np.asarray(lo, dtype=np.int64)
    hi = np.asarray(hi, dtype=np.int64)
    nf = np.int64(1) << depth
    corners = np.where(corners_of[None] == 0, lo[:, None, :], hi[:, None, :])
    keys = (corners[..., 0] * (nf + 1) + corners[..., 1]) * (nf + 1) + corners[..., 2]
    uniq, inverse = np.unique(keys.ravel(), return_inverse=True)
    k = np.stack([uniq // ((nf + 1) * (nf + 1)), (uniq // (nf + 1)) % (nf + 1), uniq % (nf + 1)], axis=1)
    dom = np.asarray(domain, dtype=np.float64)
    step = np.ldexp(dom[:, 1] - dom[:, 0], -depth)
    points = np.where(k == nf, dom[:, 1], dom[:, 0] + k * step)
    return points, inverse.reshape(-1, 8).astype(np.int32)


@dataclass(frozen=True)
class JointBoxes:
    """The joint-space boxes on their integer lattice and their npz columns (same order)."""

    lo: np.ndarray
    hi: np.ndarray
    depth: int
    domain: np.ndarray
    columns: dict


def joint_boxes(joint) -> JointBoxes:
    """Integer bounds of the voxels (uniform grid) or boxes (adaptive paving) of a joint space.

    Joint spaces come in two shapes: a uniform voxel grid
    (:class:`~intervalkin.space.joint_space.JointPaving`) or an adaptive dyadic paving
    (an object with a ``paving`` attribute); both list their npz columns with ``columns()``.
    """
    cols = joint.columns()
    if hasattr(joint, "paving"):  # adaptive: the boxes of a dyadic paving
        p = joint.paving
        lo, hi = fine_bounds(p.level, p.ijk, p.depth)
        return JointBoxes(lo, hi, int(p.depth), np.asarray(p.domain, dtype=np.float64), cols)
    n = joint.n  # uniform: voxel (i, j, k) in C order, as columns() lists them
    idx = np.indices((n, n, n)).reshape(3, -1).T.astype(np.int64)
    r0, h = joint.approx_grid()
    domain = np.stack([r0, r0 + n * h], axis=1)
    return JointBoxes(idx, idx + 1, int(joint.depth), domain, cols)


def cell_by_id(joint) -> dict:
    """{cell id: cell} of a joint space (the cells of an adaptive paving are not listed in id order)."""
    return {int(c.id): c for c in joint.cells}
