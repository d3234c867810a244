"""The two pieces of each fold box, and how they touch the boxes around them.

A *fold box* is an undecided joint box with a certified fold model
(:mod:`intervalkin.solve.fold_model`): g(S) meets it in the graph of a continuous
function along one axis k, and the box minus g(S) is two connected pieces, *below*
(q_k < h) and *above* (q_k > h), each of constant count and aspect split.

Pieces join the cells of the paving through shared faces.  For two face-adjacent
boxes, a few points of the shared face are placed: in a clear box a point is always
placed (the box is off g(S)); in a fold box by the side test (a Krawczyk step at the
point parameter).  A point placed at both ends lies in both pieces (or in the piece
and the clear box), off g(S), so their union is connected: an edge of the piece
graph.  A point that cannot be placed gives no edge (a join not made, never a false
one).  Each piece also keeps a *witness*: a point proved to lie in it, where a
certified solve gives its count when no clear box shares its component.

Node numbering of the piece graph: leaf b of the paving is node b; piece s (0 below,
1 above) of fold model t is node n + 2 t + s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.solve.fold_model import FoldModels, side_of

__all__ = ["FoldPieces", "fold_pieces", "FACE_FRACTIONS"]

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


def fold_pieces(geometry: Geometry, lo: np.ndarray, hi: np.ndarray, clear: np.ndarray, face_edges: np.ndarray,
                box: np.ndarray, models: FoldModels) -> FoldPieces:
    """The piece graph edges and witnesses of fold boxes ``box`` (their ``models``) in a paving.

    lo, hi : (n, 3) leaves; clear : (n,) bool, proved off g(S); face_edges : (2, e)
    face-adjacent leaf pairs.  Certified: every edge joins two connected sets off g(S)
    that share a point; every witness lies in its piece.
    """
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
    side_in = side_of(geometry, models, t_in, inner.reshape(-1, 3))
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
            side = side_of(geometry, models, t[is_model], q[is_model])
            nd[is_model] = n + 2 * t[is_model] + (side > 0)
            ok[is_model] = side != 0
        node.append(nd)
        placed.append(ok)
    both = placed[0] & placed[1]
    e = np.unique(np.sort(np.stack([node[0][both], node[1][both]]), axis=0), axis=1)
    witness = np.full((2 * m, 3), np.nan)
    for nd, ok in zip(node, placed):
        piece = ok & (nd >= n)
        witness[nd[piece] - n] = q[piece]
    witness[2 * t_in[good] + (side_in[good] > 0)] = inner.reshape(-1, 3)[good]
    return FoldPieces(np.asarray(box, dtype=np.int64), models, e.astype(np.int64), witness)
