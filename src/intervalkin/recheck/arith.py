"""Interval arithmetic on arrays of float64 bounds, rounded outward after every operation.

An interval array is a pair ``(lo, hi)`` of float64 arrays of one shape, standing
for the real intervals [lo[k], hi[k]].  Every function here returns bounds that
enclose the exact real result for every choice of points in its arguments:

* ``+``, ``-``, ``*`` of IEEE 754 binary64 are correctly rounded (round to
  nearest), so the exact result lies within half an ulp of the float numpy
  returns; a float at or beyond the next one toward -inf (lower bound) or +inf
  (upper bound) is therefore an enclosure.  :func:`down` and :func:`up` give one
  with four array operations, v -+ |v| 2^-52 -+ 2^-1022 (about five times faster
  than :func:`numpy.nextafter`; why it is never short of that next float:
  proofs/lemma-box-label-recheck.md, item 1).  Every bound of every operation is
  stepped, even when the operation happened to be exact: a step too many only
  widens the interval by an ulp or two.
* cos and sin are not correctly rounded in numpy (on AVX-512 machines numpy uses
  Intel's SVML, documented at 4 ulp at most, elsewhere the C library, about 1
  ulp).  For |t| <= :data:`TRIG_ARG_MAX` and |cos t| <= 1 an error of 4 ulp is at
  most 4 * 2^-52 = 2^-50 in absolute value; :data:`TRIG_MARGIN` = 2^-44 is 64
  times that.  ``tests/recheck/test_arith.py`` compares numpy's values with arb at
  a million points, near the zeros and extrema included, and asserts the error
  stays under 2^-50.
* The extrema of cos and sin inside an interval are located with the enclosure
  [:data:`PI_LO`, :data:`PI_HI`] of pi, so a multiple of pi/2 that might lie in
  the interval is always counted as lying in it (a wider, still sound, result).

This module is the recheck's own rounding layer: it uses numpy only, not
:mod:`intervalkin.core.interval`, so that a slip in the library's arithmetic is
not shared by the recheck.  Inputs must be finite; the caller validates boxes.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

__all__ = ['PI_LO', 'PI_HI', 'TRIG_MARGIN', 'TRIG_ARG_MAX', 'Iv', 'down', 'up', 'point', 'const',
           'add', 'sub', 'mul', 'sqr', 'neg', 'cos_sin', 'fraction_enclosure']

#: (lo, hi) float64 arrays of one shape.
Iv = tuple[np.ndarray, np.ndarray]

#: math.pi is the float nearest to pi and lies below it (pi = 3.14159265358979323846..., math.pi =
#: 3.141592653589793115997...); its successor lies above.  tests/recheck/test_arith.py checks both in arb.
PI_LO = math.pi
PI_HI = math.nextafter(math.pi, math.inf)
#: Absolute error margin added to numpy's cos and sin (64 times the 4-ulp bound, see the module docstring).
TRIG_MARGIN = 2.0 ** -44
#: Beyond this |argument| cos and sin are given as [-1, 1] (no accuracy is assumed far from 0).
TRIG_ARG_MAX = 64.0


#: 2^-52: |v| times this is at least the gap from a normal float v to its neighbours.
_ULP_SCALE = 2.0 ** -52
#: The smallest normal float: it covers the gaps below 2^-970, where |v| 2^-52 falls short (and is not
#: flushed to zero, as a subnormal constant would be on a machine that flushes them).
_GAP_FLOOR = 2.0 ** -1022


def down(v: np.ndarray) -> np.ndarray:
    """A float at or below the next float toward -inf of each ``v`` (finite): a lower bound of any real within
    half an ulp of ``v``.  (v - |v| 2^-52) - 2^-1022, each operation rounded to nearest."""
    v = np.asarray(v, dtype=np.float64)
    return (v - np.abs(v) * _ULP_SCALE) - _GAP_FLOOR


def up(v: np.ndarray) -> np.ndarray:
    """A float at or above the next float toward +inf of each ``v`` (finite): an upper bound of any real within
    half an ulp of ``v``.  (v + |v| 2^-52) + 2^-1022, the mirror image of :func:`down`."""
    v = np.asarray(v, dtype=np.float64)
    return (v + np.abs(v) * _ULP_SCALE) + _GAP_FLOOR


def point(v: np.ndarray) -> Iv:
    """The degenerate intervals [v, v] (the floats are exact real numbers)."""
    v = np.asarray(v, dtype=np.float64)
    return v, v


def const(lo: float, hi: float, like: np.ndarray) -> Iv:
    """The constant interval [lo, hi] broadcast to the shape of ``like``."""
    return np.full(np.shape(like), lo, dtype=np.float64), np.full(np.shape(like), hi, dtype=np.float64)


def add(a: Iv, b: Iv) -> Iv:
    """a + b, enclosed."""
    return down(a[0] + b[0]), up(a[1] + b[1])


def sub(a: Iv, b: Iv) -> Iv:
    """a - b, enclosed (the lower bound pairs a's low end with b's high end)."""
    return down(a[0] - b[1]), up(a[1] - b[0])


def neg(a: Iv) -> Iv:
    """-a (exact: negation of a float is a float)."""
    return -a[1], -a[0]


def mul(a: Iv, b: Iv) -> Iv:
    """a * b, enclosed: the extreme of the four end-point products, each rounded outward."""
    p1, p2, p3, p4 = a[0] * b[0], a[0] * b[1], a[1] * b[0], a[1] * b[1]
    lo = np.minimum(np.minimum(p1, p2), np.minimum(p3, p4))
    hi = np.maximum(np.maximum(p1, p2), np.maximum(p3, p4))
    return down(lo), up(hi)


def sqr(a: Iv) -> Iv:
    """a^2, enclosed without the sign loss of a * a: its low end is 0 when a holds 0."""
    l2, h2 = a[0] * a[0], a[1] * a[1]
    lo = np.where(a[0] > 0, l2, np.where(a[1] < 0, h2, 0.0))
    # a square is >= 0, so the lower bound may be clipped at 0 after the outward step
    return np.maximum(down(lo), 0.0), up(np.maximum(l2, h2))


def cos_sin(t: Iv) -> tuple[Iv, Iv]:
    """(cos t, sin t) over the intervals t, enclosed.

    At the end points numpy's values are widened by :data:`TRIG_MARGIN`; the
    interval then takes the minimum and maximum of the two.  Inside, cos reaches
    +1 at 2k pi and -1 at (2k + 1) pi, sin +1 at (2k + 1/2) pi and -1 at
    (2k - 1/2) pi: all are multiples j pi/2, and every j whose enclosure
    [j PI_LO / 2, j PI_HI / 2] (rounded outward) meets t sets the extremum.  The
    candidates j are j0 .. j0 + 6 with j0 = floor(t_lo / (pi/2)) - 1 computed
    in floats: an interval narrower than 6 holds fewer than 3.82 multiples of
    pi/2 past t_lo, and the float quotient is off by far less than one, so no j
    in t is missed.  Intervals of width >= 6 or with |t| > :data:`TRIG_ARG_MAX`
    get [-1, 1] for both.
    """
    lo, hi = t
    c_lo, c_hi = np.cos(lo), np.cos(hi)
    s_lo, s_hi = np.sin(lo), np.sin(hi)
    cl = down(np.minimum(c_lo, c_hi) - TRIG_MARGIN)
    ch = up(np.maximum(c_lo, c_hi) + TRIG_MARGIN)
    sl = down(np.minimum(s_lo, s_hi) - TRIG_MARGIN)
    sh = up(np.maximum(s_lo, s_hi) + TRIG_MARGIN)
    wide = ~((hi - lo < 6.0) & (np.abs(lo) <= TRIG_ARG_MAX) & (np.abs(hi) <= TRIG_ARG_MAX))
    # inputs of the wide branch are kept finite so that the candidate arithmetic stays quiet
    safe_lo = np.where(wide, 0.0, lo)
    safe_hi = np.where(wide, 0.0, hi)
    j0 = np.floor(safe_lo / (PI_LO / 2)) - 1.0
    half_lo, half_hi = PI_LO / 2, PI_HI / 2  # exact halvings of floats
    for step in range(7):
        j = j0 + step  # small integers: exact in float
        e1, e2 = j * half_lo, j * half_hi
        m_lo, m_hi = down(np.minimum(e1, e2)), up(np.maximum(e1, e2))
        meets = (safe_lo <= m_hi) & (safe_hi >= m_lo)
        r = np.mod(j, 4.0)  # j pi/2: 0 -> cos max, 1 -> sin max, 2 -> cos min, 3 -> sin min
        ch = np.where(meets & (r == 0.0), 1.0, ch)
        sh = np.where(meets & (r == 1.0), 1.0, sh)
        cl = np.where(meets & (r == 2.0), -1.0, cl)
        sl = np.where(meets & (r == 3.0), -1.0, sl)
    one = np.ones_like(lo)
    cl, sl = np.where(wide, -one, cl), np.where(wide, -one, sl)
    ch, sh = np.where(wide, one, ch), np.where(wide, one, sh)
    # cos and sin lie in [-1, 1]: clipping keeps the enclosure and removes the margin's overshoot
    return ((np.maximum(cl, -1.0), np.minimum(ch, 1.0)),
            (np.maximum(sl, -1.0), np.minimum(sh, 1.0)))


def fraction_enclosure(q: Fraction) -> tuple[float, float]:
    """Floats lo <= q <= hi (one ulp apart at most), decided by exact rational comparison.

    ``float(q)`` is the float nearest to q (Python divides integers with correct
    rounding); comparing it exactly with q says on which side the neighbour lies.
    """
    q = Fraction(q)
    f = float(q)
    if Fraction(f) == q:
        return f, f
    if Fraction(f) < q:
        return f, math.nextafter(f, math.inf)
    return math.nextafter(f, -math.inf), f
