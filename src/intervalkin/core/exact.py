"""Exact numbers to float bounds (the scalar half of the rounding layer) and to text, standard library only.

The geometry is data read as exact decimals (:class:`fractions.Fraction`, square
roots of rationals) and the trusted arithmetic is arb; float64 intervals enter the
vectorized code through the two functions here.  Both return a pair of floats
(lo, hi) with lo <= v <= hi for the exact value v:

* :func:`fraction_bounds`: ``float(q)`` is the float nearest to q (Python rounds
  int / int correctly), so q lies between it and its neighbour on the side the
  exact comparison ``Fraction(float(q))`` vs q says; when q is a float the pair
  is degenerate.  The result is as tight as float64 allows (at most one ulp wide).
* :func:`arb_to_bounds`: the end points of an arb ball are exact binary numbers;
  their conversion to float is within one ulp, so one ulp further out (one
  ``math.nextafter`` step) is an enclosure.  A non-finite ball gives (-inf, inf).

:func:`exact_text` writes a rational exactly, as a decimal when it has one ("14.98"),
else as "p/q": the form of the certificates and of the limits named in messages.

This module imports neither numpy nor flint (an arb ball is only asked for its
end points), so the geometry parser and the independent checker can use it.  The
array half of the rounding layer is :mod:`intervalkin.core.interval`; nothing
else in the package moves a float by an ulp (proofs/lemma-outward-rounding.md).
"""

from __future__ import annotations

import math
from fractions import Fraction

__all__ = ['fraction_bounds', 'arb_to_bounds', 'exact_text']


def fraction_bounds(q: Fraction) -> tuple[float, float]:
    """Floats lo <= q <= hi, one ulp apart at most (equal when q is a float).

    Examples
    --------
    >>> fraction_bounds(Fraction(1, 2))
    (0.5, 0.5)
    >>> lo, hi = fraction_bounds(Fraction(1, 10))
    >>> Fraction(lo) < Fraction(1, 10) < Fraction(hi), math.nextafter(lo, math.inf) == hi
    (True, True)
    """
    q = Fraction(q)
    f = float(q)  # correctly rounded to nearest
    fq = Fraction(f)
    if fq == q:
        return f, f
    if fq < q:
        return f, math.nextafter(f, math.inf)
    return math.nextafter(f, -math.inf), f


def arb_to_bounds(x) -> tuple[float, float]:
    """Floats lo <= every point of the arb ball x <= hi.

    ``x.lower()`` and ``x.upper()`` are exact; their conversion to float is
    within one ulp, so one more ulp outward is an enclosure.
    """
    if not x.is_finite():
        return -math.inf, math.inf
    lo = math.nextafter(float(x.lower()), -math.inf)
    hi = math.nextafter(float(x.upper()), math.inf)
    return lo, hi


def exact_text(q: Fraction) -> str:
    """The exact decimal "14.98" when the denominator divides a power of ten, else "p/q".

    Examples
    --------
    >>> exact_text(Fraction("14.980")), exact_text(Fraction(-1, 20)), exact_text(Fraction(32)), exact_text(Fraction(1, 3))
    ('14.98', '-0.05', '32', '1/3')
    """
    q = Fraction(q)
    d, twos, fives = q.denominator, 0, 0
    while d % 2 == 0:
        d, twos = d // 2, twos + 1
    while d % 5 == 0:
        d, fives = d // 5, fives + 1
    if d != 1:
        return f"{q.numerator}/{q.denominator}"
    digits = max(twos, fives)
    if digits == 0:
        return str(q.numerator)
    scaled = abs(q.numerator) * 10**digits // q.denominator
    sign = "-" if q < 0 else ""
    return f"{sign}{scaled // 10**digits}.{scaled % 10**digits:0{digits}d}"
