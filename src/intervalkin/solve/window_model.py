"""Window models of joint boxes: the roots of the reduced equation that may merge, bounded by Rolle.

The claim
---------
Let R be a joint box, r = rho^2 and f(phi; r) the reduced equation
(:mod:`intervalkin.kinematics.reduced_equation`), D(phi) the determinant of the 2 x 2
position system.  The circle of orientations is cut into pieces; each piece is *settled*
(f != 0, or df/dphi != 0, over R^2 x piece) or *open*.  Cut points where the sign of f is
certified for all r in R^2 split the circle into *arcs*:

* an arc of one piece with f != 0 holds no root;
* an arc of monotone pieces (one sign s of df/dphi) holds exactly one root, simple, when
  the signs of f at its ends differ, and none otherwise; the root has D != 0 and the
  sign of det A is DET_SIGN * sign(D) * s (proofs/lemma-window-model.md);
* an arc with an open piece is a *window* [a, b].  On it the d-th phi-derivative of f
  has one strict sign over R^2 x [a, b], d = 2 (a pair window) or d = 3 (a triple
  window): by Rolle f(.; r) has at most d roots in [a, b] counted with multiplicity, for
  every r, and their number has the parity of [sign f(a) != sign f(b)].  D != 0 on it
  (*box-wide*), or D may vanish there (*D-open*: the sign of D at each root is proved at
  the point);
* a window where neither holds is cut into *sub-windows*, runs of pieces sharing one
  signed derivative of order 1, 2 or 3 (:mod:`intervalkin.solve.window_split`); the sign
  of f at a cut between two of them is proved at the point.

A box is modelled (``ok``) when every window is modelled so.  Then the
roots off the windows, their number and their det A signs, are the same for every r in
R (:attr:`WindowModels.off`), and the signature at a point q of R is that plus the roots
in each window at q, counted by :func:`intervalkin.solve.window_count.window_signature` from certified signs of f(.; q).

What is certified: every sign used is proved with ball arithmetic over (R^2, piece)
(:class:`intervalkin.solve.simple_roots.ReducedBoxes`, outward by construction, cos and
sin included).  What is not: a window model says nothing about how many connected pieces
R minus g(S) has; it proves the count at each point q from a test at q.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from intervalkin.core.errors import InputError
from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import PI_HI, PI_LO, sign_label
from intervalkin.solve.simple_roots import PIECES, ReducedBoxes, initial_pieces
from intervalkin.solve.window_split import (D_GAP, cut_at_d_zeros, d_zeros, denominator_enclosure, gap_positive,
                                           line_misses_circle, sub_windows)

__all__ = ["WindowModels", "window_models", "cut_interval", "denominator_enclosure", "DET_SIGN",
           "WINDOW_HALVINGS", "DEGREE_HALVINGS", "degree_signs", "uniform_sign", "POINT_HALVINGS", "POINT_CROWD"]

#: At a simple root phi* of f with D(phi*) != 0: sign det A = DET_SIGN * sign D(phi*) * sign f'(phi*).
#: det A = D g' exactly at a solution, with f = D^2 g (proofs/lemma-window-model.md, step 2).
DET_SIGN = 1
#: Bisections of a piece before it is left open (one fewer than the simple-roots test: on the default
#: paving's no-model leaves the same share is modelled, in a third less time).
WINDOW_HALVINGS = 6
#: Bisections of a window's pieces while proving the sign of D and of the d-th derivative.
DEGREE_HALVINGS = 3
#: Bisections of the sub-pieces of a window at a point before the point is left undecided.
POINT_HALVINGS = 18
#: Boxes modelled together (bounded memory).
_CHUNK = 4096
#: Pieces narrower than this are not bisected further.
_MIN_WIDTH = 2.0**-30
#: A (point, window) pair with more open sub-pieces than this is left undecided.
POINT_CROWD = 64


@dataclass(frozen=True, eq=False)
class WindowModels:
    """Window models of n joint boxes.

    Attributes
    ----------
    boxes : (n, 3, 2) the joint boxes R.
    ok : (n,) bool, every window of the box is modelled (and the roots off the windows have
        certified det A signs).
    off : (n, 3) int64, (count, n_wa1, n_wa2) of the roots off the windows, the same for every
        point of the box (-1 where not ok).
    window_box : (w,) int64, the box of each window (sorted; windows of boxes not ok are dropped).
    degree : (w,) int8, 2 or 3 (1 to 3 for a sub-window): the bound on the roots in the window,
        with multiplicity.
    end_signs : (w, 2) int8, certified sign of f at the window's first and last cut, for all r in
        R^2; 0 at an inner cut of a sub-window (the sign is proved at each point).
    d_sign : (w,) int8, the sign of D on the window; 0 where it is not proved (a D-open window, or
        a sub-window: the sign of D is proved at each root, at the point).
    piece_window, piece_lo, piece_hi : (p,) the pieces of each window in circle order (a window
        may run across phi = pi: its pieces then end at PI_HI and restart at -PI_HI).
    root_box, root_lo, root_hi : (a,) the arcs off the windows that hold a root (exactly one, for
        every point of the box), sorted by box: the arc runs from root_lo to root_hi in circle
        order (across phi = pi when root_hi <= root_lo).  ``off[:, 0]`` of a modelled box is its
        number of such arcs; the rest of the circle off the windows holds no root.
    """

    boxes: np.ndarray
    ok: np.ndarray
    off: np.ndarray
    window_box: np.ndarray
    degree: np.ndarray
    end_signs: np.ndarray
    d_sign: np.ndarray
    piece_window: np.ndarray
    piece_lo: np.ndarray
    piece_hi: np.ndarray
    root_box: np.ndarray
    root_lo: np.ndarray
    root_hi: np.ndarray

    def concat(self, other: "WindowModels") -> "WindowModels":
        """The models of these boxes followed by those of ``other`` (window and piece indices shifted)."""
        n, w = len(self.ok), len(self.degree)
        return WindowModels(*(np.concatenate([a, b]) for a, b in (
            (self.boxes, other.boxes), (self.ok, other.ok), (self.off, other.off),
            (self.window_box, other.window_box + n), (self.degree, other.degree),
            (self.end_signs, other.end_signs), (self.d_sign, other.d_sign),
            (self.piece_window, other.piece_window + w), (self.piece_lo, other.piece_lo),
            (self.piece_hi, other.piece_hi), (self.root_box, other.root_box + n), (self.root_lo, other.root_lo),
            (self.root_hi, other.root_hi))))

    def window_renumber(self, rows: np.ndarray) -> np.ndarray:
        """(w,) the index of each window among those of boxes ``rows`` (increasing), -1 for the others."""
        keep = np.isin(self.window_box, rows)
        return np.where(keep, np.cumsum(keep) - 1, -1)

    def take(self, rows: np.ndarray) -> "WindowModels":
        """The models of boxes ``rows`` (increasing), with their windows, pieces and root arcs, renumbered."""
        rows = np.asarray(rows, dtype=np.int64)
        new = np.full(len(self.ok), -1, dtype=np.int64)
        new[rows] = np.arange(rows.size)
        renumber = self.window_renumber(rows)
        win = np.flatnonzero(renumber >= 0)
        piece = np.flatnonzero(renumber[self.piece_window] >= 0)
        root = np.flatnonzero(new[self.root_box] >= 0)
        return WindowModels(self.boxes[rows], self.ok[rows], self.off[rows], new[self.window_box[win]],
                            self.degree[win], self.end_signs[win], self.d_sign[win],
                            renumber[self.piece_window[piece]], self.piece_lo[piece], self.piece_hi[piece],
                            new[self.root_box[root]], self.root_lo[root], self.root_hi[root])

    def box_wide(self) -> np.ndarray:
        """(w,) bool: windows whose end signs and sign of D hold over the whole box (non-zero)."""
        return (self.d_sign != 0) & np.all(self.end_signs != 0, axis=1)

    def windows_of(self, box: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(first window, number of windows) of each box index in ``box``."""
        start = np.searchsorted(self.window_box, box, side="left")
        return start, np.searchsorted(self.window_box, box, side="right") - start


def cut_interval(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The interval of a cut point: [x, x], or around phi = pi for the seam cut (+-PI_HI)."""
    seam = np.abs(x) == PI_HI
    return np.where(seam, -PI_HI * (x < 0) + PI_LO * (x > 0), x), np.where(seam, -PI_LO * (x < 0) + PI_HI * (x > 0), x)


def _settle(geometry: Geometry, boxes: np.ndarray, data: ReducedBoxes, n: int, pieces: int, halvings: int):
    """Every piece, settled or open: (owner, lo, hi, kind, sign) sorted by owner and lo.

    kind 0: f != 0 on R^2 x piece (sign: of f); 1: df/dphi != 0 (sign: of df/dphi); 2: open.
    The circle is cut at phi_D +- D_GAP around each zero phi_D of D: f = |N|^2 >= 0 there, and where the
    gap piece is proved f > 0 (:func:`~intervalkin.solve.window_split.gap_positive`) no window spans phi_D.
    A piece over which the line of legs 1 and 2 misses the circle of leg 1 is settled f > 0 as well
    (:func:`~intervalkin.solve.window_split.line_misses_circle`).
    """
    owner, lo, hi = initial_pieces(n, pieces)
    owner, lo, hi = cut_at_d_zeros(geometry, owner, lo, hi, np.ones(n, dtype=bool))
    zeros = d_zeros(geometry)
    out: list[tuple] = []
    for round_ in range(halvings + 1):
        sf = sign_label(data.enclosure(owner, lo, hi, 0))
        gap = np.flatnonzero((sf == 0) & (hi - lo <= 4 * D_GAP)
                             & ((lo[:, None] <= zeros) & (zeros <= hi[:, None])).any(axis=1))
        if gap.size:
            sf[gap[gap_positive(geometry, boxes, owner[gap], lo[gap], hi[gap])]] = 1
        miss = np.flatnonzero(sf == 0)
        if miss.size:
            sf[miss[line_misses_circle(geometry, boxes, owner[miss], lo[miss], hi[miss])]] = 1
        kind, sign = np.where(sf != 0, 0, 2).astype(np.int8), sf.copy()
        idx = np.flatnonzero(sf == 0)
        if idx.size:
            sd = sign_label(data.enclosure(owner[idx], lo[idx], hi[idx], 1))
            kind[idx], sign[idx] = np.where(sd != 0, 1, 2), sd
        stop = (kind != 2) | (hi - lo < _MIN_WIDTH) | (round_ == halvings)
        out.append((owner[stop], lo[stop], hi[stop], kind[stop], sign[stop]))
        owner, lo, hi = owner[~stop], lo[~stop], hi[~stop]
        if owner.size == 0:
            break
        mid = np.minimum(np.maximum(0.5 * lo + 0.5 * hi, lo), hi)
        owner, lo, hi = np.concatenate([owner, owner]), np.concatenate([lo, mid]), np.concatenate([mid, hi])
    cols = [np.concatenate([o[i] for o in out]) for i in range(5)]
    order = np.lexsort((cols[1], cols[0]))
    return tuple(c[order] for c in cols)


def uniform_sign(values: np.ndarray, group: np.ndarray, n: int) -> np.ndarray:
    """(n,) the common value of ``values`` over each group when it is one non-zero sign, else 0."""
    lo, hi = np.full(n, 2, dtype=np.int64), np.full(n, -2, dtype=np.int64)
    np.minimum.at(lo, group, values)
    np.maximum.at(hi, group, values)
    return np.where((lo == hi) & (lo != 0), lo, 0)


def degree_signs(geometry: Geometry, data: ReducedBoxes, box: np.ndarray, group: np.ndarray, lo: np.ndarray,
            hi: np.ndarray, d: int, n_groups: int, halvings: int) -> tuple[np.ndarray, np.ndarray]:
    """Per group of pieces (on box ``box[group]``): the one strict sign of the d-th derivative of f over
    it, and of D (0: not proved)."""
    parts_w, parts_f, parts_d = [], [], []
    for round_ in range(halvings + 1):
        sf = sign_label(data.enclosure(box[group], lo, hi, d))
        sd = sign_label(denominator_enclosure(geometry, lo, hi))
        stop = ((sf != 0) & (sd != 0)) | (hi - lo < _MIN_WIDTH) | (round_ == halvings)
        parts_w.append(group[stop]), parts_f.append(sf[stop]), parts_d.append(sd[stop])
        group, lo, hi = group[~stop], lo[~stop], hi[~stop]
        if group.size == 0:
            break
        mid = np.minimum(np.maximum(0.5 * lo + 0.5 * hi, lo), hi)
        group, lo, hi = np.concatenate([group, group]), np.concatenate([lo, mid]), np.concatenate([mid, hi])
    w = np.concatenate(parts_w)
    return uniform_sign(np.concatenate(parts_f), w, n_groups), uniform_sign(np.concatenate(parts_d), w, n_groups)


def window_models(geometry: Geometry, boxes: np.ndarray, pieces: int = PIECES, halvings: int = WINDOW_HALVINGS,
                  degree_halvings: int = DEGREE_HALVINGS) -> WindowModels:
    """Window models of joint boxes (n, 3, 2), rho > 0; vectorised over boxes and pieces.

    Cost: like the simple-roots test (:func:`intervalkin.solve.simple_roots.open_pieces`), plus
    the enclosures of the 2nd and 3rd phi-derivatives over the windows' pieces.
    """
    boxes = np.asarray(boxes, dtype=np.float64)
    if boxes.ndim != 3 or boxes.shape[1:] != (3, 2):
        raise InputError(f"boxes: expected shape (n, 3, 2), got {boxes.shape}")
    if np.any(~(boxes[:, :, 0] > 0)) or np.any(~(boxes[:, :, 0] <= boxes[:, :, 1])):
        raise InputError("boxes: expected 0 < lo <= hi in every coordinate")
    if len(boxes) == 0:
        z = np.zeros(0, dtype=np.int64)
        return WindowModels(boxes, z.astype(bool), np.zeros((0, 3), np.int64), z, z.astype(np.int8),
                            np.zeros((0, 2), np.int8), z.astype(np.int8), z, z.astype(float), z.astype(float),
                            z, z.astype(float), z.astype(float))
    parts = [_chunk(geometry, boxes[k:k + _CHUNK], pieces, halvings, degree_halvings)
             for k in range(0, len(boxes), _CHUNK)]
    base_box = np.cumsum([0] + [len(p.ok) for p in parts])
    base_win = np.cumsum([0] + [len(p.degree) for p in parts])
    cat = np.concatenate
    return WindowModels(boxes, cat([p.ok for p in parts]), cat([p.off for p in parts]),
                        cat([p.window_box + b for p, b in zip(parts, base_box)]), cat([p.degree for p in parts]),
                        cat([p.end_signs for p in parts]), cat([p.d_sign for p in parts]),
                        cat([p.piece_window + b for p, b in zip(parts, base_win)]),
                        cat([p.piece_lo for p in parts]), cat([p.piece_hi for p in parts]),
                        cat([p.root_box + b for p, b in zip(parts, base_box)]), cat([p.root_lo for p in parts]),
                        cat([p.root_hi for p in parts]))


def _chunk(geometry: Geometry, boxes: np.ndarray, pieces: int, halvings: int, degree_halvings: int) -> WindowModels:
    n = len(boxes)
    data = ReducedBoxes(geometry, boxes)
    owner, lo, hi, kind, sign = _settle(geometry, boxes, data, n, pieces, halvings)
    m = owner.size
    first, count = np.searchsorted(owner, np.arange(n)), np.bincount(owner, minlength=n)
    pos = np.arange(m) - first[owner]
    prev = np.where(pos == 0, first[owner] + count[owner] - 1, np.arange(m) - 1)  # cyclic, across phi = pi
    # the sign of f at the start cut of each piece: a point enclosure, or the sign of a neighbour with f != 0
    cut = sign_label(data.enclosure(owner, *cut_interval(lo), 0)).astype(np.int64)
    for j in (np.arange(m), prev):
        known = kind[j] == 0
        assert not np.any(cut[known] * sign[j][known] < 0), "two enclosures of f disagree: unsound evaluation"
        cut = np.where(known, sign[j], cut)
    has_break = np.bincount(owner, weights=cut != 0, minlength=n) > 0
    # rotate each box's pieces to start at its first certified cut: arcs are then contiguous runs
    first_break = np.full(n, np.iinfo(np.int64).max)
    np.minimum.at(first_break, owner[cut != 0], pos[cut != 0])
    keep = np.flatnonzero(has_break[owner])
    rot = (pos[keep] - first_break[owner[keep]]) % count[owner[keep]]
    order = keep[np.lexsort((rot, owner[keep]))]
    owner, lo, hi, kind, sign, cut = (a[order] for a in (owner, lo, hi, kind, sign, cut))
    arc = np.cumsum(cut != 0) - 1
    n_arcs = int(arc[-1]) + 1 if arc.size else 0
    arc_first = np.flatnonzero(cut != 0)
    arc_box = owner[arc_first]
    last = np.append(arc_box[1:] != arc_box[:-1], True)
    box_first_arc = np.searchsorted(arc_box, arc_box, side="left")
    end_first = np.where(last, arc_first[box_first_arc], np.append(arc_first[1:], 0))
    s_start, s_end = cut[arc_first], cut[end_first]
    n_open = np.bincount(arc, weights=kind == 2, minlength=n_arcs)
    n_zero = np.bincount(arc, weights=kind == 0, minlength=n_arcs)
    assert np.all(np.bincount(arc, minlength=n_arcs)[n_zero > 0] == 1), "a piece with f != 0 inside an arc"
    # arcs of monotone pieces: one root when the end signs differ; sign of D at it by the endpoint rule
    mono_arc = (n_open == 0) & (n_zero == 0)
    mono = kind == 1
    sigma = uniform_sign(sign[mono], arc[mono], n_arcs)
    d_piece = sign_label(denominator_enclosure(geometry, lo[mono], hi[mono])).astype(np.int64)
    # where D may vanish on a monotone piece, f > 0 at its zeros (a root with D = 0 is multiple), so the
    # root lies before the first zero (f' > 0) or after the last one (f' < 0): D there has the sign of D
    # at the piece's start or end
    end = np.where(sign[mono] > 0, lo[mono], hi[mono])
    d_end = sign_label(denominator_enclosure(geometry, *cut_interval(end))).astype(np.int64)
    d_arc = uniform_sign(np.where(d_piece != 0, d_piece, d_end), arc[mono], n_arcs)
    root = mono_arc & (s_start != s_end)
    bad_arc = (mono_arc & (sigma == 0)) | (root & (d_arc == 0))
    det = DET_SIGN * sigma * d_arc
    off = np.stack([np.bincount(arc_box, weights=w, minlength=n) for w in (root, root & (det > 0), root & (det < 0))],
                   axis=1).astype(np.int64)
    # windows: arcs with an open piece
    win_arc = np.flatnonzero(n_open > 0)
    n_win = win_arc.size
    wmap = np.full(n_arcs, -1, dtype=np.int64)
    wmap[win_arc] = np.arange(n_win)
    sel = np.flatnonzero(wmap[arc] >= 0)
    pw, plo, phi = wmap[arc[sel]], lo[sel], hi[sel]
    wbox, n_p = arc_box[win_arc], pw.size
    f2p, d2p = degree_signs(geometry, data, wbox[pw], np.arange(n_p), plo, phi, 2, n_p, degree_halvings)
    f2, d2 = uniform_sign(f2p, pw, n_win), uniform_sign(d2p, pw, n_win)
    pair = (f2 != 0) & (d2 != 0)
    rest = np.flatnonzero(~pair[pw])
    f3p, d3p = degree_signs(geometry, data, wbox[pw], rest, plo[rest], phi[rest], 3, n_p, degree_halvings)
    f3, d3 = uniform_sign(f3p[rest], pw[rest], n_win), uniform_sign(d3p[rest], pw[rest], n_win)
    triple = ~pair & (f3 != 0) & (d3 != 0)
    # D-open windows (d_sign 0 unless the other pass proved it), then the rest cut into sub-windows
    loose = ~pair & ~triple
    degree = np.select([pair, triple, loose & (f2 != 0), loose & (f3 != 0)], [2, 3, 2, 3], 0)
    d_sign = np.select([pair, triple], [d2, d3], np.where(d2 != 0, d2, d3))
    # a chunk with no window at all (boxes clear of g(S)) has no pieces here
    w_first, w_last = np.r_[True, pw[1:] != pw[:-1]][:n_p], np.r_[pw[1:] != pw[:-1], True][:n_p]
    split = np.flatnonzero(degree[pw] == 0)
    starts, order, failed = sub_windows(pw[split], np.stack([np.where(kind[sel] == 1, sign[sel], 0), f2p, f3p])[:, split])
    run_start, p_degree = w_first.copy(), degree[pw]
    run_start[split] |= starts
    p_degree[split] = order
    run = np.cumsum(run_start) - 1
    first = np.flatnonzero(run_start)
    last = np.r_[first[1:], n_p][:first.size] - 1
    rw = pw[first]
    run_d = np.where(degree[rw] > 0, d_sign[rw], uniform_sign(np.where(d2p != 0, d2p, d3p), run, first.size))
    ends = np.stack([np.where(w_first[first], s_start[win_arc[rw]], 0), np.where(w_last[last], s_end[win_arc[rw]], 0)], axis=1)
    bad = np.bincount(arc_box, weights=bad_arc, minlength=n) + np.bincount(wbox[pw[split]], weights=failed, minlength=n)
    ok = has_break & (bad == 0)
    off[~ok] = -1
    rk = ok[wbox[rw]]
    renumber = np.cumsum(rk) - 1
    pk = rk[run]
    piece_window, piece_lo, piece_hi = cut_at_d_zeros(geometry, renumber[run[pk]], plo[pk], phi[pk], run_d[rk] == 0)
    # the arcs holding one fixed root, from their first cut to the end of their last piece
    arc_last = np.r_[arc_first[1:], owner.size] - 1
    held = np.flatnonzero(root & ok[arc_box])
    return WindowModels(boxes, ok, off, wbox[rw[rk]], p_degree[first[rk]].astype(np.int8), ends[rk].astype(np.int8),
                        run_d[rk].astype(np.int8), piece_window, piece_lo, piece_hi,
                        arc_box[held], lo[arc_first[held]], hi[arc_last[held]])
