"""D-open windows cut at the zero of D: two firm half-windows on each side of the plane of double roots.

At a zero phi_D of D (fixed by the geometry), f(phi_D; r) = s(phi_D; r)^2 / |m_2(phi_D)|^2 with
s = m_2 x N affine in r (proofs/lemma-gap-at-d-zeros.md).  So f(phi_D; r) > 0 for every r off the
surface

    Pi = { rho : s(phi_D; rho^2) = 0 },

a quadric of joint space (a plane in r = rho^2), where f has a double root at phi_D that the
elimination makes and that is no singularity of the manipulator.  A window W = [a, b] of a box R whose
sign of D is not proved (a *D-open* window, :mod:`intervalkin.solve.window_model`) holds phi_D; on
R+ = R minus Pi with s > 0 and R- with s < 0, W is the union of two *half-windows*

    W_L = [a, phi_D],   W_R = [phi_D, b],

whose cut phi_D has the certified sign f > 0, and on each of which D has one sign (phi_D is its only
zero in W).  Each half is then a firm window (end signs and sign of D proved over R+ and R-): of fixed
count, a pair window (0 or 2 roots) or a cusp window (1 or 3), with f^(d) of one sign on it, d its degree
(re-proved on the half's own pieces, else the window's).  The two halves together hold at most the
window's degree (Rolle on W).

What is proved over the box, for every r in R^2 with s(phi_D; r) != 0 (:func:`split_at_zeros_of_d`):

* D is strictly monotone on the gap G (the window's pieces inside [phi~ - D_GAP, phi~ + D_GAP], phi~ the float
  zero) and its end values have opposite signs, so G holds phi_D and D has no other zero in G; every other piece of W
  has a proved sign of D, the one of G's end on its side;
* the half's degree: f^(d) of one strict sign over R^2 x (the half's pieces), which cover the half
  (G is given to both halves, so each half's pieces cover it);
* the sign of ds(phi_D; r)/dr_l, l = 1..3 (``rising``), from an enclosure over G: moving rho_l in that
  direction (rho > 0) never decreases s, so a path along which every rho_l moves the way ``side *
  rising_l`` allows keeps the sign ``side`` of s and never meets Pi.

The joint retraction (:mod:`intervalkin.space.joint_retraction`) reads the halves as windows of the
box and gives each node of such a box one copy per side of Pi, retracting only in directions that keep
its side.  Pi itself has measure zero; each component of a signature's set is open, so it has points off
Pi (proofs/lemma-joint-retraction.md, the plane paragraph).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from intervalkin.core.ball import Ball, cos_sin_multiple
from intervalkin.core.geometry import Geometry
from intervalkin.core.rows import ramp
from intervalkin.core.interval import Interval, certainly_positive, sign_label
from intervalkin.kinematics.reduced_equation import aligned_numerator, denominator
from intervalkin.solve.simple_roots import ReducedBoxes, trig_basis
from intervalkin.solve.window_model import WindowModels, degree_signs, uniform_sign
from intervalkin.solve.window_split import D_GAP, d_zeros, denominator_enclosure

__all__ = ["PlaneSplit", "split_at_zeros_of_d", "PLANE_HALVINGS"]

#: Bisections of the halves' pieces while proving their degree: none is needed on the paper's paving (the same
#: halves are proved with 0 or 1, in a fifth of the time of 3).
PLANE_HALVINGS = 0


@dataclass(frozen=True, eq=False)
class PlaneSplit:
    """Window models with each box's D-open window replaced by its two halves (module docstring).

    models : the models; a split box's halves stand where its D-open window stood (a half proved empty, of
        degree 1 with equal end signs, is left out).
    plane : (n,) int8, 0 for a box not split, k + 1 for one split at the k-th zero of D (:func:`d_zeros`).
    rising : (n, 3) int8, the certified sign of ds(phi_D; r)/dr_l over the split box's gap piece (0: not
        proved, and the box never moves along rho_l); zeros for the other boxes.
    twin : (w,) int64, for a half the index of the other half of its window, -1 for every other window.
    window_degree : (w,) int8, for a half the degree of the whole window (the two halves hold at most that
        many roots together), else the window's own degree.
    """

    models: WindowModels
    plane: np.ndarray
    rising: np.ndarray
    twin: np.ndarray
    window_degree: np.ndarray


def _window_spans(models: WindowModels) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(first piece, number of pieces) of each window, and the window of each piece."""
    pw = models.piece_window
    w = len(models.degree)
    first = np.searchsorted(pw, np.arange(w))
    return first, np.bincount(pw, minlength=w), pw


def split_at_zeros_of_d(geometry: Geometry, models: WindowModels,
                        halvings: int = PLANE_HALVINGS) -> PlaneSplit:
    """The halves of every modelled box's D-open window (module docstring) where everything listed there is
    proved; the other boxes and windows are unchanged.  Vectorised over windows and pieces."""
    n, w = len(models.ok), len(models.degree)
    unchanged = PlaneSplit(models, np.zeros(n, np.int8), np.zeros((n, 3), np.int8), np.full(w, -1, np.int64),
                           models.degree.copy())
    zeros = d_zeros(geometry)
    d_open = (models.d_sign == 0) & (models.end_signs != 0).all(axis=1) & models.ok[models.window_box]
    d_open &= np.bincount(models.window_box, weights=d_open, minlength=n)[models.window_box] == 1
    if not d_open.any() or zeros.size == 0:
        return unchanged
    first, count, pw = _window_spans(models)
    # the gap G around a float zero z: the window's pieces inside [z - D_GAP, z + D_GAP] (window_split.cut_at_d_zeros
    # cut there; some may have been bisected, and some settled since): its first and last piece
    lo, hi = models.piece_lo, models.piece_hi
    g_first = np.full(w, np.iinfo(np.int64).max)
    g_last = np.full(w, -1)
    g_zero = np.full(w, -1)
    for k, z in enumerate(zeros):
        inside = np.flatnonzero((lo >= z - D_GAP) & (hi <= z + D_GAP) & d_open[pw])
        np.minimum.at(g_first, pw[inside], inside)
        np.maximum.at(g_last, pw[inside], inside)
        g_zero[pw[inside]] = np.where(g_zero[pw[inside]] == -1, k, -2)  # -2: pieces near both zeros
    # the pieces inside one interval are consecutive (a window's pieces are in circle order); that G holds the
    # zero of D is proved below, by D's signs at its ends
    cand = np.flatnonzero(d_open & (g_zero >= 0))
    if not cand.size:
        return unchanged
    g, g_end, zero = g_first[cand], g_last[cand], g_zero[cand]
    g_lo, g_hi = lo[g], hi[g_end]
    # D strictly monotone on G with ends of opposite signs: one zero, phi_D, inside
    d = Ball.from_interval(denominator(geometry))
    piece = Ball.from_interval(Interval(g_lo, g_hi))
    c, s_ = cos_sin_multiple(piece, 1, 1)
    slope = sign_label((d[1] * c + d[2] * s_).to_interval())
    before = sign_label(denominator_enclosure(geometry, g_lo, g_lo))
    after = sign_label(denominator_enclosure(geometry, g_hi, g_hi))
    ok = (slope != 0) & (before != 0) & (after == -before)
    # the sign of D on every other piece: that of G's end on its side
    own = np.repeat(np.arange(cand.size), count[cand])
    idx = first[cand][own] + ramp(count[cand])
    d_piece = sign_label(denominator_enclosure(geometry, lo[idx], hi[idx])).astype(np.int64)
    want = np.where(idx < g[own], before[own], after[own])
    bad = ((idx < g[own]) | (idx > g_end[own])) & (d_piece != want)
    ok &= np.bincount(own, weights=bad, minlength=cand.size) == 0
    # the slopes of s(phi_D; r) in r, over G; |m_2|^2 > 0 there, so the plane's sides are the signs of s
    aligned = aligned_numerator(geometry)
    basis = trig_basis(piece)
    coef = sign_label(basis.matmul(Ball.from_interval(aligned.coefficients)).to_interval())[:, 1:]
    leg = basis.matmul(Ball.from_interval(Interval(aligned.leg_square.lo[:, None], aligned.leg_square.hi[:, None])))
    ok &= certainly_positive(leg[:, 0].to_interval()) & (coef != 0).any(axis=1)
    if not ok.any():
        return unchanged
    return _assemble(geometry, models, cand[ok], g[ok], g_end[ok], before[ok], after[ok], coef[ok], zero[ok], halvings)


def _assemble(geometry, models, cand, g, g_end, before, after, coef, zero, halvings) -> PlaneSplit:
    n, w = len(models.ok), len(models.degree)
    first, count, pw = _window_spans(models)
    box = models.window_box[cand]
    # the halves' pieces: W_L from the window's start to G's end, W_R from G's start to its end (G in both)
    k_left = g_end - first[cand] + 1
    k_right = first[cand] + count[cand] - g
    half_len = np.stack([k_left, k_right], axis=1).ravel()  # half 2j: left of window cand[j], 2j + 1: right
    half_start = np.stack([first[cand], g], axis=1).ravel()
    half_piece = half_start.repeat(half_len) + ramp(half_len)
    half_of = np.repeat(np.arange(2 * cand.size), half_len)
    # the degree of each half on its own pieces: f'' of one sign gives 2, else f''' gives 3, else f' gives 1
    rows = np.unique(box)
    data = ReducedBoxes(geometry, models.boxes[rows])
    owner = np.searchsorted(rows, np.repeat(box, 2)[half_of])
    lo, hi = models.piece_lo[half_piece], models.piece_hi[half_piece]
    m = half_piece.size
    degree = np.repeat(models.degree[cand].astype(np.int64), 2)
    for d in (3, 2, 1):
        f_sign = degree_signs(geometry, data, owner, np.arange(m), lo, hi, d, m, halvings)[0]
        degree = np.where(uniform_sign(f_sign, half_of, 2 * cand.size) != 0, np.minimum(degree, d), degree)
    ends = np.stack([models.end_signs[cand, 0], np.ones(cand.size), np.ones(cand.size),
                     models.end_signs[cand, 1]], axis=1).reshape(-1, 2).astype(np.int8)
    d_sign = np.stack([before, after], axis=1).ravel().astype(np.int8)
    # a half of degree 1 holds one root when its end signs differ (bound 2 keeps it a window of fixed count),
    # none when they agree (left out)
    empty = (degree == 1) & (ends[:, 0] == ends[:, 1])
    degree = np.where(degree == 1, 2, degree)
    # the new window table: every window not split, then the halves, sorted by box and circle order
    keep = np.ones(w, dtype=bool)
    keep[cand] = False
    old = np.flatnonzero(keep)
    half = np.flatnonzero(~empty)
    key_box = np.r_[models.window_box[old], np.repeat(box, 2)[half]]
    key_pos = np.r_[old.astype(np.float64), np.repeat(cand, 2)[half] + 0.5 * (half % 2)]
    order = np.lexsort((key_pos, key_box))
    new_of_old = np.full(w, -1)
    new_of_half = np.full(2 * cand.size, -1)
    slot = np.empty(order.size, dtype=np.int64)
    slot[order] = np.arange(order.size)
    new_of_old[old] = slot[:old.size]
    new_of_half[half] = slot[old.size:]
    cat = np.concatenate
    degree_new = cat([models.degree[old], degree[half].astype(np.int8)])[order]
    ends_new = cat([models.end_signs[old], ends[half]])[order]
    d_new = cat([models.d_sign[old], d_sign[half]])[order]
    whole = cat([models.degree[old], np.repeat(models.degree[cand], 2)[half]])[order]
    # pieces: those of unsplit windows, then the halves' (G twice), sorted by new window and circle position
    on_old = keep[pw]
    p_half = ~empty[half_of]
    p_window = cat([new_of_old[pw[on_old]], new_of_half[half_of[p_half]]])
    p_pos = cat([np.flatnonzero(on_old), half_piece[p_half]]).astype(np.float64)
    p_order = np.lexsort((p_pos, p_window))
    p_lo = cat([models.piece_lo[on_old], lo[p_half]])[p_order]
    p_hi = cat([models.piece_hi[on_old], hi[p_half]])[p_order]
    twin = np.full(order.size, -1, dtype=np.int64)
    pairs = new_of_half.reshape(-1, 2)
    both = (pairs >= 0).all(axis=1)
    twin[pairs[both, 0]], twin[pairs[both, 1]] = pairs[both, 1], pairs[both, 0]
    plane = np.zeros(n, dtype=np.int8)
    plane[box] = zero + 1
    rising = np.zeros((n, 3), dtype=np.int8)
    rising[box] = coef
    split = WindowModels(models.boxes, models.ok, models.off, key_box[order], degree_new, ends_new, d_new,
                         p_window[p_order], p_lo, p_hi, models.root_box, models.root_lo, models.root_hi)
    return PlaneSplit(split, plane, rising, twin, whole)

