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
and n_2 in WA2 lie n_1 + n_2 basic regions).  What is not: the graphs are not written into the
certificates.  Where a *count barrier* exists (a region around a cell whose boundary carries no
point of its count, :mod:`intervalkin.certify.separation_claims`), the separation is also written
to ``certificates/joint_separation.json`` and re-proved by ``intervalkin verify``; the others
(cells told apart only by the patterns of window models) are re-proved by nothing yet, and the
printed certified lower bounds use none of them.  Where two cells stay in one group, the leaves on the
near-shortest chains between them (:attr:`Separation.between`) say where a finer paving may cut the chains
(:mod:`intervalkin.space.joint_zones`): a choice of effort, not part of any proof.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from intervalkin.core.geometry import Geometry
from intervalkin.paving.adjacency import shares_face
from intervalkin.solve.window_fold import CLEAR, FOLD
from intervalkin.space.joint_closure import decided_traces, piece_cells
from intervalkin.space.joint_pattern_nodes import PatternNodes, expand
from intervalkin.space.joint_refutation import Refuter, near_shortest, nodes_between

__all__ = ["Separation", "separated_cells", "leaf_signatures", "possible_counts"]

_NOWRAP = (False, False, False)
#: Marks in the (n, 2, 3) signature array: no such piece (absent or proved empty); signature unknown.
NO_PIECE, UNKNOWN = -2, -1
#: Possible-count mask of a leaf that may hold any count.
ANY = -1
#: Rounds of window models on the shortest chains joining two cells of one signature (joint_refutation).
REFUTE_ROUNDS = 24
#: The leaves BETWEEN two cells still joined: those on chains of G_sigma at most this many contacts longer than
#: the shortest (where a finer paving may cut them, :mod:`intervalkin.space.joint_zones`).
BETWEEN_SLACK = 2


@dataclass(frozen=True)
class Separation:
    """groups : per signature (count, n_wa1, n_wa2), the cells of that signature grouped by the
    components of G_sigma that hold them; cells in different groups are proved to be different
    components of the joint box minus g(S).  pattern_nodes : nodes standing for a pattern of a
    window-modelled leaf; refuted_contacts, leaves_modelled : edges cut by window models of both ends
    in the refutation rounds, and the leaves given a window model for them; rounds : the most rounds
    one signature used."""

    groups: dict[tuple[int, int, int], tuple[tuple[int, ...], ...]]
    pattern_nodes: int = 0
    refuted_contacts: int = 0
    leaves_modelled: int = 0
    rounds: int = 0
    between: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64), compare=False)
    #: the pavings made again with finer zones (space.joint_topology), one dict each: what they proved, kept or not
    zone_passes: tuple = ()

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
                "pattern_nodes": self.pattern_nodes,
                "refuted_contacts": self.refuted_contacts,
                "leaves_modelled_for_refutation": self.leaves_modelled,
                "refutation_rounds": self.rounds,
                "leaves_between_joined_cells": int(self.between.size),
                "zone_passes": [dict(p) for p in self.zone_passes],
                "certified": "cells in different groups of one signature are different components of the joint "
                             "box minus g(S): no chain of face contacts between leaves (or patterns of window-"
                             "modelled leaves) that may hold that signature joins them (proofs/lemma-separation.md, "
                             "lemma-window-patterns.md, lemma-refuted-contact.md); proved by the library; the ones "
                             "a count barrier also proves are in certificates/joint_separation.json, re-proved by "
                             "intervalkin verify (count_barriers), and only those raise the certified lower bound "
                             "of the basic regions"}


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


def separated_cells(jp, geometry: Geometry, rounds: int = REFUTE_ROUNDS) -> Separation:
    """The cells of a joint paving grouped, signature by signature, by the components of G_sigma (module docstring).

    ``rounds``: while a group holds two cells, up to this many rounds of window models on the edges of
    the shortest chains between them (:mod:`intervalkin.space.joint_refutation`); 0 for none, and none on
    a paving without window models (without pattern nodes the chains run through leaves that may hold
    anything: on the paper's manipulator they raised no bound and took a minute).
    """
    if jp.windows is None:
        rounds = 0
    g = _Graph(jp, geometry)
    w = jp.windows
    refuter = Refuter(geometry, jp.paving.lo, jp.paving.hi, None if w is None else (w.leaf, w.models))
    groups: dict[tuple[int, int, int], tuple[tuple[int, ...], ...]] = {}
    size = g.n + len(g.pat.count)
    fragment = {c.id for c in jp.fragments}
    refuted = used = 0
    between: list[np.ndarray] = []
    for s in sorted({c.signature for c in g.every if c.signature[0] >= 0}):  # a fragment may have no solve
        mine = [c for c in g.every if c.signature == s]
        all_src, all_dst = g.edges(s)
        cut = np.zeros(all_src.size, dtype=bool)
        tried = np.zeros(all_src.size, dtype=bool)
        within = g.inside(all_src, all_dst, s)  # edges inside one cell: cutting them separates nothing
        for round_ in range(rounds + 1):
            src, dst = all_src[~cut], all_dst[~cut]
            comp = _components(size, src, dst)
            by_comp: dict[int, list[int]] = {}
            for c in mine:
                leaves = g.leaves_of[c.id]
                if np.unique(comp[leaves]).size != 1:
                    raise AssertionError(f"soundness bug: cell {c.id} is not inside one component of G_sigma "
                                         f"for its signature {s}")
                by_comp.setdefault(int(comp[leaves[0]]), []).append(c.id)
            # rounds are spent on groups holding two cells; fragments (islands of the local refinement) ride along
            merged = [[c for c in cs if c not in fragment] for cs in by_comp.values()]
            merged = [cs for cs in merged if len(cs) > 1]
            if not merged or round_ == rounds:
                break
            fresh = np.zeros(all_src.size, dtype=bool)
            # the chains from the group's first cell to the others, and (three cells or more) to each of them apart:
            # a pair whose chains cannot be cut (the nearest, or truly joined) must not hide the chains to the others
            targets = [(cs, cs[1:]) for cs in merged] + [(cs, [c]) for cs in merged if len(cs) > 2 for c in cs[1:]]
            for cs, to in targets:
                live = np.flatnonzero(~cut & ~tried & (all_src < g.n) & ~within)
                goal = np.concatenate([g.leaves_of[c] for c in to])
                pick = live[near_shortest(size, src, dst, g.leaves_of[cs[0]], goal, all_src[live], all_dst[live])]
                tried[pick] = True
                fresh[pick[g.refute(refuter, all_src[pick], all_dst[pick], s)]] = True
            if not fresh.any():
                break
            cut |= fresh
        groups[s] = tuple(tuple(sorted(cs)) for cs in sorted(by_comp.values()))
        refuted += int(cut.sum())
        used = max(used, round_)
        for cs in merged:  # from the group's first cell to each other one; a pattern node stands for its leaf
            for c in cs[1:]:
                v = nodes_between(size, all_src[~cut], all_dst[~cut], g.leaves_of[cs[0]], g.leaves_of[c], BETWEEN_SLACK)
                between.append(np.r_[v[v < g.n], g.pat.leaf[v[v >= g.n] - g.n]])
    between = np.unique(np.concatenate(between)) if between else np.zeros(0, dtype=np.int64)
    return Separation(groups, len(g.pat.count), refuted, refuter.modelled, used, between)


class _Graph:
    """What the graphs G_sigma share: the leaves, their models and traces, the pattern nodes."""

    def __init__(self, jp, geometry: Geometry):
        p = jp.paving
        self.n = n = len(jp.cell)
        self.every = jp.cells + jp.fragments
        self.sig = sig = leaf_signatures(jp)
        self.counts = possible_counts(jp)
        self.has_model = (sig[:, :, 0] != NO_PIECE).any(axis=1)
        self.cells = cells = piece_cells(jp)[0]
        self.cell_sig = np.full((max((c.id for c in self.every), default=-1) + 1, 3), -9, dtype=np.int64)
        for c in self.every:
            self.cell_sig[c.id] = c.signature
        # a point of each connected piece of a leaf with a complete model: a clear leaf's centre, a fold piece's witness
        self.points = np.full((n, 2, 3), np.nan)
        clear = jp.cell >= 0
        self.points[clear, 0] = 0.5 * (p.lo[clear] + p.hi[clear])
        if jp.pieces is not None and len(jp.pieces):
            self.points[jp.pieces.box] = jp.pieces.witness.reshape(-1, 2, 3)
        self.leaves_of = {c.id: np.flatnonzero((cells == c.id).any(axis=1)) for c in self.every}
        self.a, self.b = a, b = shares_face(p.level, p.ijk, int(p.level.max()), periodic=_NOWRAP)
        self.pat = pat = PatternNodes(jp, self.has_model, self.counts)
        is_p = pat.is_p
        # the traces of the ends that may decide them, once for every signature
        look = (_worth_deciding(sig, cells, a, b) & ~is_p[a] & ~is_p[b]) | (is_p[a] ^ is_p[b])
        c = np.flatnonzero(look)
        flo, fhi = np.maximum(p.lo[a[c]], p.lo[b[c]]), np.minimum(p.hi[a[c]], p.hi[b[c]])
        self.trace = trace = np.full((a.size, 2, 2), -1, dtype=np.int8)  # (contact, end, piece): 1, 0 empty, -1
        where = np.full((a.size, 2, 2, 3), np.nan)
        for end, leaf in enumerate((a[c], b[c])):
            solid = ~is_p[leaf]
            trace[c[solid], end], where[c[solid], end] = decided_traces(jp, geometry, leaf[solid], flo[solid],
                                                                        fhi[solid])
        # contacts of a pattern leaf L with a solid end E: the pattern of L at E's trace points
        mixed = np.flatnonzero(is_p[a] ^ is_p[b])
        e_end = np.where(is_p[a[mixed]], 1, 0)
        self.e_leaf = np.where(e_end == 1, b[mixed], a[mixed])
        self.l_leaf = np.where(e_end == 1, a[mixed], b[mixed])
        self.e_trace, e_where = trace[mixed, e_end], where[mixed, e_end]
        self.code_at = np.full((mixed.size, 2), -1, dtype=np.int64)  # -1: joined to every pattern of the count
        for slot in (0, 1):
            c_e = sig[self.e_leaf, slot, 0]
            # a piece of certified count c whose neighbour holds one pattern of count c needs no evaluation
            # (none: a contradiction, evaluated so that the soundness check below sees it)
            ambiguous = (c_e == UNKNOWN) | (pat.rows_with(self.l_leaf, np.maximum(c_e, 0)) != 1)
            at = np.flatnonzero((self.e_trace[:, slot] == 1) & ambiguous)
            self.code_at[at, slot] = pat.at(geometry, self.l_leaf[at], e_where[at, slot])
        self.both = np.flatnonzero(is_p[a] & is_p[b])
        self.overlap = pat.overlaps(a[self.both], b[self.both])

    def may(self, s: tuple[int, int, int]) -> np.ndarray:
        """(n, 2) bool: the pieces of the leaves with a complete model that may carry signature s."""
        return (self.sig == np.array(s, dtype=np.int64)).all(axis=2) | (self.sig[:, :, 0] == UNKNOWN)

    def inside(self, u: np.ndarray, v: np.ndarray, s: tuple[int, int, int]) -> np.ndarray:
        """(m,) bool: edges between two leaves that both hold pieces of one cell of signature s (cutting them
        separates nothing: a cell's leaves are one component); pattern nodes (>= n) hold no cell."""
        same = np.zeros(u.size, dtype=bool)
        both = np.flatnonzero((u < self.n) & (v < self.n))
        ca, cb = self.cells[u[both]], self.cells[v[both]]
        for i in (0, 1):
            for j in (0, 1):
                same[both] |= ((ca[:, i] >= 0) & (ca[:, i] == cb[:, j])
                               & (self.cell_sig[np.maximum(ca[:, i], 0)] == s).all(axis=1))
        return same

    def refute(self, refuter: Refuter, u: np.ndarray, v: np.ndarray, s: tuple[int, int, int]) -> np.ndarray:
        """(m,) bool: edges (u leaf, v leaf or pattern node) that window models of both ends prove to carry no
        point with s's count (the pieces of a leaf with a complete model each hold the pattern at its point,
        a pattern node its own)."""
        # a leaf without a complete model may hold any pattern: one slot, no point
        whole = np.array([True, False])
        may = np.where(self.has_model[:, None], self.may(s), whole)
        node = v >= self.n
        k = np.where(node, v - self.n, 0)
        leaf_v, code_v = v.copy(), np.full(v.size, -1, dtype=np.int64)
        leaf_v[node], code_v[node] = self.pat.leaf[k[node]], self.pat.code[k[node]]
        pts_v = np.where(node[:, None, None], np.nan, self.points[leaf_v])
        may_v = np.where(node[:, None], whole, may[leaf_v])
        counts = self.sig[:, :, 0]
        return refuter.cut(u, leaf_v, s[0], (self.points[u], pts_v), (may[u], may_v), code_v,
                           (counts[u], np.where(node[:, None], UNKNOWN, counts[leaf_v])))

    def edges(self, s: tuple[int, int, int]) -> tuple[np.ndarray, np.ndarray]:
        """The edges (src, dst) of G_sigma for sigma = ``s`` (nodes: the leaves, then n + the pattern nodes;
        src is a leaf wherever one end is)."""
        n, a, b, sig, pat = self.n, self.a, self.b, self.sig, self.pat
        is_p, has_model, counts = pat.is_p, self.has_model, self.counts
        may = self.may(s)  # (n, 2) pieces that may carry s
        admit = ~is_p & np.where(has_model, may.any(axis=1), (counts == ANY) | ((counts >> s[0]) & 1 == 1))
        for c in self.every:
            if c.signature == s and not admit[self.leaves_of[c.id]].all():
                raise AssertionError(f"soundness bug: a leaf of cell {c.id} does not admit its signature {s}")
        # solid-solid contacts: cut when an end decides its traces and each of its pieces that may carry s is empty
        keep = admit[a] & admit[b]
        for end, leaf in enumerate((a, b)):
            m = may[leaf]
            empty = (self.trace[:, end] == 0) | ~m
            keep &= ~(has_model[leaf] & m.any(axis=1) & empty.all(axis=1))
        src, dst = [a[keep]], [b[keep]]
        start, length, sel = pat.rows(s[0])
        # solid-pattern contacts: the pattern found at a trace point, or every pattern with the count
        e_leaf, l_leaf, e_trace = self.e_leaf, self.l_leaf, self.e_trace
        m = may[e_leaf] & has_model[e_leaf, None]
        deciding = has_model[e_leaf] & np.all((e_trace != -1) | ~m, axis=1)
        for slot in (0, 1):
            hit = np.flatnonzero(admit[e_leaf] & deciding & m[:, slot] & (e_trace[:, slot] == 1))
            row = pat.row_of(l_leaf[hit], self.code_at[hit, slot])
            known = row >= 0
            other = known & (pat.count[np.maximum(row, 0)] != s[0])
            if np.any(other & (sig[e_leaf[hit], slot, 0] == s[0])):
                bad = hit[other & (sig[e_leaf[hit], slot, 0] == s[0])][:3]
                raise AssertionError("soundness bug: a trace point of one signature has a pattern of another count "
                                     f"(contacts {e_leaf[bad].tolist()} / {l_leaf[bad].tolist()})")
            # a trace of unknown signature whose point has another count carries no s
            hit, row = hit[~other], row[~other]
            known = row >= 0
            src.append(e_leaf[hit[known]])
            dst.append(n + row[known])
            x, y = expand(e_leaf[hit[~known]], start[l_leaf[hit[~known]]], length[l_leaf[hit[~known]]])
            src.append(x)
            dst.append(n + sel[y])
        blind = np.flatnonzero(admit[e_leaf] & ~deciding)
        x, y = expand(e_leaf[blind], start[l_leaf[blind]], length[l_leaf[blind]])
        src.append(x)
        dst.append(n + sel[y])
        # pattern-pattern contacts: the pairs of patterns with the count that may meet on the face
        both = self.both
        i, ra = expand(np.arange(both.size), start[a[both]], length[a[both]])
        j, rb = expand(np.arange(i.size), start[b[both[i]]], length[b[both[i]]])
        ga, gb = sel[ra[j]], sel[rb]
        meet = pat.compatible(ga, gb, self.overlap[i[j]])
        src.append(n + ga[meet])
        dst.append(n + gb[meet])
        return np.concatenate(src), np.concatenate(dst)


