"""Inverse kinematics g, the Jacobian A = dF/dX and det A: float, interval and arb.

With F_i(q, X) = |B_i - A_i|^2 - rho_i^2 (paper eq. 1-3), u_i = B_i - A_i and
r_i = B_i - B1 = R(phi) p_i,

    rho_i^2 = |u_i|^2,           row i of A = 2 (u_ix, u_iy, r_i x u_i),

where a x b = a_x b_y - a_y b_x.  Subtracting row 1 from rows 2 and 3 (r_1 = 0)
and writing d_i = u_i - u_1 = r_i - A_i + A_1 (independent of x, y) gives

    det A = 8 [ u1x (d2y w3 - w2 d3y) - u1y (d2x w3 - w2 d3x) ],
    w_i = r_i x u_i = r_i x (B1 - A_i),

a polynomial of degree 2 in (x, y) for fixed phi: the cubic terms cancel.  This
form is used everywhere (fewer occurrences of x, y means tighter intervals).
Sign convention (DESIGN.md section 2): the paper's Table 1 solutions 2, 3, 6 have
det A > 0; aspect WA1 is det A > 0, WA2 is det A < 0.

Each quantity has up to four evaluations that share ONE formula:

* ``approx_*``: float64, nearest rounding, for plotting and heuristics only;
* ``*_interval``: over arrays of boxes, sound (outward rounding), as the natural
  interval extension intersected with the centred (mean-value) form
  f(X) in f(m) + grad f(X) . (X - m);
* ``*_arb``: arb balls at the current flint precision, the trusted reference.

For the interval and float versions r_i is written L_i (cos(phi + alpha_i),
sin(phi + alpha_i)) (one occurrence of phi per coordinate); the arb version uses
p_i and cos phi, sin phi directly, so the two are independent checks of each other.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from .geometry import Geometry
from .interval import Interval, arb_to_bounds, fraction_bounds

__all__ = [
    "KinematicConstants",
    "constants",
    "approx_inverse_kinematics",
    "approx_det_a",
    "approx_jacobian",
    "rho_sq_interval",
    "rho_interval",
    "det_a_interval",
    "inverse_kinematics_arb",
    "det_a_arb",
    "jacobian_arb",
    "residual_arb",
]


# --------------------------------------------------------------------------------------
# Constants of a geometry, in every number system
# --------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class KinematicConstants:
    """Per-leg constants: base points a_i, platform radii L_i = |p_i|, angles alpha_i.

    Float arrays have shape (3,) (leg index); the ``*_iv`` entries are outward
    enclosures of the exact values (computed in arb at 128 bits).
    """

    ax: np.ndarray
    ay: np.ndarray
    radius: np.ndarray
    alpha: np.ndarray
    ax_iv: Interval
    ay_iv: Interval
    radius_iv: Interval
    alpha_iv: Interval
    rho_min_iv: Interval
    rho_max_iv: Interval


@functools.lru_cache(maxsize=32)
def constants(geometry: Geometry) -> KinematicConstants:
    """Float values and sound float enclosures of the constants of ``geometry``."""
    from flint import arb, ctx, fmpq

    old = ctx.prec
    ctx.prec = 128
    try:
        ab = [[fraction_bounds(c) for c in a] for a in geometry.base]
        rad, alp = [], []
        for i in range(3):
            px, py = geometry.platform_point(i)
            q = geometry.platform_radius_sq(i)
            rad.append(arb_to_bounds(arb(fmpq(q.numerator, q.denominator)).sqrt()))
            alp.append((0.0, 0.0) if i == 0 else arb_to_bounds(arb.atan2(py.arb(), px.arb())))
    finally:
        ctx.prec = old
    ax_iv = Interval.from_bounds([b[0][0] for b in ab], [b[0][1] for b in ab])
    ay_iv = Interval.from_bounds([b[1][0] for b in ab], [b[1][1] for b in ab])
    radius_iv = Interval.from_bounds([r[0] for r in rad], [r[1] for r in rad])
    alpha_iv = Interval.from_bounds([a[0] for a in alp], [a[1] for a in alp])
    rmin = [fraction_bounds(v) for v in geometry.rho_min]
    rmax = [fraction_bounds(v) for v in geometry.rho_max]
    return KinematicConstants(
        ax=np.array([float(a[0]) for a in geometry.base]),
        ay=np.array([float(a[1]) for a in geometry.base]),
        radius=radius_iv.mid(),
        alpha=alpha_iv.mid(),
        ax_iv=ax_iv,
        ay_iv=ay_iv,
        radius_iv=radius_iv,
        alpha_iv=alpha_iv,
        rho_min_iv=Interval.from_bounds([r[0] for r in rmin], [r[1] for r in rmin]),
        rho_max_iv=Interval.from_bounds([r[0] for r in rmax], [r[1] for r in rmax]),
    )


# --------------------------------------------------------------------------------------
# Forward-mode derivatives over intervals, for the centred form
# --------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class _Jet:
    """An interval value with an interval enclosure of its gradient in (x, y, phi)."""

    val: Interval
    grad: tuple[Interval, Interval, Interval]

    def __add__(self, o):
        if isinstance(o, _Jet):
            return _Jet(self.val + o.val, tuple(a + b for a, b in zip(self.grad, o.grad)))
        return _Jet(self.val + o, self.grad)

    __radd__ = __add__

    def __neg__(self):
        return _Jet(-self.val, tuple(-g for g in self.grad))

    def __sub__(self, o):
        return self + (-o)

    def __rsub__(self, o):
        return (-self) + o

    def __mul__(self, o):
        if isinstance(o, _Jet):
            return _Jet(self.val * o.val, tuple(a * o.val + self.val * b for a, b in zip(self.grad, o.grad)))
        return _Jet(self.val * o, tuple(g * o for g in self.grad))

    __rmul__ = __mul__

    def sqr(self):
        two_v = self.val * 2.0
        return _Jet(self.val.sqr(), tuple(two_v * g for g in self.grad))


class _IntervalOps:
    """Number system: sound intervals (natural extension)."""

    @staticmethod
    def sq(v):
        return v.sqr()

    @staticmethod
    def rot(phi, k: KinematicConstants, i: int):
        """r_i = L_i (cos(phi + alpha_i), sin(phi + alpha_i)) as (value) intervals."""
        t = phi + k.alpha_iv[i]
        L = k.radius_iv[i]
        return L * t.cos(), L * t.sin()

    @staticmethod
    def base(k: KinematicConstants, i: int):
        return k.ax_iv[i], k.ay_iv[i]


class _JetOps(_IntervalOps):
    """Number system: intervals with gradients (phi is a _Jet with grad (0, 0, 1))."""

    @staticmethod
    def rot(phi: _Jet, k: KinematicConstants, i: int):
        t = phi.val + k.alpha_iv[i]
        L = k.radius_iv[i]
        c, s = L * t.cos(), L * t.sin()
        zero = Interval.point(0.0)
        return _Jet(c, (zero, zero, -s)), _Jet(s, (zero, zero, c))


class _FloatOps:
    """Number system: float64 (approximate)."""

    @staticmethod
    def sq(v):
        return v * v

    @staticmethod
    def rot(phi, k: KinematicConstants, i: int):
        t = phi + k.alpha[i]
        return k.radius[i] * np.cos(t), k.radius[i] * np.sin(t)

    @staticmethod
    def base(k: KinematicConstants, i: int):
        return k.ax[i], k.ay[i]


class _ArbOps:
    """Number system: arb balls; constants from the exact geometry."""

    def __init__(self, geometry: Geometry):
        from flint import arb, fmpq

        self.p = [tuple(c.arb() for c in geometry.platform_point(i)) for i in range(3)]
        self.a = [tuple(arb(fmpq(c.numerator, c.denominator)) for c in pt) for pt in geometry.base]

    @staticmethod
    def sq(v):
        return v * v

    def rot(self, phi, k, i: int):
        c, s = phi.cos(), phi.sin()
        px, py = self.p[i]
        return px * c - py * s, px * s + py * c

    def base(self, k, i: int):
        return self.a[i]


# --------------------------------------------------------------------------------------
# The formulas, written once
# --------------------------------------------------------------------------------------
def _legs(ops, k, x, y, phi):
    """Per leg: (u_i, r_i, a_i) with u_i = B_i - A_i."""
    out = []
    for i in range(3):
        ax, ay = ops.base(k, i)
        if i == 0:
            out.append(((x - ax, y - ay), None, (ax, ay)))
        else:
            rx, ry = ops.rot(phi, k, i)
            out.append(((x + rx - ax, y + ry - ay), (rx, ry), (ax, ay)))
    return out


def _rho_sq_formula(ops, k, x, y, phi):
    return [ops.sq(ux) + ops.sq(uy) for (ux, uy), _, _ in _legs(ops, k, x, y, phi)]


def _det_formula(ops, k, x, y, phi):
    """det A / 8 = u1x (d2y w3 - w2 d3y) - u1y (d2x w3 - w2 d3x)."""
    a1x, a1y = ops.base(k, 0)
    u1x, u1y = x - a1x, y - a1y
    d, w = [], []
    for i in (1, 2):
        ax, ay = ops.base(k, i)
        rx, ry = ops.rot(phi, k, i)
        d.append((rx - ax + a1x, ry - ay + a1y))
        w.append(rx * (y - ay) - ry * (x - ax))
    (d2x, d2y), (d3x, d3y) = d
    w2, w3 = w
    return u1x * (d2y * w3 - w2 * d3y) - u1y * (d2x * w3 - w2 * d3x)


# --------------------------------------------------------------------------------------
# Float (approximate) versions
# --------------------------------------------------------------------------------------
def _split_points(X: np.ndarray):
    X = np.asarray(X, dtype=np.float64)
    return X[..., 0], X[..., 1], X[..., 2]


def approx_inverse_kinematics(geometry: Geometry, X: np.ndarray) -> np.ndarray:
    """rho = g(X) in float64 for poses X of shape (..., 3); returns shape (..., 3). Not certified."""
    k = constants(geometry)
    x, y, phi = _split_points(X)
    return np.sqrt(np.stack(_rho_sq_formula(_FloatOps, k, x, y, phi), axis=-1))


def approx_det_a(geometry: Geometry, X: np.ndarray) -> np.ndarray:
    """det A in float64 for poses X of shape (..., 3). Not certified."""
    k = constants(geometry)
    x, y, phi = _split_points(X)
    return 8.0 * _det_formula(_FloatOps, k, x, y, phi)


def approx_jacobian(geometry: Geometry, X: np.ndarray) -> np.ndarray:
    """A = dF/dX in float64, shape (..., 3, 3). Not certified."""
    k = constants(geometry)
    x, y, phi = _split_points(X)
    rows = []
    for i in range(3):
        ux = x - k.ax[i]
        uy = y - k.ay[i]
        if i == 0:
            rows.append(np.stack([2 * ux, 2 * uy, np.zeros_like(ux)], axis=-1))
            continue
        rx, ry = _FloatOps.rot(phi, k, i)
        ux, uy = ux + rx, uy + ry
        rows.append(np.stack([2 * ux, 2 * uy, 2 * (rx * uy - ry * ux)], axis=-1))
    return np.stack(rows, axis=-2)


# --------------------------------------------------------------------------------------
# Interval versions over arrays of boxes
# --------------------------------------------------------------------------------------
def _box_intervals(boxes: np.ndarray):
    b = np.asarray(boxes, dtype=np.float64)
    return tuple(Interval(b[:, j, 0], b[:, j, 1]) for j in range(3))


def _centred(geometry: Geometry, boxes: np.ndarray, formula) -> list[Interval] | Interval:
    """Natural extension intersected with the mean-value form, for each output of formula."""
    k = constants(geometry)
    x, y, phi = _box_intervals(boxes)
    zero, one = Interval.point(0.0), Interval.point(1.0)
    jx = _Jet(x, (one, zero, zero))
    jy = _Jet(y, (zero, one, zero))
    jp = _Jet(phi, (zero, zero, one))
    jets = formula(_JetOps, k, jx, jy, jp)
    mx, my, mp = x.mid(), y.mid(), phi.mid()
    at_mid = formula(_IntervalOps, k, Interval.point(mx), Interval.point(my), Interval.point(mp))
    single = not isinstance(jets, list)
    if single:
        jets, at_mid = [jets], [at_mid]
    out = []
    for jet, fm in zip(jets, at_mid):
        mv = fm + jet.grad[0] * (x - mx) + jet.grad[1] * (y - my) + jet.grad[2] * (phi - mp)
        out.append(jet.val.intersect(mv))
    return out[0] if single else out


def rho_sq_interval(geometry: Geometry, boxes: np.ndarray) -> list[Interval]:
    """Enclosures of rho_i^2 over each box; boxes of shape (n, 3, 2) -> three (n,) Intervals.

    Certified: every value of rho_i^2 at a point of box k lies in the k-th interval.
    """
    return _centred(geometry, boxes, _rho_sq_formula)


def rho_interval(geometry: Geometry, boxes: np.ndarray) -> list[Interval]:
    """Enclosures of rho_i = |B_i - A_i| over each box (sqrt of :func:`rho_sq_interval`)."""
    return [r.sqrt() for r in rho_sq_interval(geometry, boxes)]


def det_a_interval(geometry: Geometry, boxes: np.ndarray) -> Interval:
    """Enclosure of det A over each box; boxes (n, 3, 2) -> (n,) Interval. Certified."""
    d = _centred(geometry, boxes, _det_formula)
    return d * 8.0


# --------------------------------------------------------------------------------------
# arb versions (the trusted reference)
# --------------------------------------------------------------------------------------
@functools.lru_cache(maxsize=32)
def _arb_ops(geometry: Geometry, prec: int) -> _ArbOps:
    return _ArbOps(geometry)


def _ops_now(geometry: Geometry) -> _ArbOps:
    from flint import ctx

    return _arb_ops(geometry, ctx.prec)


def inverse_kinematics_arb(geometry: Geometry, x, y, phi) -> list:
    """[rho_1, rho_2, rho_3] as arb balls for arb inputs (at the current precision)."""
    return [r.sqrt() for r in _rho_sq_formula(_ops_now(geometry), None, x, y, phi)]


def rho_sq_arb(geometry: Geometry, x, y, phi) -> list:
    """[rho_1^2, rho_2^2, rho_3^2] as arb balls."""
    return _rho_sq_formula(_ops_now(geometry), None, x, y, phi)


def det_a_arb(geometry: Geometry, x, y, phi):
    """det A as an arb ball."""
    return 8 * _det_formula(_ops_now(geometry), None, x, y, phi)


def residual_arb(geometry: Geometry, x, y, phi, rho_sq) -> list:
    """F_i = |B_i - A_i|^2 - rho_i^2 as arb balls; rho_sq are arb balls (exact squares)."""
    return [a - b for a, b in zip(rho_sq_arb(geometry, x, y, phi), rho_sq)]


def jacobian_arb(geometry: Geometry, x, y, phi) -> list[list]:
    """A = dF/dX as a 3x3 nested list of arb balls; arguments may be wide balls."""
    ops = _ops_now(geometry)
    rows = []
    for i, ((ux, uy), r, _) in enumerate(_legs(ops, None, x, y, phi)):
        if r is None:
            rows.append([2 * ux, 2 * uy, 0 * ux])
        else:
            rx, ry = r
            rows.append([2 * ux, 2 * uy, 2 * (rx * uy - ry * ux)])
    return rows
