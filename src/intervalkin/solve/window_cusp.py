"""Cusp windows retracted along the lifted roots: how a box near a cusp edge of g(S) moves off it.

A window model (:mod:`intervalkin.solve.window_model`) of a joint box R has a *cusp window*
[w_a, w_b] when f''' has one strict sign there (or a union of runs of sub-windows has the Rolle bound 4,
:mod:`intervalkin.solve.window_union`), the end signs of f differ (e0 = sign f(w_a)) and they, and the
sign of D, hold over the whole box: f(.; r) has one or three roots in it, for every r in R^2 (r = rho^2)
off g(S).  With three roots phi_1 < phi_2 < phi_3, the signs of f' at them are -e0, e0,
-e0: the MIDDLE root is the only one with e0 f' > 0.  With one root, it has -e0 f' > 0 and
g(t) = f(t) / (t - phi) (continued by f'(phi) at t = phi) keeps the sign -e0 over the whole window.

No straight line moves the points of a box near a cusp edge off it while keeping their count (the
wedge of three roots narrows like |x|^(3/2) towards the edge).  A curved path does: keep phi fixed at
one root, move r along d u and let it follow along v so that f(phi; r) = 0 stays true
(r' = d u + H' v, H' = -d f_u / f_v).  Along it

    d/dt f_phi(phi; r) = d J / f_v,    J = f_phi,u f_v - f_phi,v f_u,
    d/dt g(t; r)       in d K / f_v for every t where f may vanish,

K the interval of J with the phi-derivatives enclosed between the root and t.  When J (resp. K) and
f_v have proved signs (sJ, sv):

* the middle root keeps e0 f_phi > 0 for d = e0 sJ sv: a box point with three roots in the window
  moves, keeping them, until r reaches a face of R;
* with d = -e0 sK sv, -e0 g stays > 0 where f may vanish: a point with one root keeps one root.

r_i moves with the sign of d (u_i f_v - v_i f_u) / f_v: one face of axis i where that is proved, either
otherwise.  The pairs (u, v) tried: the six axis pairs (u = e_a, v = e_l) and one pair per box read at its
centre (proofs/lemma-joint-retraction.md, "Cusp windows: lifted paths").  Certified: every factor is an
outward-rounded ball enclosure (:meth:`intervalkin.solve.simple_roots.ReducedBoxes.r_slope`).

Away from the cusp edge a straight segment can keep a side too: :func:`cusp_direction_signs` signs
sigma D_e f at the window's double roots, sigma the sign of f'' there; where only pairs can die along e the
one-root side keeps its count, where only pairs can be born the three-root side does ("Cusp windows: straight
ways" in the same lemma).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import Interval, sign_label
from intervalkin.core.workers import Workers
from intervalkin.solve.root_directions import piece_direction_signs, with_singular_signs
from intervalkin.solve.simple_roots import ReducedBoxes
from intervalkin.solve.window_fold import (MIN_PARALLEL_BOXES, STEADY, agreed_signs, pair_critical, pair_windows,
                                          window_kinds, window_parts)
from intervalkin.solve.window_split import aligned_r_slopes
from intervalkin.solve.window_model import DET_SIGN, WindowModels

__all__ = ["AXIS_PAIRS", "CuspRetractions", "cusp_adds", "cusp_retractions", "cusp_windows", "cusp_direction_signs",
           "cusp_retractions_where", "lifted_pair_signs", "window_hull"]

#: Halvings of a cusp window's pieces before the slopes are read.
HALVINGS = 0
#: The (l, a) pairs tried: r_l follows the root, r_a is driven.
AXIS_PAIRS = tuple((l, a) for l in range(3) for a in range(3) if a != l)


@dataclass(frozen=True, eq=False)
class CuspRetractions:
    """For boxes with one cusp window: the signature the window adds, and the faces each side retracts through.

    rows : (m,) the boxes (rows of the models); window : (m,) their cusp window.
    adds : (m, 2, 3) int64, (count, n_wa1, n_wa2) of the window's roots: one root (0), three roots (1).
    faces : (m, 2, k, 6) bool, for each side (one root, three roots) and each of k = len(AXIS_PAIRS) + 1 ways
        (the axis pairs, then the box's own pair of directions), the faces the side's points may reach along the
        lifted path (all False where the way proves nothing; every face of a way must be resolved).
    drive : (m, 2, k) int8, d: r moves along d u while the followed root is held by moving along v.
    drive_u, follow_v : (m, k, 3) the vectors u and v of each way (in r = rho^2).
    follow_lo, follow_hi : (m, 2, k) an enclosure of q = f_u / f_v at the followed root, for each side and way: along
        the way r' = d (u - q v) (where d != 0; an empty hull, lo > hi, where the side has no piece for its root).
    """

    rows: np.ndarray
    window: np.ndarray
    adds: np.ndarray
    faces: np.ndarray
    drive: np.ndarray
    drive_u: np.ndarray
    follow_v: np.ndarray
    follow_lo: np.ndarray
    follow_hi: np.ndarray


def cusp_windows(models: WindowModels) -> np.ndarray:
    """(w,) bool: the windows of degree 3 or 4 whose end signs differ, with end signs and sign of D proved over the
    box.  Either holds one or three roots at every point off g(S): an odd number (the ends differ), at most the
    degree (Rolle; 4 is the bound of a union of runs, :func:`~intervalkin.solve.window_union.joined_windows`
    with ``max_degree`` 4), so not 5.  That is all the lifted paths below use of the degree."""
    firm, even = window_kinds(models)[:2]
    return firm & ~even & ((models.degree == 3) | (models.degree == 4))


def cusp_adds(models: WindowModels, window: np.ndarray) -> np.ndarray:
    """(m, 2, 3) int64: the (count, n_wa1, n_wa2) that each cusp window adds on its one-root side (0) and its
    three-root side (1).  The det A sign of a root is DET_SIGN sign(D) sign(f'); the outer roots have f' of sign
    -e0, the middle one e0 (module docstring)."""
    window = np.asarray(window, dtype=np.int64)
    m = window.size
    e0 = models.end_signs[window, 0].astype(np.int64)
    outer_wa1 = (DET_SIGN * models.d_sign[window].astype(np.int64) * -e0) > 0
    adds = np.zeros((m, 2, 3), dtype=np.int64)
    adds[:, 0] = np.stack([np.ones(m, dtype=np.int64), outer_wa1, ~outer_wa1], axis=1)
    adds[:, 1] = np.stack([np.full(m, 3), 2 * outer_wa1 + ~outer_wa1, 2 * ~outer_wa1 + outer_wa1], axis=1)
    return adds


def cusp_retractions(geometry: Geometry, models: WindowModels, rows: np.ndarray,
                     halvings: int = HALVINGS) -> CuspRetractions:
    """The lifted retractions of boxes ``rows``, each with exactly one cusp window (module docstring).  The
    window's pieces are halved ``halvings`` times; the slopes at the followed root are read on the pieces
    where it can be (f may vanish, f' may have its sign)."""
    rows = np.asarray(rows, dtype=np.int64)
    m = rows.size
    cusp = cusp_windows(models) & np.isin(models.window_box, rows)
    window = np.flatnonzero(cusp)
    if window.size != m or not np.array_equal(models.window_box[window], rows):
        raise ValueError("cusp_retractions: each row needs exactly one cusp window")
    e0 = models.end_signs[window, 0].astype(np.int64)
    adds = cusp_adds(models, window)
    k = len(AXIS_PAIRS) + 1
    faces = np.zeros((m, 2, k, 6), dtype=bool)
    drive = np.zeros((m, 2, k), dtype=np.int8)
    drive_u, follow_v = np.zeros((m, k, 3)), np.zeros((m, k, 3))
    follow_lo, follow_hi = np.full((m, 2, k), np.inf), np.full((m, 2, k), -np.inf)
    if not m:
        return CuspRetractions(rows, window, adds, faces, drive, drive_u, follow_v, follow_lo, follow_hi)
    on = np.isin(models.piece_window, window)
    pw, lo, hi = models.piece_window[on], models.piece_lo[on], models.piece_hi[on]
    pos = np.flatnonzero(on)  # a window's pieces are stored in circle order: their index is their position
    for _ in range(halvings):
        mid = np.minimum(np.maximum(0.5 * lo + 0.5 * hi, lo), hi)
        pw, lo, hi, pos = np.r_[pw, pw], np.r_[lo, mid], np.r_[mid, hi], np.r_[pos, pos]
    slot = np.full(len(models.degree), -1, dtype=np.int64)
    slot[window] = np.arange(m)
    owner = slot[pw]
    data = ReducedBoxes(geometry, models.boxes[rows])
    f = sign_label(data.enclosure(owner, lo, hi, 0))
    f1 = sign_label(data.enclosure(owner, lo, hi, 1)) * e0[owner]
    # mean-value forms in phi: the natural form multiplies the basis' width by f's large, mostly cancelling coefficients
    f_r = [data.r_slope(owner, lo, hi, axis, mean_value=True) for axis in range(3)]
    f_phi_r = [data.r_slope(owner, lo, hi, axis, deriv=1, mean_value=True) for axis in range(3)]
    # where the followed root can be: the middle root (e0 f' > 0) for three roots, the single root (-e0 f' > 0)
    at_root = {1: (f == 0) & (f1 >= 0), 0: (f == 0) & (f1 <= 0)}
    # new roots can only appear where f may vanish; g(t) involves f' between the root and t: the span of those pieces
    first = np.full(m, np.iinfo(np.int64).max)
    last = np.full(m, -1)
    np.minimum.at(first, owner[f == 0], pos[f == 0])
    np.maximum.at(last, owner[f == 0], pos[f == 0])
    between = (pos >= first[owner]) & (pos <= last[owner])
    sets = {"root": at_root, "between": between, "owner": owner, "m": m, "e0": e0}
    eye = np.eye(3)
    drive_u[:, :len(AXIS_PAIRS)] = eye[[a for _, a in AXIS_PAIRS]][None]
    follow_v[:, :len(AXIS_PAIRS)] = eye[[l for l, _ in AXIS_PAIRS]][None]
    # one more pair per box: follow the mean direction of grad_r f over the window, drive along the normal
    # of the fold set {f = f_phi = 0} in it, both read at the box centre (floats: any fixed vectors will do)
    drive_u[:, -1], follow_v[:, -1] = _centre_directions(geometry, models.boxes[rows], owner, lo, hi, f == 0, m)
    for p in range(len(AXIS_PAIRS) + 1):
        faces[:, :, p], drive[:, :, p], follow_lo[:, :, p], follow_hi[:, :, p] = _lifted_faces(
            f_r, f_phi_r, drive_u[:, p], follow_v[:, p], sets)
    for side in (0, 1):  # a side proved empty (no piece can hold its root) retracts through any single face
        empty = np.bincount(owner, weights=at_root[side], minlength=m) == 0
        faces[empty, side] = np.eye(len(AXIS_PAIRS) + 1, 6, dtype=bool)[None]
        drive[empty, side] = 0
    return CuspRetractions(rows, window, adds, faces, drive, drive_u, follow_v, follow_lo, follow_hi)


def cusp_retractions_where(geometry: Geometry, models: WindowModels, rows: np.ndarray, window: np.ndarray,
                           where: np.ndarray) -> CuspRetractions:
    """:func:`cusp_retractions` of ``rows`` (their cusp windows ``window``) with the ways computed only for the rows
    ``where`` (m,) bool; the others get none (drive 0, no face, an empty hull of q), at no cost."""
    at = np.flatnonzero(where)
    got = cusp_retractions(geometry, models, rows[at])
    m, k = rows.size, got.faces.shape[2]
    ways = {"faces": np.zeros((m, 2, k, 6), dtype=bool), "drive": np.zeros((m, 2, k), dtype=np.int8),
            "drive_u": np.zeros((m, k, 3)), "follow_v": np.zeros((m, k, 3)),
            "follow_lo": np.full((m, 2, k), np.inf), "follow_hi": np.full((m, 2, k), -np.inf)}
    for name, value in ways.items():
        value[at] = getattr(got, name)
    return dataclasses.replace(got, rows=rows, window=window, adds=cusp_adds(models, window), **ways)


def window_hull(value: Interval, owner: np.ndarray, keep: np.ndarray, m: int) -> Interval:
    """The hull per window of the pieces ``keep`` of ``value`` (empty windows: [inf, -inf])."""
    lo = np.full(m, np.inf)
    hi = np.full(m, -np.inf)
    np.minimum.at(lo, owner[keep], value.lo[keep])
    np.maximum.at(hi, owner[keep], value.hi[keep])
    return Interval(lo, hi)


def _sign_over(value: Interval, owner: np.ndarray, keep: np.ndarray, m: int) -> np.ndarray:
    """(m,) the sign of ``value`` proved on every piece ``keep`` of each window (0: not proved, or no piece)."""
    h = window_hull(value, owner, keep, m)
    return np.where(h.lo > 0, 1, np.where(h.hi < 0, -1, 0)).astype(np.int64)


def _combine(parts: list[Interval], w: np.ndarray) -> Interval:
    """sum_i w_i parts_i for per-piece float weights w (k, 3), outward rounded."""
    out = parts[0] * w[:, 0]
    for i in (1, 2):
        out = out + parts[i] * w[:, i]
    return out


def _lifted_faces(f_r: list[Interval], f_phi_r: list[Interval], u: np.ndarray, v: np.ndarray,
                  sets: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """((m, 2, 6) bool, (m, 2) int8, (m, 2) lo, (m, 2) hi): for each side (one root, three roots), the faces its
    lifted path may leave the box through when r moves along d u, the followed root held by moving along v, d (0
    where nothing is proved: no face), and the hull of q = f_u / f_v over the pieces where the side's root can be
    (r' = d (u - q v) on the path)."""
    owner, m, e0, root = sets["owner"], sets["m"], sets["e0"], sets["root"]
    up, vp = u[owner], v[owner]
    fu, fv = _combine(f_r, up), _combine(f_r, vp)
    gu, gv = _combine(f_phi_r, up), _combine(f_phi_r, vp)
    out = np.zeros((m, 2, 6), dtype=bool)
    drives = np.zeros((m, 2), dtype=np.int8)
    q_lo, q_hi = np.full((m, 2), np.inf), np.full((m, 2), -np.inf)
    for side in (0, 1):
        at = root[side]
        sv = _sign_over(fv, owner, at, m)
        q = window_hull(fu / fv, owner, at, m)  # f_v may vanish on a piece only where sv = 0, and then d = 0
        q_lo[:, side], q_hi[:, side] = q.lo, q.hi
        if side == 1:  # d/dt f_phi at the middle root: J at one point of the window
            sk = _sign_over(gu * fv - gv * fu, owner, at, m)
        else:  # d/dt g(t) where f may vanish: f_phi,r between the root and t, the r-slopes at the root
            between = sets["between"]
            k = (window_hull(gu, owner, between, m) * window_hull(fv, owner, at, m)
                 - window_hull(gv, owner, between, m) * window_hull(fu, owner, at, m))
            sk = np.where(k.lo > 0, 1, np.where(k.hi < 0, -1, 0))
        drive = e0 * sk * sv * (1 if side == 1 else -1)  # the sign d that keeps the side (0: none proved)
        moving = np.zeros(m, dtype=bool)
        for i in range(3):  # dr_i/dt = d (u_i f_v - v_i f_u) / f_v
            still = (u[:, i] == 0) & (v[:, i] == 0)
            vel = drive * sv * _sign_over(fv * up[:, i] - fu * vp[:, i], owner, at, m)
            moving |= vel != 0
            out[:, side, 2 * i] = (drive != 0) & ~still & (vel <= 0)
            out[:, side, 2 * i + 1] = (drive != 0) & ~still & (vel >= 0)
        out[~moving, side] = False  # no coordinate proved monotone: the path might never leave the box
        drives[:, side] = np.where(moving, drive, 0)
    return out, drives, q_lo, q_hi


def _centre_directions(geometry: Geometry, boxes: np.ndarray, owner: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                       keep: np.ndarray, m: int) -> tuple[np.ndarray, np.ndarray]:
    """(u, v) (m, 3) per box: v the mean unit grad_r f, u the mean unit w = f_v grad_r f_phi - f_phi,v grad_r f,
    over the pieces ``keep`` at the box centre (float guesses; the proofs enclose whatever they are)."""
    centre = boxes.mean(axis=2)
    data = ReducedBoxes(geometry, np.stack([centre, centre], axis=-1))
    at = np.flatnonzero(keep)
    mid = 0.5 * lo[at] + 0.5 * hi[at]
    grad = np.stack([data.r_slope(owner[at], mid, mid, i).mid() for i in range(3)], axis=1)
    grad_phi = np.stack([data.r_slope(owner[at], mid, mid, i, deriv=1).mid() for i in range(3)], axis=1)
    v = np.zeros((m, 3))
    np.add.at(v, owner[at], grad / np.maximum(np.linalg.norm(grad, axis=1, keepdims=True), 1e-300))
    v /= np.maximum(np.linalg.norm(v, axis=1, keepdims=True), 1e-300)
    vp = v[owner[at]]
    w = (grad * vp).sum(axis=1, keepdims=True) * grad_phi - (grad_phi * vp).sum(axis=1, keepdims=True) * grad
    u = np.zeros((m, 3))
    np.add.at(u, owner[at], w / np.maximum(np.linalg.norm(w, axis=1, keepdims=True), 1e-300))
    u /= np.maximum(np.linalg.norm(u, axis=1, keepdims=True), 1e-300)
    return u, v


def cusp_direction_signs(geometry: Geometry, models: WindowModels, rows: np.ndarray, directions: np.ndarray,
                         workers: Workers | None = None) -> np.ndarray:
    """(w, c) int8 per cusp window of boxes ``rows`` and direction e (c, 3) in rho: +1 where only pairs can die
    along e, -1 where only pairs can be born, :data:`~intervalkin.solve.window_fold.STEADY` where no point of
    the box is a double root of f in the window, 0 otherwise (other windows: 0).

    The window's count changes along a segment only through a double root phi* of f in it (its ends have a
    proved sign of f).  On a *critical piece* (f and f' both may vanish) where f'' has a proved sign sigma, f
    has a fold at phi*: near it f's critical point moves smoothly and its value c(t) has c' = D_e f (f' = 0
    there), so sigma D_e f > 0 lets a pair near phi* only die (two roots just before, none after) and
    sigma D_e f < 0 only be born.  +1: sigma D_e f > 0 at the double roots of every critical piece that may hold
    one (:func:`~intervalkin.solve.root_directions.piece_direction_signs` at the roots); then the one-root side
    keeps its count along e (no pair to die, none born: a pair born beside the single root would make a triple
    root, where f'' = 0); -1: likewise < 0, and the three-root side keeps its count (a death would need two of
    its roots to merge; a birth would make five, more than the window's degree).  Where the elimination's forms
    leave sigma D_e f open, its sign at the singular poses of the piece is read with f'' != 0 proved at each
    (:func:`~intervalkin.solve.singular_directions.singular_direction_signs` with ``fold``).  ``workers``: boxes in
    parts (each window's signs come from its own box alone)."""
    rows = np.asarray(rows, dtype=np.int64)
    directions = np.asarray(directions, dtype=np.float64)
    w = len(models.degree)
    out = np.zeros((w, len(directions)), dtype=np.int8)
    if workers is not None and workers.count > 1 and rows.size >= MIN_PARALLEL_BOXES:
        for at, signs in window_parts(cusp_direction_signs, geometry, models, rows, workers, directions):
            out[at] = signs
        return out
    cusp = cusp_windows(models) & np.isin(models.window_box, rows)
    if not cusp.any():
        return out
    row = np.full(len(models.ok), -1, dtype=np.int64)
    row[rows] = np.arange(rows.size)
    on = np.isin(models.piece_window, np.flatnonzero(cusp))
    pw, lo, hi = models.piece_window[on], models.piece_lo[on], models.piece_hi[on]
    data = ReducedBoxes(geometry, models.boxes[rows])
    owner = row[models.window_box][pw]
    crit = (sign_label(data.enclosure(owner, lo, hi, 0)) == 0) & (sign_label(data.enclosure(owner, lo, hi, 1)) == 0)
    pw, lo, hi, owner = pw[crit], lo[crit], hi[crit], owner[crit]
    sigma = sign_label(data.enclosure(owner, lo, hi, 2))
    signs, quiet = piece_direction_signs(geometry, models.boxes[rows], data, owner, lo, hi, directions)
    folded = (signs * sigma[:, None]).astype(np.int8)  # sigma 0 (f'' without a proved sign): nothing proved
    # what those forms leave open, the singular poses give: sigma D_e f with f'' != 0 at each double root
    with_singular_signs(geometry, models.boxes[rows], owner, lo, hi, directions, folded, quiet, np.arange(pw.size),
                        fold=True, curvature=sigma.astype(np.int8))
    out[:] = agreed_signs(pw, folded, np.ones(pw.size, dtype=np.int8), quiet, w)
    out[cusp & (np.bincount(pw, weights=~quiet, minlength=w) == 0)] = STEADY
    return out


def lifted_pair_signs(geometry: Geometry, models: WindowModels, rows: np.ndarray, u: np.ndarray, v: np.ndarray,
                      q_lo: np.ndarray, q_hi: np.ndarray, halvings: int) -> np.ndarray:
    """(w, k) int8 for the pair windows of boxes ``rows`` (m,) and k ways per box, u, v (m, k, 3) in r = rho^2 and
    q in [q_lo, q_hi] (m, k): the sign of s (D_u f - q D_v f), s the window's end sign, proved over R^2 x every
    critical piece of the window (:func:`~intervalkin.solve.window_fold.critical_pieces`, halved ``halvings``
    times) and every such q; 0 where not proved or q's hull is empty.  Other windows: 0.

    A lifted path of the box's cusp window moves r with velocity d (u - q v), q = f_u / f_v at the followed root
    (:func:`cusp_retractions`), so u = min s f of a pair window moves along it with the sign of d times this one
    wherever its minimum can sit (proofs/lemma-joint-retraction.md, "Cusp patterns: lifted paths").  df/dr_l is
    enclosed as for the straight directions: the Taylor form's enclosure met with
    :func:`~intervalkin.solve.window_split.aligned_r_slopes`."""
    rows = np.asarray(rows, dtype=np.int64)
    w, k = len(models.degree), u.shape[1]
    out = np.zeros((w, k), dtype=np.int8)
    even = pair_windows(models) & np.isin(models.window_box, rows)
    if not even.any():
        return out
    data, s, pw, lo, hi, owner = pair_critical(geometry, models, rows, even, halvings)
    aligned = aligned_r_slopes(geometry, models.boxes[rows], owner, lo, hi)
    grad = [data.r_slope(owner, lo, hi, axis).intersect(aligned[axis]) for axis in range(3)]
    signs = np.zeros((pw.size, k), dtype=np.int8)
    for way in range(k):
        q = Interval(q_lo[owner, way], q_hi[owner, way])
        value = _combine(grad, u[owner, way]) - q * _combine(grad, v[owner, way])
        signs[:, way] = np.where(q.lo <= q.hi, sign_label(value), 0)
    out[:] = agreed_signs(pw, signs, s[pw].astype(np.int8), np.zeros(pw.size, dtype=bool), w)
    return out
