"""Inclusion property of every interval operation, checked against arb at 256 bits.

For operands drawn as intervals and points drawn inside them, the exact result
(arb, 256 bits, on the exact float endpoints) must lie in the interval result.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from flint import arb, ctx
from hypothesis import given, settings
from hypothesis import strategies as st

from intervalkin.core.interval import PI_HI, PI_LO, TRIG_ABS_ERROR, Interval, integer_combinations, sign_label
from intervalkin.core.exact import arb_to_bounds, fraction_bounds

finite = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False, allow_infinity=False)
unit = st.floats(min_value=0.0, max_value=1.0)


@st.composite
def interval_and_point(draw, lo=-1e6, hi=1e6):
    a = draw(st.floats(min_value=lo, max_value=hi))
    b = draw(st.floats(min_value=lo, max_value=hi))
    a, b = min(a, b), max(a, b)
    t = draw(unit)
    p = a + t * (b - a)
    p = min(max(p, a), b)
    return Interval.point(a).hull(Interval.point(b)), p


def _contains(iv: Interval, exact) -> bool:
    """The exact value (an arb ball of radius ~2^-256 around it) is not outside [lo, hi].

    A failure is reported only when the whole ball lies outside the interval,
    so the verdict is wrong only if an enclosure misses by less than 2^-200 (relative).
    """
    lo = arb(float(np.asarray(iv.lo)))
    hi = arb(float(np.asarray(iv.hi)))
    assert float(exact.rad()) <= 2.0**-200 * max(1.0, abs(float(exact.mid())))
    return not (exact < lo or exact > hi)


@pytest.fixture(autouse=True)
def _high_precision():
    old = ctx.prec
    ctx.prec = 256
    yield
    ctx.prec = old


@settings(max_examples=400, deadline=None)
@given(interval_and_point(), interval_and_point())
def test_add_sub_mul_contain_exact(a, b):
    (ia, pa), (ib, pb) = a, b
    xa, xb = arb(pa), arb(pb)
    assert _contains(ia + ib, xa + xb)
    assert _contains(ia - ib, xa - xb)
    assert _contains(ia * ib, xa * xb)


@settings(max_examples=400, deadline=None)
@given(interval_and_point(), interval_and_point())
def test_div_contains_exact(a, b):
    (ia, pa), (ib, pb) = a, b
    q = ia / ib
    if pb == 0.0:
        return  # the quotient is undefined at this point; nothing to enclose
    assert _contains(q, arb(pa) / arb(pb))


@settings(max_examples=400, deadline=None)
@given(interval_and_point())
def test_sqr_sqrt_contain_exact(a):
    ia, pa = a
    assert _contains(ia.sqr(), arb(pa) * arb(pa))
    if pa >= 0:
        assert _contains(ia.sqrt(), arb(pa).sqrt())


@settings(max_examples=2000, deadline=None)
@given(interval_and_point(-64.0, 64.0))
def test_cos_sin_contain_exact(a):
    ia, pa = a
    assert _contains(ia.cos(), arb(pa).cos())
    assert _contains(ia.sin(), arb(pa).sin())


def test_trig_error_bound():
    """numpy's cos/sin stay within TRIG_ABS_ERROR of arb on many arguments.

    Includes the floats next to multiples of pi/2 (where cos or sin is tiny and
    argument reduction matters) and uniform draws over [-64, 64].
    """
    rng = np.random.default_rng(7)
    k = np.arange(-40, 41) * (np.pi / 2)
    xs = np.concatenate(
        [
            rng.uniform(-64, 64, 6000),
            rng.uniform(-4, 4, 4000),
            k,
            np.nextafter(k, np.inf),
            np.nextafter(k, -np.inf),
            k + 1e-9,
        ]
    )
    worst = 0.0
    for x in xs:
        a = arb(float(x))
        for f, g in ((np.cos, a.cos()), (np.sin, a.sin())):
            err = abs(arb(float(f(x))) - g)
            worst = max(worst, float(err.upper()))
    assert worst <= TRIG_ABS_ERROR / 16, worst


def test_trig_extrema_found_with_pi_enclosure():
    """Intervals that straddle a multiple of pi/2 reach +-1 exactly where they should."""
    for n in range(-20, 21):
        c = n * np.pi / 2
        iv = Interval.from_bounds(c - 1e-12, c + 1e-12)
        cos, sin = iv.cos(), iv.sin()
        m = n % 4
        if m == 0:
            assert cos.hi == 1.0
        if m == 2:
            assert cos.lo == -1.0
        if m == 1:
            assert sin.hi == 1.0
        if m == 3:
            assert sin.lo == -1.0
    wide = Interval.from_bounds(-10.0, 10.0)
    assert (wide.cos().lo, wide.cos().hi) == (-1.0, 1.0)


def test_trig_narrow_interval_is_tight():
    iv = Interval.from_bounds(0.3, 0.3 + 1e-10)
    c = iv.cos()
    assert c.hi - c.lo < 1e-9


def test_pi_enclosure():
    p = arb.pi()
    assert arb(PI_LO) < p < arb(PI_HI)


def test_fraction_and_arb_bounds():
    for q in (Fraction(1591, 100), Fraction(-1, 3), Fraction(10), Fraction(208982941167, 806560000)):
        lo, hi = fraction_bounds(q)
        assert Fraction(lo) <= q <= Fraction(hi)
        assert hi == lo or np.nextafter(lo, np.inf) == hi
    x = arb(2).sqrt()
    lo, hi = arb_to_bounds(x)
    assert arb(lo) < x < arb(hi)


def test_vectorized_shapes_and_sign_label():
    a = Interval.from_bounds([-2.0, 1.0, -1.0], [-1.0, 2.0, 1.0])
    assert list(sign_label(a)) == [-1, 1, 0]
    assert (a * a).shape == (3,)


def test_sign_label_reads_an_empty_interval_as_its_lower_end_and_keeps_0_d_arrays():
    """lo > 0 wins where hi < 0 holds too (an empty [lo, hi] reads +1), NaN reads 0, and a 0-d input stays an
    array: what callers relied on before the label was computed from the booleans' bytes."""
    got = sign_label(Interval.from_bounds([3.0, -3.0, np.nan, 0.0], [-1.0, -1.0, np.nan, 0.0]))
    assert got.dtype == np.int8 and got.tolist() == [1, -1, 0, 0]
    zero_d = sign_label(Interval(1.0, 2.0))
    assert isinstance(zero_d, np.ndarray) and zero_d.shape == () and int(zero_d) == 1
    assert sign_label(Interval(np.zeros((2, 1)) - 1.0, -np.ones((1, 3)))).shape == (2, 3)


#: Magnitudes from tiny to past 2**1000, where integer_combinations checks its ends for overflow.
_SPREAD = st.floats(min_value=-1e305, max_value=1e305, allow_nan=False, allow_infinity=False)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(_SPREAD, _SPREAD, unit), min_size=3, max_size=3),
       st.lists(st.lists(st.integers(-2, 2), min_size=3, max_size=3), min_size=1, max_size=6))
def test_integer_combinations_contain_the_exact_sums(ends, rows):
    lo = np.array([[min(a, b) for a, b, _ in ends]])
    hi = np.array([[max(a, b) for a, b, _ in ends]])
    x = [min(max(l + t * (h - l), l), h) for l, h, t in zip(lo[0], hi[0], (t for _, _, t in ends))]
    e = np.array(rows)
    got = integer_combinations(lo, hi, e)
    for j, row in enumerate(rows):
        exact = sum(Fraction(int(c)) * Fraction(float(v)) for c, v in zip(row, x))
        assert (got.lo[0, j] == -np.inf or Fraction(float(got.lo[0, j])) <= exact)
        assert (got.hi[0, j] == np.inf or exact <= Fraction(float(got.hi[0, j])))


def test_integer_combinations_of_unbounded_or_nan_ends_are_the_whole_line():
    lo = np.array([[-np.inf, 0.0, 1.0], [np.nan, 0.0, 1.0], [0.0, 0.0, 1.0]])
    hi = np.array([[1.0, 0.0, 1.0], [1.0, 0.0, 1.0], [1.0, 0.0, 1.0]])
    got = integer_combinations(lo, hi, np.array([[1, 0, 0], [0, 0, 2]]))
    assert got.lo[:2, 0].tolist() == [-np.inf, -np.inf] and got.hi[:2, 0].tolist() == [np.inf, np.inf]
    # a row whose unbounded column has weight 0 is unbounded too (0 * inf is NaN, not 0): never a finite guess
    assert got.lo[:2, 1].tolist() == [-np.inf, -np.inf]
    assert np.isfinite(got.lo[2]).all() and got.lo[2, 1] <= 2.0 <= got.hi[2, 1]


def test_intersect_of_disjoint_enclosures_is_refused():
    with pytest.raises(AssertionError):
        Interval.from_bounds(0.0, 1.0).intersect(Interval.from_bounds(2.0, 3.0))


def test_round_to_nearest_would_fail():
    """The suite can catch a missing outward rounding: 0.1 + 0.2 in floats is not an enclosure.

    The operands are the floats 0.1 and 0.2 themselves (exact reals, not widened decimals),
    so Interval.__add__ without outward rounding returns [fl(0.1 + 0.2)] and fails here.
    """
    exact = arb(0.1) + arb(0.2)  # floats are exact in arb; the sum is exact at 256 bits
    s = Interval.point(0.1) + Interval.point(0.2)
    assert _contains(s, exact)
    naive = Interval.point(0.1 + 0.2)
    assert not _contains(naive, exact)


def test_product_rounding_would_fail():
    """Same for a product: fl(0.1 * 3) lies above the exact product of the floats 0.1 and 3."""
    exact = arb(0.1) * 3
    assert _contains(Interval.point(0.1) * 3.0, exact)
    assert not _contains(Interval.point(0.1 * 3.0), exact)
