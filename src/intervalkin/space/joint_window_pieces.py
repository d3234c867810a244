"""The pieces of window-clear leaves and window folds, and how they touch the leaves around them.

A window-clear leaf is one piece (it lies off g(S)); a window fold is cut by one sheet of
g(S) into piece 0 (its pair window holds no root) and piece 1 (two roots), each connected
(:mod:`intervalkin.solve.window_fold`, proofs/lemma-window-fold.md).  They join the piece
graph of the paving (:mod:`intervalkin.space.joint_pieces`) the same way fold pieces do: a
point of a shared face is placed at both ends (a clear leaf holds it; a fold box by its side
test; a window fold by the count certified at the point), and a point placed at both ends
gives an edge between two connected sets off g(S) that share it.  An unplaced point gives no
edge: joins may be missed, never invented.

The points: each window fold places the two corners of the shared face where u is smallest
and largest (piece 1 meets the face exactly when the first corner is in it, and piece 0 when
the second is, when u is monotone along every axis), so the edges between such a window fold and
a clear leaf, a window-clear leaf or another such window fold are all found when those corners are
decided.  For a two-axis fold (lemma, statement 4') they are points to try.
The face centre is placed where no end is a window fold, or one end is a fold box (whose
traces on a face need not be connected: edges there may be missed).  The corners of the leaf
itself serve as witnesses.

Node numbering: leaf b is node b, fold piece s of fold model t is n + 2 t + s, and piece s of
window row j (``JointWindows.leaf[j]``) is n + 2 m + 2 j + s, m the number of fold models.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.workers import Workers
from intervalkin.solve.window_fold import CLEAR, FOLD, extreme_corners, fold_piece
from intervalkin.space.joint_pieces import FoldPieces, fold_sides, placed_edges
from intervalkin.space.joint_windows import JointWindows

__all__ = ["WindowPieces", "window_pieces", "window_sides"]


@dataclass(frozen=True, eq=False)
class WindowPieces:
    """Edges and witnesses of the window pieces of a paving.

    first : the node of piece 0 of window row 0 (n + 2 m); box : (k,) the leaf of each window row; edges : (2, e) node pairs proved to
    touch, each with at least one window piece; witness : (2 k, 3) a point proved inside each
    window piece (rows of ``JointWindows``), NaN where none was found (or the row has no pieces).
    """

    first: int
    box: np.ndarray
    edges: np.ndarray
    witness: np.ndarray


def window_sides(geometry: Geometry, windows: JointWindows, rows: np.ndarray, points: np.ndarray,
                 workers: Workers | None = None) -> np.ndarray:
    """(m,) int8: the window piece (0 or 1) of each point in window row ``rows``; -1 where not decided."""
    workers = Workers(1) if workers is None else workers
    rows = np.asarray(rows, dtype=np.int64)
    # the same corner is asked for by several faces of a leaf: each (row, point) is proved once
    keys, back = np.unique(np.column_stack([rows.astype(np.float64), points]), axis=0, return_inverse=True)
    rows, points = keys[:, 0].astype(np.int64), keys[:, 1:]
    parts = workers.parts(len(rows))
    out = np.empty(len(rows), dtype=np.int8)
    calls = [(geometry, windows.models, windows.folds, rows[a:b], points[a:b]) for a, b in parts]
    for (a, b), side in zip(parts, workers.run(fold_piece, calls)):
        out[a:b] = side
    return out[back.ravel()]


def _face(lo: np.ndarray, hi: np.ndarray, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return np.maximum(lo[a], lo[b]), np.minimum(hi[a], hi[b])


def window_pieces(geometry: Geometry, lo: np.ndarray, hi: np.ndarray, clear: np.ndarray, face_edges: np.ndarray,
                  pieces: FoldPieces | None, windows: JointWindows, workers: Workers | None = None) -> WindowPieces:
    """The edges and witnesses of the window pieces of a paving with leaves lo, hi (n, 3).

    clear : (n,) bool, proved off g(S) by the paving; face_edges : (2, e) face-adjacent leaf
    pairs; pieces : the fold pieces (their nodes come before the window pieces).  Certified:
    every edge joins two connected sets off g(S) that share a point; every witness lies in its piece.
    """
    n = len(lo)
    m = 0 if pieces is None else len(pieces)
    first = n + 2 * m
    folds = windows.folds
    k = len(windows.leaf)
    pieced = np.isin(folds.kind, (CLEAR, FOLD))
    wrow = np.full(n, -1, dtype=np.int64)
    wrow[windows.leaf[pieced]] = np.flatnonzero(pieced)
    frow = np.full(n, -1, dtype=np.int64)
    if m:
        frow[pieces.box] = np.arange(m)
    usable = clear | (frow >= 0) | (wrow >= 0)
    a, b = face_edges
    sel = usable[a] & usable[b] & ((wrow[a] >= 0) | (wrow[b] >= 0))
    a, b = a[sel], b[sel]
    flo, fhi = _face(lo, hi, a, b)
    # a window fold's pieces meet the face exactly where they hold its extreme corners (u is monotone);
    # a window-clear leaf or a clear leaf is one piece: the corners place the other end's pieces fully
    fold_end = [(folds.kind[np.maximum(wrow[e], 0)] == FOLD) & (wrow[e] >= 0) for e in (a, b)]
    pts = np.repeat((0.5 * flo + 0.5 * fhi)[:, None, :], 5, axis=1)
    use = np.zeros(pts.shape[:2], dtype=bool)
    use[:, 0] = ~(fold_end[0] | fold_end[1]) | (frow[a] >= 0) | (frow[b] >= 0)
    for c, (e, is_fold) in enumerate(zip((a, b), fold_end)):
        low, high = extreme_corners(flo, fhi, folds.rising[np.maximum(wrow[e], 0)],
                                    folds.edge_rising[np.maximum(wrow[e], 0)])
        pts[:, 1 + 2 * c], pts[:, 2 + 2 * c] = low, high
        use[is_fold, 1 + 2 * c:3 + 2 * c] = True
    q = pts[use]
    node, placed = [], []
    for e in (a, b):
        end = np.broadcast_to(e[:, None], use.shape)[use]
        nd = end.astype(np.int64)
        ok = np.ones(len(q), dtype=bool)
        t = frow[end]
        at = np.flatnonzero(t >= 0)
        if at.size:
            side = fold_sides(geometry, pieces.models, t[at], q[at], workers or Workers(1))
            nd[at] = n + 2 * t[at] + (side > 0)
            ok[at] = side != 0
        j = wrow[end]
        at = np.flatnonzero(j >= 0)
        if at.size:
            side = window_sides(geometry, windows, j[at], q[at], workers)
            nd[at] = first + 2 * j[at] + np.maximum(side, 0)
            ok[at] = side >= 0
        node.append(nd)
        placed.append(ok)
    edges, witness = placed_edges(node, placed, q, first, 2 * k)
    # the leaf's own extreme corners: in piece 1 and piece 0 when these are not empty
    j = np.flatnonzero(pieced)
    leaf = windows.leaf[j]
    low, high = extreme_corners(lo[leaf], hi[leaf], folds.rising[j], folds.edge_rising[j])
    corner_rows = np.r_[j, j]
    corners = np.concatenate([low, high])
    side = window_sides(geometry, windows, corner_rows, corners, workers)
    good = side >= 0
    witness[2 * corner_rows[good] + side[good]] = corners[good]
    return WindowPieces(first, windows.leaf, edges.astype(np.int64), witness)


def signatures_from_windows(wp: WindowPieces, windows: JointWindows, n: int, m: int) -> np.ndarray:
    """(2 m, 3): the signature each fold piece takes from a window piece it touches, -1 where none.

    A fold piece and a window piece joined by an edge share a connected set off g(S), so the
    window piece's signature (fixed by its model) is the fold piece's.  Two window pieces that
    give one fold piece different signatures would be a soundness bug, and are raised.
    """
    out = np.full((2 * m, 3), -1, dtype=np.int64)
    e = wp.edges
    for src, dst in ((0, 1), (1, 0)):
        sel = (e[src] >= wp.first) & (e[dst] >= n) & (e[dst] < wp.first)
        node, piece = e[dst, sel] - n, e[src, sel] - wp.first
        sig = windows.folds.signature[piece // 2, piece % 2]
        known = out[node, 0] >= 0
        if np.any(known & (out[node] != sig).any(axis=1)):
            raise AssertionError("two window pieces give one fold piece different signatures (unsound)")
        out[node] = sig
    return out


def check_window_cells(window_cell: np.ndarray, windows: JointWindows, signature_of_cell: dict) -> None:
    """Raise if a window piece joined to a cell has a signature other than the cell's (never, if sound)."""
    at = np.flatnonzero(window_cell >= 0)
    sig = windows.folds.signature[at // 2, at % 2]
    cell = np.array([signature_of_cell[int(c)] for c in window_cell[at]], dtype=np.int64).reshape(-1, 3)
    if np.any((sig != cell).any(axis=1)):
        raise AssertionError("a window piece's signature differs from its cell's (unsound)")


def window_cell_of(geometry: Geometry, windows: JointWindows, window_cell: np.ndarray, leaf: np.ndarray,
                   points: np.ndarray) -> np.ndarray:
    """(m,) the cell of each point (m, 3) lying in leaf ``leaf`` (m,) of the paving: the cell of its window
    piece; -1 where the leaf has no window pieces, the point's piece is not decided, or the piece has no cell."""
    out = np.full(len(leaf), -1, dtype=np.int64)
    if windows.folds is None or not len(windows.leaf):
        return out
    row = np.minimum(np.searchsorted(windows.leaf, leaf), len(windows.leaf) - 1)
    has = np.flatnonzero((windows.leaf[row] == leaf) & np.isin(windows.folds.kind[row], (CLEAR, FOLD)))
    if has.size:
        side = window_sides(geometry, windows, row[has], points[has])
        ok = side >= 0
        out[has[ok]] = window_cell[2 * row[has[ok]] + side[ok]]
    return out


def window_columns(columns: dict[str, np.ndarray], windows: JointWindows, window_cell: np.ndarray) -> dict:
    """The npz columns with the window-pieced leaves filled in (a new dict; the arrays are copied).

    A window-clear leaf gets its cell and signature like a clear box.  A window fold gets
    ``fold_axis`` = the first axis along which its sheet is a graph (its slope proved on the
    whole leaf), and the cells and counts of its pieces below (q_k < h) and above (q_k > h): below
    is piece 1 (two roots in the pair window) when u grows with q_k, piece 0 otherwise.
    """
    out = {k: v.copy() for k, v in columns.items()}
    folds = windows.folds
    if folds is None or not len(window_cell):
        return out
    j = np.flatnonzero(folds.kind == CLEAR)
    leaf = windows.leaf[j]
    out["cell"][leaf] = window_cell[2 * j]
    for c, name in enumerate(("count", "n_wa1", "n_wa2")):
        out[name][leaf] = folds.signature[j, 0, c]
    j = np.flatnonzero(folds.kind == FOLD)
    leaf = windows.leaf[j]
    k = np.argmax(folds.rising[j] != 0, axis=1)
    below = (folds.rising[j, k] > 0).astype(np.int64)
    out["fold_axis"][leaf] = k
    out["cell_below"][leaf], out["cell_above"][leaf] = window_cell[2 * j + below], window_cell[2 * j + 1 - below]
    out["count_below"][leaf] = folds.signature[j, below, 0]
    out["count_above"][leaf] = folds.signature[j, 1 - below, 0]
    return out
