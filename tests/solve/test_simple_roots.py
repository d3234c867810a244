"""The joint-space predicate: boxes on which every root of the reduced equation is simple.

- the reduced equation as a quadratic form in r = rho^2 (kinematics.reduced_equation)
  equals the solver's own reduction at random exact r and phi, in arb;
- ball arithmetic (core.ball) encloses exact results at random points of its balls;
- a box PROVED clear has the same certified solution count and aspect split at its
  corners and at random exact points (the claim of solve.simple_roots);
- boxes around a point of g(S) and around the double root of a concurrent-legs
  manipulator are never called clear.
"""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from flint import arb, ctx, fmpq
from hypothesis import given, settings
from hypothesis import strategies as st

from intervalkin.core.ball import Ball, cos_sin_multiple
from intervalkin.core.geometry import load_geometry
from intervalkin.core.interval import Interval
from intervalkin.kinematics.reduced_equation import (
    HARMONICS,
    MONOMIALS,
    reduced_equation,
)
from intervalkin.kinematics.sextic import laurent_value, reduction
from intervalkin.solve.dkp import solve
from intervalkin.solve import simple_roots
from intervalkin.solve.simple_roots import ReducedBoxes, basis_waves, initial_pieces, open_pieces, trig_basis
from tests.solve.shared import box_across_singular_image, concurrent_legs_box
from tests.solve.shared import split_of as _split

DATA = Path(__file__).parents[1] / "data"


def _q(x: float) -> arb:
    f = Fraction(x)
    return arb(fmpq(f.numerator, f.denominator))


def test_reduced_equation_matches_the_solver_reduction(paper_geometry):
    """sum_h c_h(r) basis_h(phi) (float enclosures of C) contains f(phi; r) of the solver's reduction."""
    C = reduced_equation(paper_geometry).coefficients
    rng = np.random.default_rng(3)
    with ctx.workprec(200):
        for _ in range(20):
            r = [Fraction(int(v), 7) for v in rng.integers(700, 7200, 3)]
            phi = float(rng.uniform(-np.pi, np.pi))
            exact = laurent_value(reduction(paper_geometry, [arb(fmpq(v.numerator, v.denominator)) for v in r]).f, _q(phi)).real
            mono = [Fraction(1) if not e else r[e[0]] if len(e) == 1 else r[e[0]] * r[e[1]] for e in MONOMIALS]
            basis = [arb(1) if k == 0 else (_q(phi) * k).sin() if s else (_q(phi) * k).cos() for k, s in HARMONICS]
            total = arb(0)
            for h in range(7):
                for m in range(10):
                    c = arb(C.lo[h, m]).union(arb(C.hi[h, m]))
                    total += c * basis[h] * arb(fmpq(mono[m].numerator, mono[m].denominator))
            assert total.overlaps(exact), (r, phi)
            # and the enclosure is tight: relative width far below any use
            assert float(total.rad()) < 1e-6 * (1 + abs(float(exact.mid())))


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(-50, 50), min_size=4, max_size=4), st.lists(st.floats(0, 1), min_size=4, max_size=4),
       st.lists(st.floats(0, 1), min_size=4, max_size=4), st.integers(1, 3), st.integers(0, 2))
def test_ball_operations_enclose_exact_values(mids, rads, ts, k, deriv):
    """Products, dot products, matrix products and cos/sin of k phi contain the exact values at points of the balls."""
    a = Ball(np.array(mids[:2]), np.array(rads[:2]))
    b = Ball(np.array(mids[2:]), np.array(rads[2:]))
    pa = [Fraction(m) + (2 * Fraction(t) - 1) * Fraction(r) for m, r, t in zip(mids[:2], rads[:2], ts[:2])]
    pb = [Fraction(m) + (2 * Fraction(t) - 1) * Fraction(r) for m, r, t in zip(mids[2:], rads[2:], ts[2:])]
    prod = (a * b).to_interval()
    for i in range(2):
        assert Fraction(prod.lo[i]) <= pa[i] * pb[i] <= Fraction(prod.hi[i])
    dot = a.dot(b).to_interval()
    assert Fraction(float(dot.lo)) <= pa[0] * pb[0] + pa[1] * pb[1] <= Fraction(float(dot.hi))
    mat = a.matmul(Ball(np.array([[mids[2]], [mids[3]]]), np.array([[rads[2]], [rads[3]]]))).to_interval()
    assert Fraction(float(mat.lo[0])) <= pa[0] * pb[0] + pa[1] * pb[1] <= Fraction(float(mat.hi[0]))
    col = Ball(np.array([[mids[2]], [mids[3]]]), np.array([[rads[2]], [rads[3]]]))
    stacked = Ball(np.tile(a.mid, (2, 3, 1)), np.tile(a.rad, (2, 3, 1))).matmul(col)  # (2, 3, 1): as one matrix
    exact = pa[0] * pb[0] + pa[1] * pb[1]
    assert stacked.mid.shape == (2, 3, 1)
    iv = stacked.to_interval()
    assert all(Fraction(float(lo)) <= exact <= Fraction(float(hi)) for lo, hi in zip(iv.lo.ravel(), iv.hi.ravel()))
    assert Ball(np.zeros((0, 3, 2)), np.zeros((0, 3, 2))).matmul(col).mid.shape == (0, 3, 1)
    rows = Ball(a.mid[None, None, :], a.rad[None, None, :]).row_matmul(
        Ball(np.array([[[mids[2]], [mids[3]]]]), np.array([[[rads[2]], [rads[3]]]]))).to_interval()
    assert Fraction(float(rows.lo[0, 0, 0])) <= pa[0] * pb[0] + pa[1] * pb[1] <= Fraction(float(rows.hi[0, 0, 0]))
    phi = Ball(np.array([mids[0] / 20]), np.array([rads[0]]))
    c, s = cos_sin_multiple(phi, k, deriv)
    point = _q(mids[0] / 20) + (2 * _q(ts[0]) - 1) * _q(rads[0])
    with ctx.workprec(120):
        t = point * k
        exact = [t.cos(), t.sin(), -t.sin(), t.cos(), -t.cos(), -t.sin()][2 * deriv: 2 * deriv + 2]
        for ball, value in zip((c, s), exact):
            iv = ball.to_interval()
            assert arb(float(iv.lo[0])) <= value * k**deriv <= arb(float(iv.hi[0]))


def test_enclosures_in_blocks_are_those_of_each_row(paper_geometry, monkeypatch):
    """The enclosure of a long array of (box, piece) rows, taken in blocks, is row by row the enclosure of that
    row alone (a block put back out of order, or the bases of one row paired with another's box, would show);
    and the cos and sin shared by its three bases are the ones each would compute."""
    rng = np.random.default_rng(3)
    lo = rng.uniform(10, 31.5, size=(40, 3))
    data = ReducedBoxes(paper_geometry, _boxes(lo, 0.05))
    owner = np.sort(rng.integers(0, 40, 300))
    a = rng.uniform(-np.pi, 3.0, 300)
    b = a + rng.choice([1e-3, 0.05, 0.1], 300)
    monkeypatch.setattr(simple_roots, "_ROWS", 64)
    for deriv in range(4):
        whole = data.enclosure(owner, a, b, deriv)
        for i in rng.choice(300, 12, replace=False):
            alone = data.enclosure(owner[i:i + 1], a[i:i + 1], b[i:i + 1], deriv)
            assert (whole.lo[i], whole.hi[i]) == (alone.lo[0], alone.hi[0])
    phi = Ball.from_interval(Interval(a, b))
    for deriv in range(3):
        shared, own = trig_basis(phi, deriv, basis_waves(phi.mid)), trig_basis(phi, deriv)
        assert np.array_equal(shared.mid, own.mid) and np.array_equal(shared.rad, own.rad)


def test_ball_from_interval_contains_the_interval():
    iv = Interval(np.array([1.0, -3.0, 0.1]), np.array([1.0 + 2**-30, 5.0, 0.3]))
    b = Ball.from_interval(iv).to_interval()
    assert np.all(b.lo <= iv.lo) and np.all(b.hi >= iv.hi)


def clear_boxes(geometry, boxes: np.ndarray) -> np.ndarray:
    """The simple-roots test alone: True where no piece of the orientation circle is left open."""
    boxes = np.asarray(boxes, dtype=np.float64)
    owner, _, _ = open_pieces(geometry, boxes, *initial_pieces(len(boxes)))
    return np.bincount(owner, minlength=len(boxes)) == 0


def _boxes(lo: np.ndarray, width: float) -> np.ndarray:
    return np.stack([lo, lo + width], axis=-1)


def test_clear_boxes_keep_one_count_and_split(paper_geometry):
    """Every corner and random exact point of a clear box: the same certified count and aspect split."""
    rng = np.random.default_rng(11)
    lo = rng.uniform(10, 31.9, size=(60, 3))
    boxes = _boxes(lo, 0.08)
    ok = clear_boxes(paper_geometry, boxes)
    assert ok.sum() >= 30, "most small boxes of the joint box are off g(S)"
    for box in boxes[ok][:12]:
        points = [[Fraction(box[i, (c >> i) & 1]) for i in range(3)] for c in (0, 7)]
        points.append([Fraction(box[i, 0]) + Fraction(int(rng.integers(1, 99)), 100) * Fraction(box[i, 1] - box[i, 0])
                       for i in range(3)])
        splits = {_split(solve(paper_geometry, p)) for p in points}
        assert len(splits) == 1, (box, splits)


def test_boxes_across_the_singular_image_are_not_clear(paper_geometry):
    """A box holding a joint vector with a double root (on g(S)) is refused, however small."""
    assert not clear_boxes(paper_geometry, box_across_singular_image(paper_geometry))[0]


@pytest.mark.parametrize("width", [1e-2, 1e-4])
def test_double_root_of_concurrent_legs_is_not_clear(width):
    g = load_geometry(DATA / "concurrent_legs.toml")
    assert not clear_boxes(g, concurrent_legs_box(width))[0]
