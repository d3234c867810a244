"""The two pieces of each fold box, and how they touch the boxes around them.

A *fold box* is an undecided joint box with a certified fold model
(:mod:`intervalkin.solve.fold_model`): g(S) meets it in the graph of a continuous
function along one axis k, and the box minus g(S) is two connected pieces, *below*
(q_k < h) and *above* (q_k > h), each of constant count and aspect split.

Pieces join the cells of the paving through shared faces.  For two face-adjacent
boxes, a few points of the shared face are placed: in a clear box a point is always
placed (the box is off g(S)); in a fold box by the side test (Krawczyk steps at the
point parameter, with the preconditioner taken again over the shrunk box where the
model's does not decide).  A point placed at both ends lies in both pieces (or in the piece
and the clear box), off g(S), so their union is connected: an edge of the piece
graph.  A point that cannot be placed gives no edge (a join not made, never a false
one).  Each piece also keeps a *witness*: a point proved to lie in it, where a
certified solve gives its count when no clear box shares its component.

Node numbering of the piece graph: leaf b of the paving is node b; piece s (0 below,
1 above) of fold model t is node n + 2 t + s.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.workers import Workers
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

from intervalkin.solve.dkp import solve
from intervalkin.solve.fold_model import FoldModels
from intervalkin.solve.fold_side import PAIR, empty_by_parts, pair_sides, placed_side

__all__ = ["FoldPieces", "fold_pieces", "fold_sides", "placed_edges", "FACE_FRACTIONS", "PieceSignatures", "piece_signatures"]

#: Where points are placed on a shared face, as fractions of its two sides.
FACE_FRACTIONS = ((0.5, 0.5), (0.1, 0.1), (0.1, 0.9), (0.9, 0.1), (0.9, 0.9))
#: Where the two inner witnesses of a fold box sit along its axis k (the centre in the other two axes).
INNER_FRACTIONS = (0.02, 0.98)


@dataclass(frozen=True, eq=False)
class FoldPieces:
    """The pieces of the fold boxes of a paving.

    box : (m,) leaf index of each fold box; models : their :class:`FoldModels` (rows of
    ``box``); edges : (2, e) node pairs proved to touch (module docstring);
    witness : (2 m, 3) a point proved inside each piece, NaN where none was found.
    """

    box: np.ndarray
    models: FoldModels
    edges: np.ndarray
    witness: np.ndarray

    def __len__(self) -> int:
        return len(self.box)


def _face_points(lo: np.ndarray, hi: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(e, p, 3) points of the face shared by boxes a and b (face-adjacent, no wrap)."""
    flo = np.maximum(lo[a], lo[b])
    fhi = np.minimum(hi[a], hi[b])
    flat = np.argmin(fhi - flo, axis=1)  # the axis across the face (zero width)
    others = np.array([[1, 2], [0, 2], [0, 1]])[flat]
    rows = np.arange(len(a))
    f = np.array(FACE_FRACTIONS)
    pts = np.repeat(flo[:, None, :], len(f), axis=1)
    for c in range(2):
        ax = others[:, c]
        lo_c, hi_c = flo[rows, ax], fhi[rows, ax]
        v = lo_c[:, None] + f[None, :, c] * (hi_c - lo_c)[:, None]
        pts[rows[:, None], np.arange(len(f))[None, :], ax[:, None]] = np.clip(v, lo_c[:, None], hi_c[:, None])
    return pts


def fold_sides(geometry: Geometry, models: FoldModels, box: np.ndarray, points: np.ndarray,
           workers: Workers) -> np.ndarray:
    """:func:`~intervalkin.solve.fold_side.placed_side` (the quick side test, the tight one where it does not
    decide) in parts on the workers; each part ships only the models its points use."""
    parts = workers.parts(len(box))
    if len(parts) == 1:
        return placed_side(geometry, models, box, points)
    order = np.argsort(box, kind="stable")
    calls = []
    for a, b in parts:
        uniq, inv = np.unique(box[order[a:b]], return_inverse=True)
        calls.append((geometry, models.take(uniq), inv, points[order[a:b]]))
    out = np.empty(len(box), dtype=np.int8)
    for (a, b), side in zip(parts, workers.run(placed_side, calls)):
        out[order[a:b]] = side
    return out


def placed_edges(node: list[np.ndarray], placed: list[np.ndarray], q: np.ndarray, first: int,
                 pieces: int) -> tuple[np.ndarray, np.ndarray]:
    """(edges (2, e), witnesses (pieces, 3)) from points q placed at both ends of their contacts: node[0], node[1]
    the piece graph nodes, placed[0], placed[1] whether each end placed it; pieces are the nodes from ``first`` on."""
    both = placed[0] & placed[1]
    edges = np.unique(np.sort(np.stack([node[0][both], node[1][both]]), axis=0), axis=1)
    witness = np.full((pieces, 3), np.nan)
    for nd, ok in zip(node, placed):
        mine = ok & (nd >= first)
        witness[nd[mine] - first] = q[mine]
    return edges, witness


def fold_pieces(geometry: Geometry, lo: np.ndarray, hi: np.ndarray, clear: np.ndarray, face_edges: np.ndarray,
                box: np.ndarray, models: FoldModels, workers: Workers | None = None) -> FoldPieces:
    """The piece graph edges and witnesses of fold boxes ``box`` (their ``models``) in a paving.

    lo, hi : (n, 3) leaves; clear : (n,) bool, proved off g(S); face_edges : (2, e)
    face-adjacent leaf pairs.  Certified: every edge joins two connected sets off g(S)
    that share a point; every witness lies in its piece.
    """
    workers = Workers(1) if workers is None else workers
    n = len(lo)
    m = len(box)
    model_of = np.full(n, -1, dtype=np.int64)
    model_of[box] = np.arange(m)
    a, b = face_edges
    usable = (clear | (model_of >= 0))
    sel = usable[a] & usable[b] & ((model_of[a] >= 0) | (model_of[b] >= 0))
    a, b = a[sel], b[sel]
    pts = _face_points(lo, hi, a, b)
    # a face shared with a clear box lies in one piece: its centre is enough
    use = np.ones(pts.shape[:2], dtype=bool)
    use[(model_of[a] < 0) | (model_of[b] < 0), 1:] = False
    q = pts[use]
    # two inner witnesses per fold box, near its faces q_k = lo and q_k = hi; placed first, since a
    # piece's inner witness replaces any face point as its witness
    inner = np.repeat((0.5 * lo[box] + 0.5 * hi[box])[:, None, :], len(INNER_FRACTIONS), axis=1)
    rows = np.arange(m)
    k = models.axis[rows]
    for c, f in enumerate(INNER_FRACTIONS):
        inner[rows, c, k] = lo[box, k] + f * (hi[box, k] - lo[box, k])
    t_in = np.repeat(rows, len(INNER_FRACTIONS))
    side_in = fold_sides(geometry, models, t_in, inner.reshape(-1, 3), workers)
    good = side_in != 0
    covered = np.zeros(2 * m, dtype=bool)
    covered[2 * t_in[good] + (side_in[good] > 0)] = True
    both_covered = covered[0::2] & covered[1::2]
    node = []
    placed = []
    for end in (a, b):
        end = np.broadcast_to(end[:, None], use.shape)[use]
        t = model_of[end]
        nd = end.astype(np.int64)
        ok = np.ones(len(q), dtype=bool)
        is_model = t >= 0
        if placed:
            # a point the first end could not place gives no edge, and at the second end only a
            # witness, which matters only where the box's pieces lack an inner witness
            is_model &= placed[0] | ~both_covered[np.maximum(t, 0)]
            ok[(t >= 0) & ~is_model] = False
        if is_model.any():
            side = fold_sides(geometry, models, t[is_model], q[is_model], workers)
            nd[is_model] = n + 2 * t[is_model] + (side > 0)
            ok[is_model] = side != 0
        node.append(nd)
        placed.append(ok)
    e, witness = placed_edges(node, placed, q, n, 2 * m)
    witness[2 * t_in[good] + (side_in[good] > 0)] = inner.reshape(-1, 3)[good]
    return FoldPieces(np.asarray(box, dtype=np.int64), models, e.astype(np.int64), witness)


@dataclass(frozen=True, eq=False)
class PieceSignatures:
    """The certified signature (count, n_wa1, n_wa2) of each piece of the fold boxes.

    signature : (m, 2, 3) int64, pieces below (0) and above (1) of each fold box, -1 where unknown;
    empty : (m,) int8, -1 the piece below is proved empty, +1 the piece above, 0 neither;
    inferred : pieces whose signature came from the other piece and the side of the extra pair
    (:mod:`intervalkin.solve.fold_side`) or from a piece joined to them, not from a cell.
    """

    signature: np.ndarray
    empty: np.ndarray
    inferred: int

    def counted(self) -> np.ndarray:
        """(m,) bool: every point of the box off g(S) has a certified signature (each piece known or empty)."""
        known = self.signature[:, :, 0] >= 0
        below = known[:, 0] | (self.empty == -1)
        above = known[:, 1] | (self.empty == 1)
        return below & above & known.any(axis=1)


def piece_signatures(geometry: Geometry, lo: np.ndarray, hi: np.ndarray, pieces: FoldPieces,
                     from_cells: np.ndarray, workers: Workers | None = None) -> PieceSignatures:
    """Signatures of the fold pieces: from their cells, else from the other piece of their box.

    from_cells (2 m, 3): the signature of each piece's cell, -1 where it has none.  For a box
    with one piece unknown, the side of the extra pair gives it: above = below + s (2, 1, 1)
    (proofs/lemma-fold-side.md); pieces joined by the piece graph share their signature (a
    connected set off g(S)); a disagreement would be a soundness bug and is raised.  A piece left
    unknown gets its signature from a certified solve at its witness (one per group of joined pieces), else
    is proved empty where it can be (:func:`~intervalkin.solve.fold_side.empty_by_parts`).  Certified.
    """
    m = len(pieces)
    n = len(lo)
    sig = np.asarray(from_cells, dtype=np.int64).reshape(m, 2, 3).copy()
    before = int(np.count_nonzero(sig[:, :, 0] >= 0))
    need = np.flatnonzero((sig[:, :, 0] < 0).any(axis=1))
    side = np.zeros(m, dtype=np.int8)
    empty = np.zeros(m, dtype=np.int8)
    if need.size:
        # each box's side is proved on its own: in parts on the workers
        workers = Workers(1) if workers is None else workers
        boxes = np.stack([lo[pieces.box[need]], hi[pieces.box[need]]], axis=-1)
        parts = workers.parts(need.size)
        found = workers.run(pair_sides, [(geometry, boxes[a:b], pieces.models.take(need[a:b])) for a, b in parts])
        for (a, b), fs in zip(parts, found):
            side[need[a:b]], empty[need[a:b]] = fs.side, fs.empty
    # pieces joined to each other (not to a cell) form groups of one signature
    e = pieces.edges
    pp = (e[0] >= n) & (e[1] >= n)
    a, b = e[0, pp] - n, e[1, pp] - n
    graph = csr_matrix((np.ones(a.size), (a, b)), shape=(2 * m, 2 * m))
    _, group = connected_components(graph, directed=False)
    _spread(sig, side, group)
    # a piece still unknown that holds a witness: one certified solve there gives its signature (the piece is
    # connected and off g(S)), one solve per group of joined pieces
    flat = sig.reshape(2 * m, 3)
    open_ = np.flatnonzero((flat[:, 0] < 0) & np.isfinite(pieces.witness).all(axis=1))
    _, first = np.unique(group[open_], return_index=True)
    solved = False
    for i in open_[first]:
        got = solve(geometry, [Fraction(float(v)) for v in pieces.witness[i]]).signature
        if got is not None:
            flat[i] = got
            solved = True
    if solved:
        _spread(sig, side, group)
    checked = (sig[:, :, 0] >= 0).all(axis=1) & (side != 0)
    bad = checked & ((sig[:, 1] - sig[:, 0]) != side[:, None].astype(np.int64) * PAIR).any(axis=1)
    if bad.any() or (sig < -1).any():
        raise AssertionError("a fold box's pieces disagree with the side of its extra pair (unsound)")
    # a piece still unknown may be empty: the sheet stays beyond the box's face all along it
    t, s = np.nonzero((sig[:, :, 0] < 0) & (empty == 0)[:, None])
    if t.size:
        boxes = np.stack([lo[pieces.box[t]], hi[pieces.box[t]]], axis=-1)
        proved = empty_by_parts(geometry, boxes, pieces.models.take(t), s)
        empty[t[proved]] = np.where(s[proved] == 1, 1, -1)
    return PieceSignatures(sig, empty, int(np.count_nonzero(sig[:, :, 0] >= 0)) - before)


def _spread(sig: np.ndarray, side: np.ndarray, group: np.ndarray) -> None:
    """Signatures (m, 2, 3) spread in place: inside a box by the side of its extra pair, and to every piece of a
    group of joined pieces; a disagreement is a soundness bug and is raised."""
    m = len(sig)
    for _ in range(4):
        for s, (src, dst) in ((1, (0, 1)), (-1, (1, 0))):
            # dst = src + s' (2, 1, 1) with s' the side read from src's point of view
            sel = (side != 0) & (sig[:, src, 0] >= 0) & (sig[:, dst, 0] < 0)
            sig[sel, dst] = sig[sel, src] + (s * side[sel, None].astype(np.int64)) * PAIR
        flat = sig.reshape(2 * m, 3)
        known = flat[:, 0] >= 0
        rep = np.full((group.max() + 1, 3), -1, dtype=np.int64)
        rep[group[known]] = flat[known]
        clash = known & (rep[group] != flat).any(axis=1)
        if clash.any():
            raise AssertionError("two joined fold pieces have different signatures (unsound)")
        grow = ~known & (rep[group, 0] >= 0)
        if not grow.any():
            break
        flat[grow] = rep[group[grow]]
