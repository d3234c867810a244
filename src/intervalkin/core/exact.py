"""Vectorized interval arithmetic over numpy, rounded outward, and the bridge to arb.

An :class:`Interval` holds two float64 arrays ``lo`` and ``hi`` of one shape: the
k-th entry encloses the real interval [lo[k], hi[k]].  Every operation returns an
enclosure of the exact range of the operation over its operands (the inclusion
property), with rounding errors accounted for:

* ``+ - * /`` and ``sqrt`` are correctly rounded in IEEE 754 (round to nearest),
  so the exact result lies within half an ulp of the float result; moving the
  float result one ulp outward (``np.nextafter`` toward -inf / +inf) encloses it.
  This module is the only place that rounds (proofs/lemma-outward-rounding.md).
* ``cos`` and ``sin`` of numpy are not correctly rounded.  We rely on the bound
  ``|fl(cos t) - cos t| <= TRIG_ABS_ERROR`` (and the same for sin) for
  ``|t| <= TRIG_MAX_ARG``, a bound over 60 times the worst case observed (5.6e-17, a quarter of an ulp of 1)
  and checked against arb on many thousands of arguments by
  ``tests/test_interval.py::test_trig_error_bound`` (proofs/lemma-trig-enclosure.md).
  Whether an interval holds an extremum of cos or sin is decided with an
  enclosure [PI_LO, PI_HI] of pi, conservatively (a possible extremum is included).

Interval comparisons never return a bare bool meaning "true": use
:func:`certainly_positive` and friends, where False means "not proved".
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

__all__ = ['fraction_bounds', 'arb_to_bounds']


# --- exact numbers and arb ---------------------------------------------------------------
def fraction_bounds(q: Fraction) -> tuple[float, float]:
    """Floats lo <= q <= hi, as tight as float64 allows."""
    f = float(q)  # correctly rounded
    fq = Fraction(f)
    if fq == q:
        return f, f
    if fq < q:
        return f, float(np.nextafter(f, np.inf))
    return float(np.nextafter(f, -np.inf)), f


def arb_to_bounds(x) -> tuple[float, float]:
    """Floats lo <= every point of the arb ball x <= hi.

    ``x.lower()`` and ``x.upper()`` are exact; their conversion to float is within
    one ulp, so one more ulp outward is an enclosure.
    """
    if not x.is_finite():
        return -np.inf, np.inf
    lo = float(np.nextafter(float(x.lower()), -np.inf))
    hi = float(np.nextafter(float(x.upper()), np.inf))
    return lo, hi
