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


def separated_cells(jp, geometry: Geometry) -> Separation:
    """The cells of a joint paving grouped, signature by signature, by the components of G_sigma (module docstring)."""
    p = jp.paving
    n = len(jp.cell)
    every = jp.cells + jp.fragments
    sig = leaf_signatures(jp)
    counts = possible_counts(jp)
    has_model = (sig[:, :, 0] != NO_PIECE).any(axis=1)
    cells, _ = piece_cells(jp)
    edges = shares_face(p.level, p.ijk, int(p.level.max()), periodic=_NOWRAP)
    a, b = edges
    look = _worth_deciding(sig, cells, a, b)
    trace = np.full((edges.shape[1], 2, 2), -1, dtype=np.int8)  # (contact, end a/b, piece) 1 / 0 empty / -1
    done = np.zeros(edges.shape[1], dtype=bool)
    groups: dict[tuple[int, int, int], tuple[tuple[int, ...], ...]] = {}
    for s in sorted({c.signature for c in every}):
        mine = [c for c in every if c.signature == s]
        target = np.array(s, dtype=np.int64)
        may = (sig == target).all(axis=2) | (sig[:, :, 0] == UNKNOWN)  # (n, 2) pieces that may carry s
        admit = np.where(has_model, may.any(axis=1), (counts == ANY) | ((counts >> s[0]) & 1 == 1))
        keep = admit[a] & admit[b]
        comp = _components(n, a[keep], b[keep])
        seed = np.array([comp[np.flatnonzero((cells == c.id).any(axis=1))[0]] for c in mine])
        shared = np.unique(seed)[np.bincount(np.unique(seed, return_inverse=True)[1]) > 1]
        if shared.size:  # traces only split groups: decided (side tests) only inside a group holding two cells
            new = np.flatnonzero(keep & look & ~done & np.isin(comp[a], shared))
            flo, fhi = np.maximum(p.lo[a[new]], p.lo[b[new]]), np.minimum(p.hi[a[new]], p.hi[b[new]])
            for end, leaf in enumerate((a[new], b[new])):
                trace[new, end] = decided_traces(jp, geometry, leaf, flo, fhi)
            done[new] = True
            # a contact is cut when an end decides its traces and each of its pieces that may carry s is empty there
            for end, leaf in enumerate((a, b)):
                m = may[leaf]
                empty = (trace[:, end] == 0) | ~m
                keep &= ~(has_model[leaf] & m.any(axis=1) & empty.all(axis=1))
            comp = _components(n, a[keep], b[keep])
        by_comp: dict[int, list[int]] = {}
        for c in mine:
            leaves = np.flatnonzero((cells == c.id).any(axis=1))
            if not admit[leaves].all() or np.unique(comp[leaves]).size != 1:
                raise AssertionError(f"soundness bug: cell {c.id} is not inside one component of G_sigma "
                                     f"for its signature {s}")
            by_comp.setdefault(int(comp[leaves[0]]), []).append(c.id)
        groups[s] = tuple(tuple(sorted(g)) for g in sorted(by_comp.values()))
    return Separation(groups)
