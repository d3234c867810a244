"""The rounding layer: every correctly rounded operation of Interval is rounded outward, and the
checks here can tell when it is not.

:func:`enclosure_violations` compares interval results with the exact results of the same
operation on the exact float end points (rationals, :class:`fractions.Fraction`; for sqrt,
squares of the bounds).  The operands include ones where round-to-nearest lands strictly
inside the exact range (1 + 2**-54 rounds to 1, below the exact sum; 1 - 2**-55 rounds to 1,
above it), so the mutation test, which switches :func:`round_down` and :func:`round_up` off,
must see the checks fail.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import intervalkin.core.interval as interval_module
from intervalkin.core.interval import Interval

OPERATIONS = ("add", "sub", "mul", "div", "sqr", "sqrt")


def _apply(op: str, a: Interval, b: Interval) -> Interval:
    return {"add": lambda: a + b, "sub": lambda: a - b, "mul": lambda: a * b, "div": lambda: a / b,
            "sqr": lambda: a.sqr(), "sqrt": lambda: a.sqrt()}[op]()


def _exact_range(op: str, a: tuple[Fraction, Fraction], b: tuple[Fraction, Fraction]):
    """(lo, hi) of the exact range over the operands, or None where it is not a bounded rational range."""
    if op == "sqrt":
        return None  # checked through squares, see enclosure_violations
    if op == "sqr":
        lo = Fraction(0) if a[0] <= 0 <= a[1] else min(a[0] ** 2, a[1] ** 2)
        return lo, max(a[0] ** 2, a[1] ** 2)
    if op == "div" and b[0] <= 0 <= b[1]:
        return None  # unbounded
    f = {"add": lambda u, v: u + v, "sub": lambda u, v: u - v, "mul": lambda u, v: u * v,
         "div": lambda u, v: u / v}[op]
    vals = [f(u, v) for u in a for v in b]  # extremes of these operations sit at end points
    return min(vals), max(vals)


def enclosure_violations(op: str, a: Interval, b: Interval) -> list[int]:
    """Indices k where ``op`` of the k-th operands is NOT enclosed by the interval result (exact check)."""
    res = _apply(op, a, b)
    bad = []
    for k in range(np.size(a.lo)):
        ea = (Fraction(float(a.lo[k])), Fraction(float(a.hi[k])))
        eb = (Fraction(float(b.lo[k])), Fraction(float(b.hi[k])))
        lo, hi = float(res.lo[k]), float(res.hi[k])
        if not (np.isfinite(lo) or lo == -np.inf) or not (np.isfinite(hi) or hi == np.inf):
            bad.append(k)  # nan
            continue
        if op == "sqrt":
            if ea[1] < 0:
                continue
            x_lo, x_hi = max(ea[0], Fraction(0)), ea[1]
            ok = (lo <= 0 or Fraction(lo) ** 2 <= x_lo) and (hi == np.inf or (hi >= 0 and Fraction(hi) ** 2 >= x_hi))
        else:
            r = _exact_range(op, ea, eb)
            if r is None:
                continue
            ok = (lo == -np.inf or Fraction(lo) <= r[0]) and (hi == np.inf or Fraction(hi) >= r[1])
        if not ok:
            bad.append(k)
    return bad


def _tie_cases() -> tuple[Interval, Interval]:
    """Point operands whose float results round to nearest strictly inside the exact range.

    Each pair (a, b) makes at least one operation round below or above its exact result:
    1 + 2**-54 -> 1 (below), 1 - 2**-55 -> 1 (above), (1 + 2**-52)**2 = 1 + 2**-51 + 2**-104
    -> 1 + 2**-51 (below), 1 / 3 (inexact), 2 (sqrt inexact) and products of odd mantissas.
    """
    pairs = [
        (1.0, 2.0**-54), (1.0, -(2.0**-55)), (1.0 + 2.0**-52, 1.0 + 2.0**-52), (1.0, 3.0), (2.0, 3.0),
        (0.1, 0.2), (3.0, 0.1), (-0.7, 0.3), (1e16 + 2.0, 1.0), (7.0, 1e-17),
    ]
    a = np.array([p[0] for p in pairs])
    b = np.array([p[1] for p in pairs])
    return Interval.point(a), Interval.point(b)


def _random_cases(seed: int, n: int = 400) -> tuple[Interval, Interval]:
    """Seeded operand intervals over many magnitudes (no zero divisors in most of them)."""
    rng = np.random.default_rng(seed)
    scale = 10.0 ** rng.integers(-30, 30, size=(4, n))
    v = rng.uniform(-1, 1, (4, n)) * scale
    a = Interval(np.minimum(v[0], v[1]), np.maximum(v[0], v[1]))
    b = Interval(np.minimum(v[2], v[3]), np.maximum(v[2], v[3]))
    return a, b


@pytest.mark.parametrize("op", OPERATIONS)
def test_tie_cases_are_enclosed(op):
    a, b = _tie_cases()
    assert enclosure_violations(op, a, b) == []


@pytest.mark.parametrize("op", OPERATIONS)
def test_random_operands_are_enclosed(op):
    a, b = _random_cases(17)
    assert enclosure_violations(op, a, b) == []


magnitude = st.floats(min_value=-1e100, max_value=1e100, allow_nan=False, allow_infinity=False)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(magnitude, magnitude, magnitude, magnitude), min_size=1, max_size=20),
       st.sampled_from(OPERATIONS))
def test_drawn_operands_are_enclosed(rows, op):
    v = np.array(rows, dtype=np.float64).T
    a = Interval(np.minimum(v[0], v[1]), np.maximum(v[0], v[1]))
    b = Interval(np.minimum(v[2], v[3]), np.maximum(v[2], v[3]))
    assert enclosure_violations(op, a, b) == []


def test_checks_fail_when_rounding_is_switched_off(monkeypatch):
    """Mutation check: without outward rounding every correctly rounded operation is caught."""
    monkeypatch.setattr(interval_module, "round_down", lambda x: x)
    monkeypatch.setattr(interval_module, "round_up", lambda x: x)
    ta, tb = _tie_cases()
    ra, rb = _random_cases(17)
    for op in OPERATIONS:
        found = enclosure_violations(op, ta, tb) + enclosure_violations(op, ra, rb)
        assert found, f"{op}: switching the rounding off went unnoticed"
    # and the simplest case of all, spelled out
    s = Interval.point(0.1) + Interval.point(0.2)
    assert Fraction(float(s.lo)) > Fraction(0.1) + Fraction(0.2)


def test_integer_operands_that_round_are_widened():
    """An int beyond 2**53 is not a float: its conversion rounds, so it enters as a one-ulp interval."""
    n = 2**60 + 1
    s = Interval.point(0.0) + n
    assert Fraction(float(s.lo)) <= n <= Fraction(float(s.hi))
    s = Interval.point(np.zeros(2)) + np.array([2**60 + 1, 3], dtype=np.int64)
    assert Fraction(float(s.lo[0])) <= 2**60 + 1 <= Fraction(float(s.hi[0]))


def test_foreign_operands_are_refused():
    """A Fraction is not silently rounded to a float point: the operation is refused."""
    with pytest.raises(TypeError):
        Interval.point(1.0) + Fraction(1, 3)
    with pytest.raises(TypeError):
        Fraction(1, 3) * Interval.point(1.0)
