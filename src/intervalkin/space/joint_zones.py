"""Zones of the joint box to pave more finely: where the separation graph still joins two cells.

Two cells of one signature stay in one group of G_sigma (:mod:`intervalkin.space.joint_separation`) when
some chain of leaves that may hold the signature joins them.  Where the cells are truly different
components, such a chain runs through leaves too coarse to tell them apart: leaves that straddle a thin
piece of another count between them, or a crossing of two sheets of g(S) whose two quadrants of the
count hold their roots at nearby orientations (on the paper's manipulator with limits [10.5, 32], cells
3 and 7 are kept apart by a 6-solution sliver 0.016 wide in rho_1 along the face rho_3 = 10.5, which
the default leaves, 0.04 to 0.08 wide there, straddle).  A ZONE is a set of boxes of the uniform level
of the paving (``depth``); :func:`~intervalkin.space.joint_paving.pave_joint_space` splits the undecided
leaves inside it ``levels`` more times, re-testing and re-modelling each child as everywhere else.

Nothing here is a proof: a zone only says where to spend effort.  Every label of the finer paving is
proved as any other, and the separations found on it are proved by the same lemmas.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from intervalkin.core.errors import InputError

__all__ = ["RefinementZone", "MAX_ZONE_LEVELS"]

#: Levels a zone may add to its leaves (about 4**levels undecided children for a leaf along a sheet of g(S)).
MAX_ZONE_LEVELS = 6


@dataclass(frozen=True)
class RefinementZone:
    """depth : the level of the boxes of ``cells``; cells : (k, 3) int64, their integer positions at that
    level (sorted, unique); levels : how many more times the undecided leaves inside them are split."""

    depth: int
    cells: np.ndarray
    levels: int

    def __post_init__(self) -> None:
        cells = np.unique(np.asarray(self.cells, dtype=np.int64).reshape(-1, 3), axis=0)
        if isinstance(self.levels, bool) or not isinstance(self.levels, int) or not 0 <= self.levels <= MAX_ZONE_LEVELS:
            raise InputError(f"zone levels: expected an integer in 0..{MAX_ZONE_LEVELS}, got {self.levels!r}")
        if cells.size and (cells.min() < 0 or cells.max() >= 1 << self.depth):
            raise InputError(f"zone cells: expected positions in 0..{(1 << self.depth) - 1} at level {self.depth}")
        object.__setattr__(self, "cells", cells)

    @classmethod
    def of_leaves(cls, level: np.ndarray, ijk: np.ndarray, depth: int, levels: int) -> "RefinementZone":
        """The zone of the level-``depth`` boxes holding the given leaves (those coarser than ``depth`` hold
        no undecided point: only leaves proved clear stay above the uniform level)."""
        fine = level >= depth
        return cls(depth, ijk[fine] >> (level[fine] - depth)[:, None], levels)

    def union(self, other: "RefinementZone") -> "RefinementZone":
        if other.depth != self.depth:
            raise ValueError("zones of different depths")
        return RefinementZone(self.depth, np.concatenate([self.cells, other.cells]), max(self.levels, other.levels))

    def holds(self, level: np.ndarray, ijk: np.ndarray) -> np.ndarray:
        """(n,) bool: the leaves (level, ijk) lying in a box of the zone."""
        out = np.zeros(level.size, dtype=bool)
        fine = np.flatnonzero(level >= self.depth)
        if not self.cells.size or not fine.size:
            return out
        up = ijk[fine] >> (level[fine] - self.depth)[:, None]
        key = (up[:, 0] << (2 * self.depth)) | (up[:, 1] << self.depth) | up[:, 2]
        mine = (self.cells[:, 0] << (2 * self.depth)) | (self.cells[:, 1] << self.depth) | self.cells[:, 2]
        out[fine] = np.isin(key, mine)
        return out

    def to_json(self, span: np.ndarray) -> dict:
        """``span`` (3,): the widths of the joint box, for the zone's volume."""
        return {"boxes": int(len(self.cells)), "levels": self.levels,
                "volume": float(len(self.cells) * np.prod(np.asarray(span, dtype=float) / (1 << self.depth)))}

