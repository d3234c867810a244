"""Vectorized interval arithmetic over numpy, rounded outward: the array half of the rounding layer.

An :class:`Interval` holds two float64 arrays ``lo`` and ``hi`` of one
(broadcastable) shape: entry k stands for the real interval [lo[k], hi[k]].  Every
operation returns an enclosure of the exact range of the operation over its
operands (the inclusion property), rounding errors included:

* ``+ - * /`` and ``sqrt`` are correctly rounded in IEEE 754 (round to nearest),
  so the exact result lies within half an ulp of the float result; moving the
  float result one ulp outward (:func:`round_down`, :func:`round_up`:
  ``np.nextafter`` toward -inf / +inf) encloses it.
* ``cos`` and ``sin`` of numpy are not correctly rounded.  We rely on the bound
  ``|fl(cos t) - cos t| <= TRIG_ABS_ERROR`` (and the same for sin) for
  ``|t| <= TRIG_MAX_ARG``, a bound over 60 times the worst case observed (5.6e-17,
  a quarter of an ulp of 1) and checked against arb on many thousands of arguments by
  ``tests/core/test_interval.py::test_trig_error_bound`` (proofs/lemma-trig-enclosure.md).
  Whether an interval holds an extremum of cos or sin is decided with an
  enclosure [PI_LO, PI_HI] of pi, conservatively (a possible extremum is included).
  Outside [-TRIG_MAX_ARG, TRIG_MAX_ARG], or over a width of 2 pi or more, the
  answer is [-1, 1].
* Exact numbers (Fractions, arb balls) enter through
  :func:`intervalkin.core.exact.fraction_bounds` and
  :func:`~intervalkin.core.exact.arb_to_bounds` (the scalar half of the rounding
  layer, free of numpy), or :meth:`Interval.from_exact` for arrays of them.

These two modules are the only places in the package that move a float by an ulp
(proofs/lemma-outward-rounding.md); ``tests/core/test_interval_rounding.py`` switches
:func:`round_down` and :func:`round_up` off and checks that the suite's soundness
checks then fail.

Interval comparisons never return a bare bool meaning "true": use
:func:`certainly_positive` and friends, where False means "not proved".
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Iterable, Union

import numpy as np

from intervalkin.core.exact import fraction_bounds

__all__ = ['PI_LO', 'PI_HI', 'TRIG_ABS_ERROR', 'TRIG_MAX_ARG', 'round_down', 'round_up', 'Interval', 'certainly_positive', 'certainly_negative', 'sign_label', 'integer_combinations']

_NEG_INF = -np.inf
_POS_INF = np.inf

#: float64 enclosure of pi: PI_LO < pi < PI_HI (math.pi is the float just below pi).
PI_LO = 3.141592653589793
PI_HI = float(np.nextafter(PI_LO, np.inf))
#: Absolute error bound of numpy's float64 cos and sin on [-TRIG_MAX_ARG, TRIG_MAX_ARG].
TRIG_ABS_ERROR = 2.0**-48
TRIG_MAX_ARG = 64.0


#: round_down / round_up move a float by |x| 2**-52 + 2**-1021: at least one ulp of x (2**-52 |x|
#: bounds the ulp of a normal x, 2**-1021 the ulp of any x below the normal range), computed
#: with normal numbers only (subnormal arithmetic is slow on common hardware).
_ULP_REL = 2.0**-52
_ULP_ABS = 2.0**-1021
_MAX = float(np.finfo(np.float64).max)


def _ulp_bound(x: np.ndarray) -> np.ndarray:
    a = np.abs(x)
    a *= _ULP_REL
    a += _ULP_ABS
    return a


def round_down(x: np.ndarray) -> np.ndarray:
    """A float at least one ulp below x: a lower bound of any real within one ulp of x.

    x - (|x| 2**-52 + 2**-1021), rounded to nearest: the exact difference is at most
    x - ulp(x), a float, so rounding cannot carry it above that (proofs/lemma-outward-rounding.md).
    About ten times faster than ``np.nextafter``; +inf maps to the largest float, as nextafter does.
    """
    x = np.asarray(x, dtype=np.float64)
    t = _ulp_bound(x)
    if x.ndim and x.size and x.max() < _POS_INF:  # no +inf and no NaN (max is NaN then): no fix-up
        return np.subtract(x, t, out=t)
    with np.errstate(invalid="ignore"):  # inf - inf, replaced below
        r = np.subtract(x, t)
    if r.ndim:
        np.copyto(r, _MAX, where=x == _POS_INF)
    elif x == _POS_INF:
        r = np.float64(_MAX)
    return r


def round_up(x: np.ndarray) -> np.ndarray:
    """A float at least one ulp above x: an upper bound of any real within one ulp of x."""
    x = np.asarray(x, dtype=np.float64)
    t = _ulp_bound(x)
    if x.ndim and x.size and x.min() > _NEG_INF:  # no -inf and no NaN: no fix-up
        return np.add(x, t, out=t)
    with np.errstate(invalid="ignore"):  # -inf + inf, replaced below
        r = np.add(x, t)
    if r.ndim:
        np.copyto(r, -_MAX, where=x == _NEG_INF)
    elif x == _NEG_INF:
        r = np.float64(-_MAX)
    return r


Operand = Union["Interval", float, int, np.ndarray]


_POINT_TYPES = (float, int, np.ndarray, np.floating, np.integer)


def _as_interval(v: Operand) -> "Interval | None":
    """v as an Interval, None for other types (the caller returns NotImplemented).

    A float is the exact number it represents (a point).  An integer above 2**53 in
    magnitude may round when converted to float (to nearest), so it gets one ulp on
    each side.
    """
    if isinstance(v, Interval):
        return v
    if not isinstance(v, _POINT_TYPES):
        return None
    a = np.asarray(v, dtype=np.float64)
    if isinstance(v, (int, np.integer)) or (isinstance(v, np.ndarray) and v.dtype.kind in "iuO"):
        big = np.abs(a) > 2.0**53
        if np.any(big):
            return Interval(np.where(big, round_down(a), a), np.where(big, round_up(a), a))
    return Interval(a, a)


@dataclass(frozen=True, eq=False)
class Interval:
    """An array of closed intervals [lo, hi] (float64, broadcastable shapes)."""

    lo: np.ndarray
    hi: np.ndarray

    #: numpy defers to the reflected operators (``2.0 * iv``, ``array - iv``) instead of
    #: building object arrays of Intervals.
    __array_ufunc__ = None
    #: Not iterable: ``for v in iv`` would walk the first axis, never what a caller of a
    #: per-leg function meant; index explicitly (``iv[:, i]``).
    __iter__ = None

    # --- construction -----------------------------------------------------------------
    @staticmethod
    def point(x: np.ndarray | float) -> "Interval":
        """Degenerate intervals [x, x] for floats x (exact: floats are exact reals)."""
        a = np.asarray(x, dtype=np.float64)
        return Interval(a, a)

    @staticmethod
    def from_bounds(lo, hi) -> "Interval":
        return Interval(np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64))

    @staticmethod
    def from_exact(values: Iterable[Fraction]) -> "Interval":
        """Enclosures of exact rationals, one ulp wide at most (1-D, one entry per value).

        >>> from fractions import Fraction
        >>> Interval.from_exact([Fraction(1, 2)]).lo.tolist()
        [0.5]
        """
        b = [fraction_bounds(Fraction(v)) for v in values]
        return Interval(np.array([lo for lo, _ in b]), np.array([hi for _, hi in b]))

    # --- views ------------------------------------------------------------------------
    @property
    def shape(self) -> tuple[int, ...]:
        return np.broadcast_shapes(np.shape(self.lo), np.shape(self.hi))

    def mid(self) -> np.ndarray:
        """A float inside each interval (not necessarily the exact midpoint)."""
        m = 0.5 * self.lo + 0.5 * self.hi
        return np.minimum(np.maximum(m, self.lo), self.hi)

    def width(self) -> np.ndarray:
        """Upper bound of hi - lo."""
        return round_up(self.hi - self.lo)

    def __getitem__(self, idx) -> "Interval":
        lo, hi = np.broadcast_arrays(self.lo, self.hi)
        return Interval(lo[idx], hi[idx])

    def contains_point(self, x) -> np.ndarray:
        return (self.lo <= x) & (x <= self.hi)

    def intersect(self, other: "Interval") -> "Interval":
        """Intersection of two enclosures of the same quantity (keeps the sharper bound).

        Both operands must enclose the same real set, so the intersection is never
        empty for sound inputs; an empty result signals unsoundness and is asserted.
        """
        lo = np.maximum(self.lo, other.lo)
        hi = np.minimum(self.hi, other.hi)
        assert not np.any(lo > hi), "intersection of two enclosures of one quantity is empty: unsound evaluation"
        return Interval(lo, hi)

    def hull(self, other: "Interval") -> "Interval":
        return Interval(np.minimum(self.lo, other.lo), np.maximum(self.hi, other.hi))

    # --- arithmetic ---------------------------------------------------------------------
    def __neg__(self) -> "Interval":
        return Interval(-self.hi, -self.lo)

    def __add__(self, other: Operand) -> "Interval":
        o = _as_interval(other)
        if o is None:
            return NotImplemented
        return Interval(round_down(self.lo + o.lo), round_up(self.hi + o.hi))

    __radd__ = __add__

    def __sub__(self, other: Operand) -> "Interval":
        o = _as_interval(other)
        if o is None:
            return NotImplemented
        return Interval(round_down(self.lo - o.hi), round_up(self.hi - o.lo))

    def __rsub__(self, other: Operand) -> "Interval":
        o = _as_interval(other)
        return NotImplemented if o is None else o - self

    def __mul__(self, other: Operand) -> "Interval":
        o = _as_interval(other)
        if o is None:
            return NotImplemented
        p1 = self.lo * o.lo
        p3 = self.hi * o.lo
        if o.lo is o.hi:  # a point (a float operand): p2 = p1 and p4 = p3, so the same min and max
            return Interval(round_down(np.minimum(p1, p3)), round_up(np.maximum(p1, p3)))
        p2 = self.lo * o.hi
        p4 = self.hi * o.hi
        if type(p1) is np.ndarray and p1.shape == p2.shape == p3.shape == p4.shape:
            # the same min(min(p1, p2), min(p3, p4)) and max, with the products as scratch (fewer temporaries)
            lo = np.minimum(p1, p2)
            hi = np.maximum(p1, p2, out=p1)
            np.minimum(lo, np.minimum(p3, p4, out=p2), out=lo)
            np.maximum(hi, np.maximum(p3, p4, out=p3), out=hi)
        else:
            lo = np.minimum(np.minimum(p1, p2), np.minimum(p3, p4))
            hi = np.maximum(np.maximum(p1, p2), np.maximum(p3, p4))
        return Interval(round_down(lo), round_up(hi))

    __rmul__ = __mul__

    def __truediv__(self, other: Operand) -> "Interval":
        o = _as_interval(other)
        if o is None:
            return NotImplemented
        zero_in = (o.lo <= 0) & (o.hi >= 0)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # inf bounds are still sound
            q1 = self.lo / o.lo
            q2 = self.lo / o.hi
            q3 = self.hi / o.lo
            q4 = self.hi / o.hi
        lo = np.minimum(np.minimum(q1, q2), np.minimum(q3, q4))
        hi = np.maximum(np.maximum(q1, q2), np.maximum(q3, q4))
        lo = np.where(zero_in, _NEG_INF, round_down(lo))
        hi = np.where(zero_in, _POS_INF, round_up(hi))
        return Interval(lo, hi)

    def __rtruediv__(self, other: Operand) -> "Interval":
        o = _as_interval(other)
        return NotImplemented if o is None else o / self

    def sqr(self) -> "Interval":
        """x^2 over the interval (tighter than x * x: one occurrence of x)."""
        a = self.lo * self.lo
        b = self.hi * self.hi
        hi = round_up(np.maximum(a, b))
        lo = np.where(self.lo >= 0, a, np.where(self.hi <= 0, b, 0.0))
        lo = np.maximum(round_down(lo), 0.0)
        return Interval(lo, hi)

    def sqrt(self) -> "Interval":
        """sqrt over the part of the interval where it is defined (x >= 0)."""
        lo = np.maximum(round_down(np.sqrt(np.maximum(self.lo, 0.0))), 0.0)
        hi = round_up(np.sqrt(np.maximum(self.hi, 0.0)))
        return Interval(lo, hi)

    def cos(self) -> "Interval":
        """cos over the interval; extrema located with the enclosure of pi."""
        return _trig(self, np.cos, max_at=0, min_at=2)

    def sin(self) -> "Interval":
        """sin over the interval; extrema located with the enclosure of pi."""
        return _trig(self, np.sin, max_at=1, min_at=3)


#: Margin of the screen of :func:`_may_contain_multiple`, in turns (units of 2 pi): far above the
#: float error of the screen (below 1e-14 turns for |t| <= TRIG_MAX_ARG) and of the enclosures of n pi / 2.
_SCREEN = 1e-6
_INV_TWO_PI = 0.5 / PI_LO


def _may_contain_multiple(lo: np.ndarray, hi: np.ndarray, j: int) -> np.ndarray:
    """True where [lo, hi] may contain a point (4k + j) * pi / 2 for an integer k.

    The enclosure [n * PI_LO / 2, n * PI_HI / 2] (rounded outward) of n * pi / 2 is
    tested against [lo, hi] for the three candidate k around hi; the interval is
    shorter than 2 pi when this is called, so no other k can fall inside.

    Most intervals are far from every such point, so a float screen runs first: in
    turns from j pi / 2, an interval whose ends widened by ``_SCREEN`` hold no integer
    is more than 6e-6 from every candidate, where the enclosures (a few ulps wide)
    cannot reach it; only the rest get the outward-rounded test, so the answer is
    the same as testing every entry.
    """
    lo_f, hi_f = np.ravel(lo), np.ravel(hi)
    with np.errstate(invalid="ignore", over="ignore"):  # inf and NaN ends fall to the rounded test
        s = lo_f - j * (PI_LO / 2)
        s *= _INV_TWO_PI
        s -= _SCREEN
        e = hi_f - j * (PI_LO / 2)
        e *= _INV_TWO_PI
        e += _SCREEN
        near = ~(np.floor(e, out=e) < np.ceil(s, out=s))
    hit = np.zeros(lo_f.shape, dtype=bool)
    at = np.flatnonzero(near)
    if at.size:
        hit[at] = _rounded_test(lo_f[at], hi_f[at], j)
    return hit.reshape(np.shape(lo))


def _rounded_test(lo: np.ndarray, hi: np.ndarray, j: int) -> np.ndarray:
    """The outward-rounded test of :func:`_may_contain_multiple` for the three candidates around hi."""
    k0 = np.floor((hi - j * PI_LO / 2) / (2 * PI_LO))
    hit = np.zeros(np.shape(lo), dtype=bool)
    for dk in (-1.0, 0.0, 1.0):
        n = 4.0 * (k0 + dk) + j
        a = n * (PI_LO / 2)
        b = n * (PI_HI / 2)
        elo = round_down(np.minimum(a, b))
        ehi = round_up(np.maximum(a, b))
        hit |= (elo <= hi) & (ehi >= lo)
    return hit


def _trig(x: Interval, f, max_at: int, min_at: int) -> Interval:
    lo, hi = np.broadcast_arrays(x.lo, x.hi)
    flo = f(lo)
    fhi = f(hi)
    rlo = np.minimum(flo, fhi) - TRIG_ABS_ERROR
    rhi = np.maximum(flo, fhi) + TRIG_ABS_ERROR
    rlo = np.where(_may_contain_multiple(lo, hi, min_at), -1.0, rlo)
    rhi = np.where(_may_contain_multiple(lo, hi, max_at), 1.0, rhi)
    wide = ~((hi - lo) < 2 * PI_LO) | ~(np.abs(lo) <= TRIG_MAX_ARG) | ~(np.abs(hi) <= TRIG_MAX_ARG)
    rlo = np.where(wide, -1.0, np.maximum(round_down(rlo), -1.0))
    rhi = np.where(wide, 1.0, np.minimum(round_up(rhi), 1.0))
    return Interval(rlo, rhi)


# --- sign predicates -------------------------------------------------------------------------
def certainly_positive(x: Interval) -> np.ndarray:
    """True where every point of the interval is > 0; False means "not proved"."""
    return x.lo > 0


def certainly_negative(x: Interval) -> np.ndarray:
    """True where every point of the interval is < 0; False means "not proved"."""
    return x.hi < 0


def sign_label(x: Interval) -> np.ndarray:
    """int8 array: 1 certainly positive, -1 certainly negative, 0 undecided."""
    # booleans read as 0/1 bytes: a subtraction instead of two nested selections (several times faster); lo > 0
    # wins where both hold, as it always did (an empty [lo, hi], e.g. a root range cut to nothing, reads +1)
    pos = np.asarray(x.lo > 0)
    neg = np.asarray(x.hi < 0) > pos
    return np.asarray(np.subtract(pos.view(np.int8), neg.view(np.int8)))  # 0-d stays an array, as before


def integer_combinations(lo: np.ndarray, hi: np.ndarray, e: np.ndarray) -> Interval:
    """(m, c): enclosures of sum_l e_l x_l for x_l in [lo_l, hi_l] (m, k <= 3) and integer rows e (c, k) with
    entries in -2..2, by two matrix products per end: a float sum of at most six exact products errs by at most
    5 u times the sum of their magnitudes, and the margin taken is 2**-50 = 8 u times it
    (proofs/lemma-line-misses-circle.md, Enclosures)."""
    pos, neg = np.maximum(e, 0).T.astype(np.float64), np.minimum(e, 0).T.astype(np.float64)
    magnitude = np.maximum(np.abs(lo), np.abs(hi))
    # the same floats as c_lo = lo @ pos + hi @ neg - margin (and c_hi), computed in place: the (m, c) arrays are
    # the cost, the (m, k) inputs are small
    with np.errstate(invalid="ignore"):
        margin = magnitude @ np.abs(e).T.astype(np.float64)
        margin *= 2.0**-50
        margin += 2.0**-1000
        c_lo = lo @ pos
        c_lo += hi @ neg
        c_lo -= margin
        c_hi = hi @ pos
        c_hi += lo @ neg
        c_hi += margin
    # inputs below 2**1000 in magnitude (no inf, no NaN: NaN fails the comparison) give sums of at most six terms
    # of at most 2**1001, so finite ends: the check on the small inputs spares two passes over the large outputs
    if magnitude.size and not magnitude.max() < 2.0**1000:
        bad = ~(np.isfinite(c_lo) & np.isfinite(c_hi))
        c_lo[bad], c_hi[bad] = -np.inf, np.inf
    return Interval(c_lo, c_hi)
