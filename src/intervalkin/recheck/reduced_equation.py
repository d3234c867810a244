"""The recheck's own enclosures of the reduced equation f(phi; r) and its phi-derivatives over joint boxes.

For a joint vector q with r = q^2 (componentwise), z = B1 - A1, a_i = A_i - A_1 and
e_i(phi) = R(phi) p_i = L_i (cos(phi + alpha_i), sin(phi + alpha_i)), legs 2 and 3 minus leg 1
give the linear system m_i . z = k_i (i = 2, 3) with

    m_i = 2 (e_i - a_i),    k_i = s_i + kappa_i,   s_i = r_i - r_1,
    kappa_i = 2 a_i . e_i - |p_i|^2 - |a_i|^2,

and leg 1 gives |z|^2 = r_1.  Cramer's rule: D = m_2 x m_3 (a x b = a_x b_y - a_y b_x) and
D z = N = k_2 u + k_3 v with u = (m_3y, -m_3x), v = (-m_2y, m_2x).  Every solution has its
orientation at a root of

    f(phi; r) = |N|^2 - r_1 D^2,

and a simple root of f carries exactly one solution (a root with D = 0 has N = 0 there too, so
f and f' vanish: it is multiple; proofs/lemma-count-range.md).  f is quadratic in r, with

    df/dr_2 = 2 N . u,   df/dr_3 = 2 N . v,   df/dr_1 = -2 N . (u + v) - D^2.

Everything here is a *Taylor array*: a list of ORDER + 1 interval arrays, entry j enclosing
the j-th phi-Taylor coefficient g^(j)(phi) / j! of a quantity g at every phi of an interval
array.  Sums and products follow the rules of truncated power series (exact for the
coefficients kept), each operation rounded outward by :mod:`intervalkin.recheck.arith`.

:func:`derivative_enclosure` combines two centred forms: in r, f(phi; r) = f(phi; r0) +
grad_r f(phi; r') . (r - r0) with r' between r0 and r (the box is convex), and in phi, the
mean value theorem for the d-th derivative.  Each is intersected with the natural enclosure.

A second writing of the formulas, from the mathematics (DESIGN.md sections 1-2): it imports
nothing of the library's kinematics or solver, nor its rounding layer (the import-linter
contract); ``tests/recheck/test_reduced_equation.py`` compares it with arb.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.recheck.arith import Iv, add, const, cos_sin, down, fraction_enclosure, mul, sub, up
from intervalkin.recheck.model import constants

__all__ = ["ORDER", "ReducedConstants", "reduced_constants", "f_series", "derivative_enclosure", "derivative_enclosures",
           "sign_at_points", "d_sign"]

#: Taylor coefficients kept: enough for the third derivative and its mean value form.
ORDER = 4
_FACT = tuple(float(math.factorial(j)) for j in range(ORDER + 1))
_INV_FACT = tuple(fraction_enclosure(Fraction(1, math.factorial(j))) for j in range(ORDER + 1))

Series = list[Iv]
Pair = tuple[float, float]


@dataclass(frozen=True)
class ReducedConstants:
    """Float enclosures of the constants the reduced equation needs, legs 2 and 3 (index 0 and 1 here).

    ``a`` = A_i - A_1, ``L`` and ``alpha`` the polar form of p_i, ``kappa0`` = -|p_i|^2 - |a_i|^2."""

    a: tuple[tuple[Pair, Pair], tuple[Pair, Pair]]
    L: tuple[Pair, Pair]
    alpha: tuple[Pair, Pair]
    kappa0: tuple[Pair, Pair]


def reduced_constants(geometry: Geometry) -> ReducedConstants:
    """Enclose the constants of ``geometry`` (exact rationals, surds through arb) in floats."""
    k = constants(geometry)
    base = geometry.base
    kappa0 = []
    for i in (1, 2):
        ax, ay = base[i][0] - base[0][0], base[i][1] - base[0][1]
        kappa0.append(fraction_enclosure(-Fraction(geometry.platform_radius_sq(i)) - ax * ax - ay * ay))
    return ReducedConstants((k.c[1], k.c[2]), (k.L[1], k.L[2]), (k.alpha[1], k.alpha[2]), tuple(kappa0))


def _c(p: Pair, like: np.ndarray) -> Iv:
    return const(p[0], p[1], like)


def _zero(like: np.ndarray) -> Iv:
    return np.zeros_like(like), np.zeros_like(like)


def _s_add(a: Series, b: Series) -> Series:
    return [add(x, y) for x, y in zip(a, b)]


def _s_sub(a: Series, b: Series) -> Series:
    return [sub(x, y) for x, y in zip(a, b)]


def _s_scale(a: Series, c: Iv) -> Series:
    return [mul(x, c) for x in a]


def _s_mul(a: Series, b: Series) -> Series:
    out = []
    for j in range(min(len(a), len(b))):
        acc = mul(a[0], b[j])
        for i in range(1, j + 1):
            acc = add(acc, mul(a[i], b[j - i]))
        out.append(acc)
    return out


def _s_const(c: Iv, n: int = ORDER + 1) -> Series:
    return [c] + [_zero(c[0]) for _ in range(n - 1)]


def _trig(phi: Iv, alpha: Pair, L: Pair, n: int = ORDER + 1) -> tuple[Series, Series]:
    """L (cos, sin)(phi + alpha) as Taylor arrays: the derivatives of cos run cos, -sin, -cos, sin, ..."""
    c, s = cos_sin(add(phi, _c(alpha, phi[0])))
    neg_c, neg_s = (-c[1], -c[0]), (-s[1], -s[0])
    cycle_c, cycle_s = (c, neg_s, neg_c, s), (s, c, neg_s, neg_c)
    Lv = _c(L, phi[0])
    cs, ss = [], []
    for j in range(n):
        inv = _c(_INV_FACT[j], phi[0])  # 1/6 and 1/24 are not floats: enclosed
        cs.append(mul(Lv, mul(cycle_c[j % 4], inv)))
        ss.append(mul(Lv, mul(cycle_s[j % 4], inv)))
    return cs, ss


def _parts(k: ReducedConstants, phi: Iv, n: int = ORDER + 1) -> tuple[Series, Series, Series, Series, Series, Series,
                                                                      Series]:
    """(u_x, u_y, v_x, v_y, kappa_2, kappa_3, D) as Taylor arrays over ``phi``, the first n coefficients."""
    like = phi[0]
    m, kappa = [], []
    two = const(2.0, 2.0, like)
    for leg in (0, 1):
        ex, ey = _trig(phi, k.alpha[leg], k.L[leg], n)
        ax, ay = (_c(p, like) for p in k.a[leg])
        m.append((_s_scale(_s_sub(ex, _s_const(ax, n)), two), _s_scale(_s_sub(ey, _s_const(ay, n)), two)))
        dot = _s_add(_s_scale(ex, ax), _s_scale(ey, ay))
        kappa.append(_s_add(_s_scale(dot, two), _s_const(_c(k.kappa0[leg], like), n)))
    (m2x, m2y), (m3x, m3y) = m
    neg = lambda s: [(-hi, -lo) for lo, hi in s]  # noqa: E731 - exact negation of each coefficient
    D = _s_sub(_s_mul(m2x, m3y), _s_mul(m2y, m3x))
    return m3y, neg(m3x), neg(m2y), m2x, kappa[0], kappa[1], D


def _phi_terms(k: ReducedConstants, phi: Iv, n: int = ORDER + 1) -> tuple[Series, ...]:
    """The factors of f that depend on phi alone: with k_i = s_i + kappa_i,

        f = s_2^2 U + 2 s_2 s_3 W + s_3^2 V + 2 s_2 P_2 + 2 s_3 P_3 + P_0 - r_1 D^2,

    U = |u|^2, V = |v|^2, W = u . v, P_2 = kappa_2 U + kappa_3 W, P_3 = kappa_2 W + kappa_3 V,
    P_0 = kappa_2 P_2 + kappa_3 P_3 (expand |k_2 u + k_3 v|^2).  Returned as (U, V, W, P_2, P_3, P_0, D^2)."""
    ux, uy, vx, vy, kap2, kap3, D = _parts(k, phi, n)
    U = _s_add(_s_mul(ux, ux), _s_mul(uy, uy))
    V = _s_add(_s_mul(vx, vx), _s_mul(vy, vy))
    W = _s_add(_s_mul(ux, vx), _s_mul(uy, vy))
    P2 = _s_add(_s_mul(kap2, U), _s_mul(kap3, W))
    P3 = _s_add(_s_mul(kap2, W), _s_mul(kap3, V))
    P0 = _s_add(_s_mul(kap2, P2), _s_mul(kap3, P3))
    return U, V, W, P2, P3, P0, _s_mul(D, D)


def _combine(terms: tuple[Series, ...], r: tuple[Iv, Iv, Iv]) -> tuple[Series, list[Series]]:
    U, V, W, P2, P3, P0, D2 = terms
    like = U[0][0]
    two = const(2.0, 2.0, like)
    s2, s3 = sub(r[1], r[0]), sub(r[2], r[0])
    # h_i = (df/ds_i) / 2: h_2 = s_2 U + s_3 W + P_2, h_3 = s_3 V + s_2 W + P_3; then
    # f = s_2 (h_2 - P_2) + s_3 (h_3 - P_3) + 2 s_2 P_2 + 2 s_3 P_3 + P_0 - r_1 D^2 (the quadratic part once)
    h2 = _s_add(_s_add(_s_scale(U, s2), _s_scale(W, s3)), P2)
    h3 = _s_add(_s_add(_s_scale(V, s3), _s_scale(W, s2)), P3)
    f = _s_add(_s_add(_s_scale(_s_sub(h2, P2), s2), _s_scale(_s_sub(h3, P3), s3)),
               _s_add(_s_add(_s_scale(_s_scale(P2, two), s2), _s_scale(_s_scale(P3, two), s3)),
                      _s_sub(P0, _s_scale(D2, r[0]))))
    d2, d3 = _s_scale(h2, two), _s_scale(h3, two)
    d1 = _s_sub([(-hi, -lo) for lo, hi in _s_add(d2, d3)], D2)
    return f, [d1, d2, d3]


def f_series(k: ReducedConstants, r: tuple[Iv, Iv, Iv], phi: Iv) -> tuple[Series, list[Series]]:
    """(f, [df/dr_1, df/dr_2, df/dr_3]) as Taylor arrays over the intervals r (r_i = rho_i^2) and ``phi``
    (s_i = r_i - r_1, so d/dr_2 = d/ds_2, d/dr_3 = d/ds_3 and d/dr_1 = -d/ds_2 - d/ds_3 - D^2)."""
    return _combine(_phi_terms(k, phi), r)


def _meet(a: Iv, b: Iv) -> Iv:
    return np.maximum(a[0], b[0]), np.minimum(a[1], b[1])


def _r_centred(terms: tuple[Series, ...], r_lo: np.ndarray, r_hi: np.ndarray) -> Series:
    """f over the r box: natural form met with f(phi; r0) + grad_r f(phi; R) . (R - r0) (mean value theorem in
    r over the convex box, gradient enclosed over all of it)."""
    r0 = np.clip(r_lo + (r_hi - r_lo) / 2, r_lo, r_hi)
    f_nat, grad = _combine(terms, tuple((r_lo[:, i], r_hi[:, i]) for i in range(3)))
    f_mid, _ = _combine(terms, tuple((r0[:, i], r0[:, i]) for i in range(3)))
    out = []
    for j in range(len(f_mid)):
        acc = f_mid[j]
        for i in range(3):
            acc = add(acc, mul(grad[i][j], (down(r_lo[:, i] - r0[:, i]), up(r_hi[:, i] - r0[:, i]))))
        out.append(_meet(acc, f_nat[j]))
    return out


def derivative_enclosures(k: ReducedConstants, r_lo: np.ndarray, r_hi: np.ndarray, phi_lo: np.ndarray,
                          phi_hi: np.ndarray, orders: int = ORDER) -> list[Iv]:
    """Enclosures of d^d f / d phi^d, d = 0 .. orders - 1 (<= 3), over the boxes [r_lo, r_hi] (n, 3) x
    [phi_lo, phi_hi] (n,).

    r-centred form (above) met with the mean value form in phi:
    f^(d)(Phi) is in f^(d)(m) + f^(d+1)(Phi) (Phi - m) for m the float midpoint of Phi.
    """
    if not 0 < orders <= ORDER:
        raise ValueError(f"derivative orders {orders} outside 1..{ORDER}")
    m = np.clip(phi_lo + (phi_hi - phi_lo) / 2, phi_lo, phi_hi)
    # the Taylor coefficients up to order ``orders`` are all the forms below use (truncation keeps the others exact)
    over = _r_centred(_phi_terms(k, (phi_lo, phi_hi), orders + 1), r_lo, r_hi)
    at_m = _r_centred(_phi_terms(k, (m, m), orders + 1), r_lo, r_hi)
    offset = (down(phi_lo - m), up(phi_hi - m))
    out = []
    for d in range(orders):
        scale, next_scale = const(_FACT[d], _FACT[d], m), const(_FACT[d + 1], _FACT[d + 1], m)
        mvf = add(mul(at_m[d], scale), mul(mul(over[d + 1], next_scale), offset))
        out.append(_meet(mul(over[d], scale), mvf))
    return out


def derivative_enclosure(k: ReducedConstants, r_lo: np.ndarray, r_hi: np.ndarray, phi_lo: np.ndarray,
                         phi_hi: np.ndarray, d: int) -> Iv:
    """Enclosure of d^d f / d phi^d (d <= 3) over the boxes: :func:`derivative_enclosures`, one order."""
    if not 0 <= d < ORDER:
        raise ValueError(f"derivative order {d} outside 0..{ORDER - 1}")
    return derivative_enclosures(k, r_lo, r_hi, phi_lo, phi_hi, d + 1)[d]


def d_sign(k: ReducedConstants, phi_lo: np.ndarray, phi_hi: np.ndarray) -> np.ndarray:
    """(n,) int8: the proved sign of D = m_2 x m_3 on every phi of [phi_lo, phi_hi] (0: not proved).

    D does not depend on r.  Natural enclosure met with the mean value form D(m) + D'(Phi) (Phi - m)."""
    m = np.clip(phi_lo + (phi_hi - phi_lo) / 2, phi_lo, phi_hi)
    over = _parts(k, (phi_lo, phi_hi), 2)[-1]
    at_m = _parts(k, (m, m), 1)[-1]
    lo, hi = _meet(over[0], add(at_m[0], mul(over[1], (down(phi_lo - m), up(phi_hi - m)))))
    return np.where(lo > 0, 1, np.where(hi < 0, -1, 0)).astype(np.int8)


def sign_at_points(k: ReducedConstants, r_lo: np.ndarray, r_hi: np.ndarray, phi_lo: np.ndarray,
                   phi_hi: np.ndarray) -> np.ndarray:
    """(n,) int8: +1 / -1 where f has that sign at every (r, phi) of the boxes, 0 where it is not proved.

    Meant for narrow phi intervals (a cut point, or the enclosure [-PI_HI, -PI_LO] of -pi)."""
    lo, hi = derivative_enclosure(k, r_lo, r_hi, phi_lo, phi_hi, 0)
    return np.where(lo > 0, 1, np.where(hi < 0, -1, 0)).astype(np.int8)
