"""Cells of the direct joint-space paving: components of clear boxes, each with a certified count.

A *cell* is a face-connected component of the clear boxes of a joint paving (no
axis wraps).  It is connected (proofs/lemma-face-adjacency-connected.md) and lies
off g(S), so the number of direct-kinematic solutions and their split between the
aspects are the same at all its points (proofs/lemma-constant-count-off-gS.md):
one certified solve at an exact point of one of its boxes gives them.  The solve
is done once per cell and remembered by the box it was done in, so refining the
paving (joins) re-solves only cells that hold none of the boxes solved before; a
cell that holds boxes of several earlier cells must find one signature in them
(a disagreement would be a soundness bug, and is raised).

The *joining paths* are shortest chains of undecided boxes between two cells
with the same count and split: the places where refining can join two cells.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Callable, Sequence

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import breadth_first_order, connected_components

from intervalkin.core.geometry import Geometry
from intervalkin.core.status import Count
from intervalkin.paving.adjacency import component_labels, shares_face
from intervalkin.paving.labels import Label
from intervalkin.paving.tree import Paving
from intervalkin.solve.dkp import solve
from intervalkin.space.joint_pieces import FoldPieces
from intervalkin.space.joint_window_pieces import WindowPieces

__all__ = ["JointSpaceCell", "CellSolver", "joining_paths", "regions_from_cells"]

_NOWRAP = (False, False, False)
#: Boxes of a cell tried, largest first, before its count is left unknown (-1).
_TRIES = 4


@dataclass(frozen=True)
class JointSpaceCell:
    """A face-connected set of clear joint boxes, with its certified count.

    ``count``, ``n_wa1``, ``n_wa2``: from one complete certified solve at
    ``witness`` (exact, the centre of one box of the cell) in which the sign of
    det A is proved for every solution; -1 if that could not be done (never
    expected off g(S)).  ``volume`` is the sum of the box volumes (a float
    measure, not a certified bound).
    """

    id: int
    boxes: int
    volume: float
    count: int
    n_wa1: int
    n_wa2: int
    witness: tuple[Fraction, Fraction, Fraction]
    #: a component made only of boxes of the local refinement inside the undecided layer, touching
    #: no face of the joint box: part of some component of (joint box minus g(S)) not joined to it
    fragment: bool = False

    @property
    def signature(self) -> tuple[int, int, int]:
        return self.count, self.n_wa1, self.n_wa2

    def to_json(self) -> dict:
        return {"id": self.id, "boxes": self.boxes, "volume": self.volume, "count": self.count,
                "n_wa1": self.n_wa1, "n_wa2": self.n_wa2, "witness": [str(v) for v in self.witness],
                "fragment": self.fragment}


def _keys(level: np.ndarray, ijk: np.ndarray) -> np.ndarray:
    """One int64 per box: its level and integer coordinates (levels <= 15, coordinates < 2**16)."""
    ijk = np.asarray(ijk, dtype=np.int64)
    return (np.asarray(level, dtype=np.int64) << 48) | (ijk[:, 0] << 32) | (ijk[:, 1] << 16) | ijk[:, 2]


def _exact_centre(lo: np.ndarray, hi: np.ndarray) -> tuple[Fraction, Fraction, Fraction]:
    c = [(Fraction(float(a)) + Fraction(float(b))) / 2 for a, b in zip(lo, hi)]
    return c[0], c[1], c[2]


class CellSolver:
    """Labels the cells of successive joint pavings, solving each new cell once."""

    def __init__(self, geometry: Geometry):
        self.geometry = geometry
        self._solved: dict[int, tuple[tuple[int, int, int], tuple[Fraction, Fraction, Fraction]]] = {}
        self.edges: np.ndarray = np.zeros((2, 0), dtype=np.int64)
        self._edges_of: tuple = ()  # (depth, level, ijk) of the paving ``edges`` belong to
        #: (groups, volume) of fold and window pieces joined to no clear box at the last labelling
        self.unjoined: tuple[int, float] = (0, 0.0)
        #: cell id of each window piece (2 k,) at the last labelling, -1 where joined to none
        self.window_cell: np.ndarray = np.zeros(0, dtype=np.int32)
        #: the window pieces of the last labelling (None without them)
        self.window_pieces: WindowPieces | None = None

    def _signature(self, lo: np.ndarray, hi: np.ndarray):
        witness = _exact_centre(lo, hi)
        return solve(self.geometry, witness).signature or (-1, -1, -1), witness

    def _face_edges(self, paving: Paving, fine_depth: int) -> np.ndarray:
        """The face-adjacent pairs of the paving's leaves; the last ones again when the leaves did not change."""
        was = self._edges_of
        if not (was and was[0] == fine_depth and np.array_equal(was[1], paving.level)
                and np.array_equal(was[2], paving.ijk)):
            self.edges = shares_face(paving.level, paving.ijk, fine_depth, periodic=_NOWRAP)
            self._edges_of = (fine_depth, paving.level.copy(), paving.ijk.copy())
        return self.edges

    def label(self, paving: Paving, fine_depth: int,
              pieces_of: Callable[[np.ndarray], FoldPieces | None] | None = None,
              anchor: np.ndarray | None = None,
              windows_of: Callable[[np.ndarray, FoldPieces | None], WindowPieces | None] | None = None
              ) -> tuple[np.ndarray, list[JointSpaceCell], FoldPieces | None, np.ndarray]:
        """(cell id per box (-1 where undecided), the cells largest first, the fold pieces, cell id per piece).

        ``pieces_of(face_edges)``, when given, returns the fold pieces of the paving's
        undecided boxes (:mod:`intervalkin.space.joint_pieces`); their edges join clear
        boxes and pieces into cells, and a cell with no clear box is solved at a
        witness of one of its pieces.  ``anchor`` (n,) bool, when given: components with
        no clear anchor box are *fragments*, listed after the cells (ids follow theirs).
        ``windows_of(face_edges, pieces)``, when given, returns the window pieces
        (:mod:`intervalkin.space.joint_window_pieces`); they join the graph the same way, and
        their cells are left in ``self.window_cell``.
        """
        ok = paving.labels["clear"] == Label.INSIDE
        n = len(paving)
        self.edges = self._face_edges(paving, fine_depth)
        pieces = pieces_of(self.edges) if pieces_of is not None else None
        m2 = 2 * len(pieces) if pieces is not None else 0
        wp = windows_of(self.edges, pieces) if windows_of is not None else None
        self.window_pieces = wp
        w2 = len(wp.witness) if wp is not None else 0
        piece_points = np.concatenate([pieces.witness if m2 else np.zeros((0, 3)), wp.witness if w2 else np.zeros((0, 3))])
        # half a fold box or window fold to each of its pieces: a float measure for ordering and reports
        pv = np.repeat(np.concatenate([paving.volume()[pieces.box] if m2 else np.zeros(0),
                                       paving.volume()[wp.box] if w2 else np.zeros(0)]), 2) / 2.0
        if m2 or w2:
            live = np.zeros(n + m2 + w2, dtype=bool)
            live[:n] = ok
            live[n:] = np.isfinite(piece_points).all(axis=1)
            both = ok[self.edges[0]] & ok[self.edges[1]]
            extra = [x.edges for x in (pieces, wp) if x is not None]
            for x in extra:
                live[x.ravel()] = True
            e = np.concatenate([self.edges[:, both]] + extra, axis=1)
            comp_all = _components(n + m2 + w2, e, live)
        else:
            comp_all = component_labels(n, self.edges, ok)
        # a cell holds at least one clear box; pieces joined to none are reported, not counted
        self.unjoined = (0, 0.0)
        if m2 or w2:
            has_clear = np.zeros(int(comp_all.max()) + 1, dtype=bool)
            has_clear[comp_all[:n][ok]] = True
            alone = (comp_all[n:] >= 0) & ~has_clear[np.maximum(comp_all[n:], 0)]
            groups = np.unique(comp_all[n:][alone]).size
            self.unjoined = (int(groups), float(pv[alone].sum()))
            remap = np.cumsum(has_clear) - 1
            comp_all = np.where((comp_all >= 0) & has_clear[np.maximum(comp_all, 0)],
                                remap[np.maximum(comp_all, 0)], -1)
        comp, piece_comp = comp_all[:n], comp_all[n:]
        keys = _keys(paving.level, paving.ijk)
        known = np.flatnonzero(ok & np.isin(keys, np.fromiter(self._solved, dtype=np.int64, count=len(self._solved))))
        first: dict[int, int] = {}
        for k in known:  # one earlier solve per component is enough; all must agree
            c = int(comp[k])
            if c in first:
                if self._solved[int(keys[k])][0] != self._solved[int(keys[first[c]])][0]:
                    raise AssertionError("two solved boxes of one joint cell have different counts (unsound)")
            else:
                first[c] = int(k)
        vol = paving.volume()
        ncomp = int(comp_all.max()) + 1 if (comp_all >= 0).any() else 0
        box_count = np.bincount(comp[ok], minlength=ncomp)
        comp_vol = np.bincount(comp[ok], weights=vol[ok], minlength=ncomp)
        if m2 or w2:
            has = piece_comp >= 0
            comp_vol += np.bincount(piece_comp[has], weights=pv[has], minlength=ncomp)
        anchored = np.ones(ncomp, dtype=bool)
        if anchor is not None:
            anchored = np.bincount(comp[ok & anchor], minlength=ncomp) > 0
        order = np.lexsort((-comp_vol, ~anchored))  # the cells by volume, then the fragments
        new_id = np.empty(ncomp, dtype=np.int64)
        new_id[order] = np.arange(ncomp)
        # the largest boxes of each component first: their centres are farthest from g(S)
        idx = np.flatnonzero(ok)
        by_size = idx[np.lexsort((idx, paving.level[idx], comp[idx]))]
        start = np.searchsorted(comp[by_size], np.arange(ncomp))
        p_order = np.argsort(piece_comp, kind="stable")
        p_start = np.searchsorted(piece_comp[p_order], np.arange(ncomp))
        p_end = np.searchsorted(piece_comp[p_order], np.arange(ncomp), side="right")
        cells = []
        for c in order:
            c = int(c)
            sig, witness = (-1, -1, -1), (Fraction(0), Fraction(0), Fraction(0))
            if c in first:
                sig, witness = self._solved[int(keys[first[c]])]
            else:
                tries = by_size[start[c]:start[c] + min(_TRIES, int(box_count[c]))]
                for b in tries:
                    sig, witness = self._signature(paving.lo[b], paving.hi[b])
                    if sig[0] >= 0:
                        self._solved[int(keys[b])] = (sig, witness)  # only proved signatures are reused
                        break
                if sig[0] < 0 and (m2 or w2):
                    # no clear box of the cell gave a complete solve (or it has none): try its pieces' points
                    for w in piece_points[p_order[p_start[c]:p_end[c]]][:4 * _TRIES]:
                        if np.isfinite(w).all():
                            sig, witness = self._signature(w, w)
                            if sig[0] >= 0:
                                break
            cells.append(JointSpaceCell(int(new_id[c]), int(box_count[c]), float(comp_vol[c]), *sig, witness,
                                        not bool(anchored[c])))
        cell = np.full(len(paving), -1, dtype=np.int32)
        cell[ok] = new_id[comp[ok]]
        piece_cell = np.where(piece_comp >= 0, new_id[np.maximum(piece_comp, 0)], -1).astype(np.int32)
        self.window_cell = piece_cell[m2:]
        return cell, cells, pieces, piece_cell[:m2]


def _components(n: int, edges: np.ndarray, live: np.ndarray) -> np.ndarray:
    """(n,) component id of each live node under ``edges`` (ids 0..c-1 by first node), -1 elsewhere."""
    keep = live[edges[0]] & live[edges[1]]
    g = csr_matrix((np.ones(int(keep.sum())), (edges[0, keep], edges[1, keep])), shape=(n, n))
    _, lab = connected_components(g, directed=False)
    out = np.full(n, -1, dtype=np.int64)
    ids, first = np.unique(lab[live], return_inverse=True)
    out[live] = first
    return out


def joining_paths(edges: np.ndarray, cell: np.ndarray, cells: list[JointSpaceCell]) -> np.ndarray:
    """(n,) bool: the undecided boxes on a shortest chain of undecided boxes between two cells of one signature.

    For each signature (count, n_wa1, n_wa2) held by several cells, a breadth-first
    search from each cell (contracted to one node) through undecided boxes reaches the
    other cells of that signature; the boxes of the shortest chains are returned.  They
    are where refining can join two cells: a chain of one box is a wall between them,
    a longer chain follows a thin layer (a slab along a face of the joint box) that
    the current boxes are too coarse to certify.  Chains through cells of another
    signature are not searched (such cells are certainly different components).
    """
    n = len(cell)
    out = np.zeros(n, dtype=bool)
    groups: dict[tuple[int, int, int], list[int]] = {}
    for c in cells:
        if c.count >= 0:
            groups.setdefault(c.signature, []).append(c.id)
    groups = {k: v for k, v in groups.items() if len(v) > 1}
    if not groups:
        return out
    undecided = cell < 0
    a, b = edges
    size = n + len(cells)
    for ids in groups.values():
        member = np.zeros(len(cells), dtype=bool)
        member[ids] = True
        # nodes: the undecided boxes keep their index; the boxes of cell c become node n + c
        node = np.where(undecided, np.arange(n), np.where(cell >= 0, n + np.maximum(cell, 0), -1))
        usable = undecided | ((cell >= 0) & member[np.maximum(cell, 0)])
        keep = usable[a] & usable[b] & (undecided[a] | undecided[b])
        u, v = node[a[keep]], node[b[keep]]
        # only the nodes on an edge take part: renumbered in order, the search visits them in the same order
        used = np.zeros(size, dtype=bool)
        used[u] = used[v] = True
        used[n + np.asarray(ids)] = True
        old = np.flatnonzero(used)
        new = np.cumsum(used) - 1
        graph = _both_ways(new[u], new[v], old.size)
        _, comp = connected_components(graph, directed=False)
        cid = new[n + np.asarray(ids)]
        on_path = np.zeros(old.size, dtype=bool)
        for k in range(len(ids) - 1):
            src, dst = cid[k], cid[k + 1:]
            dst = dst[comp[dst] == comp[src]]  # no chain to a cell of another component
            if dst.size == 0:
                continue
            _, pred = breadth_first_order(graph, src, directed=True, return_predecessors=True)
            on_path[:] = False
            at = pred[dst]
            while at.size:  # up the search tree from every cell at once; shared stretches walked once
                at = np.unique(at[(at >= 0) & (at != src)])
                at = at[~on_path[at]]
                on_path[at] = True
                at = pred[at]
            hit = old[on_path]
            out[hit[hit < n]] = True
    return out


def _both_ways(u: np.ndarray, v: np.ndarray, size: int) -> csr_matrix:
    """The graph of edges (u, v) for a directed search that visits what an undirected one visits, in its order.

    scipy's undirected breadth-first search takes each node's neighbours in the graph,
    then in its transpose (converted afresh at every call); this graph lists them in that
    order, so a directed search from any node gives the same predecessors at a fraction
    of the cost.
    """
    g = csr_matrix((np.ones(u.size), (u, v)), shape=(size, size))
    gt = g.T.tocsr()
    rows = np.arange(size)
    at = np.concatenate([np.repeat(rows, np.diff(g.indptr)), np.repeat(rows, np.diff(gt.indptr))])
    cols = np.concatenate([g.indices, gt.indices])[np.argsort(at, kind="stable")]
    indptr = g.indptr.astype(np.int64) + gt.indptr.astype(np.int64)
    return csr_matrix((np.ones(cols.size), cols, indptr), shape=(size, size))


def regions_from_cells(cells: Sequence[JointSpaceCell], proved_lower: int = 0, undecided: dict | None = None) -> Count:
    """The basic regions implied by the joint cells (Theorem 1), as a :class:`Count`.

    Above a component C of (joint box minus g(S)) whose points have n_wa1 + n_wa2
    solutions, each aspect holds exactly that many basic regions (Theorem 1 and
    Proposition 1 of the paper; proofs/lemma-theorem1-distinctness.md).  The count
    found is the sum of the cells' counts, over EVERY cell, whether or not a
    workspace box lands in it.  The lower bound is ``proved_lower``, the bound the
    certificates back (cells of different signatures lie in different components,
    so the sum over the distinct signatures is a bound too, but its witnesses are
    not yet written as certificate claims, so it is not declared).  Not proved: that
    two cells of one signature are different components, or that no cell is hidden
    in the undecided boxes; no upper bound.
    """
    known = [c for c in cells if c.count >= 0]
    found = sum(c.count for c in known)
    lower = proved_lower
    unknown = len(cells) - len(known)
    tally = ", ".join(f"{n} with {k}" for k, n in sorted(_tally(known).items())) or "none"
    return Count(
        max(found, lower), lower, None, False,
        f"the sum of the certified solution counts of the {len(known)} cells of the direct joint paving "
        f"(cells by solutions: {tally}); at least {lower} are proved by the certified witnesses (distinct "
        "solutions and aspect splits, Theorem 1); two cells of one signature may still be one component "
        "joined through undecided boxes, and small cells may hide in them, so no upper bound is proved"
        + (f"; {unknown} cells whose solve did not complete are not counted" if unknown else ""),
        dict(undecided or {}))


def _tally(cells: Sequence[JointSpaceCell]) -> dict[int, int]:
    out: dict[int, int] = {}
    for c in cells:
        out[c.count] = out.get(c.count, 0) + 1
    return out
