"""Certified enclosures of rho_i^2, det A and the Jacobian A over arrays of boxes, with gradients.

Every function takes boxes of shape (n, 3, 2) ((x, y, phi) x (lo, hi); phi in
radians, any real) and returns :class:`~intervalkin.core.interval.Interval` arrays.
Certified: for every box k and every point of box k, the exact value lies in entry k
(outward-rounded interval arithmetic throughout; cos and sin with the error bound of
:mod:`intervalkin.core.interval`).  The formulas are those of
:mod:`intervalkin.kinematics.formulas`, evaluated here on intervals.

The phi-tight form
------------------
For fixed phi, rho_i^2, w_i (the phi entry of row i of A, over 2) and Q = det A / 8
are polynomials of degree at most 2 in (x, y); all the dependence on phi sits in the
platform vectors r_i(phi) and, for Q, in the coefficients a..e(phi).  A quantity f of
this kind is enclosed over a box b = [x] x [y] x [phi] by the intersection of three
sound enclosures:

1. centred form in phi:   f([x], [y], phi_m) + f_phi(b) ([phi] - phi_m)
   (mean value theorem in phi; phi_m is a float in [phi], f_phi(b) an enclosure of
   df/dphi over the whole box);
2. natural form in phi:   f([x], [y], [phi]), the phi-dependent parts enclosed over
   [phi] (for Q's coefficients, the hull of their enclosures over 8 pieces of [phi]:
   a product of two functions of phi is enclosed much better piece by piece);
3. monotonicity: where f_phi(b) has a certified sign, f over b lies between its
   enclosures on the faces phi = phi_lo and phi = phi_hi.

At fixed phi (or with the phi parts as intervals) the (x, y) part is enclosed with
little or no dependency overestimation: rho_i^2 = (d_ix + r_ix)^2 + (d_iy + r_iy)^2 is a
sum of squares of independent terms (exact range); w_i = r_ix d_iy - r_iy d_ix is linear
in (x, y) (exact range); Q is written as its exact second-order Taylor expansion at the
centre m of the (x, y) rectangle, Q(m) + grad Q(m) . (u, v) + a u^2 + b u v + c v^2 with
u, v the offsets from m (the overestimation is of second order in the box width).
Boxes that are points in phi take the natural form alone (the three forms coincide).

The derivatives in phi come from the formulas: d r_i / d phi = (-r_iy, r_ix), so
d rho_i^2 / d phi = 2 w_i and d w_i / d phi = -(r_i . d_i); the coefficients of Q are
differentiated in forward mode with :class:`PhiDual` (the package's one derivative
type).  The phi-dependent parts are computed once per distinct phi range of the array
(a paving level has at most 2**level of them), so most of the cost is per-box (x, y)
arithmetic.

Gradients: the Jacobian A is the gradient of (rho_1^2, rho_2^2, rho_3^2)
(:func:`jacobian_interval`); :func:`det_a_gradient_interval` encloses grad det A.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from intervalkin.core.errors import InputError
from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import Interval
from intervalkin.kinematics.constants import KinematicConstants, constants
from intervalkin.kinematics.formulas import det_coefficients, leg_moment, leg_rho_sq, quadratic_gradient, quadratic_with_gradient

__all__ = ['PhiDual', 'rho_sq_interval', 'rho_sq_leg_interval', 'rho_interval', 'LegForms', 'rho_sq_leg_forms',
           'jacobian_interval', 'det_a_interval', 'det_a_gradient_interval']

#: Pieces of each phi range over which the coefficients of det A are enclosed (their hull is used).
DET_PHI_PIECES = 8


class PhiDual:
    """An Interval value v with an Interval enclosure d of its derivative in phi (forward mode).

    Sound operations: (u, u') + (v, v') = (u + v, u' + v') and
    (u, u') (v, v') = (u v, u' v + u v'); other operands are constants in phi.
    """

    __slots__ = ("v", "d")

    def __init__(self, v: Interval, d: Interval):
        self.v, self.d = v, d

    def __add__(self, o):
        return PhiDual(self.v + o.v, self.d + o.d) if isinstance(o, PhiDual) else PhiDual(self.v + o, self.d)

    __radd__ = __add__

    def __sub__(self, o):
        return PhiDual(self.v - o.v, self.d - o.d) if isinstance(o, PhiDual) else PhiDual(self.v - o, self.d)

    def __rsub__(self, o):
        return PhiDual(o - self.v, -self.d)

    def __neg__(self):
        return PhiDual(-self.v, -self.d)

    def __mul__(self, o):
        if isinstance(o, PhiDual):
            return PhiDual(self.v * o.v, self.d * o.v + self.v * o.d)
        return PhiDual(self.v * o, self.d * o)

    __rmul__ = __mul__


# --------------------------------------------------------------------------------------
# The phi ranges of an array of boxes
# --------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class _PhiRanges:
    """The distinct phi ranges of the boxes, sampled once each.

    ``samples`` is an Interval (u, c): its first ``pieces`` columns cover [phi_lo, phi_hi]
    (consecutive pieces share their ends), ``cols`` gives the thin columns phi_lo, phi_m,
    phi_hi (None: not sampled).  When every range is a single float (``thin``) there is one
    column and the natural form is the whole answer.  ``inv`` (n,) maps each box to its
    range (None: one range per box, in order); ``offset`` (n,) is [phi] - phi_m.
    """

    samples: Interval
    pieces: int
    cols: tuple
    thin: bool
    inv: np.ndarray | None
    offset: Interval


def _phi_ranges(boxes: np.ndarray, pieces: int, ends: bool = True) -> _PhiRanges:
    if np.array_equal(boxes[:, 2, 0], boxes[:, 2, 1]):  # points in phi: one sample per box
        phi = boxes[:, 2, :1]
        offset = Interval.point(np.zeros(len(boxes)))
        return _PhiRanges(Interval(phi, phi), 1, (0, 0, 0), True, None, offset)
    key = boxes[:, 2, 0] + 1j * boxes[:, 2, 1]
    u, inv = np.unique(key, return_inverse=True)
    inv = inv.reshape(-1)
    pl, ph = u.real.copy(), u.imag.copy()
    pm = np.minimum(np.maximum(0.5 * pl + 0.5 * ph, pl), ph)
    s = np.arange(pieces + 1, dtype=np.float64) / pieces
    cuts = pl[:, None] + (ph - pl)[:, None] * s[None, :]
    cuts[:, 0], cuts[:, -1] = pl, ph
    cuts = np.maximum.accumulate(np.minimum(np.maximum(cuts, pl[:, None]), ph[:, None]), axis=1)
    thin = [pl, pm, ph] if ends else [pm]
    lo = np.concatenate([cuts[:, :-1]] + [t[:, None] for t in thin], axis=1)
    hi = np.concatenate([cuts[:, 1:]] + [t[:, None] for t in thin], axis=1)
    cols = (pieces, pieces + 1, pieces + 2) if ends else (None, pieces, None)
    offset = Interval(boxes[:, 2, 0], boxes[:, 2, 1]) - pm[inv]
    return _PhiRanges(Interval(lo, hi), pieces, cols, False, inv, offset)


@dataclass(frozen=True, eq=False)
class _OverPhi:
    """A function of phi on each distinct phi range (arrays (u,)): ``value`` its range,
    ``slope`` the range of its derivative, ``at_lo``, ``at_mid``, ``at_hi`` its values at
    phi_lo, phi_m, phi_hi.  :meth:`box` gathers one of them to the boxes, (n,), when it is
    used (gathering all of them at once would hold many (n,) arrays at the same time)."""

    fields: dict
    rows: object

    def box(self, name: str) -> Interval:
        v = self.fields[name]
        return Interval(v.lo[self.rows], v.hi[self.rows])


def _over_phi(ph: _PhiRanges, duals) -> list[_OverPhi]:
    """The PhiDuals evaluated on ``ph.samples``, as functions over each phi range."""
    p = ph.pieces
    rows = slice(None) if ph.inv is None else ph.inv

    def hull(lo, hi):
        return Interval(lo[:, 0], hi[:, 0]) if p == 1 else Interval(np.min(lo[:, :p], axis=1), np.max(hi[:, :p], axis=1))

    out = []
    for f in duals:
        v_lo, v_hi = np.broadcast_arrays(f.v.lo, f.v.hi)
        d_lo, d_hi = np.broadcast_arrays(f.d.lo, f.d.hi)
        fields = {"value": hull(v_lo, v_hi), "slope": hull(d_lo, d_hi)}
        for name, c in zip(("at_lo", "at_mid", "at_hi"), ph.cols):
            if c is not None:
                fields[name] = Interval(v_lo[:, c], v_hi[:, c])
        out.append(_OverPhi(fields, rows))
    return out


def _rotation(k: KinematicConstants, i: int, phi: Interval) -> tuple[PhiDual, PhiDual]:
    """r_i = L_i (cos(phi + alpha_i), sin(phi + alpha_i)) with its derivative (-r_iy, r_ix)."""
    t = phi + k.alpha_iv[i]
    L = k.radius_iv[i]
    c, s = L * t.cos(), L * t.sin()
    return PhiDual(c, -s), PhiDual(s, c)


def _phi_tight(form, slope: Interval, offset: Interval, ends: bool = True) -> Interval:
    """Centred form in phi, intersected with the natural form and, where the slope has a sign
    and ``ends``, monotonicity.

    ``form(name)`` evaluates the quantity over the boxes with its phi-dependent parts taken
    as ``name`` ("at_mid", "value", "at_lo", "at_hi"; see :class:`_OverPhi`); the forms are
    evaluated one after the other, so few (n,) temporaries live at once.
    """
    e = (form("at_mid") + slope * offset).intersect(form("value"))
    if not ends:
        return e
    up, down = slope.lo > 0, slope.hi < 0
    face = form("at_lo")  # the minimum where increasing, the maximum where decreasing
    lo, hi = np.where(up, face.lo, e.lo), np.where(down, face.hi, e.hi)
    face = form("at_hi")
    lo, hi = np.where(down, face.lo, lo), np.where(up, face.hi, hi)
    return e.intersect(Interval(lo, hi))


def _stack(parts: list[Interval], axis: int) -> Interval:
    return Interval(np.stack([np.broadcast_to(p.lo, p.shape) for p in parts], axis=axis),
                    np.stack([np.broadcast_to(p.hi, p.shape) for p in parts], axis=axis))


def _boxes(boxes) -> np.ndarray:
    b = np.asarray(boxes, dtype=np.float64)
    if b.ndim != 3 or b.shape[1:] != (3, 2):
        raise InputError(f"boxes: expected an array of shape (n, 3, 2), got shape {b.shape}")
    return b


def _leg_offsets(k: KinematicConstants, b: np.ndarray, i: int) -> tuple[Interval, Interval]:
    """d_i = B1 - A_i over the boxes."""
    return Interval(b[:, 0, 0], b[:, 0, 1]) - k.ax_iv[i], Interval(b[:, 1, 0], b[:, 1, 1]) - k.ay_iv[i]


# --------------------------------------------------------------------------------------
# rho_i^2 and the Jacobian (its gradient)
# --------------------------------------------------------------------------------------
def rho_sq_interval(geometry: Geometry, boxes: np.ndarray) -> Interval:
    """Enclosures of rho_i^2 = |B_i - A_i|^2 over each box: boxes (n, 3, 2) -> Interval (n, 3).

    Leg 1 is (x - a_1x)^2 + (y - a_1y)^2 (exact ranges of two squares); legs 2 and 3
    take the phi-tight form (module docstring) with slope 2 w_i.  Certified.
    """
    b = _boxes(boxes)
    k = constants(geometry)
    ph = _phi_ranges(b, 1)
    out = Interval(np.empty((len(b), 3)), np.empty((len(b), 3)))  # filled leg by leg (peak memory)
    for i in range(3):
        e = _rho_sq_leg(k, b, ph, i)
        out.lo[:, i], out.hi[:, i] = e.lo, e.hi
    return out


def rho_sq_leg_interval(geometry: Geometry, boxes: np.ndarray, leg: int) -> Interval:
    """Column ``leg`` of :func:`rho_sq_interval` alone (the same enclosure), Interval (n,).  Certified."""
    b = _boxes(boxes)
    return _rho_sq_leg(constants(geometry), b, _phi_ranges(b, 1), leg)


def _rho_sq_leg(k: KinematicConstants, b: np.ndarray, ph: _PhiRanges, i: int) -> Interval:
    dx, dy = _leg_offsets(k, b, i)
    if i == 0:
        return leg_rho_sq(dx, dy)
    rx, ry = _over_phi(ph, _rotation(k, i, ph.samples))

    def form(name):
        return leg_rho_sq(dx, dy, rx.box(name), ry.box(name))

    if ph.thin:
        return form("value")
    return _phi_tight(form, leg_moment(dx, dy, rx.box("value"), ry.box("value")) * 2.0, ph.offset)


def rho_interval(geometry: Geometry, boxes: np.ndarray) -> Interval:
    """Enclosures of rho_i = |B_i - A_i| over each box (square root of :func:`rho_sq_interval`), (n, 3)."""
    return rho_sq_interval(geometry, boxes).sqrt()


@dataclass(frozen=True, eq=False)
class LegForms:
    """rho_i^2 = (x + c_x(phi))^2 + (y + c_y(phi))^2, c_i(phi) = r_i(phi) - A_i, in the pieces a contractor uses.

    Natural form: ``cx``, ``cy`` enclose c_i over [phi].  Centred form in phi: for every
    point (x, y, phi) of box k there is a slope s in ``slope[k]`` (an enclosure of
    d rho_i^2 / d phi = 2 w_i over the box) with
    rho_i^2(x, y, phi) = (x + c_x(phi_m))^2 + (y + c_y(phi_m))^2 + s (phi - phi_m),
    where ``phi_mid[k]`` is phi_m, a float of [phi], and ``cx_mid``, ``cy_mid`` enclose c_i(phi_m).
    All Interval arrays have shape (n,).  Leg 1 (p_1 = 0) has thin c and a zero slope.
    """

    cx: Interval
    cy: Interval
    cx_mid: Interval
    cy_mid: Interval
    phi_mid: np.ndarray
    slope: Interval


def rho_sq_leg_forms(geometry: Geometry, boxes: np.ndarray, leg: int) -> LegForms:
    """The natural and centred-in-phi pieces of rho_leg^2 over each box (see :class:`LegForms`).

    One trig evaluation per box (no sharing of phi ranges: a contractor's boxes are off the
    grid).  Certified: each piece encloses its exact counterpart.
    """
    b = _boxes(boxes)
    k = constants(geometry)
    n = len(b)
    phi = Interval(b[:, 2, 0], b[:, 2, 1])
    pm = phi.mid()
    zero = Interval.point(np.zeros(n))
    if leg == 0:
        cx, cy = zero - k.ax_iv[0], zero - k.ay_iv[0]
        return LegForms(cx, cy, cx, cy, pm, zero)
    rx, ry = _rotation(k, leg, phi)
    rxm, rym = _rotation(k, leg, Interval.point(pm))
    dx, dy = _leg_offsets(k, b, leg)
    slope = leg_moment(dx, dy, rx.v, ry.v) * 2.0
    return LegForms(rx.v - k.ax_iv[leg], ry.v - k.ay_iv[leg], rxm.v - k.ax_iv[leg], rym.v - k.ay_iv[leg], pm, slope)


def jacobian_interval(geometry: Geometry, boxes: np.ndarray) -> Interval:
    """A = dF/dX = grad (rho_1^2, rho_2^2, rho_3^2) over each box: boxes (n, 3, 2) -> Interval (n, 3, 3).

    Row i is 2 (d_ix + r_ix, d_iy + r_iy, w_i): the first two entries in natural form
    (d_i and r_i are independent), w_i in the centred form in phi (slope -(r_i . d_i))
    intersected with the natural form; the faces phi_lo, phi_hi are not sampled (the
    Krawczyk boxes this serves are narrow in phi, where monotonicity adds nothing).
    Certified.
    """
    b = _boxes(boxes)
    k = constants(geometry)
    ph = _phi_ranges(b, 1, ends=False)
    dx, dy = _leg_offsets(k, b, 0)
    rows = [_stack([dx * 2.0, dy * 2.0, Interval.point(np.zeros(len(b)))], 1)]
    for i in (1, 2):
        dx, dy = _leg_offsets(k, b, i)
        rx, ry = _over_phi(ph, _rotation(k, i, ph.samples))
        Rx, Ry = rx.box("value"), ry.box("value")
        w = leg_moment(dx, dy, PhiDual(Rx, rx.box("slope")), PhiDual(Ry, ry.box("slope")))
        if not ph.thin:
            w = _phi_tight(lambda name: w.v if name == "value" else leg_moment(dx, dy, rx.box(name), ry.box(name)),
                           w.d, ph.offset, ends=False)
        else:
            w = w.v
        rows.append(_stack([(dx + Rx) * 2.0, (dy + Ry) * 2.0, w * 2.0], 1))
    return _stack(rows, 1)


# --------------------------------------------------------------------------------------
# det A and its gradient
# --------------------------------------------------------------------------------------
def _det_coefficients_over(k: KinematicConstants, ph: _PhiRanges) -> list[_OverPhi]:
    e2x, e2y = k.ax_iv[1] - k.ax_iv[0], k.ay_iv[1] - k.ay_iv[0]
    e3x, e3y = k.ax_iv[2] - k.ax_iv[0], k.ay_iv[2] - k.ay_iv[0]
    r2x, r2y = _rotation(k, 1, ph.samples)
    r3x, r3y = _rotation(k, 2, ph.samples)
    return _over_phi(ph, det_coefficients(r2x, r2y, r3x, r3y, e2x, e2y, e3x, e3y))


def _taylor(coef, Xm: Interval, Ym: Interval, U: Interval, V: Interval, UU: Interval, UV: Interval,
            VV: Interval) -> Interval:
    """The quadratic over X = Xm + U, Y = Ym + V, as its exact Taylor expansion at (Xm, Ym);
    UU, UV, VV enclose U^2, U V, V^2 (computed once for the five forms of a box)."""
    a, b, c = coef[:3]
    q, (gx, gy) = quadratic_with_gradient(coef, Xm, Ym)
    return q + gx * U + gy * V + a * UU + b * UV + c * VV


def _centre_offsets(k: KinematicConstants, b: np.ndarray):
    """X = x - a_1x = Xm + U and Y = y - a_1y = Ym + V: centres (thin) and offsets over each box."""
    x, y = Interval(b[:, 0, 0], b[:, 0, 1]), Interval(b[:, 1, 0], b[:, 1, 1])
    xm, ym = x.mid(), y.mid()
    return Interval.point(xm) - k.ax_iv[0], Interval.point(ym) - k.ay_iv[0], x - xm, y - ym


def _det_q(geometry: Geometry, b: np.ndarray, enclose: bool = True):
    """(Q enclosure, coefficients over phi, slope dQ/dphi over the box) with Q = det A / 8.  Without
    ``enclose``, Q is None and the faces phi_lo, phi_hi (which only Q uses) are not sampled: the same
    coefficients and slope (hulls over the same pieces), for about two thirds of the cost."""
    k = constants(geometry)
    ph = _phi_ranges(b, DET_PHI_PIECES, ends=enclose)
    co = _det_coefficients_over(k, ph)
    Xm, Ym, U, V = _centre_offsets(k, b)
    squares = (U.sqr(), U * V, V.sqr())

    def form(name):
        return _taylor([c.box(name) for c in co], Xm, Ym, U, V, *squares)

    slope = form("slope")
    q = None if not enclose else form("value") if ph.thin else _phi_tight(form, slope, ph.offset)
    return q, co, slope


def det_a_interval(geometry: Geometry, boxes: np.ndarray) -> Interval:
    """Enclosure of det A over each box: boxes (n, 3, 2) -> Interval (n,).

    The phi-tight form of Q = det A / 8 (module docstring), times 8.  Certified.
    """
    q, _, _ = _det_q(geometry, _boxes(boxes))
    return q * 8.0


def det_a_gradient_interval(geometry: Geometry, boxes: np.ndarray) -> Interval:
    """Enclosure of grad det A = (d/dx, d/dy, d/dphi) det A over each box: Interval (n, 3).

    d/dx and d/dy are 8 (2 a X + b Y + d) and 8 (b X + 2 c Y + e) with the coefficients
    over the phi range; d/dphi is 8 dQ/dphi, the slope of the centred form.  Certified.
    """
    b = _boxes(boxes)
    k = constants(geometry)
    _, co, slope = _det_q(geometry, b, enclose=False)
    Xm, Ym, U, V = _centre_offsets(k, b)
    gx, gy = quadratic_gradient([c.box("value") for c in co], Xm + U, Ym + V)
    return _stack([gx, gy, slope], 1) * 8.0
