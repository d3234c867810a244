"""Midpoint-radius ("ball") arithmetic over numpy arrays, for batched dot products.

:class:`~intervalkin.core.interval.Interval` rounds every operation outward with
``nextafter``: simple and sharp, but each product costs a dozen array passes.  Where
the work is small matrix products over millions of rows (the reduced equation over
joint-space boxes), a ball <m, r> = [m - r, m + r] with float matrix products is
an order of magnitude cheaper.  Its soundness rests on a priori bounds instead of
directed rounding (proofs/lemma-ball-arithmetic.md):

* a float sum of n products, in any order and with or without fused multiply-add,
  is within gamma_n * (the same sum of absolute values) of the exact sum, with
  gamma_n = n u / (1 - n u) and u = 2^-53 (Higham, Accuracy and Stability of
  Numerical Algorithms, 2nd ed., section 3.1); every expression here has n <= 64,
  so gamma_n < :data:`REL` = 2^-40;
* radii are sums and products of non-negative floats, each rounded to nearest, so
  a computed radius is at least (1 - u)^k times the exact one for a chain of k
  operations; multiplying it by (1 + REL) covers k < 2^12;
* an underflowing product loses at most 2^-1074; :data:`TINY` added to every
  radius covers a few thousand of them.

So each operation returns the float midpoint and a radius that bounds, together,
the propagated radii, the rounding of the midpoint and the rounding of the radius.
cos and sin use numpy's error bound from :mod:`intervalkin.core.interval`
(TRIG_ABS_ERROR, valid for |argument| <= TRIG_MAX_ARG) and a Lipschitz bound.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from intervalkin.core.interval import TRIG_ABS_ERROR, TRIG_MAX_ARG, Interval, round_down, round_up

__all__ = ["Ball", "REL", "TINY", "cos_sin_at", "cos_sin_multiple"]

#: Relative inflation: bounds gamma_n for n <= 2^12 and the rounding of radius arithmetic.
REL = 2.0**-40
#: Absolute inflation: covers underflow in a few thousand products.
TINY = 2.0**-1000


def _safe(rad: np.ndarray, magnitude: np.ndarray) -> np.ndarray:
    """Radius plus the rounding of a midpoint of size ``magnitude``, inflated for its own rounding."""
    return (rad + REL * magnitude) * (1.0 + REL) + TINY


@dataclass(frozen=True, eq=False)
class Ball:
    """An array of balls [mid - rad, mid + rad] (float64, broadcastable shapes)."""

    mid: np.ndarray
    rad: np.ndarray

    @staticmethod
    def point(x) -> "Ball":
        """Balls of radius 0 around floats (exact)."""
        m = np.asarray(x, dtype=np.float64)
        return Ball(m, np.zeros_like(m))

    @staticmethod
    def from_interval(x: Interval) -> "Ball":
        """The smallest float ball around each interval (both ends inside it)."""
        lo, hi = np.broadcast_arrays(np.asarray(x.lo, dtype=np.float64), np.asarray(x.hi, dtype=np.float64))
        m = np.minimum(np.maximum(0.5 * lo + 0.5 * hi, lo), hi)
        r = np.maximum(m - lo, hi - m)  # m - lo and hi - m are exact or rounded: inflate
        return Ball(m, r * (1.0 + REL) + TINY)

    def to_interval(self) -> Interval:
        """[mid - rad, mid + rad], rounded outward."""
        return Interval(round_down(self.mid - self.rad), round_up(self.mid + self.rad))

    def magnitude(self) -> np.ndarray:
        """An upper bound of |x| over the ball (up to the REL inflation of the caller)."""
        return np.abs(self.mid) + self.rad

    def __getitem__(self, idx) -> "Ball":
        m, r = np.broadcast_arrays(self.mid, self.rad)
        return Ball(m[idx], r[idx])

    def __add__(self, o: "Ball") -> "Ball":
        m = self.mid + o.mid
        return Ball(m, _safe(self.rad + o.rad, np.abs(m)))

    def __neg__(self) -> "Ball":
        return Ball(-self.mid, self.rad)

    def __sub__(self, o: "Ball") -> "Ball":
        return self + (-o)

    def __mul__(self, o: "Ball") -> "Ball":
        m = self.mid * o.mid
        r = np.abs(self.mid) * o.rad + self.rad * (np.abs(o.mid) + o.rad)
        return Ball(m, _safe(r, np.abs(m)))

    def scale(self, c: float) -> "Ball":
        """c * x for a float c."""
        m = self.mid * c
        return Ball(m, _safe(self.rad * abs(c), np.abs(m)))

    def dot(self, o: "Ball") -> "Ball":
        """sum over the last axis of the elementwise product (n <= 64 terms)."""
        am, bm = np.abs(self.mid), np.abs(o.mid)
        m = np.einsum("...k,...k->...", self.mid, o.mid)
        r = np.einsum("...k,...k->...", am, o.rad) + np.einsum("...k,...k->...", self.rad, bm + o.rad)
        return Ball(m, _safe(r, np.einsum("...k,...k->...", am, bm)))

    def dot_rows(self, o: "Ball") -> "Ball":
        """self (m, k) dotted with each row of o (m, j, k): a ball (m, j); the same bound as :meth:`dot`,
        with explicit subscripts (several times faster than broadcasting for large m)."""
        am, bm = np.abs(self.mid), np.abs(o.mid)
        m = np.einsum("mk,mjk->mj", self.mid, o.mid)
        r = np.einsum("mk,mjk->mj", am, o.rad) + np.einsum("mk,mjk->mj", self.rad, bm + o.rad)
        return Ball(m, _safe(r, np.einsum("mk,mjk->mj", am, bm)))

    def row_matmul(self, o: "Ball") -> "Ball":
        """self (m, l, k) times the matrix o[i] (k, j) of each row i: a ball (m, l, j); the same bound as
        :meth:`matmul` (k <= 64).  ``o`` is best C-contiguous: numpy's stacked matmul is then several times
        faster than :meth:`dot_rows` repeated for each of the l rows."""
        am, om = np.abs(self.mid), np.abs(o.mid)
        m = self.mid @ o.mid
        r = am @ o.rad + self.rad @ (om + o.rad)
        return Ball(m, _safe(r, am @ om))

    def matmul(self, c: "Ball") -> "Ball":
        """self (..., k) times the matrix c (k, j): a ball (..., j); k <= 64."""
        if self.mid.ndim > 2 and self.mid.shape == self.rad.shape:
            # one product of a (rows, k) matrix: numpy's stacked product of a 3-D array is about twice slower
            flat = Ball(self.mid.reshape(-1, self.mid.shape[-1]), self.rad.reshape(-1, self.rad.shape[-1])).matmul(c)
            shape = self.mid.shape[:-1] + flat.mid.shape[-1:]
            return Ball(flat.mid.reshape(shape), flat.rad.reshape(shape))
        am, cm = np.abs(self.mid), np.abs(c.mid)
        m = self.mid @ c.mid
        r = am @ c.rad + self.rad @ (cm + c.rad)
        return Ball(m, _safe(r, am @ cm))


def cos_sin_at(mid: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """numpy's (cos, sin) of the float product k * mid: the midpoints :func:`cos_sin_multiple` starts from, for
    callers that need balls of several radii or derivatives about the same midpoints."""
    t = mid * k
    return np.cos(t), np.sin(t)


def cos_sin_multiple(phi: Ball, k: int, deriv: int = 0,
                     at_mid: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[Ball, Ball]:
    """Balls of d^deriv/dphi^deriv of (cos k phi, sin k phi) over each ball of phi.

    The midpoint is numpy's value at k * mid (error TRIG_ABS_ERROR, plus the
    rounding of k * mid, which moves the argument by at most 2^-52 |k mid|); the
    radius adds the Lipschitz bound k^(deriv + 1) * rad.  Requires
    |k phi| <= TRIG_MAX_ARG.  ``at_mid``: :func:`cos_sin_at` of ``phi.mid`` and k, when already computed
    (the same floats, so the same balls).
    """
    t = phi.mid * k
    if np.any(np.abs(t) + k * phi.rad > TRIG_MAX_ARG):
        raise ValueError("cos_sin_multiple: argument beyond TRIG_MAX_ARG")
    scale = float(k) ** deriv
    # d^j/dphi^j cos(k phi) = k^j cos(k phi + j pi / 2); sin likewise
    j = deriv % 4
    c, s = (np.cos(t), np.sin(t)) if at_mid is None else at_mid
    values = {0: (c, s), 1: (-s, c), 2: (-c, -s), 3: (s, -c)}[j]
    err = scale * (TRIG_ABS_ERROR + 2.0**-52 * np.abs(t) + k * phi.rad)
    return tuple(Ball(v * scale, _safe(err, np.abs(v * scale))) for v in values)
