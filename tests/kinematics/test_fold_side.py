"""The side of the extra pair at a fold (kinematics.fold_side) against an independent computation.

At singular poses X* (det A = 0, found by float bisection), the curvature of rho_k^2 along
the four-bar curve rho_i = const, rho_j = const is computed in mpmath at 50 digits by
walking the curve (a tangent step corrected back onto both constraints by Newton) and a
second difference; its sign must be the one :func:`pair_side` certifies on a tiny box
around X*.  A mutation (the Lagrange weights w_l dropped) is caught by the same data.
"""

from __future__ import annotations

import mpmath as mp
import numpy as np
import pytest

from intervalkin.kinematics import fold_side
from intervalkin.kinematics.constants import constants
from intervalkin.kinematics.fold_side import pair_side
from tests.solve.shared import det_zeros_along_y


def _rho_sq(k, X):
    x, y, phi = X
    out = []
    for leg in range(3):
        t = phi + mp.mpf(float(k.alpha[leg]))
        bx = x + mp.mpf(float(k.radius[leg])) * mp.cos(t) - mp.mpf(float(k.ax[leg]))
        by = y + mp.mpf(float(k.radius[leg])) * mp.sin(t) - mp.mpf(float(k.ay[leg]))
        out.append(bx * bx + by * by)
    return out


def _grad(k, X, leg):
    h = mp.mpf("1e-20")
    return mp.matrix([(_rho_sq(k, [X[a] + (h if a == b else 0) for a in range(3)])[leg]
                       - _rho_sq(k, [X[a] - (h if a == b else 0) for a in range(3)])[leg]) / (2 * h)
                      for b in range(3)])


def _dot(u, w):
    return mp.fsum(u[r] * w[r] for r in range(3))


def _curvature(k, X0, axis):
    """Second difference of rho_k^2 along the curve rho_i^2, rho_j^2 = their values at X0 (50 digits)."""
    i, j = [a for a in range(3) if a != axis]
    X0 = mp.matrix([mp.mpf(float(v)) for v in X0])
    target = _rho_sq(k, X0)
    gi, gj = _grad(k, X0, i), _grad(k, X0, j)
    v = mp.matrix([gi[1] * gj[2] - gi[2] * gj[1], gi[2] * gj[0] - gi[0] * gj[2], gi[0] * gj[1] - gi[1] * gj[0]])
    v = v / mp.norm(v)

    def on_curve(t):
        X = X0 + t * v
        for _ in range(8):  # Newton in the plane of the two gradients
            r = _rho_sq(k, X)
            a, b = _grad(k, X, i), _grad(k, X, j)
            M = mp.matrix([[_dot(a, a), _dot(a, b)], [_dot(b, a), _dot(b, b)]])
            c = mp.lu_solve(M, mp.matrix([target[i] - r[i], target[j] - r[j]]))
            X = X + c[0] * a + c[1] * b
        return _rho_sq(k, X)[axis]

    t = mp.mpf("1e-6")
    return (on_curve(t) + on_curve(-t) - 2 * on_curve(0)) / (t * t)


@pytest.fixture(scope="module")
def fold_poses(paper_geometry):
    """Singular poses (det A = 0 within an ulp along y) whose joint vectors lie in the joint box."""
    rng = np.random.default_rng(17)
    x = rng.uniform(-10, 30, 400)
    phi = rng.uniform(-np.pi, np.pi, 400)
    line, a, b = det_zeros_along_y(paper_geometry, x, phi, np.linspace(-10, 30, 161))
    X = np.stack([x[line], 0.5 * (a + b), phi[line]], axis=1)
    boxes = np.stack([X, X], axis=-1)
    boxes[:, 1, 0], boxes[:, 1, 1] = np.minimum(a, b) - 1e-12, np.maximum(a, b) + 1e-12
    return X[:60], boxes[:60]


def _agreement(geometry, X, boxes, side_fn):
    k = constants(geometry)
    mp.mp.dps = 50
    agree = disagree = proved = 0
    for axis in range(3):
        s = side_fn(geometry, boxes, np.full(len(boxes), axis))
        for n in np.flatnonzero(s != 0):
            proved += 1
            c = _curvature(k, X[n], axis)
            if abs(c) < mp.mpf("1e-8"):
                continue  # too close to a cusp for the second difference to be trusted
            if int(mp.sign(c)) == int(s[n]):
                agree += 1
            else:
                disagree += 1
    return agree, disagree, proved


def test_side_matches_the_curvature_along_the_four_bar_curve(paper_geometry, fold_poses):
    X, boxes = fold_poses
    agree, disagree, proved = _agreement(paper_geometry, X, boxes, pair_side)
    assert disagree == 0
    assert proved >= 0.9 * 3 * len(X) and agree >= 0.85 * 3 * len(X), (agree, proved)


def test_dropping_the_lagrange_weights_is_caught(paper_geometry, fold_poses, monkeypatch):
    """Mutation: every w_l taken as 1 (f'' as the plain sum of the v^T H_l v): the sides no longer match."""
    X, boxes = fold_poses
    monkeypatch.setattr(fold_side, "_cross2", lambda ax, ay, bx, by: ax * 0.0 + 1.0)
    agree, disagree, proved = _agreement(paper_geometry, X, boxes, fold_side.pair_side)
    assert disagree > 0
