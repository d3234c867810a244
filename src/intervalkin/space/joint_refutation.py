"""Refuting joins: window models of both ends of a face contact may prove it carries no point of a count.

The separation graph G_sigma (:mod:`intervalkin.space.joint_separation`) keeps an edge between two
leaves whenever it cannot prove the shared face free of signature sigma.  Where it joins two cells of
sigma, the join runs through some contacts between leaves with complete models (fold boxes whose
traces are not decided, pieces of unknown count).  Those leaves get window models here, on demand, and
a contact is cut for sigma when no pattern of the one end with sigma's count can meet a pattern of the
other with that count on the face (:func:`intervalkin.space.joint_patterns.exclusive`, proofs/
lemma-window-patterns.md): a point of the face with that count would hold one in each.

Which contacts are tried is a choice of effort, not of soundness: those on the shortest chains of
G_sigma between the cells of a group (breadth first from one cell and from the others; a contact
(u, v) lies on a chain of length at most d + :data:`SLACK` when dist(u) + 1 + dist'(v) is at most
that), at most :data:`BATCH` at a time.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import shortest_path

from intervalkin.core.geometry import Geometry
from intervalkin.solve.window_model import WindowModels, window_models
from intervalkin.space.joint_patterns import EVERY, NONE, exclusive, pattern_at, row_of, window_patterns

__all__ = ["Refuter", "SLACK", "BATCH"]

#: Chains tried: up to this many contacts longer than the shortest.
SLACK = 2
#: Contacts tried at most per round and signature.
BATCH = 20000


class Refuter:
    """Window models of leaves of a joint paving, made on demand, and the contacts they cut."""

    def __init__(self, geometry: Geometry, lo: np.ndarray, hi: np.ndarray):
        self._geometry, self._lo, self._hi = geometry, lo, hi
        self._inserted = np.zeros(0, dtype=np.int64)  # the modelled leaves, in the order of the models' rows
        self._leaf = np.zeros(0, dtype=np.int64)  # the same, sorted; self._row: their rows
        self._row = np.zeros(0, dtype=np.int64)
        self._models: WindowModels | None = None
        self._patterns = None
        self.modelled = 0

    def _model(self, leaves: np.ndarray) -> None:
        new = np.setdiff1d(leaves, self._leaf)
        if new.size == 0:
            return
        m = window_models(self._geometry, np.stack([self._lo[new], self._hi[new]], axis=-1))
        self._models = m if self._models is None else self._models.concat(m)
        self._inserted = np.r_[self._inserted, new]  # leaf of each models row
        self._row = np.argsort(self._inserted, kind="stable")
        self._leaf = self._inserted[self._row]
        self._patterns = window_patterns(self._models)
        self.modelled += int(new.size)

    def cut(self, a: np.ndarray, b: np.ndarray, count: int, points: tuple[np.ndarray, np.ndarray] | None = None,
            may: tuple[np.ndarray, np.ndarray] | None = None, code_b: np.ndarray | None = None) -> np.ndarray:
        """(m,) bool: contacts (a[i], b[i]) proved to carry no point with ``count`` solutions.

        ``points`` (m, 2, 3) per end: a point of each connected piece of the end's leaf off g(S) (NaN:
        none known), and ``may`` (m, 2) bool: the pieces that may hold the count.  A piece holds one
        pattern, the one found at its point; without them every pattern of the count is possible.
        ``code_b`` (m,): where not -1, b stands only for its points of that pattern (a pattern node).
        """
        if a.size == 0:
            return np.zeros(0, dtype=bool)
        self._model(np.unique(np.r_[a, b]))
        ra = self._row[np.searchsorted(self._leaf, a)]
        rb = self._row[np.searchsorted(self._leaf, b)]
        only = [None, None]
        if points is not None:
            for end, (rows, pts, m) in enumerate(zip((ra, rb), points, may)):
                only[end] = self._piece_rows(rows, pts, m)
        if code_b is not None:
            node = np.flatnonzero(code_b >= 0)
            row = row_of(self._patterns, rb[node], code_b[node])
            if only[1] is None:
                only[1] = np.full((a.size, 2), EVERY, dtype=np.int64)
            only[1][node] = np.column_stack([np.where(row >= 0, row, EVERY), np.full(node.size, NONE)])
        return exclusive(self._models, self._patterns, ra, rb, count, only[0], only[1])

    def _piece_rows(self, rows: np.ndarray, pts: np.ndarray, may: np.ndarray) -> np.ndarray:
        """(m, 2) the pattern row of each piece that may hold the count (EVERY where not found), NONE elsewhere."""
        out = np.where(may, EVERY, NONE).astype(np.int64)
        for slot in (0, 1):
            at = np.flatnonzero(may[:, slot] & np.isfinite(pts[:, slot]).all(axis=1))
            if at.size:
                code = pattern_at(self._geometry, self._models, self._patterns, rows[at], pts[at, slot])
                row = row_of(self._patterns, rows[at], code)
                out[at, slot] = np.where(row >= 0, row, EVERY)
        return out


def near_shortest(n: int, src: np.ndarray, dst: np.ndarray, start: np.ndarray, goal: np.ndarray,
                  a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Indices into the candidate contacts (a, b) lying on a chain of the graph (src, dst) on n nodes
    from a node of ``start`` to a node of ``goal`` at most :data:`SLACK` longer than the shortest,
    shortest first, at most :data:`BATCH`; empty when no chain joins them."""
    hub = n  # one extra node next to every start (or goal) node: one breadth-first search each
    dist = []
    for ends in (start, goal):
        graph = coo_matrix((np.ones(src.size + ends.size), (np.r_[src, np.full(ends.size, hub)], np.r_[dst, ends])),
                           shape=(n + 1, n + 1))
        dist.append(shortest_path(graph, directed=False, unweighted=True, indices=hub)[:n] - 1)
    d0, d1 = dist
    through = np.minimum(d0[a] + 1 + d1[b], d0[b] + 1 + d1[a])
    finite = np.isfinite(through)
    if not finite.any():
        return np.zeros(0, dtype=np.int64)
    best = through[finite].min()
    pick = np.flatnonzero(finite & (through <= best + SLACK))
    return pick[np.argsort(through[pick], kind="stable")][:BATCH]
