"""Certified continuation of direct-kinematic solutions along joint-space paths.

Used by :mod:`intervalkin.space.basic_region` to tell which sheet above a joint cell a piece
of certified boxes lies in (proofs/lemma-sheet-continuation.md).

Parameter Krawczyk test
-----------------------
Along a segment q(t) = q_a + t (q_b - q_a) of joint space (q_a, q_b exact, t a
float) the system is F(X, t)_i = |B_i(X) - A_i|^2 - rho_i(t)^2.  For a box X,
a parameter interval T = [t0, t1], a point m of X, a float matrix Y (inverse of
the float Jacobian at m) and an interval matrix J(X) enclosing dF/dX over X
(independent of t),

    K(X, T) = m - Y F(m, tm) - (T - tm) Y dF/dt(m, T) + (I - Y J(X)) (X - m)

encloses m - Y F(m, t) + (I - Y J(X)) (X - m) for every t in T (mean value in t,
dF_i/dt = -2 rho_i(t) (q_b - q_a)_i).  If K(X, T) lies in the interior of X,
then for EVERY t in T the box X holds exactly one solution x(t), every Jacobian
on X is non-singular (so det A keeps one sign on X) and t -> x(t) is continuous
(proofs/lemma-krawczyk-uniqueness.md applied at each t; closed graph in a
compact box).  Every zero of F(., t1) in X also lies in

    K1 = p - Y F(p, t1) + (I - Y J(X)) (X - p)     (any point p of X),

so K1 n X is a box that holds the solution at t1 (no interior test needed).
All of it is evaluated with :class:`intervalkin.core.interval.Interval` (outward
rounding), vectorized over many tracks at once.

Tracking
--------
A track carries a box Z known to hold the followed solution at q(t).  A step
[t, t1] predicts the solution at t1 in float (tangent + Newton), builds X around
both ends and around Z, and accepts the step when K(X, [t, t1]) is inside X:
the followed solution is then the unique one in X for all of [t, t1], and
Z := K1 n X at t1.  The step doubles on success and halves on failure, with a
floor below which the track gives up (never a guess).

Voxel paths
-----------
Paths run inside one joint cell: between centres of face-adjacent voxels of the
cell (the segment lies in the union of the two closed voxels), in straight runs
along a breadth-first tree of the cell rooted at the cell's witness voxel.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import Interval
from intervalkin.kinematics.constants import KinematicConstants, _k, constants
from intervalkin.kinematics.formulas import _det_formula, _rho_sq_formula

__all__ = ['rho_sq_interval', 'rho_interval', 'det_a_interval']


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


def _stack(parts, axis):
    return Interval(np.stack([np.broadcast_to(p.lo, p.shape) for p in parts], axis=axis),
                    np.stack([np.broadcast_to(p.hi, p.shape) for p in parts], axis=axis))


def _legs_interval(geometry: Geometry, x: Interval, y: Interval, phi: Interval):
    """Per leg i: (x - a_ix, y - a_iy, r_ix, r_iy) as Intervals (r_1 = 0)."""
    k = _k(geometry)
    out = []
    for i in range(3):
        dx, dy = x - k.ax_iv[i], y - k.ay_iv[i]
        if i == 0:
            out.append((dx, dy, None, None))
        else:
            ang = phi + k.alpha_iv[i]
            out.append((dx, dy, k.radius_iv[i] * ang.cos(), k.radius_iv[i] * ang.sin()))
    return out


def rho_sq_enclosure(geometry: Geometry, lo: np.ndarray, hi: np.ndarray) -> Interval:
    """rho_i^2 = |B_i - A_i|^2 over boxes [lo, hi] (m, 3): Interval (m, 3) (natural form)."""
    x, y, phi = (Interval(lo[:, j], hi[:, j]) for j in range(3))
    parts = []
    for dx, dy, rx, ry in _legs_interval(geometry, x, y, phi):
        ux, uy = (dx, dy) if rx is None else (dx + rx, dy + ry)
        parts.append(ux.sqr() + uy.sqr())
    return _stack(parts, 1)


def jacobian_enclosure(geometry: Geometry, lo: np.ndarray, hi: np.ndarray) -> Interval:
    """A = dF/dX over boxes [lo, hi] (m, 3): Interval (m, 3, 3).

    Row i is 2 (u_ix, u_iy, w_i) with u_i = B1 - A_i + r_i and w_i = r_i x (B1 - A_i).
    The first two columns hold x, y, phi once each (natural form); w_i is the
    natural form intersected with its mean-value form about the box centre
    (dw/dx = -r_iy, dw/dy = r_ix, dw/dphi = -(r_ix d_ix + r_iy d_iy), d_i = B1 - A_i).
    """
    x, y, phi = (Interval(lo[:, j], hi[:, j]) for j in range(3))
    m = Interval(lo, hi).mid()
    mx, my, mp = (Interval.point(m[:, j]) for j in range(3))
    at_mid = _legs_interval(geometry, mx, my, mp)
    rows = []
    for (dx, dy, rx, ry), (cx, cy, crx, cry) in zip(_legs_interval(geometry, x, y, phi), at_mid):
        if rx is None:
            rows.append(_stack([dx * 2.0, dy * 2.0, Interval.point(np.zeros(lo.shape[0]))], 1))
            continue
        natural = rx * dy - ry * dx
        centred = (crx * cy - cry * cx) + (-ry) * (x - mx) + rx * (y - my) + (-(rx * dx + ry * dy)) * (phi - mp)
        w = natural.intersect(centred)
        rows.append(_stack([(dx + rx) * 2.0, (dy + ry) * 2.0, w * 2.0], 1))
    return _stack(rows, 1)
