"""Cusp windows retracted along the flow of their inflection: a curved way for both sides of a cusp edge.

A cusp window [w_a, w_b] of a joint box R (:mod:`intervalkin.solve.window_cusp`) holds one or three roots
of f(phi; r), r = rho^2, at every point of R off g(S).  Where f''' has one proved sign s3 on the whole
window, write g = s3 f, so g''' > 0: g'' increases, g' is convex and has at most two zeros c1 < c2, the
local maximum M = g(c1) and the local minimum m = g(c2).  When moreover g''(w_a) < 0 < g''(w_b) over R,
every r has exactly one inflection psi(r) in the window (g''(psi) = 0, smooth in r), and when the ends have
g(w_a) < 0 < g(w_b) (the other orientation never holds three roots), with alpha = g'(psi) the smallest slope:

* three roots exactly when alpha < 0 and M > 0 > m;
* one root otherwise (alpha >= 0; or M < 0; or m > 0).

The field.  Fix an axis j and solve, at each r, for the vector V(r) with V_j = 0 and

    grad_r g(psi; r) . V = 0,        grad_r g'(psi; r) . V = -1,

a 2 x 2 system in the other two axes i, k (Cramer: V_i = a_k / det, V_k = -a_i / det with a = grad_r g,
b = grad_r g' at psi and det = a_i b_k - a_k b_i).  Along dr/dt = V the smallest slope falls at unit rate
(d alpha / dt = D_V g'(psi) + g''(psi) D_V psi = -1), and by the envelope theorem dM/dt = h(c1) and
dm/dt = h(c2), h(phi) = grad_r g(phi; r) . V.  As h(psi) = 0 and h'(psi) = -1, Taylor's theorem gives

    h(c) = (psi - c) (1 + h''(xi) (psi - c) / 2),    xi between psi and c,

so with |h''| <= K over the window and the box (h'' = grad_r g'' . V) and W the window's length, K W < 2
makes h(c1) > 0 > h(c2).  Closer: at every r of the box c1 and c2 lie in the pieces P where g' may vanish and
psi in the run Psi (below), so c1 in [min P, psi] and c2 in [psi, max P]; with K_L, K_R the bounds of |h''| on
the pieces meeting [min P, max Psi] and [min Psi, max P], K_L (max Psi - min P) < 2 and K_R (max P - min Psi) < 2
suffice (a side without a piece of P has no critical point to bound; a window across phi = pi keeps K W).  Near
the cusp edge c1, c2 and psi come together, so these distances are far below W.  Then M rises and m falls along +V, which keeps the three-root side (M > 0 > m stay; a
critical point cannot leave the window, where g(w_a) < 0 < g(w_b)); along -V, M falls and m rises and alpha
rises, which keeps the one-root side (M < 0 stays, or m > 0 stays; when c1 and c2 merge g becomes monotone;
if one of them leaves the window the value left inside has the sign of the end it left by).  This is the
second-order fact the straight ways lack: it needs no sign of f'' at the cusp edge, where c1, c2 and psi
meet (proofs/lemma-joint-retraction.md, "Cusp windows: the inflection flow").

The flow leaves R through a face when one of V_i, V_k has a proved sign (then |V| is bounded below on R and
that coordinate is monotone); a coordinate whose sign is not proved may reach either of its faces, and
r_j = rho_j^2 stays.  So each side gets the faces its points may reach, for each choice of j.

As a way of a cusp pattern.  Where V_i has a proved sign s_i, +V = |V_i| s_i (e_i - q e_k) with
q = -V_k / V_i = a_i / a_k (det cancels), so the flow moves r with velocity d (u - q v), u = e_i, v = e_k, q in
the hull of a_i / a_k, d = s_i on the three-root side and -s_i on the one-root side (with i and k exchanged where
only V_k is signed): the form of a lifted path (:func:`~intervalkin.solve.window_cusp.lifted_pair_signs`), so
a pair window keeps its status along the flow when s (D_u f - q D_v f) has the sign that keeps it on the
window's critical pieces for every such q (proofs/lemma-joint-retraction.md, "Cusp patterns: the inflection
flow").

The enclosures.  psi lies in the run Psi of pieces between the first and the last where g'' may vanish (halved
twice).  With psi0 its centre, a(psi) = a(psi0) + (psi - psi0) mean(b) (the mean of b over [psi0, psi], in the hull
B of b over Psi, entry by entry), so

    det(a(psi), b(psi)) = det(a(psi0), b(psi)) + (psi - psi0) det(mean(b), b(psi) - mean(b)),

and each entry of b(psi) - mean(b) is at most |psi - psi0| max |grad_r g''| over Psi: the part of a along b, which
interval products of hulls would count at full width, drops out.  Certified: every quantity is an outward-rounded
enclosure over R^2 x pieces (:meth:`~intervalkin.solve.simple_roots.ReducedBoxes.enclosure` and ``r_slope``, with
the mean-value form over pieces), so the true V(r) lies in the enclosure of the Cramer quotients.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import Interval, round_up, sign_label
from intervalkin.solve.simple_roots import ReducedBoxes
from intervalkin.solve.window_cusp import cusp_windows, window_hull
from intervalkin.solve.window_model import WindowModels

__all__ = ["InflectionFlows", "flow_ways", "inflection_flows", "FLOW_AXES"]

#: The axis j held still by each flow (V_j = 0), one way per axis.
FLOW_AXES = (0, 1, 2)
#: Halvings of the inflection's run of pieces before the gradients there are enclosed (on the default paving's 9297
#: leaves with one cusp window: 1079 flows with none, 1084 with one, 1086 with two and with three).
HALVINGS = 2
#: Halvings of the window's pieces when finding where g' may vanish (the critical points' pieces).
CRITICAL_HALVINGS = 2


@dataclass(frozen=True, eq=False)
class InflectionFlows:
    """The inflection flows of boxes with one cusp window, one way per held axis j of :data:`FLOW_AXES`.

    faces : (m, 2, 3, 6) bool, for each side (0 one root, along -V; 1 three roots, along +V) and way, the faces
        (2 axis + 0 low, + 1 high) the side's points may reach (all False where the flow is not proved).
    drive : (m, 2, 3) int8, d: along the side's flow r moves with velocity d (u - q v) times a positive factor
        (0 where the flow is not proved).
    drive_u, follow_v : (m, 3, 3) the vectors u and v of each way (unit vectors of r = rho^2).
    follow_lo, follow_hi : (m, 3) an enclosure of q over the box (module docstring); lo > hi where not proved.
    """

    faces: np.ndarray
    drive: np.ndarray
    drive_u: np.ndarray
    follow_v: np.ndarray
    follow_lo: np.ndarray
    follow_hi: np.ndarray


def inflection_flows(geometry: Geometry, models: WindowModels, rows: np.ndarray, halvings: int = HALVINGS) -> np.ndarray:
    """(m, 2, 3, 6) bool for boxes ``rows`` (m,), each with exactly one cusp window: the faces of
    :func:`flow_ways`."""
    return flow_ways(geometry, models, rows, halvings).faces


def flow_ways(geometry: Geometry, models: WindowModels, rows: np.ndarray, halvings: int = HALVINGS,
              near_critical: bool = True) -> InflectionFlows:
    """The inflection flows of boxes ``rows`` (m,), each with exactly one cusp window (:class:`InflectionFlows`,
    module docstring).  A flow is not proved where the window's f''' is not signed, the inflection is not forced
    into the window, det A of the 2 x 2 system is not signed, K W >= 2, or no moving coordinate is proved
    monotone.  The window's pieces are halved ``halvings`` times for the enclosures at the inflection.
    ``near_critical``: bound h'' only between the inflection's run and the pieces where g' may vanish (module
    docstring); False keeps the bound over the whole window's length W (the weaker test, for comparison)."""
    rows = np.asarray(rows, dtype=np.int64)
    m = rows.size
    ways = len(FLOW_AXES)
    faces = np.zeros((m, 2, ways, 6), dtype=bool)
    drive = np.zeros((m, 2, ways), dtype=np.int8)
    drive_u, follow_v = np.zeros((m, ways, 3)), np.zeros((m, ways, 3))
    follow_lo, follow_hi = np.ones((m, ways)), np.zeros((m, ways))
    result = InflectionFlows(faces, drive, drive_u, follow_v, follow_lo, follow_hi)
    window = np.flatnonzero(cusp_windows(models) & np.isin(models.window_box, rows))
    if window.size != m or not np.array_equal(models.window_box[window], rows):
        raise ValueError("inflection_flows: each row needs exactly one cusp window")
    if not m:
        return result
    on = np.isin(models.piece_window, window)
    pw, lo, hi = models.piece_window[on], models.piece_lo[on], models.piece_hi[on]
    slot = np.full(len(models.degree), -1, dtype=np.int64)
    slot[window] = np.arange(m)
    owner = slot[pw]
    data = ReducedBoxes(geometry, models.boxes[rows])
    # s3: the sign of f''' proved on every piece of the window (g = s3 f has g''' > 0)
    third = sign_label(data.enclosure(owner, lo, hi, 3)).astype(np.float64)
    low3, high3 = np.full(m, 2.0), np.full(m, -2.0)
    np.minimum.at(low3, owner, third)
    np.maximum.at(high3, owner, third)
    s3 = np.where((low3 == high3) & (low3 != 0), low3, 0.0)
    # the window's ends (its pieces are stored in circle order) and its length along the circle
    first = np.full(m, np.iinfo(np.int64).max)
    last = np.full(m, -1)
    at = np.arange(owner.size)
    np.minimum.at(first, owner, at)
    np.maximum.at(last, owner, at)
    ends = np.arange(m)
    g2_a = data.enclosure(ends, lo[first], lo[first], 2) * s3
    g2_b = data.enclosure(ends, hi[last], hi[last], 2) * s3
    length = round_up(np.bincount(owner, weights=hi - lo, minlength=m) * (1.0 + 2.0**-40))
    # g(w_a) < 0 < g(w_b): the orientation in which the window can hold three roots (with g''' > 0 and the other
    # one, g' would need two changes of sign from - to + to -, which a convex g' cannot make)
    rising = s3 * models.end_signs[window, 0] < 0
    forced = rising & (models.degree[window] == 3) & (g2_a.hi < 0) & (g2_b.lo > 0)
    # h'' = grad_r g'' . V, per piece of the window (its hulls bound h'' between psi and a critical point)
    sp = s3[owner]
    wo, wlo, whi = owner, lo, hi
    c_piece = [data.r_slope(owner, lo, hi, i, 2, mean_value=True) * sp for i in range(3)]
    c = [window_hull(ci, owner, np.ones(owner.size, dtype=bool), m) for ci in c_piece]
    # the critical points c1 < c2 lie, at every r of the box, where g' may vanish (halved CRITICAL_HALVINGS times)
    crit_lo, crit_hi = np.full(m, np.inf), np.full(m, -np.inf)
    co, clo, chi = owner, lo, hi
    for round_ in range(CRITICAL_HALVINGS + 1):
        if round_:
            mid = np.minimum(np.maximum(0.5 * clo + 0.5 * chi, clo), chi)
            co, clo, chi = np.r_[co, co], np.r_[clo, mid], np.r_[mid, chi]
        crit = sign_label(data.enclosure(co, clo, chi, 1)) == 0
        co, clo, chi = co[crit], clo[crit], chi[crit]
    np.minimum.at(crit_lo, co, clo)
    np.maximum.at(crit_hi, co, chi)
    # the run of pieces that holds the inflection (between the first and the last where g'' may vanish), halved:
    # grad_r g turns with phi at the rate grad_r g', which a wide run spreads over its hull
    keep = np.ones(owner.size, dtype=bool)
    for round_ in range(halvings + 1):
        owner, lo, hi = owner[keep], lo[keep], hi[keep]
        if round_:
            mid = np.minimum(np.maximum(0.5 * lo + 0.5 * hi, lo), hi)
            owner, lo, hi = np.r_[owner, owner], np.r_[lo, mid], np.r_[mid, hi]
        psi = sign_label(data.enclosure(owner, lo, hi, 2)) == 0
        span = window_hull(Interval(lo, hi), owner, psi, m)
        keep = (lo >= span.lo[owner]) & (hi <= span.hi[owner])
    owner, lo, hi, sp = owner[keep], lo[keep], hi[keep], s3[owner[keep]]
    # a run across phi = pi has a hull far wider than its pieces: not used
    near = (np.bincount(owner, minlength=m) > 0) & (span.hi - span.lo <= np.bincount(owner, weights=hi - lo, minlength=m)
                                                   * (1.0 + 2.0**-30) + 2.0**-40)
    every = np.ones(owner.size, dtype=bool)
    b = [window_hull(data.r_slope(owner, lo, hi, i, 1, mean_value=True) * sp, owner, every, m) for i in range(3)]
    c_psi = [window_hull(data.r_slope(owner, lo, hi, i, 2, mean_value=True) * sp, owner, every, m) for i in range(3)]
    # psi0 the run's centre: a(psi) = a(psi0) + (psi - psi0) mean(b), and that part, parallel to b, drops out of det
    psi0 = np.where(near, 0.5 * span.lo + 0.5 * span.hi, 0.0)
    offset = Interval(np.where(near, span.lo, 0.0), np.where(near, span.hi, 0.0)) - psi0  # psi - psi0
    a0 = [data.r_slope(ends, psi0, psi0, i, 0) * s3 for i in range(3)]
    a = [a0[i] + offset * b[i] for i in range(3)]
    reach = np.maximum(np.abs(offset.lo), np.abs(offset.hi))
    # b(psi) - mean(b) per entry: grad_r g'' over the run times at most |psi - psi0|
    e = [Interval(-x, x) for x in (round_up(reach * np.maximum(np.abs(ci.lo), np.abs(ci.hi))) for ci in c_psi)]
    base = forced & near
    # c1 sits in [crit_lo, psi], c2 in [psi, crit_hi]: the Taylor bound needs h'' there only, over those distances
    # (a window across phi = pi keeps the bound over its whole length W)
    flat = wlo[first] < whi[last]
    left_at = (whi >= crit_lo[wo]) & (wlo <= span.hi[wo])
    right_at = (wlo <= crit_hi[wo]) & (whi >= span.lo[wo])
    c_left = [window_hull(ci, wo, left_at, m) for ci in c_piece]
    c_right = [window_hull(ci, wo, right_at, m) for ci in c_piece]
    # (float comparisons are exact: a side is vacuous when no piece of P reaches the run)
    none_left, none_right = ~(crit_lo < span.hi), ~(crit_hi > span.lo)
    with np.errstate(invalid="ignore"):
        d_left = np.where(none_left, 0.0, round_up(span.hi - crit_lo))
        d_right = np.where(none_right, 0.0, round_up(crit_hi - span.lo))
    for way, j in enumerate(FLOW_AXES):
        i, k = [x for x in range(3) if x != j]
        # det(a(psi), b(psi)) = det(a(psi0), b(psi)) + (psi - psi0) det(mean(b), b(psi) - mean(b))
        det = (a0[i] * b[k] - a0[k] * b[i]) + offset * (b[i] * e[k] - b[k] * e[i])
        signed = base & ((det.lo > 0) | (det.hi < 0))
        with np.errstate(all="ignore"):  # unsigned det: the quotients are not used
            vi = a[k] / det
            vk = -a[i] / det
            curve = c[i] * vi + c[k] * vk  # h'' = grad_r g'' . V over the window and the box
            bound = np.maximum(np.abs(curve.lo), np.abs(curve.hi))
            small = round_up(bound * length) < 2.0
            sides = []
            for ch, dist, none in ((c_left, d_left, none_left), (c_right, d_right, none_right)):
                part = ch[i] * vi + ch[k] * vk
                b_side = np.maximum(np.abs(part.lo), np.abs(part.hi))
                # no critical piece on this side: c1 (c2) is never in the window there, nothing to bound
                sides.append(none | (np.isfinite(b_side) & (round_up(b_side * dist) < 2.0)))
            small = np.where(near_critical & flat & np.isfinite(bound), sides[0] & sides[1], small)
        si, sk = sign_label(vi), sign_label(vk)
        good = signed & small & np.isfinite(bound) & ((si != 0) | (sk != 0))
        for side, toward in ((1, 1), (0, -1)):
            for axis, sv in ((i, si), (k, sk)):
                faces[:, side, way, 2 * axis] = good & (toward * sv <= 0)
                faces[:, side, way, 2 * axis + 1] = good & (toward * sv >= 0)
        # the way as d (u - q v): u along a coordinate whose V entry is signed, q = a_u / a_v (det cancels)
        by_i = good & (si != 0)
        by_k = good & (si == 0)
        with np.errstate(all="ignore"):
            q_i, q_k = a[i] / a[k], a[k] / a[i]
        for sel, (ua, va), q, sv in ((by_i, (i, k), q_i, si), (by_k, (k, i), q_k, sk)):
            drive_u[sel, way, ua] = 1.0
            follow_v[sel, way, va] = 1.0
            follow_lo[sel, way], follow_hi[sel, way] = q.lo[sel], q.hi[sel]
            drive[sel, 1, way], drive[sel, 0, way] = sv[sel], -sv[sel]
    return result
