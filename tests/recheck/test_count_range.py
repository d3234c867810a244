"""Proved ranges of the number of solutions over joint boxes hold the certified solver's counts.

Random joint boxes of the paper's manipulator and of the second design, from a hundredth to half a
unit wide; at random points of each, the library's certified solver (a complete solve) gives the count,
which must lie in the range.  The ranges must also say something: on small boxes a fair share is
exact.  A parity rule turned the wrong way round is caught by the same sampling.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

import intervalkin.recheck.count_range as cr_mod
from intervalkin.core.geometry import load_geometry
from intervalkin.recheck.count_range import NO_BOUND, count_lower, count_ranges, excludes_count, r_box, supported
from intervalkin.recheck.reduced_equation import reduced_constants
from intervalkin.solve.dkp import solve
from tests.conftest import SECOND_DESIGN


@pytest.fixture(scope="module", params=["paper", "second"])
def geometry(request, paper_geometry):
    return paper_geometry if request.param == "paper" else load_geometry(SECOND_DESIGN)


def _boxes(geometry, seed: int, n: int):
    rng = np.random.default_rng(seed)
    lo_lim = np.array([float(v) for v in geometry.rho_min])
    hi_lim = np.array([float(v) for v in geometry.rho_max])
    w = 10.0 ** rng.uniform(-2, -0.3, (n, 3))
    lo = rng.uniform(lo_lim, hi_lim - w)
    return lo, lo + w, rng


def _counts_at(geometry, lo, hi, rng, per_box: int):
    """(box index, certified count) at random points of the boxes (points with an incomplete solve skipped)."""
    out = []
    for i in range(len(lo)):
        for _ in range(per_box):
            q = tuple(Fraction(float(v)) for v in rng.uniform(lo[i], hi[i]))
            res = solve(geometry, q)
            if res.complete:
                out.append((i, len(res.solutions)))
    return out


def test_ranges_hold_the_certified_counts(geometry):
    lo, hi, rng = _boxes(geometry, 11, 60)
    ranges = count_ranges(geometry, lo, hi)
    assert np.all(ranges.lo <= ranges.hi)
    seen = _counts_at(geometry, lo, hi, rng, 3)
    assert len(seen) > 100
    for i, c in seen:
        assert ranges.lo[i] <= c <= ranges.hi[i], (lo[i], hi[i], c, ranges.lo[i], ranges.hi[i])


def test_cut_sign_changes_bound_the_count_below(geometry):
    """Statement 2 with the cut angles as the only points (count_lower, the barriers' first test): never above the
    solver's count at a point of the box, and not vacuous."""
    lo, hi, rng = _boxes(geometry, 13, 40)
    low = count_lower(reduced_constants(geometry), lo, hi)
    seen = _counts_at(geometry, lo, hi, rng, 2)
    assert len(seen) > 60
    for i, c in seen:
        assert low[i] <= c, (lo[i], hi[i], c, low[i])
    assert sum(low[i] > 0 for i, _ in seen) > len(seen) // 3


def test_excludes_count_holds_the_solver_counts(geometry):
    """Where excludes_count proves a box free of a count the solver never finds it there, and it proves at least
    what the ranges alone prove (the cut signs only come first)."""
    lo, hi, rng = _boxes(geometry, 17, 40)
    seen = _counts_at(geometry, lo, hi, rng, 2)
    ranges = count_ranges(geometry, lo, hi)
    for c in (0, 2, 4):
        free = excludes_count(geometry, lo, hi, c)
        assert np.all(free | ~ranges.excludes(c))
        assert not any(free[i] and n == c for i, n in seen)
    assert excludes_count(geometry, lo[:0], hi[:0], 2).shape == (0,)


def test_ranges_decide_small_boxes(paper_geometry):
    lo, hi, rng = _boxes(paper_geometry, 12, 200)
    hi = lo + (hi - lo) * 0.05  # a few hundredths wide at most
    ranges = count_ranges(paper_geometry, lo, hi)
    exact = ranges.lo == ranges.hi
    assert exact.mean() > 0.3, exact.mean()
    assert np.all(ranges.hi < NO_BOUND)
    for i, c in _counts_at(paper_geometry, lo[exact][:30], hi[exact][:30], rng, 1):
        assert c == ranges.lo[exact][i]


def test_a_wrong_parity_rule_is_caught(paper_geometry, monkeypatch):
    """Mutation: lowering the bound when the parity matches (instead of when it does not) gives ranges
    that miss counts the solver finds."""
    def wrong(order, e_lo, e_hi):
        known = (e_lo != 0) & (e_hi != 0)
        odd = known & (e_lo != e_hi)
        return np.where(known & ((order % 2) == odd) & (order > 0), order - 1, order)

    monkeypatch.setattr(cr_mod, "run_bounds", wrong)
    lo, hi, rng = _boxes(paper_geometry, 11, 60)
    ranges = cr_mod.count_ranges(paper_geometry, lo, hi)
    seen = _counts_at(paper_geometry, lo, hi, rng, 2)
    assert any(not ranges.lo[i] <= c <= ranges.hi[i] for i, c in seen)


def test_bad_boxes_and_unsupported_geometries_are_refused(paper_geometry):
    with pytest.raises(ValueError, match="0 < lo <= hi"):
        r_box(np.array([[11.0, 12, 13]]), np.array([[10.0, 12, 13]]))
    with pytest.raises(ValueError, match="0 < lo <= hi"):
        r_box(np.array([[np.nan, 12, 13]]), np.array([[11.0, 12, 13]]))
    assert supported(paper_geometry)
