"""rho_i^2 and det A enclosed at float poses (kinematics.point_enclosures) against arb.

- at random poses (and poses near det A = 0, where cancellation is worst) the arb values at
  256 bits lie in the enclosures;
- the enclosures are tight (a few ulps of the values' scale), so a Krawczyk step built on them
  can contract;
- they overlap the box enclosures of kinematics.enclosures taken at the same (degenerate) boxes.
"""

from __future__ import annotations

import numpy as np
from flint import arb, ctx

from intervalkin.kinematics.enclosures import det_a_interval, rho_sq_interval
from intervalkin.kinematics.formulas import det_a_arb, rho_sq_arb
from intervalkin.kinematics.point_enclosures import rho_sq_det_at
from tests.solve.shared import det_zeros_along_y


def _poses(geometry, rng, n):
    P = np.c_[rng.uniform(-15, 35, n), rng.uniform(-15, 35, n), rng.uniform(-np.pi, np.pi, n)]
    # half of them moved onto det A = 0 along y (the first sign change of each line): the hardest place
    half = P[: n // 2]
    line, a, _ = det_zeros_along_y(geometry, half[:, 0], half[:, 2], np.linspace(-15, 35, 201))
    first = np.r_[True, line[1:] != line[:-1]]
    half[line[first], 1] = a[first]
    return P


def test_arb_values_lie_in_the_point_enclosures(paper_geometry):
    P = _poses(paper_geometry, np.random.default_rng(7), 400)
    r, d = rho_sq_det_at(paper_geometry, P)
    old = ctx.prec
    ctx.prec = 256
    try:
        for i, (x, y, phi) in enumerate(P):
            xs, ys, ps = arb(float(x)), arb(float(y)), arb(float(phi))
            for leg, v in enumerate(rho_sq_arb(paper_geometry, xs, ys, ps)):
                assert r.lo[i, leg] <= float(v.lower()) and float(v.upper()) <= r.hi[i, leg], (i, leg)
            v = det_a_arb(paper_geometry, xs, ys, ps)
            assert d.lo[i] <= float(v.lower()) and float(v.upper()) <= d.hi[i], i
    finally:
        ctx.prec = old


def test_point_enclosures_are_tight_and_agree_with_the_box_enclosures(paper_geometry):
    P = _poses(paper_geometry, np.random.default_rng(8), 200)
    r, d = rho_sq_det_at(paper_geometry, P)
    scale = np.abs(r.hi).max(axis=1)
    assert np.all(r.hi - r.lo <= 1e-12 * scale[:, None] + 1e-12)
    # near det A = 0 the width is set by the size of the terms that cancel: the scale of det A itself
    assert np.all(d.hi - d.lo <= 1e-12 * np.abs(d.hi).max())
    boxes = np.stack([P, P], axis=-1)
    rb, db = rho_sq_interval(paper_geometry, boxes), det_a_interval(paper_geometry, boxes)
    assert np.all((r.lo <= rb.hi) & (rb.lo <= r.hi))
    assert np.all((d.lo <= db.hi) & (db.lo <= d.hi))
