"""Tri-state predicates over arrays of boxes: joint limits (W), det A sign, aspects.

Every function here takes boxes of shape (n, 3, 2) (x, y, phi; phi in radians) and
returns (n,) ``uint8`` :class:`~intervalkin.paving.labels.Label` arrays.  A label is made
only from outward-rounded :class:`~intervalkin.core.interval.Interval` operations, never
from a float comparison of approximate values.

Tight enclosures (what decides the undecided layer)
---------------------------------------------------

Both rho_i^2 and det A are, for fixed phi, polynomials of degree 2 in (x, y)
(kinematics module docstring).  Write Q = det A / 8 with X = x - a1x, Y = y - a1y:

    Q = a X^2 + b X Y + c Y^2 + d X + e Y,

where a..e are trigonometric polynomials in phi (products of the components of
r_2 = R(phi) p_2 and r_3 = R(phi) p_3 and the base offsets).  For every box:

1. the phi-dependent coefficients are enclosed once per distinct phi interval of
   the array (a paving level has at most 2**level of them), at the ends and the
   middle of the phi interval (thin), and over the whole interval (hull over 8
   sub-intervals), together with their phi-derivatives (forward mode);
2. a quadratic with given coefficients is enclosed over the (x, y) rectangle by its
   exact Taylor expansion at the centre, Q(m) + grad Q(m).(u, v) + a u^2 + b u v
   + c v^2 (no gradient overestimation; only the u v term is loose);
3. three sound enclosures are intersected: the centred form in phi
   Q(x, y, phi_m) + dQ/dphi(box) (phi - phi_m); the natural form in phi (coefficient
   ranges); and, where dQ/dphi(box) has a certified sign, monotonicity in phi
   (the minimum and maximum lie on the faces phi = phi_lo, phi = phi_hi).

rho_i^2 = (x - a_ix + r_ix)^2 + (y - a_iy + r_iy)^2 gets the same treatment: its
phi-derivative is 2 (r_ix (y - a_iy) - r_iy (x - a_ix)), linear in (x, y), and for
fixed phi the two squares are enclosed exactly.
"""

from __future__ import annotations

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import Interval
from intervalkin.kinematics.constants import constants

__all__ = ['det_a_tight', 'rho_sq_tight']
_SUBDIVISIONS = 8


# --------------------------------------------------------------------------------------
# Small helpers over Interval
# --------------------------------------------------------------------------------------
def _iv(lo, hi=None) -> Interval:
    lo = np.asarray(lo, dtype=np.float64)
    return Interval(lo, lo if hi is None else np.asarray(hi, dtype=np.float64))


def _take(x: Interval, idx: np.ndarray) -> Interval:
    lo, hi = np.broadcast_arrays(x.lo, x.hi)
    return Interval(lo[idx], hi[idx])


def _hull_last(x: Interval) -> Interval:
    """Hull over the last axis."""
    return Interval(np.min(x.lo, axis=-1), np.max(x.hi, axis=-1))


def _monotone(e: Interval, slope: Interval, at_lo: Interval, at_hi: Interval) -> Interval:
    """Intersect e with the monotonicity enclosure where the phi-slope has a certified sign."""
    up = slope.lo > 0
    down = slope.hi < 0
    lo = np.where(up, at_lo.lo, np.where(down, at_hi.lo, e.lo))
    hi = np.where(up, at_hi.hi, np.where(down, at_lo.hi, e.hi))
    return e.intersect(Interval(lo, hi))


class _Dual:
    """An Interval value with an Interval enclosure of its derivative in phi."""

    __slots__ = ("v", "d")

    def __init__(self, v: Interval, d: Interval):
        self.v, self.d = v, d

    def __add__(self, o):
        return _Dual(self.v + o.v, self.d + o.d) if isinstance(o, _Dual) else _Dual(self.v + o, self.d)

    def __sub__(self, o):
        return _Dual(self.v - o.v, self.d - o.d) if isinstance(o, _Dual) else _Dual(self.v - o, self.d)

    def __neg__(self):
        return _Dual(-self.v, -self.d)

    def __mul__(self, o):
        if isinstance(o, _Dual):
            return _Dual(self.v * o.v, self.d * o.v + self.v * o.d)
        return _Dual(self.v * o, self.d * o)


def _unique_phi(boxes: np.ndarray):
    """Distinct phi intervals of the boxes: (lo (u,), hi (u,), inverse index (n,))."""
    key = boxes[:, 2, 0] + 1j * boxes[:, 2, 1]
    u, inv = np.unique(key, return_inverse=True)
    return u.real.copy(), u.imag.copy(), inv.reshape(-1)


def _phi_samples(pl: np.ndarray, ph: np.ndarray):
    """Thin phi at lo, mid, hi (floats inside the interval) and S covering sub-intervals."""
    pm = np.minimum(np.maximum(0.5 * pl + 0.5 * ph, pl), ph)
    s = np.arange(_SUBDIVISIONS + 1, dtype=np.float64) / _SUBDIVISIONS
    cuts = pl[:, None] + (ph - pl)[:, None] * s[None, :]
    cuts[:, 0] = pl
    cuts[:, -1] = ph
    cuts = np.maximum.accumulate(np.minimum(np.maximum(cuts, pl[:, None]), ph[:, None]), axis=1)
    sub = Interval(cuts[:, :-1], cuts[:, 1:])  # consecutive pieces share their ends: they cover [pl, ph]
    return pm, sub


def _rot_dual(k, i: int, phi: Interval) -> tuple[_Dual, _Dual]:
    """r_i = L_i (cos(phi + alpha_i), sin(phi + alpha_i)) with its phi-derivative (-r_iy, r_ix)."""
    t = phi + k.alpha_iv[i]
    L = k.radius_iv[i]
    c = L * t.cos()
    s = L * t.sin()
    return _Dual(c, -s), _Dual(s, c)


# --------------------------------------------------------------------------------------
# det A
# --------------------------------------------------------------------------------------
def _det_coefficients(k, phi: Interval):
    """(a, b, c, d, e) of Q = det A / 8 as _Duals in phi, over the phi intervals given."""
    r2x, r2y = _rot_dual(k, 1, phi)
    r3x, r3y = _rot_dual(k, 2, phi)
    e2x = k.ax_iv[1] - k.ax_iv[0]
    e2y = k.ay_iv[1] - k.ay_iv[0]
    e3x = k.ax_iv[2] - k.ax_iv[0]
    e3y = k.ay_iv[2] - k.ay_iv[0]
    k2 = r2y * e2x - r2x * e2y
    k3 = r3y * e3x - r3x * e3y
    d2x, d2y = r2x - e2x, r2y - e2y
    d3x, d3y = r3x - e3x, r3y - e3y
    pX = r2y * d3y - r3y * d2y
    pY = r3x * d2y - r2x * d3y
    p0 = d2y * k3 - k2 * d3y
    rX = r2y * d3x - r3y * d2x
    rY = r3x * d2x - r2x * d3x
    r0 = d2x * k3 - k2 * d3x
    return pX, pY - rX, -rY, p0, -r0


def _quad(coef, Xm: Interval, Ym: Interval, U: Interval, V: Interval) -> Interval:
    """Enclosure of a X^2 + b XY + c Y^2 + d X + e Y for X = Xm + U, Y = Ym + V (Taylor, exact)."""
    a, b, c, d, e = coef
    q0 = Xm * (a * Xm + b * Ym + d) + Ym * (c * Ym + e)
    gx = (a * Xm) * 2.0 + b * Ym + d
    gy = b * Xm + (c * Ym) * 2.0 + e
    return q0 + gx * U + gy * V + a * U.sqr() + b * (U * V) + c * V.sqr()


def _xy_parts(boxes: np.ndarray, ox: Interval, oy: Interval):
    """Centres and offsets: X = x - ox = Xm + U over the box, same for y."""
    xl, xh = boxes[:, 0, 0], boxes[:, 0, 1]
    yl, yh = boxes[:, 1, 0], boxes[:, 1, 1]
    xm = np.minimum(np.maximum(0.5 * xl + 0.5 * xh, xl), xh)
    ym = np.minimum(np.maximum(0.5 * yl + 0.5 * yh, yl), yh)
    Xm = _iv(xm) - ox
    Ym = _iv(ym) - oy
    U = _iv(xl, xh) - xm
    V = _iv(yl, yh) - ym
    return Xm, Ym, U, V


def _det_q_tight(geometry: Geometry, boxes: np.ndarray) -> Interval:
    boxes = np.asarray(boxes, dtype=np.float64)
    k = constants(geometry)
    pl, ph, inv = _unique_phi(boxes)
    pm, sub = _phi_samples(pl, ph)
    c_lo = [c.v for c in _det_coefficients(k, _iv(pl))]
    c_mid = [c.v for c in _det_coefficients(k, _iv(pm))]
    c_hi = [c.v for c in _det_coefficients(k, _iv(ph))]
    c_rng = _det_coefficients(k, sub)
    c_val = [_hull_last(c.v) for c in c_rng]
    c_der = [_hull_last(c.d) for c in c_rng]

    def g(cs):
        return [_take(c, inv) for c in cs]

    Xm, Ym, U, V = _xy_parts(boxes, k.ax_iv[0], k.ay_iv[0])
    q_mid = _quad(g(c_mid), Xm, Ym, U, V)
    slope = _quad(g(c_der), Xm, Ym, U, V)
    dphi = _iv(boxes[:, 2, 0], boxes[:, 2, 1]) - pm[inv]
    e1 = q_mid + slope * dphi
    e2 = _quad(g(c_val), Xm, Ym, U, V)
    q = e1.intersect(e2)
    q = _monotone(q, slope, _quad(g(c_lo), Xm, Ym, U, V), _quad(g(c_hi), Xm, Ym, U, V))
    return q


def det_a_tight(geometry: Geometry, boxes: np.ndarray) -> Interval:
    """Enclosure of det A over each box, boxes (n, 3, 2) -> (n,) Interval. Certified.

    Intersection of the centred form in phi, the natural form in phi and (where the
    phi-slope has a certified sign) monotonicity, each with an exact Taylor
    enclosure in (x, y) (module docstring).  Sharper than
    :func:`intervalkin.kinematics.enclosures.det_a_interval` near det A = 0.
    """
    return _det_q_tight(geometry, boxes) * 8.0


# --------------------------------------------------------------------------------------
# rho_i^2
# --------------------------------------------------------------------------------------
def rho_sq_tight(geometry: Geometry, boxes: np.ndarray) -> list[Interval]:
    """Enclosures of rho_i^2 over each box: boxes (n, 3, 2) -> three (n,) Intervals. Certified."""
    boxes = np.asarray(boxes, dtype=np.float64)
    k = constants(geometry)
    x = _iv(boxes[:, 0, 0], boxes[:, 0, 1])
    y = _iv(boxes[:, 1, 0], boxes[:, 1, 1])
    out = [(x - k.ax_iv[0]).sqr() + (y - k.ay_iv[0]).sqr()]
    pl, ph, inv = _unique_phi(boxes)
    pm, sub = _phi_samples(pl, ph)
    dphi = _iv(boxes[:, 2, 0], boxes[:, 2, 1]) - pm[inv]
    for i in (1, 2):
        X = x - k.ax_iv[i]
        Y = y - k.ay_iv[i]

        def at(phi: Interval):
            rx, ry = _rot_dual(k, i, phi)
            return _take(rx.v, inv), _take(ry.v, inv)

        def sq(rx, ry):
            return (X + rx).sqr() + (Y + ry).sqr()

        rxs, rys = _rot_dual(k, i, sub)
        Rx, Ry = _take(_hull_last(rxs.v), inv), _take(_hull_last(rys.v), inv)
        slope = (Rx * Y - Ry * X) * 2.0  # d rho_i^2 / d phi over the box
        mx, my = at(_iv(pm))
        e = sq(mx, my) + slope * dphi
        e = e.intersect(sq(Rx, Ry))
        lx, ly = at(_iv(pl))
        hx, hy = at(_iv(ph))
        e = _monotone(e, slope, sq(lx, ly), sq(hx, hy))
        out.append(e)
    return out
