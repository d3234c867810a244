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
from intervalkin.kinematics.formulas import approx_det_a, det_a_arb, rho_sq_arb
from intervalkin.kinematics.point_enclosures import rho_sq_det_at


def _poses(geometry, rng, n):
    P = np.c_[rng.uniform(-15, 35, n), rng.uniform(-15, 35, n), rng.uniform(-np.pi, np.pi, n)]
    # half of them moved onto det A = 0 along y (bisection in float): the hardest place for the sign
    for row in P[: n // 2]:
        ys = np.linspace(-15, 35, 201)
        det = approx_det_a(geometry, np.c_[np.full(201, row[0]), ys, np.full(201, row[2])])
        ch = np.flatnonzero(np.sign(det[:-1]) != np.sign(det[1:]))
        if ch.size:
            a, b = ys[ch[0]], ys[ch[0] + 1]
            for _ in range(60):
                m = 0.5 * (a + b)
                if np.sign(approx_det_a(geometry, np.array([[row[0], m, row[2]]]))[0]) == np.sign(det[ch[0]]):
                    a = m
                else:
                    b = m
            row[1] = a
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
