"""The recheck's own enclosures of rho_i^2 and det A over arrays of boxes, and the four label tests.

The manipulator (DESIGN.md section 1): a pose is (x, y, phi), B1 = (x, y), and
B_i = B1 + r_i with r_i = R(phi) p_i, p_i the platform points in the platform
frame (p_1 = 0, p_2 = (l2, 0), p_3 = (p3x, p3y)).  Leg i has length
rho_i = |B_i - A_i|.  In polar form r_i = L_i (cos(phi + alpha_i), sin(phi +
alpha_i)) with L_i = |p_i| and alpha_i = atan2(p_iy, p_ix): phi then occurs once
per coordinate, which keeps the enclosure of a wide phi range tight.

rho_i^2 = (x + r_ix - A_ix)^2 + (y + r_iy - A_iy)^2.

det A, A = dF/dX with F_i = rho_i^2 - (given rho_i)^2, has rows
2 (u_ix, u_iy, r_i x u_i), u_i = B_i - A_i, a x b = a_x b_y - a_y b_x.  Take
u = u_1 = B1 - A_1 and subtract row 1 from rows 2 and 3: they become
2 (d_i, w_i) with d_i = r_i - (A_i - A_1) and w_i = r_i x u_i = r_i x (B1 - A_i)
(since r_i x r_i = 0).  Expanding along the third column, whose first entry is 0,

    det A = 8 (w_3 (u x d_2) - w_2 (u x d_3)).

The sign convention is the library's and the checker's (det A > 0 is the
``det_positive`` INSIDE label, aspect WA1); ``tests/recheck/test_model.py``
compares this formula with the 3x3 determinant of the rows above in arb.

Constants come from the exact geometry: rationals are enclosed by exact
comparison (:func:`~intervalkin.recheck.arith.fraction_enclosure`), the square
root L_i and the angle alpha_i by arb at 128 bits, then one ulp outward.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

import numpy as np
from flint import arb, ctx, fmpq

from intervalkin.core.geometry import Geometry
from intervalkin.recheck.arith import Iv, add, const, cos_sin, down, fraction_enclosure, mul, neg, sqr, sub, up

__all__ = ['Constants', 'constants', 'rho_sq', 'rho_sq_centred', 'det_a', 'det_a_gradient', 'det_a_centred', 'TESTS', 'REFUTATIONS']

Pair = tuple[float, float]


def _ball(q: Fraction):
    return arb(fmpq(q.numerator, q.denominator))


def _ball_bounds(b) -> Pair:
    """Floats enclosing an arb ball: its end points are exact binary numbers, converted within an ulp."""
    if not b.is_finite():
        raise ValueError("a geometry constant is not finite")
    return math.nextafter(float(b.lower()), -math.inf), math.nextafter(float(b.upper()), math.inf)


@dataclass(frozen=True)
class Constants:
    """Float enclosures of the constants of one geometry (each a (lo, hi) pair).

    ``a[i]`` = (A_ix, A_iy); ``c[i]`` = A_i - A_1 (exact rational, then enclosed);
    ``L[i]``, ``alpha[i]`` the polar form of p_i (i = 1, 2); ``rmin2[i]``,
    ``rmax2[i]`` the squared limits.
    """

    a: tuple[tuple[Pair, Pair], ...]
    c: tuple[tuple[Pair, Pair], ...]
    L: tuple[Pair, ...]
    alpha: tuple[Pair, ...]
    rmin2: tuple[Pair, ...]
    rmax2: tuple[Pair, ...]
    #: a length that turns phi widths into distances when choosing the side to bisect (max L_i, approximate)
    reach: float


def constants(geometry: Geometry) -> Constants:
    """Enclose the constants of ``geometry`` (exact rationals and surds) in floats."""
    base = geometry.base
    a = tuple((fraction_enclosure(ax), fraction_enclosure(ay)) for ax, ay in base)
    c = tuple((fraction_enclosure(base[i][0] - base[0][0]), fraction_enclosure(base[i][1] - base[0][1]))
              for i in range(3))
    L, alpha = [(0.0, 0.0)], [(0.0, 0.0)]
    with ctx.workprec(128):
        for i in (1, 2):
            px, py = (s.arb() for s in geometry.platform_point(i))
            L.append(_ball_bounds(_ball(geometry.platform_radius_sq(i)).sqrt()))
            alpha.append(_ball_bounds(arb.atan2(py, px)))
    rmin2 = tuple(fraction_enclosure(v * v) for v in geometry.rho_min)
    rmax2 = tuple(fraction_enclosure(v * v) for v in geometry.rho_max)
    return Constants(a, c, tuple(L), tuple(alpha), rmin2, rmax2, max(h for _, h in L))


def _k(p: Pair, like: np.ndarray) -> Iv:
    return const(p[0], p[1], like)


def _r(k: Constants, phi: Iv, i: int) -> Iv:
    """r_i = L_i (cos, sin)(phi + alpha_i), enclosed (i = 1, 2)."""
    c, s = cos_sin(add(phi, _k(k.alpha[i], phi[0])))
    L = _k(k.L[i], phi[0])
    return mul(L, c), mul(L, s)


def rho_sq(k: Constants, x: Iv, y: Iv, phi: Iv) -> list[Iv]:
    """rho_i^2 for the three legs, enclosed over the boxes x * y * phi."""
    out = []
    for i in range(3):
        ax, ay = _k(k.a[i][0], x[0]), _k(k.a[i][1], x[0])
        if i == 0:
            out.append(add(sqr(sub(x, ax)), sqr(sub(y, ay))))
        else:
            rx, ry = _r(k, phi, i)
            out.append(add(sqr(add(sub(x, ax), rx)), sqr(add(sub(y, ay), ry))))
    return out


def _legs(k: Constants, x: Iv, y: Iv, phi: Iv) -> list[tuple]:
    """For legs 2 and 3: (r_i, d_i = r_i - (A_i - A_1), v_i = B1 - A_i), each an (x, y) pair of intervals."""
    out = []
    for i in (1, 2):
        r = _r(k, phi, i)
        d = (sub(r[0], _k(k.c[i][0], x[0])), sub(r[1], _k(k.c[i][1], x[0])))
        v = (sub(x, _k(k.a[i][0], x[0])), sub(y, _k(k.a[i][1], x[0])))
        out.append((r, d, v))
    return out


def _cross(a: tuple[Iv, Iv], b: tuple[Iv, Iv]) -> Iv:
    """a x b = a_x b_y - a_y b_x, enclosed."""
    return sub(mul(a[0], b[1]), mul(a[1], b[0]))


def det_a(k: Constants, x: Iv, y: Iv, phi: Iv) -> Iv:
    """det A = 8 (w_3 (u x d_2) - w_2 (u x d_3)), w_i = r_i x (B1 - A_i), natural enclosure over the boxes."""
    u = (sub(x, _k(k.a[0][0], x[0])), sub(y, _k(k.a[0][1], x[0])))
    (r2, d2, v2), (r3, d3, v3) = _legs(k, x, y, phi)
    w2, w3 = _cross(r2, v2), _cross(r3, v3)
    inner = sub(mul(w3, _cross(u, d2)), mul(w2, _cross(u, d3)))
    return mul(_k((8.0, 8.0), x[0]), inner)


def det_a_gradient(k: Constants, x: Iv, y: Iv, phi: Iv) -> tuple[Iv, Iv, Iv]:
    """(d/dx, d/dy, d/dphi) of det A / 8 = Q = w_3 k_2 - w_2 k_3 (k_i = u x d_i), enclosed over the boxes.

    With dw_i/dx = -r_iy, dw_i/dy = r_ix, dk_i/dx = d_iy, dk_i/dy = -d_ix, and
    d r_i / d phi = r_i' = (-r_iy, r_ix) (so d d_i / d phi = r_i'),
    dw_i/dphi = r_i' x (B1 - A_i) and dk_i/dphi = u x r_i'.
    """
    u = (sub(x, _k(k.a[0][0], x[0])), sub(y, _k(k.a[0][1], x[0])))
    (r2, d2, v2), (r3, d3, v3) = _legs(k, x, y, phi)
    w2, w3 = _cross(r2, v2), _cross(r3, v3)
    k2, k3 = _cross(u, d2), _cross(u, d3)
    gx = sub(add(mul(neg(r3[1]), k2), mul(w3, d2[1])), add(mul(neg(r2[1]), k3), mul(w2, d3[1])))
    gy = sub(sub(mul(r3[0], k2), mul(w3, d2[0])), sub(mul(r2[0], k3), mul(w2, d3[0])))
    t2, t3 = (neg(r2[1]), r2[0]), (neg(r3[1]), r3[0])  # r_i'
    gphi = sub(add(mul(_cross(t3, v3), k2), mul(w3, _cross(u, t2))),
               add(mul(_cross(t2, v2), k3), mul(w2, _cross(u, t3))))
    return gx, gy, gphi


def det_a_centred(k: Constants, x: Iv, y: Iv, phi: Iv) -> Iv:
    """det A by the mean value form: det(m) + 8 grad Q(box) . (X - m), m a float point of each box.

    For every X of the box, det(X) = det(m) + 8 grad Q(xi) . (X - m) with xi on
    the segment [m, X], inside the (convex) box: so the enclosure of grad Q over
    the box times the enclosure of X - m, added to an enclosure of det(m), holds
    det(X).  Its width shrinks with the square of the box's, where the natural
    form's shrinks only linearly.
    """
    mids = [np.clip(lo + (hi - lo) / 2, lo, hi) for lo, hi in (x, y, phi)]
    at_m = det_a(k, (mids[0], mids[0]), (mids[1], mids[1]), (mids[2], mids[2]))
    grad = det_a_gradient(k, x, y, phi)
    total = at_m
    for g, (lo, hi), m in zip(grad, (x, y, phi), mids):
        offset = (down(lo - m), up(hi - m))
        total = add(total, mul(mul(_k((8.0, 8.0), lo), g), offset))
    return total


def rho_sq_centred(k: Constants, x: Iv, y: Iv, phi: Iv) -> list[Iv]:
    """rho_i^2 by the mean value form, intersected with the natural enclosure.

    The gradient of rho_i^2 = |u_i|^2, u_i = B1 + r_i - A_i, is
    2 (u_ix, u_iy, r_i x u_i) (d r_i / d phi = (-r_iy, r_ix)): row i of A.  As
    for :func:`det_a_centred`, rho_i^2(m) plus the gradient over the box times
    (X - m) holds rho_i^2(X) for every X of the box.
    """
    mids = [np.clip(lo + (hi - lo) / 2, lo, hi) for lo, hi in (x, y, phi)]
    at_m = rho_sq(k, *((m, m) for m in mids))
    natural = rho_sq(k, x, y, phi)
    two = _k((2.0, 2.0), x[0])
    offsets = [(down(lo - m), up(hi - m)) for (lo, hi), m in zip((x, y, phi), mids)]
    out = []
    for i in range(3):
        ux, uy = sub(x, _k(k.a[i][0], x[0])), sub(y, _k(k.a[i][1], x[0]))
        grad = [ux, uy]
        if i > 0:
            rx, ry = _r(k, phi, i)
            ux, uy = add(ux, rx), add(uy, ry)
            grad = [ux, uy, _cross((rx, ry), (ux, uy))]
        total = at_m[i]
        for g, off in zip(grad, offsets):
            total = add(total, mul(mul(two, g), off))
        nat = natural[i]
        out.append((np.maximum(total[0], nat[0]), np.minimum(total[1], nat[1])))
    return out


def _w_test(k: Constants, box: tuple[Iv, Iv, Iv], inside: bool) -> np.ndarray:
    """Where W INSIDE (``inside``) or W OUTSIDE is proved: natural form, then the centred form on the rest."""
    def decide(r: list[Iv]) -> np.ndarray:
        if inside:
            ok = np.ones(r[0][0].shape, dtype=bool)
            for i in range(3):
                ok &= (r[i][0] >= k.rmin2[i][1]) & (r[i][1] <= k.rmax2[i][0])
        else:
            ok = np.zeros(r[0][0].shape, dtype=bool)
            for i in range(3):
                ok |= (r[i][1] < k.rmin2[i][0]) | (r[i][0] > k.rmax2[i][1])
        return ok
    ok = decide(rho_sq(k, *box))
    rest = np.flatnonzero(~ok)
    if len(rest):
        ok[rest] = decide(rho_sq_centred(k, *(tuple((b[0][rest], b[1][rest]) for b in box))))
    return ok


def _w_inside(k: Constants, box: tuple[Iv, Iv, Iv]) -> np.ndarray:
    return _w_test(k, box, True)


def _w_outside(k: Constants, box: tuple[Iv, Iv, Iv]) -> np.ndarray:
    return _w_test(k, box, False)


def _det_sign(k: Constants, box: tuple[Iv, Iv, Iv], sign: int) -> np.ndarray:
    """Where det A has the sign ``sign`` on the whole box: natural form, then the centred form on the rest."""
    lo, hi = det_a(k, *box)
    ok = lo > 0.0 if sign > 0 else hi < 0.0
    # the centred form is tried only where the natural one left the sign open but possible
    rest = np.flatnonzero(~ok & ((hi > 0.0) if sign > 0 else (lo < 0.0)))
    if len(rest):
        sub_box = tuple((b[0][rest], b[1][rest]) for b in box)
        c_lo, c_hi = det_a_centred(k, *sub_box)
        ok[rest] = c_lo > 0.0 if sign > 0 else c_hi < 0.0
    return ok


def _det_positive(k: Constants, box: tuple[Iv, Iv, Iv]) -> np.ndarray:
    return _det_sign(k, box, 1)


def _det_negative(k: Constants, box: tuple[Iv, Iv, Iv]) -> np.ndarray:
    return _det_sign(k, box, -1)


#: (label name, claimed value as the npz writes it) -> test: True where the claim is PROVED on the box.
#: in_workspace 1: every leg within its limits at every pose; -1: some leg beyond a limit at every pose.
#: det_sign 1: det A > 0 on the box; -1: det A < 0 on it.
TESTS = {
    ("in_workspace", 1): _w_inside,
    ("in_workspace", -1): _w_outside,
    ("det_sign", 1): _det_positive,
    ("det_sign", -1): _det_negative,
}
#: The test whose success on a sub-box proves the claim FALSE somewhere in the box (the opposite label).
REFUTATIONS = {
    ("in_workspace", 1): _w_outside,
    ("in_workspace", -1): _w_inside,
    ("det_sign", 1): _det_negative,
    ("det_sign", -1): _det_positive,
}
