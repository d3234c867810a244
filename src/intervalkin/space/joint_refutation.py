"""Refuting joins: window models of both ends of a face contact may prove it carries no point of a count.

The separation graph G_sigma (:mod:`intervalkin.space.joint_separation`) keeps an edge between two
leaves whenever it cannot prove the shared face free of signature sigma.  Where it joins two cells of
sigma, the join runs through some contacts between leaves with complete models (fold boxes whose
traces are not decided, pieces of unknown count).  Those leaves get window models here, on demand, and
a contact is cut for sigma when no pattern of the one end with sigma's count can meet a pattern of the
other with that count on the face (:func:`intervalkin.space.joint_patterns.exclusive`, proofs/
lemma-refuted-contact.md): a point of the face with that count would hold one in each.  A piece of a
complete model is connected and off g(S), so it holds one pattern: the one found at its witness, or
at a probe point of the leaf whose count is the piece's and not the other piece's.  A leaf whose own
window model fails is modelled by its eight halves (which tile it), with no restriction.

What is certified: every cut (the lemma; every sign behind it in ball arithmetic).  What is not:
nothing is written to the certificates, so ``intervalkin verify`` does not re-prove the cuts.

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

__all__ = ["Refuter", "near_shortest", "nodes_between", "SLACK", "BATCH"]

#: Chains tried: up to this many contacts longer than the shortest.
SLACK = 2
#: Contacts tried at most per round and signature.
BATCH = 20000


class Refuter:
    """Window models of leaves of a joint paving, made on demand, and the contacts they cut.

    A leaf whose window model fails (a window that might hold too many roots, an arc with no signed
    derivative) is modelled as its eight halves instead: a point of the leaf lies in one of them.
    """

    def __init__(self, geometry: Geometry, lo: np.ndarray, hi: np.ndarray, known: tuple | None = None):
        """``known``: (leaves, models), window models the paving already made (sorted leaves, one row each):
        taken as they are rather than made again (a box's model depends on the box alone)."""
        self._geometry, self._lo, self._hi = geometry, lo, hi
        self._known = known
        self._leaf = np.zeros(0, dtype=np.int64)  # the modelled leaves, sorted
        self._row = np.zeros(0, dtype=np.int64)  # the models row of each (its own, or its first half's)
        self._halves = np.zeros(0, dtype=bool)  # modelled as eight halves (rows row .. row + 7)
        self._models: WindowModels | None = None
        self._patterns = None
        self.modelled = 0

    def _add(self, boxes: np.ndarray, taken: np.ndarray | None = None) -> np.ndarray:
        """Model boxes (k, 3, 2), the first ones by the paving's models of rows ``taken`` (increasing); their rows."""
        if taken is not None and taken.size:
            m = self._known[1].take(taken)
            if taken.size < len(boxes):
                m = m.concat(window_models(self._geometry, boxes[taken.size:]))
        else:
            m = window_models(self._geometry, boxes)
        first = 0 if self._models is None else len(self._models.ok)
        self._models = m if self._models is None else self._models.concat(m)
        return first + np.arange(len(boxes))

    def _known_first(self, leaves: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
        """``leaves`` (sorted) reordered with those the paving already modelled first, and their rows there."""
        if self._known is None or len(self._known[0]) == 0:
            return leaves, None
        known = self._known[0]
        at = np.minimum(np.searchsorted(known, leaves), len(known) - 1)
        have = known[at] == leaves
        return np.r_[leaves[have], leaves[~have]], at[have]

    def _model(self, leaves: np.ndarray) -> None:
        new = np.setdiff1d(leaves, self._leaf)
        if new.size == 0:
            return
        new, taken = self._known_first(new)
        lo, hi = self._lo[new], self._hi[new]
        row = self._add(np.stack([lo, hi], axis=-1), taken)
        self._patterns = window_patterns(self._models)
        halves = ~np.isin(row, self._patterns.box)
        if halves.any():
            k = np.flatnonzero(halves)
            mid = 0.5 * (lo[k] + hi[k])
            corner = (np.arange(8)[:, None] >> np.arange(3)) & 1  # (8, 3): which half along each axis
            c_lo = np.where(corner[None], mid[:, None], lo[k][:, None])
            c_hi = np.where(corner[None], hi[k][:, None], mid[:, None])
            row[k] = self._add(np.stack([c_lo, c_hi], axis=-1).reshape(-1, 3, 2))[::8]
            self._patterns = window_patterns(self._models)
        leaf = np.r_[self._leaf, new]
        order = np.argsort(leaf, kind="stable")
        self._leaf, self._row = leaf[order], np.r_[self._row, row][order]
        self._halves = np.r_[self._halves, halves][order]
        self.modelled += int(new.size)

    def cut(self, a: np.ndarray, b: np.ndarray, count: int, points: tuple[np.ndarray, np.ndarray] | None = None,
            may: tuple[np.ndarray, np.ndarray] | None = None, code_b: np.ndarray | None = None,
            piece_counts: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
        """(m,) bool: contacts (a[i], b[i]) proved to carry no point with ``count`` solutions.

        ``points`` (m, 2, 3) per end: a point of each connected piece of the end's leaf off g(S) (NaN:
        none known), and ``may`` (m, 2) bool: the pieces that may hold the count.  A piece holds one
        pattern, the one found at its point; without them every pattern of the count is possible.
        ``code_b`` (m,): where not -1, b stands only for its points of that pattern (a pattern node).
        ``piece_counts`` (m, 2) per end: the certified count of each piece (-1 unknown, -2 no piece); a
        piece with no point takes the pattern found at a probe point of its leaf whose count is its own
        and not the other piece's (a point of the leaf off g(S) lies in one of the pieces).
        A leaf modelled as halves has no such restriction: the contact is cut when every pair of a
        half of the one end and a half (or the whole) of the other that meet is proved free of the count.
        """
        if a.size == 0:
            return np.zeros(0, dtype=bool)
        self._model(np.unique(np.r_[a, b]))
        ia, ib = np.searchsorted(self._leaf, a), np.searchsorted(self._leaf, b)
        ra, rb = self._row[ia], self._row[ib]
        only = [np.full((a.size, 2), EVERY, dtype=np.int64), np.full((a.size, 2), EVERY, dtype=np.int64)]
        if points is not None:
            counts = piece_counts or (None, None)
            for end, (leaf, i, rows, pts, m, pc) in enumerate(zip((a, b), (ia, ib), (ra, rb), points, may, counts)):
                whole = np.flatnonzero(~self._halves[i])  # a half's model says nothing of its leaf's pieces
                only[end][whole] = self._piece_rows(leaf[whole], rows[whole], pts[whole], m[whole],
                                                    None if pc is None else pc[whole])
        if code_b is not None:
            node = np.flatnonzero(code_b >= 0)
            row = row_of(self._patterns, rb[node], code_b[node])
            only[1][node] = np.column_stack([np.where(row >= 0, row, EVERY), np.full(node.size, NONE)])
        # every pair of parts (the leaf, or its halves) of the two ends whose closed boxes meet
        na, nb = np.where(self._halves[ia], 8, 1), np.where(self._halves[ib], 8, 1)
        c = np.repeat(np.arange(a.size), na * nb)
        k = np.arange(c.size) - np.repeat(np.cumsum(na * nb) - na * nb, na * nb)
        pa, pb = ra[c] + k // nb[c], rb[c] + k % nb[c]
        boxes = self._models.boxes
        meet = np.all(np.maximum(boxes[pa, :, 0], boxes[pb, :, 0]) <= np.minimum(boxes[pa, :, 1], boxes[pb, :, 1]),
                      axis=1)
        c, pa, pb = c[meet], pa[meet], pb[meet]
        # a piece's pattern is a fact about its leaf's own model: halves may hold any pattern
        oa = np.where(self._halves[ia][c, None], EVERY, only[0][c])
        ob = np.where(self._halves[ib][c, None], EVERY, only[1][c])
        free = exclusive(self._models, self._patterns, pa, pb, count, oa, ob)
        held = np.bincount(c, weights=~free, minlength=a.size)
        return (held == 0) & (np.bincount(c, minlength=a.size) > 0)

    def _piece_rows(self, leaf: np.ndarray, rows: np.ndarray, pts: np.ndarray, may: np.ndarray,
                    counts: np.ndarray | None) -> np.ndarray:
        """(m, 2) the pattern row of each piece that may hold the count (EVERY where not found), NONE elsewhere."""
        out = np.where(may, EVERY, NONE).astype(np.int64)
        for slot in (0, 1):
            at = np.flatnonzero(may[:, slot] & np.isfinite(pts[:, slot]).all(axis=1))
            if at.size:
                code = pattern_at(self._geometry, self._models, self._patterns, rows[at], pts[at, slot])
                row = row_of(self._patterns, rows[at], code)
                out[at, slot] = np.where(row >= 0, row, EVERY)
        if counts is None:
            return out
        # pieces still without a pattern, of a known count that the other piece (if any) does not share
        known = counts >= 0
        other = counts[:, ::-1]
        want = may & (out == EVERY) & known & (other != counts) & ((other >= 0) | (other == NONE_PIECE))
        need = np.flatnonzero(want.any(axis=1))
        if need.size == 0:
            return out
        lo, hi = self._lo[leaf[need]], self._hi[leaf[need]]
        probe = lo[:, None, :] + PROBES[None, :, :] * (hi - lo)[:, None, :]  # (k, p, 3)
        p = PROBES.shape[0]
        r = np.repeat(rows[need], p)
        code = pattern_at(self._geometry, self._models, self._patterns, r, probe.reshape(-1, 3))
        row = row_of(self._patterns, r, code).reshape(-1, p)
        total = np.where(row >= 0, self._patterns.count[np.maximum(row, 0)], -1)
        for slot in (0, 1):
            hit = want[need, slot][:, None] & (total == counts[need, slot][:, None])
            first = np.argmax(hit, axis=1)
            got = hit.any(axis=1)
            out[need[got], slot] = row[got, first[got]]
        return out


#: Probe points of a leaf, as fractions of its sides: the centre and the corners drawn in by a tenth.
PROBES = np.array([[0.5, 0.5, 0.5]] + [[0.1 + 0.8 * ((k >> j) & 1) for j in range(3)] for k in range(8)])
#: A slot of ``piece_counts`` with no piece (as joint_separation.NO_PIECE).
NONE_PIECE = -2


def near_shortest(n: int, src: np.ndarray, dst: np.ndarray, start: np.ndarray, goal: np.ndarray,
                  a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Indices into the candidate contacts (a, b) lying on a chain of the graph (src, dst) on n nodes
    from a node of ``start`` to a node of ``goal`` at most :data:`SLACK` longer than the shortest,
    shortest first, at most :data:`BATCH`; empty when no chain joins them."""
    d0, d1 = _distances(n, src, dst, start), _distances(n, src, dst, goal)
    through = np.minimum(d0[a] + 1 + d1[b], d0[b] + 1 + d1[a])
    finite = np.isfinite(through)
    if not finite.any():
        return np.zeros(0, dtype=np.int64)
    best = through[finite].min()
    pick = np.flatnonzero(finite & (through <= best + SLACK))
    return pick[np.argsort(through[pick], kind="stable")][:BATCH]


def nodes_between(n: int, src: np.ndarray, dst: np.ndarray, start: np.ndarray, goal: np.ndarray,
                  slack: int) -> np.ndarray:
    """The nodes on chains of the graph (src, dst) on n nodes from ``start`` to ``goal`` at most ``slack`` edges
    longer than the shortest (d(start, v) + d(v, goal) within slack of its least); empty when none joins them."""
    total = _distances(n, src, dst, start) + _distances(n, src, dst, goal)
    if not np.isfinite(total).any():
        return np.zeros(0, dtype=np.int64)
    return np.flatnonzero(total <= total.min() + slack)


def _distances(n: int, src: np.ndarray, dst: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """(n,) the number of edges from the nearest node of ``ends`` (inf where none leads)."""
    hub = n  # one extra node next to every end node: one breadth-first search
    graph = coo_matrix((np.ones(src.size + ends.size), (np.r_[src, np.full(ends.size, hub)], np.r_[dst, ends])),
                       shape=(n + 1, n + 1))
    return shortest_path(graph, directed=False, unweighted=True, indices=hub)[:n] - 1
