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
from dataclasses import dataclass

import numpy as np

from intervalkin.core.exact import arb_to_bounds, fraction_bounds
from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import Interval

__all__ = ['KinematicConstants', 'constants']


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
# Enclosures over arrays of boxes
# --------------------------------------------------------------------------------------
_CONSTANTS: dict[int, tuple[Geometry, KinematicConstants]] = {}


def _k(geometry: Geometry) -> KinematicConstants:
    """constants(geometry), cached by identity (hashing a Geometry costs more than a step)."""
    hit = _CONSTANTS.get(id(geometry))
    if hit is None or hit[0] is not geometry:
        hit = _CONSTANTS[id(geometry)] = (geometry, constants(geometry))
    return hit[1]
