"""rho_i^2 and det A enclosed at float poses: the cheap evaluation of Newton and Krawczyk steps.

The box enclosures of :mod:`intervalkin.kinematics.enclosures` fight overestimation
over wide boxes (Taylor forms, monotonicity in phi); at a single float pose there is
nothing to fight, and the formulas of :mod:`intervalkin.kinematics.formulas` evaluated
once in outward-rounded :class:`~intervalkin.core.interval.Interval` arithmetic enclose
the exact values (lemma-outward-rounding.md; cos and sin are enclosed by
lemma-trig-enclosure.md; the constants are the outward enclosures of
:mod:`intervalkin.kinematics.constants`).  Certified: the exact rho_i^2 and det A of the
pose lie in the returned intervals.
"""

from __future__ import annotations

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import Interval
from intervalkin.kinematics.constants import constants
from intervalkin.kinematics.formulas import det_from_legs, leg_rho_sq, leg_vectors

__all__ = ["rho_sq_det_at"]


def rho_sq_det_at(geometry: Geometry, poses: np.ndarray) -> tuple[Interval, Interval]:
    """(rho^2 (n, 3), det A (n,)) enclosed at the float poses (n, 3) = (x, y, phi)."""
    P = np.asarray(poses, dtype=np.float64)
    k = constants(geometry)
    x, y, phi = Interval.point(P[:, 0]), Interval.point(P[:, 1]), Interval.point(P[:, 2])
    base = [(k.ax_iv[i], k.ay_iv[i]) for i in range(3)]

    def rotation(i, phi):
        t = phi + k.alpha_iv[i]
        return k.radius_iv[i] * t.cos(), k.radius_iv[i] * t.sin()

    legs = leg_vectors(base, rotation, x, y, phi)
    sq = [leg_rho_sq(*leg) for leg in legs]
    det = det_from_legs(base, legs, x, y)
    return Interval(np.stack([s.lo for s in sq], 1), np.stack([s.hi for s in sq], 1)), det
