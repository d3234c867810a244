"""Paths through the voxels of one joint cell, along which solutions are followed.

A joint cell (:mod:`intervalkin.space.joint_space`) is a face-connected set of
voxels of the joint grid, certified off g(S).  To carry the names of the
solutions (their sheets) across a cell, the certified continuation of
:mod:`intervalkin.solve.continuation` follows them along straight joint-space
segments that stay inside the cell:

* :func:`voxel_tree` spans the cell's voxels by a breadth-first tree from a root
  voxel, preferring to continue in the parent's direction, so that tree paths
  run in long straight runs;
* :func:`straight_edges` cuts the part of the tree that reaches given voxels
  into straight runs: the segment between the centres of the two end voxels of
  a run lies in the union of the closed voxels of the run, hence in the cell
  (closed voxels of a cell are off g(S) too);
* :func:`voxel_centres` encloses the exact voxel centres rho_min + (k + 1/2) step
  in intervals, the end points of those segments;
* :func:`voxel_of_points` finds the voxel of float joint vectors, decided
  exactly.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from intervalkin.core.exact import fraction_bounds
from intervalkin.core.interval import Interval

__all__ = ['voxel_tree', 'straight_edges', 'voxel_centres', 'voxel_of_points']


def voxel_tree(in_cell: np.ndarray, root: tuple[int, int, int]):
    """Breadth-first tree of the True voxels of a 3-D grid, from ``root``.

    Returns (parent, direction) as flat arrays over the grid (-1 outside the
    tree).  ``direction`` d in 0..5 says the voxel is its parent moved one step
    along axis d // 2, in the + sense when d is even.  Among the parents at the
    previous distance, one reached along the parent's own direction is preferred,
    so that the tree paths run in long straight runs.
    """
    shape = in_cell.shape
    free = in_cell.ravel()
    n = free.size
    strides = np.array([shape[1] * shape[2], shape[2], 1], dtype=np.int64)
    parent = np.full(n, -1, dtype=np.int64)
    direction = np.full(n, -1, dtype=np.int8)
    seen = np.zeros(n, dtype=bool)
    r = int(np.dot(root, strides))
    if not free[r]:
        raise ValueError("root voxel is not in the cell")
    seen[r] = True
    front = np.array([r], dtype=np.int64)
    while front.size:
        coords = np.stack(np.unravel_index(front, shape), axis=1)
        cand_v, cand_u, cand_d, cand_pref = [], [], [], []
        for d in range(6):
            axis, sgn = d // 2, (1 if d % 2 == 0 else -1)
            c = coords[:, axis] + sgn
            okc = (c >= 0) & (c < shape[axis])
            u = front[okc]
            v = u + sgn * strides[axis]
            keep = free[v] & ~seen[v]
            u, v = u[keep], v[keep]
            cand_v.append(v)
            cand_u.append(u)
            cand_d.append(np.full(v.size, d, dtype=np.int8))
            cand_pref.append((direction[u] != d).astype(np.int8))  # 0 = same direction as the parent link
        v = np.concatenate(cand_v)
        if v.size == 0:
            break
        u = np.concatenate(cand_u)
        dd = np.concatenate(cand_d)
        pref = np.concatenate(cand_pref)
        order = np.lexsort((dd, pref, v))
        v, u, dd = v[order], u[order], dd[order]
        first = np.ones(v.size, dtype=bool)
        first[1:] = v[1:] != v[:-1]
        v, u, dd = v[first], u[first], dd[first]
        parent[v] = u
        direction[v] = dd
        seen[v] = True
        front = v
    return parent, direction


def straight_edges(parent: np.ndarray, direction: np.ndarray, root: int, targets, max_run: int = 1 << 30):
    """Edges (top, bottom, length) of the tree spanned by root and targets, cut into straight runs.

    Each edge joins two voxels of one straight run of the tree, at most
    ``max_run`` voxels apart; every voxel in between is a tree voxel, so the
    segment between their centres lies in the union of the closed voxels of
    the run.  Edges are listed top-down: an edge's top is the root or the
    bottom of an earlier edge.
    """
    children: dict[int, list[int]] = {}
    in_union = {root}
    for t in targets:
        v = int(t)
        while v not in in_union:
            in_union.add(v)
            u = int(parent[v])
            if u < 0:
                raise ValueError("target voxel not in the tree")
            children.setdefault(u, []).append(v)
            v = u
    target_set = {int(t) for t in targets}
    edges: list[tuple[int, int, int]] = []
    stack = [(root, c) for c in children.get(root, [])]
    while stack:
        top, v = stack.pop()
        run = 1
        while run < max_run:  # walk down the straight run while the node is not a stop
            ch = children.get(v, [])
            if v in target_set or len(ch) != 1 or direction[ch[0]] != direction[v]:
                break
            v = ch[0]
            run += 1
        edges.append((top, v, run))
        stack.extend((v, c) for c in children.get(v, []))
    return edges


def voxel_centres(joint, flat: np.ndarray) -> Interval:
    """Enclosures (m, 3) of the exact centres rho_min + (k + 1/2) step of voxels (flat C order)."""
    idx = np.stack(np.unravel_index(np.asarray(flat, dtype=np.int64), (joint.n,) * 3), axis=1).astype(np.float64)
    r0 = [fraction_bounds(v) for v in joint.rho_min]
    h = [fraction_bounds(v) for v in joint.step]
    R0 = Interval(np.array([b[0] for b in r0]), np.array([b[1] for b in r0]))
    H = Interval(np.array([b[0] for b in h]), np.array([b[1] for b in h]))
    return R0 + H * (idx + 0.5)


def voxel_of_points(joint, q: np.ndarray) -> np.ndarray:
    """Voxel index (m, 3) of float joint vectors q (m, 3), checked exactly; -1 rows when outside.

    The float guess floor((q - rho_min) / step) may be one off; the exact test
    (closed voxels, Fractions) decides among it and its two neighbours.
    """
    r0, h = joint.approx_grid()
    k = np.floor((q - r0) / h).astype(np.int64)
    out = np.full(q.shape, -1, dtype=np.int64)
    for i in range(len(q)):
        row = []
        for j in range(3):
            v = Fraction(float(q[i, j]))
            kk = int(k[i, j])
            for cand in (kk, kk - 1, kk + 1):  # the float floor may be one off; the exact test decides
                lo_edge = joint.rho_min[j] + cand * joint.step[j]
                if 0 <= cand < joint.n and lo_edge <= v <= lo_edge + joint.step[j]:
                    row.append(cand)
                    break
            else:
                row = None
                break
        if row is not None:
            out[i] = row
    return out
