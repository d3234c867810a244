"""Routes through the joint cells: where a path from a joint vector to another might run.

:class:`JointGrid` is the joint grid of an analysis (voxel centres as floats,
the cell of each voxel, -1 for a voxel that may meet g(S)), and
:func:`voxel_route` gives a polyline from one voxel of a cell to another through
the centres of the cell's voxels: a breadth-first path, its straight runs
merged.  Consecutive voxels of the path share a face, so each leg of the
polyline lies in the union of the closed voxels it crosses, all of them voxels
of the cell: certified off the enclosure of g(S) by the joint paving
(:mod:`intervalkin.space.joint_space`).  The centres are floats near the true
centres; that is harmless, a leg between two points of the cell's closed
voxels along an axis stays in them.  Whoever uses a route proves its legs into
and out of the cell (:mod:`intervalkin.space.pose_path`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ['JointGrid', 'cell_tree', 'voxel_route']

#: The six face neighbours of a voxel.
_STEPS = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])


@dataclass(frozen=True)
class JointGrid:
    """A joint grid as a guide: ``origin`` and ``step`` (3,) floats, ``cell`` (n, n, n) ids (-1: undecided voxel)."""

    origin: np.ndarray
    step: np.ndarray
    cell: np.ndarray

    @staticmethod
    def of_paving(joint) -> "JointGrid":
        """The guide of a :class:`~intervalkin.space.joint_space.JointPaving`."""
        return JointGrid(np.array([float(v) for v in joint.rho_min]), np.array([float(v) for v in joint.step]),
                         np.asarray(joint.cell))

    @staticmethod
    def of_columns(lo: np.ndarray, hi: np.ndarray, cell: np.ndarray) -> "JointGrid | None":
        """The guide of the columns of ``joint.npz`` (one row per voxel, in C order); None if they are not a grid."""
        n = int(round(len(cell) ** (1.0 / 3.0)))
        if n < 1 or n**3 != len(cell) or len(lo) != len(cell):
            return None
        return JointGrid(np.asarray(lo[0], float), np.asarray(hi[0] - lo[0], float), np.asarray(cell).reshape(n, n, n))

    @property
    def n(self) -> int:
        return int(self.cell.shape[0])

    def centres(self, ijk: np.ndarray) -> np.ndarray:
        """Float centres (m, 3) of voxels ``ijk`` (m, 3)."""
        return self.origin + (np.asarray(ijk) + 0.5) * self.step

    def voxel_of(self, q: np.ndarray) -> np.ndarray:
        """Voxel indices (m, 3) of float joint vectors (m, 3); rows of -1 outside the grid."""
        ijk = np.floor((np.asarray(q) - self.origin) / self.step).astype(np.int64)
        bad = np.any((ijk < 0) | (ijk >= self.n), axis=1)
        ijk[bad] = -1
        return ijk

    def certified_voxel_holding(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray | None:
        """The voxel of a certified cell that holds the whole box [lo, hi] (3,), or None.

        The float voxel bounds are within a few ulps of the exact ones (origin and
        step are the floats nearest exact rationals), so the box must clear them
        by a margin of 1e-9 voxel widths, far more than that error.
        """
        ijk = np.floor((np.asarray(lo) - self.origin) / self.step).astype(np.int64)
        if np.any(ijk < 0) or np.any(ijk >= self.n) or self.cell[tuple(ijk)] < 0:
            return None
        margin = 1e-9 * self.step
        v_lo = self.origin + ijk * self.step + margin
        v_hi = self.origin + (ijk + 1) * self.step - margin
        return ijk if np.all(v_lo <= lo) and np.all(hi <= v_hi) else None

    def nearest_voxels(self, q: np.ndarray, k: int) -> np.ndarray:
        """The ``k`` voxels of certified cells whose centres are nearest the float point q (3,): (k, 3)."""
        ijk = np.argwhere(self.cell >= 0)
        d = np.linalg.norm(self.centres(ijk) - q, axis=1)
        return ijk[np.argsort(d, kind="stable")[:k]]


def cell_tree(grid: JointGrid, root: np.ndarray) -> np.ndarray:
    """Breadth-first parents over the voxels of root's cell: flat index -> parent flat index (-1 unreached, root itself).

    Cost: one pass of array work per layer of the search.
    """
    n = grid.n
    inside = (grid.cell == grid.cell[tuple(root)]).ravel()
    parent = np.full(n**3, -1, dtype=np.int64)
    r = int(np.ravel_multi_index(tuple(root), (n, n, n)))
    parent[r] = r
    frontier = np.array([r])
    while frontier.size:
        ijk = np.stack(np.unravel_index(frontier, (n, n, n)), axis=1)
        reached = []
        for d in _STEPS:
            nb = ijk + d
            ok = np.all((nb >= 0) & (nb < n), axis=1)
            flat = np.ravel_multi_index(tuple(nb[ok].T), (n, n, n))
            src = frontier[ok]
            new = inside[flat] & (parent[flat] < 0)
            flat, src = flat[new], src[new]
            flat, first = np.unique(flat, return_index=True)
            parent[flat] = src[first]
            reached.append(flat)
        frontier = np.unique(np.concatenate(reached)) if reached else np.array([], dtype=np.int64)
    return parent


def voxel_route(grid: JointGrid, parent: np.ndarray, target: np.ndarray) -> np.ndarray | None:
    """Centres (k, 3) of the corners of the tree path from the root to voxel ``target`` (root first), or None.

    Straight runs of the path are merged: only the voxels where it turns, and
    its two ends, are kept.
    """
    n = grid.n
    t = int(np.ravel_multi_index(tuple(target), (n, n, n)))
    if parent[t] < 0:
        return None
    path = [t]
    while parent[path[-1]] != path[-1]:
        path.append(int(parent[path[-1]]))
    ijk = np.stack(np.unravel_index(np.array(path[::-1]), (n, n, n)), axis=1)
    if len(ijk) > 2:
        d = np.diff(ijk, axis=0)
        turn = np.any(d[1:] != d[:-1], axis=1)
        keep = np.concatenate([[True], turn, [True]])
        ijk = ijk[keep]
    return grid.centres(ijk)
