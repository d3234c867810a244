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

import functools

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.kinematics.constants import KinematicConstants, constants

__all__ = ['approx_inverse_kinematics', 'approx_det_a', 'approx_jacobian', 'inverse_kinematics_arb', 'det_a_arb', 'residual_arb', 'jacobian_arb']


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


def _approx_f_and_jacobian(k: KinematicConstants, X: np.ndarray):
    """Float rho_i^2 (m, 3) and A (m, 3, 3) at poses X (m, 3).  Not certified (predictors only)."""
    x, y, phi = X[:, 0], X[:, 1], X[:, 2]
    rsq = np.empty((len(X), 3))
    A = np.zeros((len(X), 3, 3))
    for i in range(3):
        dx, dy = x - k.ax[i], y - k.ay[i]
        if i == 0:
            rx = ry = 0.0
        else:
            rx, ry = k.radius[i] * np.cos(phi + k.alpha[i]), k.radius[i] * np.sin(phi + k.alpha[i])
        ux, uy = dx + rx, dy + ry
        rsq[:, i] = ux * ux + uy * uy
        A[:, i, 0], A[:, i, 1], A[:, i, 2] = 2 * ux, 2 * uy, 2 * (rx * dy - ry * dx)
    return rsq, A
