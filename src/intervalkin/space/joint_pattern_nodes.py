"""Pattern nodes: the window-modelled leaves of a joint paving as one node per possible pattern.

A leaf L with a window model but no complete model may hold several pieces of L minus g(S), near a
cusp edge or a crossing of two sheets of g(S).  :mod:`intervalkin.space.joint_patterns` proves that
the pattern (solutions per super-window) is constant on each such piece, and which patterns of two
neighbouring leaves may meet on their shared face.  :class:`PatternNodes` gives the separation graph
(:mod:`intervalkin.space.joint_separation`) a node per (leaf, pattern) and the tables to join them:
the rows of each count, the row of a code, the pattern at a point.
"""

from __future__ import annotations

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.space.joint_patterns import compatible, pattern_at, row_of, unit_overlaps, window_patterns

__all__ = ["PatternNodes", "expand", "runs"]

#: Possible-count mask of a leaf that may hold any count (as in joint_separation).
ANY = -1


def runs(keys: np.ndarray, wanted: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(start, length) of the run of each ``wanted`` value in the sorted array ``keys``."""
    lo = np.searchsorted(keys, wanted, side="left")
    return lo, np.searchsorted(keys, wanted, side="right") - lo


def expand(src: np.ndarray, start: np.ndarray, length: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pairs (src[i], start[i] + j) for j < length[i]."""
    rep = np.repeat(np.arange(src.size), length)
    return src[rep], start[rep] + np.arange(rep.size) - np.repeat(np.cumsum(length) - length, length)



class PatternNodes:
    """The pattern nodes of a joint paving: each leaf with a window model and no complete model (and not
    said to hold anything) stands in G_sigma as one node per pattern it may hold, rather than one node.

    Node k (0 <= k < len(count)) is pattern row ``k`` of leaf ``leaf[k]``; ``is_p`` (n,) marks the leaves
    so represented.  Rows of a leaf are contiguous and sorted by code.
    """

    def __init__(self, jp, has_model: np.ndarray, counts: np.ndarray):
        n = len(jp.cell)
        self.is_p = np.zeros(n, dtype=bool)
        self.count = np.zeros(0, dtype=np.int64)
        self.leaf = np.zeros(0, dtype=np.int64)
        self.code = np.zeros(0, dtype=np.int64)
        self._row = np.zeros(0, dtype=np.int64)
        w = jp.windows
        if w is None:
            return
        self._w = w
        self._wp = window_patterns(w.models)
        leaf = w.leaf[self._wp.box]
        # a leaf said to hold anything (counts ANY) stays one node, whatever its model
        keep = ~has_model[leaf] & (counts[leaf] != ANY)
        self._row = np.flatnonzero(keep)
        self.leaf, self.code, self.count = leaf[keep], self._wp.code[keep], self._wp.count[keep]
        self.is_p[self.leaf] = True

    def overlaps(self, leaf_a: np.ndarray, leaf_b: np.ndarray) -> np.ndarray:
        """(c, U, U) unit overlaps of pattern leaves sharing a face (see :func:`unit_overlaps`)."""
        if self.leaf.size == 0:
            return np.zeros((leaf_a.size, 1, 1), dtype=bool)
        box_a, box_b = (np.searchsorted(self._w.leaf, x) for x in (leaf_a, leaf_b))
        return unit_overlaps(self._w.models, self._wp, box_a, box_b)

    def compatible(self, node_a: np.ndarray, node_b: np.ndarray, overlap: np.ndarray) -> np.ndarray:
        """Whether pattern nodes node_a[i] and node_b[i] of two leaves sharing a face may meet on it."""
        if self.leaf.size == 0:
            return np.zeros(0, dtype=bool)
        return compatible(self._w.models, self._wp, self._row[node_a], self._row[node_b], overlap)

    def rows(self, count: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The rows with ``count``, compacted: (n,) start and length of each leaf's run among them, and the
        global row of each compacted one."""
        n = len(self.is_p)
        sel = self.count == count
        start = np.zeros(n, dtype=np.int64)
        length = np.zeros(n, dtype=np.int64)
        if self.leaf.size:
            leaves = np.flatnonzero(self.is_p)
            first, size = runs(self.leaf, leaves)
            before = np.r_[0, np.cumsum(sel)]
            # rows with the count are not contiguous inside a leaf's run: index them through a compacted view
            start[leaves] = before[first]
            length[leaves] = before[first + size] - before[first]
        return start, length, np.flatnonzero(sel)

    def rows_with(self, leaf: np.ndarray, count: np.ndarray) -> np.ndarray:
        """(m,) the number of patterns of ``leaf`` with total ``count`` (0 for a leaf with no patterns)."""
        out = np.zeros(leaf.size, dtype=np.int64)
        if self.leaf.size == 0 or leaf.size == 0:
            return out
        first, size = runs(self.leaf, leaf)
        for c in np.unique(count):  # a handful of counts: 0, 2, 4, 6
            at = np.flatnonzero(count == c)
            before = np.r_[0, np.cumsum(self.count == c)]
            out[at] = before[first[at] + size[at]] - before[first[at]]
        return out

    def row_of(self, leaf: np.ndarray, code: np.ndarray) -> np.ndarray:
        """Node of (leaf, code), -1 where code is -1 or not a pattern node of the leaf."""
        out = np.full(leaf.size, -1, dtype=np.int64)
        if self.leaf.size == 0 or leaf.size == 0:
            return out
        row = row_of(self._wp, np.searchsorted(self._w.leaf, leaf), code)  # a row of all the window patterns
        node = np.minimum(np.searchsorted(self._row, row), self._row.size - 1)  # self._row is sorted
        found = (row >= 0) & (self._row[node] == row)
        out[found] = node[found]
        return out

    def at(self, geometry: Geometry, leaf: np.ndarray, points: np.ndarray) -> np.ndarray:
        """The certified pattern code of ``leaf`` at ``points`` (-1 where undecided)."""
        if self.leaf.size == 0:
            return np.full(len(leaf), -1, dtype=np.int64)
        rows = np.searchsorted(self._w.leaf, leaf)
        return pattern_at(geometry, self._w.models, self._wp, rows, points)
