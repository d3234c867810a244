"""The constants of a geometry in each number system the formulas are evaluated in.

Leg i (i = 1, 2, 3) of a 3-RPR has a base point A_i = (a_ix, a_iy) and a platform
point p_i in the platform frame (p_1 = 0).  In polar form p_i = L_i (cos alpha_i,
sin alpha_i), so that the platform vector of leg i at orientation phi is

    r_i(phi) = R(phi) p_i = L_i (cos(phi + alpha_i), sin(phi + alpha_i)).

The geometry holds these numbers exactly (rationals, and square roots of rationals
for the coordinates of B3).  :func:`constants` turns them into

* floats: a_i, L_i, alpha_i rounded to nearest (for the ``approx_*`` formulas);
* intervals: outward float enclosures of the exact a_i, L_i, alpha_i and of the
  squared joint limits rho_min_i^2, rho_max_i^2 (L_i and alpha_i are computed in
  arb at 128 bits and rounded outward by :func:`intervalkin.core.exact.arb_to_bounds`);
* arb balls: the exact a_i and p_i at the working precision (:meth:`KinematicConstants.arb`).

One cache holds them, keyed by the identity of the geometry object (hashing a
Geometry costs more than an enclosure step of a continuation); the cached entry
keeps its geometry alive, so an identity is never reused while it is cached.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from flint import arb, ctx, fmpq

from intervalkin.core.exact import arb_to_bounds
from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import Interval

__all__ = ['KinematicConstants', 'constants']

#: Geometries kept in the cache at most (the oldest entry leaves first).
_CACHE_SIZE = 32
_CACHE: dict[int, "KinematicConstants"] = {}
#: Precision (bits) of the arb computation of L_i and alpha_i before rounding outward.
_PREC = 128


@dataclass(frozen=True, eq=False)
class KinematicConstants:
    """Per-leg constants of one geometry; arrays have shape (3,), indexed by leg.

    Attributes
    ----------
    geometry : the exact geometry these were computed from.
    ax, ay, radius, alpha : float64 arrays, a_i and the polar form (L_i, alpha_i) of p_i,
        rounded to nearest (not certified).
    ax_iv, ay_iv, radius_iv, alpha_iv : Interval (3,), outward enclosures of the same.
    rho_min_sq_iv, rho_max_sq_iv : Interval (3,), outward enclosures of rho_min_i^2, rho_max_i^2.
    """

    geometry: Geometry
    ax: np.ndarray
    ay: np.ndarray
    radius: np.ndarray
    alpha: np.ndarray
    ax_iv: Interval
    ay_iv: Interval
    radius_iv: Interval
    alpha_iv: Interval
    rho_min_sq_iv: Interval
    rho_max_sq_iv: Interval
    _arb: dict = field(default_factory=dict, repr=False)

    def arb(self) -> tuple[list[tuple], list[tuple]]:
        """(base, platform): [(a_ix, a_iy)] and [(p_ix, p_iy)] as arb balls at the current precision.

        Exact inputs (``arb(fmpq)``, :meth:`Surd.arb`), so the balls are as narrow
        as the precision allows; cached per precision.
        """
        prec = ctx.prec
        hit = self._arb.get(prec)
        if hit is None:
            g = self.geometry
            base = [tuple(arb(fmpq(c.numerator, c.denominator)) for c in a) for a in g.base]
            platform = [tuple(c.arb() for c in g.platform_point(i)) for i in range(3)]
            hit = self._arb[prec] = (base, platform)
        return hit


def constants(geometry: Geometry) -> KinematicConstants:
    """The constants of ``geometry`` in float, interval and arb form (cached by identity)."""
    hit = _CACHE.get(id(geometry))
    if hit is not None and hit.geometry is geometry:
        return hit
    k = _compute(geometry)
    if len(_CACHE) >= _CACHE_SIZE:
        del _CACHE[next(iter(_CACHE))]
    _CACHE[id(geometry)] = k
    return k


def _compute(geometry: Geometry) -> KinematicConstants:
    old = ctx.prec
    ctx.prec = _PREC
    try:
        radius, alpha = [], []
        for i in range(3):
            px, py = geometry.platform_point(i)
            q = geometry.platform_radius_sq(i)
            radius.append(arb_to_bounds(arb(fmpq(q.numerator, q.denominator)).sqrt()))
            alpha.append((0.0, 0.0) if i == 0 else arb_to_bounds(arb.atan2(py.arb(), px.arb())))
    finally:
        ctx.prec = old
    radius_iv = Interval.from_bounds([r[0] for r in radius], [r[1] for r in radius])
    alpha_iv = Interval.from_bounds([a[0] for a in alpha], [a[1] for a in alpha])
    return KinematicConstants(
        geometry=geometry,
        ax=np.array([float(a[0]) for a in geometry.base]),
        ay=np.array([float(a[1]) for a in geometry.base]),
        radius=radius_iv.mid(),
        alpha=alpha_iv.mid(),
        ax_iv=Interval.from_exact(a[0] for a in geometry.base),
        ay_iv=Interval.from_exact(a[1] for a in geometry.base),
        radius_iv=radius_iv,
        alpha_iv=alpha_iv,
        rho_min_sq_iv=Interval.from_exact(v * v for v in geometry.rho_min),
        rho_max_sq_iv=Interval.from_exact(v * v for v in geometry.rho_max),
    )
