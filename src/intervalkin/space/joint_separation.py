"""Separations: cells of equal signature proved to lie in different components of the joint box minus g(S).

Two cells with the same signature (count, n_wa1, n_wa2) are one component when a path off g(S)
joins them.  Along such a path the signature does not change (lemma-constant-count-off-gS.md),
so the path only ever visits points whose signature is that of the cells.  The separation
check builds, for each signature sigma of the paving's cells, the graph G_sigma:

* a node per leaf that *admits* sigma: some point of the leaf off g(S) may have signature
  sigma.  A leaf does not admit sigma when that is proved: a clear or window-clear leaf has
  one signature everywhere; the two pieces of a fold box or of a window fold have certified
  signatures (or are proved empty); a window-modelled leaf has a certified set of possible
  counts (:func:`possible_counts`);
* an edge per face contact of two admitting leaves, unless the contact is proved to carry no
  point of signature sigma: one end decides its traces on the shared rectangle
  (:func:`intervalkin.space.joint_closure.decided_traces`) and every piece of that end that
  may carry sigma has an empty trace there.

A path of signature sigma from a cell C to a cell D, pushed into the interior of the joint box
and off the edges of the leaves (general position), passes from leaf to leaf through interior
points of shared faces, each of signature sigma: consecutive leaves admit sigma and their
contact carries a point of sigma.  So C and D lie in one connected component of G_sigma.
Contrapositive: cells in different components of G_sigma are different components of the
joint box minus g(S) (proofs/lemma-separation.md).  A node stands for all the points of
signature sigma in its leaf, whether or not they form one piece: the argument never needs a
leaf's piece to be connected, only which signatures it can hold.

What is certified: for each signature, the number of groups of G_sigma that hold a cell is a
lower bound on the number of components with that signature; summed with the counts it is
a lower bound on the basic regions (Theorem 1: above a component with n_1 solutions in WA1
and n_2 in WA2 lie n_1 + n_2 basic regions).  What is not: these separations are not yet
written into the certificates, so ``intervalkin verify`` does not re-prove them, and the
printed lower bounds do not use them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from intervalkin.core.geometry import Geometry
from intervalkin.paving.adjacency import shares_face
from intervalkin.solve.window_fold import CLEAR, FOLD
from intervalkin.space.joint_closure import decided_traces, piece_cells
from intervalkin.space.joint_patterns import compatible, pattern_at, unit_overlaps, window_patterns

__all__ = ["Separation", "separated_cells", "leaf_signatures", "possible_counts"]

_NOWRAP = (False, False, False)
#: Marks in the (n, 2, 3) signature array: no such piece (absent or proved empty); signature unknown.
NO_PIECE, UNKNOWN = -2, -1
#: Possible-count mask of a leaf that may hold any count.
ANY = -1


@dataclass(frozen=True)
class Separation:
    """groups : per signature (count, n_wa1, n_wa2), the cells of that signature grouped by the
    components of G_sigma that hold them; cells in different groups are proved to be different
    components of the joint box minus g(S)."""

    groups: dict[tuple[int, int, int], tuple[tuple[int, ...], ...]]

    def components_at_least(self) -> int:
        """A proved lower bound on the number of components of the joint box minus g(S) that hold a cell."""
        return sum(len(g) for g in self.groups.values())

    def basic_regions_at_least(self) -> int:
        """A proved lower bound on the number of basic regions: each group is at least one component."""
        return sum(len(g) * sig[0] for sig, g in self.groups.items() if sig[0] > 0)

    def to_json(self) -> dict:
        return {"by_signature": [{"signature": list(sig), "groups": [list(g) for g in groups],
                                  "components_at_least": len(groups)}
                                 for sig, groups in sorted(self.groups.items())],
                "components_at_least": self.components_at_least(),
                "basic_regions_at_least": self.basic_regions_at_least(),
                "certified": "cells in different groups of one signature are different components of the joint "
                             "box minus g(S): no face contact chain of leaves that may hold that signature joins "
                             "them (proofs/lemma-separation.md); not yet in the certificates, so the lower bounds "
                             "printed elsewhere do not use it"}


def leaf_signatures(jp) -> np.ndarray:
    """(n, 2, 3) int64: the certified signatures of the pieces of each leaf with a complete model.

    Row i, slot s: (count, n_wa1, n_wa2) of piece s of leaf i; :data:`NO_PIECE` in every entry for
    a piece that does not exist or is proved empty; :data:`UNKNOWN` for a piece whose signature is
    not certified.  Leaves with no complete model have both slots :data:`NO_PIECE` (see
    :func:`possible_counts` for what they may hold).
    """
    n = len(jp.cell)
    sig = np.full((n, 2, 3), NO_PIECE, dtype=np.int64)
    every = {c.id: c.signature for c in jp.cells + jp.fragments}
    clear = np.flatnonzero(jp.cell >= 0)
    if clear.size:
        table = np.full((max(every) + 1, 3), UNKNOWN, dtype=np.int64)
        for cid, s in every.items():
            table[cid] = s
        sig[clear, 0] = table[jp.cell[clear]]
    if jp.pieces is not None and len(jp.pieces):
        s = jp.piece_signatures.signature.copy()
        empty = jp.piece_signatures.empty
        s[empty == -1, 0] = NO_PIECE
        s[empty == 1, 1] = NO_PIECE
        sig[jp.pieces.box] = s
    w = jp.windows
    if w is not None and w.folds is not None:
        kind = w.folds.kind
        one = kind == CLEAR
        sig[w.leaf[one], 0] = w.folds.signature[one, 0]
        two = kind == FOLD  # folds with slopes on all three axes and two-axis folds: two pieces each
        sig[w.leaf[two]] = w.folds.signature[two]
    return sig


def possible_counts(jp) -> np.ndarray:
    """(n,) int64 bit masks: bit c set when a point of the leaf off g(S) may have c solutions.

    :data:`ANY` for leaves with neither a complete model nor a window model.  For a window-modelled
    leaf (proofs/lemma-window-model.md) the roots off the windows are the same everywhere; a
    window whose end signs and sign of D are proved over the box adds one root (degree 2, end
    signs differ), none or two (end signs agree), one or three (degree 3, end signs differ); any
    other window adds between none and its degree.  Leaves with a complete model get the counts
    of their pieces.
    """
    n = len(jp.cell)
    mask = np.full(n, ANY, dtype=np.int64)
    sig = leaf_signatures(jp)
    known = (sig[:, :, 0] != NO_PIECE).any(axis=1)
    counted = known & ~(sig[:, :, 0] == UNKNOWN).any(axis=1)
    bits = np.where(sig[:, :, 0] >= 0, np.left_shift(1, np.maximum(sig[:, :, 0], 0)), 0)
    mask[counted] = (bits[:, 0] | bits[:, 1])[counted]
    w = jp.windows
    if w is None:
        return mask
    m = w.models
    ends = m.end_signs.astype(np.int64)
    firm = (ends != 0).all(axis=1) & (m.d_sign != 0)
    even = firm & (ends[:, 0] == ends[:, 1])
    odd = firm & ~even
    add = np.where(even, 0b101, np.where(odd & (m.degree == 2), 0b10, np.where(
        odd & (m.degree == 3), 0b1010, np.left_shift(1, m.degree.astype(np.int64) + 1) - 1)))
    box_mask = np.where(m.ok, np.left_shift(1, np.maximum(m.off[:, 0], 0)), ANY).astype(np.int64)
    box = m.window_box
    if box.size:
        rank = np.arange(box.size) - np.searchsorted(box, box, side="left")
        for r in range(int(rank.max()) + 1):  # one pass per window position, vectorised over boxes
            at = rank == r
            b, a = box[at], add[at]
            grown = np.zeros(b.size, dtype=np.int64)
            for bit in range(4):
                grown |= np.where((a >> bit) & 1 == 1, box_mask[b] << bit, 0)
            box_mask[b] = np.where(box_mask[b] == ANY, ANY, grown)
    modelled = ~counted[w.leaf]
    mask[w.leaf[modelled]] = box_mask[modelled]
    return mask


def _worth_deciding(sig: np.ndarray, cells: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Contacts whose traces may cut an edge of some G_sigma (deciding them costs side tests; the rest keep
    their edges, which can only merge groups).  Not worth it: a contact with a one-piece end (its rectangle
    lies off g(S) with that end's signature, so the other end's piece of that signature meets it), one
    with no two-piece end, and one whose ends hold pieces of the same cells (an edge between them
    cannot join two groups)."""
    pieces = (sig[:, :, 0] != NO_PIECE).sum(axis=1)
    look = ((pieces[a] == 2) & (pieces[b] != 1)) | ((pieces[b] == 2) & (pieces[a] != 1))
    ca, cb = np.sort(cells[a], axis=1), np.sort(cells[b], axis=1)
    same = (ca == cb).all(axis=1) & ((ca >= 0) | (ca == NO_PIECE)).all(axis=1)
    return look & ~same


def _components(n: int, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    graph = coo_matrix((np.ones(a.size, dtype=np.int8), (a, b)), shape=(n, n))
    return connected_components(graph, directed=False)[1]


def _runs(keys: np.ndarray, wanted: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(start, length) of the run of each ``wanted`` value in the sorted array ``keys``."""
    lo = np.searchsorted(keys, wanted, side="left")
    return lo, np.searchsorted(keys, wanted, side="right") - lo


def _expand(src: np.ndarray, start: np.ndarray, length: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pairs (src[i], start[i] + j) for j < length[i]."""
    rep = np.repeat(np.arange(src.size), length)
    return src[rep], start[rep] + np.arange(rep.size) - np.repeat(np.cumsum(length) - length, length)


def separated_cells(jp, geometry: Geometry) -> Separation:
    """The cells of a joint paving grouped, signature by signature, by the components of G_sigma (module docstring)."""
    p = jp.paving
    n = len(jp.cell)
    every = jp.cells + jp.fragments
    sig = leaf_signatures(jp)
    counts = possible_counts(jp)
    has_model = (sig[:, :, 0] != NO_PIECE).any(axis=1)
    cells, _ = piece_cells(jp)
    a, b = shares_face(p.level, p.ijk, int(p.level.max()), periodic=_NOWRAP)
    pat = _Patterns(jp, has_model, counts)
    is_p = pat.is_p
    # the traces of the ends that may decide them, once for every signature
    look = (_worth_deciding(sig, cells, a, b) & ~is_p[a] & ~is_p[b]) | (is_p[a] ^ is_p[b])
    c = np.flatnonzero(look)
    flo, fhi = np.maximum(p.lo[a[c]], p.lo[b[c]]), np.minimum(p.hi[a[c]], p.hi[b[c]])
    trace = np.full((a.size, 2, 2), -1, dtype=np.int8)  # (contact, end a/b, piece): 1, 0 empty, -1 not decided
    where = np.full((a.size, 2, 2, 3), np.nan)
    for end, leaf in enumerate((a[c], b[c])):
        solid = ~is_p[leaf]
        trace[c[solid], end], where[c[solid], end] = decided_traces(jp, geometry, leaf[solid], flo[solid], fhi[solid])
    # contacts of a pattern leaf L with a solid end E: the pattern of L at E's trace points
    mixed = np.flatnonzero(is_p[a] ^ is_p[b])
    e_end = np.where(is_p[a[mixed]], 1, 0)
    e_leaf, l_leaf = np.where(e_end == 1, b[mixed], a[mixed]), np.where(e_end == 1, a[mixed], b[mixed])
    e_trace, e_where = trace[mixed, e_end], where[mixed, e_end]
    code_at = np.full((mixed.size, 2), -1, dtype=np.int64)
    for slot in (0, 1):
        at = np.flatnonzero(e_trace[:, slot] == 1)
        code_at[at, slot] = pat.at(geometry, l_leaf[at], e_where[at, slot])
    both = np.flatnonzero(is_p[a] & is_p[b])
    overlap = pat.overlaps(a[both], b[both])
    groups: dict[tuple[int, int, int], tuple[tuple[int, ...], ...]] = {}
    for s in sorted({c.signature for c in every}):
        mine = [c for c in every if c.signature == s]
        target = np.array(s, dtype=np.int64)
        may = (sig == target).all(axis=2) | (sig[:, :, 0] == UNKNOWN)  # (n, 2) pieces that may carry s
        admit = ~is_p & np.where(has_model, may.any(axis=1), (counts == ANY) | ((counts >> s[0]) & 1 == 1))
        # solid-solid contacts: cut when an end decides its traces and each of its pieces that may carry s is empty
        keep = admit[a] & admit[b]
        for end, leaf in enumerate((a, b)):
            m = may[leaf]
            empty = (trace[:, end] == 0) | ~m
            keep &= ~(has_model[leaf] & m.any(axis=1) & empty.all(axis=1))
        src, dst = [a[keep]], [b[keep]]
        start, length, sel = pat.rows(s[0])
        # solid-pattern contacts: the pattern found at a trace point, or every pattern with the count
        m = may[e_leaf] & has_model[e_leaf, None]
        deciding = has_model[e_leaf] & np.all((e_trace != -1) | ~m, axis=1)
        for slot in (0, 1):
            hit = np.flatnonzero(admit[e_leaf] & deciding & m[:, slot] & (e_trace[:, slot] == 1))
            row = pat.row_of(l_leaf[hit], code_at[hit, slot])
            known = row >= 0
            other = known & (pat.count[np.maximum(row, 0)] != s[0])
            if np.any(other & (sig[e_leaf[hit], slot, 0] == s[0])):
                bad = hit[other & (sig[e_leaf[hit], slot, 0] == s[0])][:3]
                raise AssertionError("soundness bug: a trace point of one signature has a pattern of another count "
                                     f"(contacts {e_leaf[bad].tolist()} / {l_leaf[bad].tolist()})")
            known &= ~other  # a trace of unknown signature whose point has another count carries no s
            hit = hit[known | (row < 0)]
            row = row[known | (row < 0)]
            known = row >= 0
            src.append(e_leaf[hit[known]])
            dst.append(n + row[known])
            blind = hit[~known]
            x, y = _expand(e_leaf[blind], start[l_leaf[blind]], length[l_leaf[blind]])
            src.append(x)
            dst.append(n + sel[y])
        blind = np.flatnonzero(admit[e_leaf] & ~deciding)
        x, y = _expand(e_leaf[blind], start[l_leaf[blind]], length[l_leaf[blind]])
        src.append(x)
        dst.append(n + sel[y])
        # pattern-pattern contacts: the pairs of patterns with the count that may meet on the face
        i, ra = _expand(np.arange(both.size), start[a[both]], length[a[both]])
        j, rb = _expand(np.arange(i.size), start[b[both[i]]], length[b[both[i]]])
        ga, gb = sel[ra[j]], sel[rb]
        meet = pat.compatible(ga, gb, overlap[i[j]])
        src.append(n + ga[meet])
        dst.append(n + gb[meet])
        comp = _components(n + len(pat.count), np.concatenate(src), np.concatenate(dst))
        by_comp: dict[int, list[int]] = {}
        for c in mine:
            leaves = np.flatnonzero((cells == c.id).any(axis=1))
            if not admit[leaves].all() or np.unique(comp[leaves]).size != 1:
                raise AssertionError(f"soundness bug: cell {c.id} is not inside one component of G_sigma "
                                     f"for its signature {s}")
            by_comp.setdefault(int(comp[leaves[0]]), []).append(c.id)
        groups[s] = tuple(tuple(sorted(g)) for g in sorted(by_comp.values()))
    return Separation(groups)


class _Patterns:
    """The pattern nodes of a paving: leaves with a window model and no complete model (module docstring of
    :mod:`intervalkin.space.joint_patterns`), one node per pattern the leaf may hold."""

    def __init__(self, jp, has_model: np.ndarray, counts: np.ndarray):
        n = len(jp.cell)
        self.is_p = np.zeros(n, dtype=bool)
        self.count = np.zeros(0, dtype=np.int64)
        self._leaf = np.zeros(0, dtype=np.int64)
        self._code = np.zeros(0, dtype=np.int64)
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
        self._leaf, self._code, self.count = leaf[keep], self._wp.code[keep], self._wp.count[keep]
        self.is_p[self._leaf] = True

    def overlaps(self, leaf_a: np.ndarray, leaf_b: np.ndarray) -> np.ndarray:
        """(c, U, U) unit overlaps of pattern leaves sharing a face (see :func:`unit_overlaps`)."""
        if self._leaf.size == 0:
            return np.zeros((leaf_a.size, 1, 1), dtype=bool)
        box_a, box_b = (np.searchsorted(self._w.leaf, x) for x in (leaf_a, leaf_b))
        return unit_overlaps(self._w.models, self._wp, box_a, box_b)

    def compatible(self, node_a: np.ndarray, node_b: np.ndarray, overlap: np.ndarray) -> np.ndarray:
        """Whether pattern nodes node_a[i] and node_b[i] of two leaves sharing a face may meet on it."""
        return compatible(self._w.models, self._wp, self._row[node_a], self._row[node_b], overlap)

    def rows(self, count: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The rows with ``count``, compacted: (n,) start and length of each leaf's run among them, and the
        global row of each compacted one."""
        n = len(self.is_p)
        sel = self.count == count
        start = np.zeros(n, dtype=np.int64)
        length = np.zeros(n, dtype=np.int64)
        if self._leaf.size:
            leaves = np.flatnonzero(self.is_p)
            first, size = _runs(self._leaf, leaves)
            before = np.r_[0, np.cumsum(sel)]
            # rows with the count are not contiguous inside a leaf's run: index them through a compacted view
            start[leaves] = before[first]
            length[leaves] = before[first + size] - before[first]
        return start, length, np.flatnonzero(sel)

    def row_of(self, leaf: np.ndarray, code: np.ndarray) -> np.ndarray:
        """Row of (leaf, code), -1 where code is -1 or not a row."""
        out = np.full(leaf.size, -1, dtype=np.int64)
        if self._leaf.size == 0 or leaf.size == 0:
            return out
        first, size = _runs(self._leaf, leaf)
        for k in range(int(size.max()) if size.size else 0):  # a leaf has a few patterns: scan them
            hit = (k < size) & (out < 0) & (code >= 0)
            idx = np.where(hit, first + k, 0)
            ok = hit & (self._code[idx] == code)
            out[ok] = idx[ok]
        return out

    def at(self, geometry: Geometry, leaf: np.ndarray, points: np.ndarray) -> np.ndarray:
        """The certified pattern code of ``leaf`` at ``points`` (-1 where undecided)."""
        rows = np.searchsorted(self._w.leaf, leaf)
        return pattern_at(geometry, self._w.models, self._wp, rows, points)
