"""Closed cells: cells of the joint paving proved to be whole components of the joint box minus g(S).

A cell C of :class:`~intervalkin.space.joint_paving.JointSpacePaving` is a connected union of
*pieces*: clear leaves, window-clear leaves, and the pieces of fold boxes and window folds.  It is
*closed* when nothing of its component lies outside it.  That holds when every leaf holding a
piece of C has a complete model (every point of the leaf off g(S) lies in one of its pieces, each
connected), and every face contact of those leaves is *decided*: on the shared rectangle F, one
end's pieces have connected traces whose emptiness is known, and a point of each non-empty trace
is placed in a piece of the other end; every such pair that touches C has both pieces in C.

Why that suffices (proofs/lemma-closed-cell.md): the traces of one end partition F minus g(S) into
connected sets, each inside one piece of the other end, so the placed points give every pair of
pieces that touch across F.  Then C is open and closed in the joint box minus g(S) (a point of its
closure off g(S) has a small ball off g(S); the pieces that ball meets touch across faces, so they
are all in C), and C is connected: a component.  Two closed cells with the same signature, or a
closed cell and any other cell, are different components: a *separation*.

Ends whose traces are decided here: a clear or window-clear leaf (one piece, the whole face); a
window fold with its slope proved along all three axes (a piece's trace is connected and holds the
face corner where u is smallest, or largest; lemma-window-fold.md, 4(c)); a fold box whose sheet
stays strictly inside its k-range (height enclosure inside (lo_k, hi_k), lemma-fold-joint-box.md,
3(a)), on a face that is a whole face of the box: below the sheet holds the whole bottom face and
none of the top one, and on a side face a segment down to its bottom edge, which lies below the
sheet; likewise above.  Other contacts are undecided, and a cell with one is not closed.

What is certified: each closed cell is a component, given the models and side tests (each
certified).  What is not (yet): these separations are not written into the certificates, so the
checker does not re-prove them and the printed lower bounds do not use them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.paving.adjacency import shares_face
from intervalkin.solve.fold_model import normal_signs
from intervalkin.solve.fold_side import placed_side
from intervalkin.solve.window_fold import CLEAR, FOLD, extreme_corners
from intervalkin.space.joint_window_pieces import window_sides

__all__ = ["Closure", "closed_cells", "REASONS", "piece_cells", "decided_traces"]

_NOWRAP = (False, False, False)
#: Why a face contact keeps a cell from being closed.
REASONS = ("incomplete leaf", "undecided contact", "trace not decided", "point not placed", "two cells meet")


@dataclass(frozen=True)
class Closure:
    """closed : ids of the cells proved closed; open_contacts : per cell id, how many face contacts of its
    pieces keep it open, by reason (:data:`REASONS`; empty for a closed cell)."""

    closed: tuple[int, ...]
    open_contacts: dict[int, dict[str, int]]

    def to_json(self) -> dict:
        return {"closed": list(self.closed), "open_contacts": {str(k): v for k, v in self.open_contacts.items()},
                "certified": "each closed cell is a whole component of the joint box minus g(S) "
                             "(proofs/lemma-closed-cell.md); not yet in the certificates, so the lower "
                             "bounds do not use it"}


def piece_cells(jp) -> tuple[np.ndarray, np.ndarray]:
    """(n, 2) cell of piece s of each leaf (-2 where the leaf has no such piece), (n,) kind:
    0 incomplete, 1 one piece, 2 window fold (all axes), 3 fold box."""
    n = len(jp.cell)
    cells = np.full((n, 2), -2, dtype=np.int64)
    kind = np.zeros(n, dtype=np.int8)
    clear = jp.cell >= 0
    cells[clear, 0], kind[clear] = jp.cell[clear], 1
    if jp.pieces is not None and len(jp.pieces):
        cells[jp.pieces.box] = jp.piece_cell.reshape(-1, 2)
        kind[jp.pieces.box] = 3
    w = jp.windows
    if w is not None and w.folds is not None and len(jp.window_cell):
        wc = jp.window_cell.reshape(-1, 2)
        one = w.folds.kind == CLEAR
        cells[w.leaf[one], 0], kind[w.leaf[one]] = wc[one, 0], 1
        full = (w.folds.kind == FOLD) & (w.folds.rising != 0).all(axis=1)
        cells[w.leaf[full]], kind[w.leaf[full]] = wc[full], 2
    return cells, kind


def closed_cells(jp, geometry: Geometry, rounds: int = 8) -> Closure:
    """The cells of a joint paving ``jp`` (with windows or not) proved closed, and the undecided contacts of the others.

    A placed point that lies in a piece of a cell and in a piece joined to no cell joins that piece to
    the cell (the paving's own face points missed it); the check then runs again with the grown
    cells, at most ``rounds`` times.
    """
    p = jp.paving
    every = [c.id for c in jp.cells + jp.fragments]
    if sorted(every) != list(range(len(every))):
        raise ValueError("cell ids must be 0 .. number of cells - 1")
    cells, kind = piece_cells(jp)
    edges = shares_face(p.level, p.ijk, int(p.level.max()), periodic=_NOWRAP)
    fold_dir = _fold_directions(jp, geometry)
    for _ in range(rounds):
        bad, grow = _check(jp, geometry, cells, kind, edges, fold_dir, len(every))
        if not len(grow):
            break
        cells[grow[:, 0], grow[:, 1]] = grow[:, 2]
    counts = {c: {why: int(v) for why, v in zip(REASONS, bad[c]) if v} for c in every}
    return Closure(tuple(c for c in every if not counts[c]), counts)


def _check(jp, geometry: Geometry, cells: np.ndarray, kind: np.ndarray, edges: np.ndarray, fold_dir: np.ndarray,
           ncells: int) -> tuple[np.ndarray, np.ndarray]:
    """(open contacts per cell, (g, 3) rows (leaf, piece, cell) of pieces joined to no cell that a placed point
    puts in a cell)."""
    p = jp.paving
    bad = np.zeros((ncells, len(REASONS)), dtype=np.int64)

    def blame(c: np.ndarray, why: str) -> None:
        c = np.asarray(c).ravel()
        np.add.at(bad[:, REASONS.index(why)], c[c >= 0], 1)

    holds = (cells >= 0).any(axis=1)
    e = edges[:, holds[edges[0]] | holds[edges[1]]]
    # an incomplete leaf holding a piece of a cell, or beside a leaf holding one, opens that cell
    incomplete = kind == 0
    blame(cells[incomplete], "incomplete leaf")
    blame(cells[e[0]][incomplete[e[1]]], "incomplete leaf")
    blame(cells[e[1]][incomplete[e[0]]], "incomplete leaf")
    # only the cells still closed so far are examined further (side tests cost)
    alive = np.zeros(ncells + 3, dtype=bool)  # indices -1, -2 (no cell, no piece) read False
    alive[:ncells] = bad.sum(axis=1) == 0
    e = e[:, (alive[cells[e[0]]].any(axis=1) | alive[cells[e[1]]].any(axis=1))
          & ~incomplete[e[0]] & ~incomplete[e[1]]]
    a, b = e
    flo, fhi = np.maximum(p.lo[a], p.lo[b]), np.minimum(p.hi[a], p.hi[b])
    # the deciding end: the one whose traces on the face are decided (prefer one-piece leaves)
    dec_a = _decides(jp, kind, a, flo, fhi, fold_dir)
    dec_b = _decides(jp, kind, b, flo, fhi, fold_dir)
    use_a = dec_a & ~((kind[b] == 1) & dec_b)
    use_b = ~use_a & dec_b
    undecided = ~use_a & ~use_b
    blame(cells[a][undecided], "undecided contact")
    blame(cells[b][undecided], "undecided contact")
    src = np.where(use_a, a, b)[~undecided]
    dst = np.where(use_a, b, a)[~undecided]
    pts, piece, present = _trace_points(jp, geometry, kind, src, flo[~undecided], fhi[~undecided], fold_dir)
    # each point of a non-empty trace is placed at the other end: its two pieces touch
    rows = np.repeat(np.arange(len(src)), 2)
    tr = present.ravel()  # 1 present, 0 empty, -1 unknown
    unknown = np.flatnonzero(tr < 0)
    blame(cells[src[rows[unknown]], piece.ravel()[unknown]], "trace not decided")
    blame(cells[dst[rows[unknown]]], "trace not decided")
    at = np.flatnonzero(tr > 0)
    other = _place(jp, geometry, kind, dst[rows[at]], pts.reshape(-1, 3)[at])
    here = cells[src[rows[at]], piece.ravel()[at]]
    there = np.where(other >= 0, cells[dst[rows[at]], np.maximum(other, 0)], -3)
    unplaced = other < 0
    blame(here[unplaced], "point not placed")
    blame(cells[dst[rows[at[unplaced]]]], "point not placed")
    # a piece joined to no cell that touches a cell's piece belongs to that cell's component
    grow = []
    for mine, theirs, leaf, pc in ((here, there, dst[rows[at]], other), (there, here, src[rows[at]], piece.ravel()[at])):
        g = ~unplaced & (mine >= 0) & (theirs == -1)
        grow.append(np.stack([leaf[g], pc[g], mine[g]], axis=1))
    grow = np.unique(np.concatenate(grow), axis=0)
    # the same piece put in two cells: those cells meet (not separated); neither is closed
    key = grow[:, 0] * 2 + grow[:, 1]
    dup = np.zeros(len(key), dtype=bool)
    dup[1:] = key[1:] == key[:-1]
    twice = np.isin(key, key[dup])
    blame(grow[twice, 2], "two cells meet")
    grow = grow[~twice]
    clash = ~unplaced & (here >= 0) & (there >= 0) & (here != there)
    blame(here[clash], "two cells meet")
    blame(there[clash], "two cells meet")
    return bad, grow


def decided_traces(jp, geometry: Geometry, leaf: np.ndarray, flo: np.ndarray,
                   fhi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each leaf and rectangle [flo, fhi] on one of its faces: (m, 2) int8, whether the trace of its
    piece 0 and piece 1 there is non-empty (1) or proved empty (0), -1 where the leaf does not decide its
    traces on that rectangle (module docstring) or has no such piece; and (m, 2, 3) a point of each
    non-empty trace (a point of the rectangle proved to lie in that piece)."""
    cells, kind = piece_cells(jp)
    fold_dir = _fold_directions(jp, geometry)
    out = np.full((len(leaf), 2), -1, dtype=np.int8)
    pts = np.full((len(leaf), 2, 3), np.nan)
    ok = np.flatnonzero(_decides(jp, kind, leaf, flo, fhi, fold_dir))
    if ok.size:
        pts[ok], _, out[ok] = _trace_points(jp, geometry, kind, leaf[ok], flo[ok], fhi[ok], fold_dir)
    out[cells[leaf] == -2] = -1
    pts[out != 1] = np.nan
    return out, pts


def _fold_directions(jp, geometry: Geometry) -> np.ndarray:
    """(m, 3) int8 per fold model: the direction along each axis in which the piece below the sheet is
    kept (-1 along the sheet's axis k; along l != k, the sign of dh/drho_l = -rho_l w_l / (rho_k w_k));
    0 on every axis unless the three signs of w are proved over the pose box (lemma-fold-joint-box.md, 3(b))."""
    if jp.pieces is None or not len(jp.pieces):
        return np.zeros((0, 3), dtype=np.int8)
    models = jp.pieces.models
    sg = normal_signs(geometry, models.pose).astype(np.int64)
    k = models.axis.astype(np.int64)
    r = np.arange(len(k))
    out = -sg * sg[r, k][:, None]
    out[r, k] = -1
    out[(sg == 0).any(axis=1)] = 0
    return out.astype(np.int8)


def _decides(jp, kind: np.ndarray, leaf: np.ndarray, flo: np.ndarray, fhi: np.ndarray,
             fold_dir: np.ndarray) -> np.ndarray:
    """Whether ``leaf``'s traces on the rectangles [flo, fhi] are decided (module docstring)."""
    out = (kind[leaf] == 1) | (kind[leaf] == 2)
    fold = np.flatnonzero(kind[leaf] == 3)
    if fold.size:
        t = _fold_row(jp, leaf[fold])
        k = jp.pieces.models.axis[t].astype(np.int64)
        h = jp.pieces.models.height
        lo, hi = jp.paving.lo[leaf[fold]], jp.paving.hi[leaf[fold]]
        r = np.arange(fold.size)
        inside = (h.lo[t] > lo[r, k]) & (h.hi[t] < hi[r, k])
        flat = np.argmin(fhi[fold] - flo[fold], axis=1)
        span = np.ones(3, dtype=bool)[None, :] & (np.arange(3)[None, :] != flat[:, None])
        whole = np.all(~span | ((flo[fold] == lo) & (fhi[fold] == hi)), axis=1)
        out[fold] = (inside & whole) | (fold_dir[t] != 0).all(axis=1)
    return out


def _fold_row(jp, leaf: np.ndarray) -> np.ndarray:
    row = np.full(len(jp.cell), -1, dtype=np.int64)
    row[jp.pieces.box] = np.arange(len(jp.pieces))
    return row[leaf]


def _trace_points(jp, geometry: Geometry, kind: np.ndarray, leaf: np.ndarray, flo: np.ndarray, fhi: np.ndarray,
                  fold_dir: np.ndarray):
    """(m, 2, 3) a point of each piece's trace, (m, 2) the piece index, (m, 2) 1 non-empty, 0 empty, -1 unknown."""
    m = len(leaf)
    pts = np.repeat((0.5 * flo + 0.5 * fhi)[:, None, :], 2, axis=1)
    piece = np.tile(np.array([0, 1]), (m, 1))
    present = np.zeros((m, 2), dtype=np.int64)
    present[kind[leaf] == 1, 0] = 1
    wf = np.flatnonzero(kind[leaf] == 2)
    if wf.size:
        w = jp.windows
        row = np.searchsorted(w.leaf, leaf[wf])
        low, high = extreme_corners(flo[wf], fhi[wf], w.folds.rising[row])
        s_low = window_sides(geometry, w, row, low)
        s_high = window_sides(geometry, w, row, high)
        pts[wf, 1], pts[wf, 0] = low, high
        present[wf, 1] = np.where(s_low == 1, 1, np.where(s_low == 0, 0, -1))
        present[wf, 0] = np.where(s_high == 0, 1, np.where(s_high == 1, 0, -1))
    fd = np.flatnonzero(kind[leaf] == 3)
    if fd.size:
        t = _fold_row(jp, leaf[fd])
        k = jp.pieces.models.axis[t].astype(np.int64)
        lo, hi = jp.paving.lo[leaf[fd]], jp.paving.hi[leaf[fd]]
        r = np.arange(fd.size)
        flat = np.argmin(fhi[fd] - flo[fd], axis=1)
        across = flat == k
        bottom = across & (flo[fd][r, k] == lo[r, k])
        # across the sheet's axis: the bottom face is all below, the top face all above
        present[fd, 0] = np.where(across, bottom.astype(np.int64), 1)
        present[fd, 1] = np.where(across, (~bottom).astype(np.int64), 1)
        below, above = pts[fd, 0].copy(), pts[fd, 1].copy()
        below[r, k] = np.where(across, below[r, k], lo[r, k])  # the bottom edge of a side face lies below
        above[r, k] = np.where(across, above[r, k], hi[r, k])
        pts[fd, 0], pts[fd, 1] = below, above
        # monotone sheets (3(b)): each piece's trace holds the face corner towards its directions
        mono = np.flatnonzero((fold_dir[t] != 0).all(axis=1))
        if mono.size:
            d = fold_dir[t[mono]]
            f_lo, f_hi = flo[fd[mono]], fhi[fd[mono]]
            low_corner, high_corner = np.where(d > 0, f_hi, f_lo), np.where(d > 0, f_lo, f_hi)
            side = placed_side(geometry, jp.pieces.models, np.r_[t[mono], t[mono]],
                              np.concatenate([low_corner, high_corner]))
            s_below, s_above = side[:mono.size], side[mono.size:]
            pts[fd[mono], 0], pts[fd[mono], 1] = low_corner, high_corner
            present[fd[mono], 0] = np.where(s_below < 0, 1, np.where(s_below > 0, 0, -1))
            present[fd[mono], 1] = np.where(s_above > 0, 1, np.where(s_above < 0, 0, -1))
    return pts, piece, present


def _place(jp, geometry: Geometry, kind: np.ndarray, leaf: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(m,) the piece of ``leaf`` holding each point (0 or 1), -1 where not placed."""
    out = np.full(len(leaf), -1, dtype=np.int64)
    out[kind[leaf] == 1] = 0
    wf = np.flatnonzero(kind[leaf] == 2)
    if wf.size:
        w = jp.windows
        out[wf] = window_sides(geometry, w, np.searchsorted(w.leaf, leaf[wf]), points[wf])
    fd = np.flatnonzero(kind[leaf] == 3)
    if fd.size:
        side = placed_side(geometry, jp.pieces.models, _fold_row(jp, leaf[fd]), points[fd])
        out[fd] = np.where(side > 0, 1, np.where(side < 0, 0, -1))
    return out
