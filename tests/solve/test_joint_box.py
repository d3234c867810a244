"""The joint-box predicate (solve.joint_box): boxes proved off g(S) by a search for singular poses.

- a box PROVED clear has the same certified solution count and aspect split at its
  corners and at random exact points;
- a box that holds the joint vector of a singular pose is never clear: singular
  poses are drawn at random and proved singular in arb (a sign change of det A
  along a tiny segment), and the box around their image must be refused;
- boxes across the image found by bisecting between two counts, and the double
  root of a concurrent-legs manipulator, are refused;
- where two solutions share one orientation (the blind spot of the reduced
  equation in phi alone) boxes are proved clear and keep their count.
"""

from __future__ import annotations

import math
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from flint import arb, ctx, fmpq
from hypothesis import given, settings
from hypothesis import strategies as st

from intervalkin.core.geometry import default_geometry, load_geometry
from intervalkin.kinematics.constants import constants
from intervalkin.kinematics.enclosures import rho_interval
from intervalkin.kinematics.formulas import (
    approx_det_a,
    approx_inverse_kinematics,
    det_a_arb,
)
from intervalkin.solve.dkp import solve
from intervalkin.solve.joint_box import clear_boxes, initial_cells, live_cells
from tests.solve.shared import box_across_singular_image, concurrent_legs_box
from tests.solve.shared import split_of as _split

DATA = Path(__file__).parents[1] / "data"
PAPER = default_geometry()


def _q(x: float) -> arb:
    f = Fraction(x)
    return arb(fmpq(f.numerator, f.denominator))


def test_initial_cells_cover_the_torus():
    owner, cells = initial_cells(2)
    assert np.all(owner[: len(owner) // 2] == 0) and np.all(owner[len(owner) // 2:] == 1)
    one = cells[owner == 0]
    area = np.sum((one[:, 1] - one[:, 0]) * (one[:, 3] - one[:, 2]))
    assert area >= (2 * math.pi) ** 2 and one[:, 0].min() <= -math.pi and one[:, 3].max() >= math.pi


def test_clear_boxes_keep_one_count_and_split(paper_geometry):
    """Every corner and a random exact point of a clear box: the same certified count and aspect split."""
    rng = np.random.default_rng(11)
    lo = rng.uniform(10, 31.9, size=(60, 3))
    boxes = np.stack([lo, lo + 0.08], axis=-1)
    ok = clear_boxes(paper_geometry, boxes)
    assert ok.sum() >= 30, "most small boxes of the joint box are off g(S)"
    for box in boxes[ok][:12]:
        points = [[Fraction(box[i, (c >> i) & 1]) for i in range(3)] for c in (0, 7)]
        points.append([Fraction(box[i, 0]) + Fraction(int(rng.integers(1, 99)), 100) * Fraction(box[i, 1] - box[i, 0])
                       for i in range(3)])
        splits = {_split(solve(paper_geometry, p)) for p in points}
        assert len(splits) == 1, (box, splits)


def _singular_pose_box(geometry, x: float, phi: float, y_from: float, y_to: float, width: float):
    """A joint box holding g(X) for an exact singular pose X = (x, y*, phi), or None if none is bracketed."""
    ys = np.linspace(y_from, y_to, 401)
    det = approx_det_a(geometry, np.stack([np.full_like(ys, x), ys, np.full_like(ys, phi)], axis=1))
    change = np.flatnonzero(np.sign(det[:-1]) * np.sign(det[1:]) < 0)
    if change.size == 0:
        return None
    a, b = ys[change[0]], ys[change[0] + 1]
    for _ in range(60):
        m = 0.5 * (a + b)
        same = np.sign(approx_det_a(geometry, np.array([[x, m, phi]]))[0]) == np.sign(
            approx_det_a(geometry, np.array([[x, a, phi]]))[0])
        a, b = (m, b) if same else (a, m)
    lo_y, hi_y = a - 1e-9, b + 1e-9
    with ctx.workprec(200):  # det A changes sign on the segment: an exact zero y* lies between (continuity)
        d_lo = det_a_arb(geometry, _q(x), _q(lo_y), _q(phi))
        d_hi = det_a_arb(geometry, _q(x), _q(hi_y), _q(phi))
        if not ((d_lo < 0 and d_hi > 0) or (d_lo > 0 and d_hi < 0)):
            return None
    rho = rho_interval(geometry, np.array([[[x, x], [lo_y, hi_y], [phi, phi]]]))
    if rho.lo.min() <= 0.5:
        return None
    centre = 0.5 * (rho.lo[0] + rho.hi[0])
    return np.stack([np.minimum(rho.lo[0], centre - width), np.maximum(rho.hi[0], centre + width)], axis=-1)


@settings(max_examples=25, deadline=None)
@given(st.floats(-25, 25), st.floats(-3.1, 3.1), st.sampled_from([1e-3, 0.05]))
def test_boxes_on_the_singular_image_are_never_clear(x, phi, width):
    """The image of a proved singular pose, boxed: the predicate must refuse it (soundness)."""
    box = _singular_pose_box(PAPER, x, phi, -30.0, 30.0, width)
    if box is None:
        return
    assert not clear_boxes(PAPER, box[None])[0], (x, phi, box)
    owner, cells = live_cells(PAPER, box[None], *initial_cells(1), rounds=8)
    assert owner.size > 0


def test_boxes_across_the_singular_image_are_not_clear(paper_geometry):
    """A box holding a point of g(S) found by exact bisection between two counts is refused."""
    assert not clear_boxes(paper_geometry, box_across_singular_image(paper_geometry))[0]


@pytest.mark.parametrize("width", [1e-2, 1e-4])
def test_double_root_of_concurrent_legs_is_not_clear(width):
    g = load_geometry(DATA / "concurrent_legs.toml")
    assert not clear_boxes(g, concurrent_legs_box(width))[0]


def _shared_orientation(geometry) -> float:
    """A float orientation phi* where the 2 x 2 position system is singular (D(phi*) = 0)."""
    k = constants(geometry)

    def d(phi):
        w = [(k.radius[j] * math.cos(phi + k.alpha[j]) + k.ax[0] - k.ax[j],
              k.radius[j] * math.sin(phi + k.alpha[j]) + k.ay[0] - k.ay[j]) for j in (1, 2)]
        return w[0][0] * w[1][1] - w[0][1] * w[1][0]

    grid = np.linspace(-math.pi, math.pi, 4001)
    vals = [d(p) for p in grid]
    i = next(i for i in range(4000) if vals[i] * vals[i + 1] < 0)
    a, b = grid[i], grid[i + 1]
    for _ in range(60):
        m = 0.5 * (a + b)
        a, b = (m, b) if d(m) * d(a) > 0 else (a, m)
    return a


def test_two_solutions_sharing_an_orientation_are_no_blind_spot(paper_geometry):
    """Around a joint vector with two solutions at one orientation phi* the box is clear and keeps its count."""
    phi = _shared_orientation(paper_geometry)
    rng = np.random.default_rng(2)
    done = 0
    for _ in range(40):
        x, y = rng.uniform(-15, 25, size=2)
        rho = approx_inverse_kinematics(paper_geometry, np.array([[x, y, phi]]))[0]
        if not np.all((rho > 10.5) & (rho < 31.5)):
            continue
        box = np.stack([rho - 0.01, rho + 0.01], axis=-1)
        if not clear_boxes(paper_geometry, box[None])[0]:
            continue
        res = solve(paper_geometry, [Fraction(float(v)) for v in rho])
        near = [s for s in res.solutions if abs(float(np.mean(s.box[2])) - phi) < 1e-6]
        assert len(near) >= 2, "the pose's partner shares its orientation (the situation under test)"
        corners = {_split(solve(paper_geometry, [Fraction(float(box[i, (c >> i) & 1])) for i in range(3)])) for c in (0, 7)}
        assert corners == {_split(res)}
        done += 1
        if done >= 3:
            break
    assert done >= 3, "boxes around two solutions sharing an orientation should be provable"
