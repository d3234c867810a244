"""The recheck's formulas are the manipulator's, and their enclosures hold the exact values over boxes.

The reference here is written a third time, from the definitions, in arb: B_i =
B1 + R(phi) p_i, rho_i^2 = |B_i - A_i|^2, and det A as the 3x3 determinant of
the rows 2 (u_ix, u_iy, r_i x u_i) expanded by cofactors.  These tests would fail
if the recheck's det A dropped a term or had the opposite sign convention from
the labels (the library's det A, ``kinematics.formulas.det_a_arb``), if a
gradient of the mean value forms were wrong, or if an enclosure missed a value.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from flint import arb, ctx

from intervalkin.core.geometry import load_geometry
from intervalkin.kinematics.formulas import det_a_arb
from intervalkin.recheck.model import (
    REFUTATIONS,
    TESTS,
    constants,
    det_a,
    det_a_centred,
    det_a_gradient,
    rho_sq,
    rho_sq_centred,
)
from tests.conftest import SECOND_DESIGN


def _reference(geometry, x, y, phi):
    """(rho_i^2 list, det A) in arb at the point (x, y, phi) (floats, taken exactly)."""
    X, Y, P = arb(x), arb(y), arb(phi)
    c, s = P.cos(), P.sin()
    rows, rho = [], []
    for i in range(3):
        px, py = (v.arb() for v in geometry.platform_point(i))
        rx, ry = px * c - py * s, px * s + py * c
        ax, ay = (arb(v.numerator) / v.denominator for v in geometry.base[i])
        ux, uy = X + rx - ax, Y + ry - ay
        rho.append(ux * ux + uy * uy)
        rows.append([2 * ux, 2 * uy, 2 * (rx * uy - ry * ux)])
    (a, b, cc), (d, e, f), (g, h, k) = rows
    det = a * (e * k - f * h) - b * (d * k - f * g) + cc * (d * h - e * g)
    return rho, det


@pytest.fixture(scope="module", params=["paper", "second"])
def geometry(request, paper_geometry):
    return paper_geometry if request.param == "paper" else load_geometry(SECOND_DESIGN)


def _boxes(rng, n):
    """Boxes of widths from 1e-9 to several units (phi up to 3 rad), and one point in each."""
    c = np.column_stack([rng.uniform(-32, 32, n), rng.uniform(-32, 32, n), rng.uniform(-math.pi, math.pi, n)])
    w = 10.0 ** rng.uniform(-9, 0.8, (n, 3))
    w[:, 2] = np.minimum(w[:, 2], 3.0)
    lo, hi = c - w / 2, c + w / 2
    pt = lo + (hi - lo) * rng.uniform(0, 1, (n, 3))
    return lo, hi, np.clip(pt, lo, hi)


def _not_outside(ball, lo: float, hi: float) -> bool:
    return not (ball < arb(lo)) and not (ball > arb(hi))


def test_det_formula_is_the_jacobian_determinant_with_the_library_sign(geometry, rng):
    k = constants(geometry)
    pts = np.column_stack([rng.uniform(-30, 30, 200), rng.uniform(-30, 30, 200), rng.uniform(-3.1, 3.1, 200)])
    lo, hi = det_a(k, *((pts[:, a], pts[:, a]) for a in range(3)))
    with ctx.workprec(128):
        for j, (x, y, phi) in enumerate(pts):
            _, ref = _reference(geometry, x, y, phi)
            lib = det_a_arb(geometry, arb(x), arb(y), arb(phi))
            assert _not_outside(ref, lo[j], hi[j]) and _not_outside(lib, lo[j], hi[j])
            assert hi[j] - lo[j] <= 1e-9 * max(1.0, abs(lo[j]))  # a point enclosure is tight


def test_enclosures_hold_the_exact_values_over_boxes(geometry, rng):
    k = constants(geometry)
    lo, hi, pt = _boxes(rng, 400)
    box = tuple((lo[:, a], hi[:, a]) for a in range(3))
    forms = {"rho": rho_sq(k, *box), "rho_c": rho_sq_centred(k, *box)}
    det_n, det_c = det_a(k, *box), det_a_centred(k, *box)
    with ctx.workprec(128):
        for j in range(len(lo)):
            rho, det = _reference(geometry, *pt[j])
            for name in ("rho", "rho_c"):
                for i in range(3):
                    assert _not_outside(rho[i], forms[name][i][0][j], forms[name][i][1][j]), (name, i, j)
            assert _not_outside(det, det_n[0][j], det_n[1][j]), j
            assert _not_outside(det, det_c[0][j], det_c[1][j]), j


def test_centred_form_is_tighter_on_small_boxes(paper_geometry, rng):
    """Why it is there: on boxes of the depth-8 size the mean value form of det A is several times narrower."""
    k = constants(paper_geometry)
    c = np.column_stack([rng.uniform(-20, 20, 500), rng.uniform(-20, 20, 500), rng.uniform(-3, 3, 500)])
    box = tuple((c[:, a] - w, c[:, a] + w) for a, w in enumerate((0.125, 0.125, 0.0123)))
    n, m = det_a(k, *box), det_a_centred(k, *box)
    assert np.median((m[1] - m[0]) / (n[1] - n[0])) < 0.6


def test_gradient_is_the_derivative_of_det_over_8(geometry, rng):
    """det_a_gradient at a point against central differences of the reference determinant (h = 2^-40, 256 bits)."""
    k = constants(geometry)
    pts = np.column_stack([rng.uniform(-30, 30, 60), rng.uniform(-30, 30, 60), rng.uniform(-3.1, 3.1, 60)])
    grad = det_a_gradient(k, *((pts[:, a], pts[:, a]) for a in range(3)))
    h = 2.0 ** -40
    with ctx.workprec(256):
        for j, p in enumerate(pts):
            for a in range(3):
                up_, dn = list(p), list(p)
                up_[a] += h
                dn[a] -= h
                fd = (_reference(geometry, *up_)[1] - _reference(geometry, *dn)[1]) / (16 * h)
                lo, hi = grad[a][0][j], grad[a][1][j]
                tol = 1e-9 * max(1.0, abs(lo))
                assert _not_outside(fd, lo - tol, hi + tol), (j, a, float(fd.mid()), lo, hi)


def test_label_tests_and_their_refutations_on_a_known_pose(paper_geometry):
    """A pose well inside W: a tiny box around it proves W INSIDE and one sign of det A, and refutes the opposites."""
    k = constants(paper_geometry)
    x, y, phi = 0.1, 12.0, 0.6  # a pose well inside W (checked below in arb)
    with ctx.workprec(128):
        rho, det = _reference(paper_geometry, x, y, phi)
        assert all(100 < float(r.mid()) < 1024 for r in rho)
        sign = 1 if det > 0 else -1
    box = tuple((np.array([v - 1e-6]), np.array([v + 1e-6])) for v in (x, y, phi))
    assert TESTS[("in_workspace", 1)](k, box)[0] and not TESTS[("in_workspace", -1)](k, box)[0]
    assert REFUTATIONS[("in_workspace", -1)](k, box)[0]
    assert TESTS[("det_sign", sign)](k, box)[0] and REFUTATIONS[("det_sign", -sign)](k, box)[0]
    assert not TESTS[("det_sign", -sign)](k, box)[0]
