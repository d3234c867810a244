"""On which side of a fold sheet of g(S) the two extra solutions live.

Let X* be a singular pose (det A = 0) and k a leg.  Fix the other two joint values
r_i, r_j: the poses with rho_i^2 = r_i^2 and rho_j^2 = r_j^2 form a smooth curve
through X* (the motion of the four-bar with legs i and j) whenever the gradients of
g_i = rho_i^2 and g_j = rho_j^2 are independent there; its tangent is

    v = a_i x a_j        (a_l = (u_lx, u_ly, u_l . J r_l), half the gradient of rho_l^2),

with u_l = B_l - A_l, r_l the platform vector of leg l and J r = (-r_y, r_x).  Since
det A(X*) = 0, f = rho_k^2 restricted to the curve is stationary at X*, and with w the
left null vector of A, w = (u_2 x u_3, u_3 x u_1, u_1 x u_2) (sum_l w_l a_l = 0 at
every singular pose), the Lagrange rule gives its second derivative

    f'' = (2 / w_k) sum_l w_l v^T H_l v / 2,    v^T H_l v / 2 = |v_p + v_phi J r_l|^2 - v_phi^2 (u_l . r_l),

where H_l is the Hessian of rho_l^2 in (x, y, phi) and v_p = (v_x, v_y).  If f'' > 0,
rho_k^2 has a strict local minimum along the curve at X*: for q_k slightly above
h = rho_k(X*) two poses near X* have the joint vector (r_i, r_j, q_k), for q_k slightly
below none (Morse lemma).  Across the sheet near g(X*) every other solution is regular
and continues, so the count ABOVE the sheet (q_k > h) exceeds the count below by 2
(f'' < 0: below exceeds above).  The two solutions born there lie on either side of
S (det A changes sign along the curve at X* when grad det A . v != 0, which a fold
model's regular E' guarantees), so one is in each aspect.

The enclosure below evaluates f'' / 2 up to the positive factor |w_k|^-1 over a pose
box with interval arithmetic: if the box holds X*, the signs it certifies are those
at X*.  Certified: +1 / -1 only when sum_l w_l q_l and w_k have certified signs.
See proofs/lemma-fold-side.md.
"""

from __future__ import annotations

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import Interval
from intervalkin.kinematics.constants import constants

__all__ = ["pair_side", "fold_curvature_interval"]


def _cross2(ax: Interval, ay: Interval, bx: Interval, by: Interval) -> Interval:
    return ax * by - ay * bx


def fold_curvature_interval(geometry: Geometry, boxes: np.ndarray, axis: np.ndarray) -> tuple[Interval, Interval]:
    """(sum_l w_l q_l, w_k) over pose boxes (n, 3, 2) for the sheet axes k = ``axis`` (n,).

    At a singular pose X* in the box, sign(f'') = sign(first) * sign(second) (module
    docstring).  Interval enclosures; certified wherever the box holds X*.
    """
    b = np.asarray(boxes, dtype=np.float64)
    axis = np.asarray(axis, dtype=np.int64)
    k = constants(geometry)
    x, y = Interval(b[:, 0, 0], b[:, 0, 1]), Interval(b[:, 1, 0], b[:, 1, 1])
    phi = Interval(b[:, 2, 0], b[:, 2, 1])
    u, r, rows = [], [], []
    for leg in range(3):
        t = phi + k.alpha_iv[leg]
        rx, ry = k.radius_iv[leg] * t.cos(), k.radius_iv[leg] * t.sin()
        ux, uy = x - k.ax_iv[leg] + rx, y - k.ay_iv[leg] + ry
        u.append((ux, uy))
        r.append((rx, ry))
        rows.append((ux, uy, uy * rx - ux * ry))
    w = [_cross2(*u[1], *u[2]), _cross2(*u[2], *u[0]), _cross2(*u[0], *u[1])]
    n = len(b)
    total = Interval(np.full(n, np.nan), np.full(n, np.nan))
    wk = Interval(np.full(n, np.nan), np.full(n, np.nan))
    for kk in range(3):
        sel = np.flatnonzero(axis == kk)
        if sel.size == 0:
            continue
        i, j = [a for a in range(3) if a != kk]
        ai = [c[sel] for c in rows[i]]
        aj = [c[sel] for c in rows[j]]
        # tangent of the four-bar curve: v = a_i x a_j (3-D cross product)
        vx = ai[1] * aj[2] - ai[2] * aj[1]
        vy = ai[2] * aj[0] - ai[0] * aj[2]
        vp = ai[0] * aj[1] - ai[1] * aj[0]
        s = Interval.point(np.zeros(sel.size))
        for leg in range(3):
            rx, ry = r[leg][0][sel], r[leg][1][sel]
            ux, uy = u[leg][0][sel], u[leg][1][sel]
            # |v_p + v_phi J r|^2 with J r = (-r_y, r_x), minus v_phi^2 (u . r)
            q = (vx - vp * ry).sqr() + (vy + vp * rx).sqr() - vp.sqr() * (ux * rx + uy * ry)
            s = s + w[leg][sel] * q
        total.lo[sel], total.hi[sel] = s.lo, s.hi
        wk.lo[sel], wk.hi[sel] = w[kk].lo[sel], w[kk].hi[sel]
    return total, wk


def _sign(iv: Interval) -> np.ndarray:
    with np.errstate(invalid="ignore"):
        return np.where(iv.lo > 0, 1, np.where(iv.hi < 0, -1, 0)).astype(np.int8)


def pair_side(geometry: Geometry, boxes: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """(n,) int8: +1 where the count above the sheet (q_k > h) is the count below plus 2, -1 where
    below exceeds above by 2, 0 where not proved.

    boxes (n, 3, 2): pose boxes each holding every singular pose of its fold sheet (a fold
    model's pose box); axis (n,): the sheet's axis k.  The two extra solutions are one per
    aspect.  Certified under that premise (module docstring).
    """
    total, wk = fold_curvature_interval(geometry, boxes, axis)
    return (_sign(total) * _sign(wk)).astype(np.int8)
