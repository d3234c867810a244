"""The recheck's interval arithmetic encloses the exact values (Fractions, arb), and numpy's cos/sin fit the margin.

The arithmetic of :mod:`intervalkin.recheck.arith` is checked against exact
rational arithmetic on the float end points (``Fraction`` of a float is exact),
and cos/sin against arb at 128 bits.  These tests would fail if a bound were
rounded the wrong way, a product's sign case were missed, an extremum of cos or
sin inside an interval were overlooked, or numpy's cos/sin erred by more than
the 4 ulp the margin is built on (proofs/lemma-box-label-recheck.md).
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from flint import arb, ctx
from hypothesis import given, settings
from hypothesis import strategies as st

from intervalkin.recheck import arith
from intervalkin.recheck.arith import PI_HI, PI_LO, TRIG_MARGIN, add, cos_sin, fraction_enclosure, mul, sqr, sub

finite = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False, allow_infinity=False)


def _interval(draw_a: float, draw_b: float) -> tuple[np.ndarray, np.ndarray]:
    lo, hi = min(draw_a, draw_b), max(draw_a, draw_b)
    return np.array([lo]), np.array([hi])


def _contains(iv, exact) -> bool:
    return Fraction(float(iv[0][0])) <= exact <= Fraction(float(iv[1][0]))


@st.composite
def interval_and_point(draw, elements=finite):
    a, b = draw(elements), draw(elements)
    lo, hi = min(a, b), max(a, b)
    t = draw(st.floats(min_value=0.0, max_value=1.0))
    p = min(max(lo + (hi - lo) * t, lo), hi)
    return (np.array([lo]), np.array([hi])), p


@settings(max_examples=400, deadline=None)
@given(interval_and_point(), interval_and_point())
def test_add_sub_mul_sqr_enclose_the_exact_results(a, b):
    (ia, pa), (ib, pb) = a, b
    fa, fb = Fraction(pa), Fraction(pb)
    assert _contains(add(ia, ib), fa + fb)
    assert _contains(sub(ia, ib), fa - fb)
    assert _contains(mul(ia, ib), fa * fb)
    assert _contains(sqr(ia), fa * fa)
    assert sqr(ia)[0][0] >= 0.0


_EDGES = [0.0, -0.0, 5e-324, -5e-324, 2.0 ** -1022, -(2.0 ** -1022), 2.0 ** -970, 2.0 ** -971, 1.0, -1.0, 2.0 ** 52,
          math.nextafter(1.0, 0.0), math.nextafter(2.0, 3.0), -math.nextafter(4.0, 0.0), 1e300, -1e300, 3.0, 6.0]


@settings(max_examples=2000, deadline=None)
@given(st.one_of(st.sampled_from(_EDGES), st.floats(allow_nan=False, allow_infinity=False, width=64)))
def test_outward_steps_pass_the_next_float_and_stay_close(v):
    """down(v) is at or below the next float toward -inf and up(v) at or above the next toward +inf, for every
    finite v (zero, subnormals, powers of two, the gap floor and the largest magnitudes included); and they stay
    within a few ulps (a step that jumped far would make every enclosure useless)."""
    with np.errstate(over="ignore"):  # next to the largest float the step may overflow: an infinite bound
        lo, hi = float(arith.down(np.array([v]))[0]), float(arith.up(np.array([v]))[0])
    assert lo <= math.nextafter(v, -math.inf) and hi >= math.nextafter(v, math.inf)
    if abs(v) < 1e307:
        gap = max(math.ulp(v), 2.0 ** -1022)
        assert Fraction(v) - Fraction(lo) <= 3 * Fraction(gap) and Fraction(hi) - Fraction(v) <= 3 * Fraction(gap)


def test_products_of_exact_values_are_still_widened():
    """An exact product is widened by an ulp anyway (the rule is 'step every bound', not 'guess exactness')."""
    lo, hi = mul((np.array([3.0]), np.array([3.0])), (np.array([2.0]), np.array([2.0])))
    assert lo[0] < 6.0 < hi[0]


def test_pi_enclosure_in_arb():
    with ctx.workprec(256):
        pi = arb.pi()
        assert arb(PI_LO) < pi < arb(PI_HI)


@settings(max_examples=600, deadline=None)
@given(interval_and_point(st.floats(min_value=-20.0, max_value=20.0)))
def test_cos_sin_enclose_arb_at_points_of_the_interval(case):
    iv, p = case
    (cl, ch), (sl, sh) = cos_sin(iv)
    # arb at 200 bits: a violation of the enclosure (a bound rounded the wrong way is off by about
    # 1e-16) would be proved; cos of a tiny t is a ball straddling 1, which is why "not proved outside"
    # is asked rather than "proved inside"
    with ctx.workprec(200):
        c, s = arb(p).cos(), arb(p).sin()
        assert not (c < arb(float(cl[0]))) and not (c > arb(float(ch[0])))
        assert not (s < arb(float(sl[0]))) and not (s > arb(float(sh[0])))


@pytest.mark.parametrize("j", range(-12, 13))
def test_extrema_at_multiples_of_half_pi_are_found(j):
    """Intervals a few ulps wide around j pi/2 (the float nearest it): the extremum there must be reached."""
    m = j * math.pi / 2
    iv = (np.array([math.nextafter(m, -math.inf)]), np.array([math.nextafter(m, math.inf)]))
    (cl, ch), (sl, sh) = cos_sin(iv)
    r = j % 4
    assert {0: ch[0] == 1.0, 1: sh[0] == 1.0, 2: cl[0] == -1.0, 3: sl[0] == -1.0}[r]


def test_wide_and_far_intervals_give_the_whole_range():
    iv = (np.array([0.0, 100.0, -3.0]), np.array([6.5, 100.5, 3.1]))
    (cl, ch), (sl, sh) = cos_sin(iv)
    assert (cl[:2] == -1).all() and (ch[:2] == 1).all() and (sl[:2] == -1).all() and (sh[:2] == 1).all()
    assert cl[2] == -1.0 and ch[2] == 1.0  # [-3, 3.1] holds 0 and pi


def test_numpy_cos_sin_error_is_far_below_the_margin():
    """numpy's cos/sin against arb at a million points of [-8, 8], a fifth of them within 1e-6 of j pi/2.

    The margin assumes an error of at most 4 ulp of 1 (2^-50); the test asserts that
    bound, so a numpy build less accurate than documented fails here before the
    margin (64 times larger) could be in doubt.
    """
    rng = np.random.default_rng(14)
    t = rng.uniform(-8.0, 8.0, 800_000)
    near = rng.integers(-5, 6, 200_000) * (math.pi / 2) + rng.uniform(-1e-6, 1e-6, 200_000)
    t = np.concatenate([t, near])
    c, s = np.cos(t), np.sin(t)
    bound = arb(2.0 ** -50)
    with ctx.workprec(100):
        for k in range(len(t)):
            a = arb(float(t[k]))
            ec = abs(arb(float(c[k])) - a.cos())
            es = abs(arb(float(s[k])) - a.sin())
            assert ec < bound and es < bound, float(t[k])
    assert TRIG_MARGIN >= 2.0 ** -50 * 64


@given(st.fractions(max_denominator=10**12).filter(lambda q: abs(q) < 10**9))
def test_fraction_enclosure_is_exact_and_tight(q):
    lo, hi = fraction_enclosure(q)
    assert Fraction(lo) <= q <= Fraction(hi)
    assert hi == lo or math.nextafter(lo, math.inf) == hi


def test_margin_constants_are_the_documented_ones():
    assert arith.TRIG_MARGIN == 2.0 ** -44 and arith.TRIG_ARG_MAX == 64.0
