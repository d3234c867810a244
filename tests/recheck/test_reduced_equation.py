"""The recheck's reduced equation: its phi-derivatives agree with arb, and its enclosures hold over boxes.

The reference is written a third time, from the definitions, in arb power series in phi
(``arb_series``): B_i = B1 + R(phi) p_i, the two linear equations of legs 2 and 3 minus leg 1,
Cramer's rule, f = |N|^2 - r_1 D^2.  Dropping a term of f, or a wrong Taylor factor, fails
``test_series_agree_with_arb_at_points``; an enclosure that misses a value fails
``test_enclosures_hold_sampled_values``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from flint import arb, arb_series, ctx

import intervalkin.recheck.reduced_equation as re_mod
from intervalkin.core.geometry import load_geometry
from intervalkin.recheck.reduced_equation import d_sign, derivative_enclosures, reduced_constants
from tests.conftest import SECOND_DESIGN


def _reference(geometry, r, phi) -> list:
    """[f, f', f'', f'''] at (r, phi) (floats, taken exactly), in arb, from the definitions."""
    old = ctx.cap
    ctx.cap = 5
    try:
        t = arb_series([arb(phi), 1])
        c, s = t.cos(), t.sin()
        a1x, a1y = (arb(v.numerator) / v.denominator for v in geometry.base[0])
        m, k = [], []
        for i in (1, 2):
            px, py = (v.arb() for v in geometry.platform_point(i))
            ex, ey = c * px - s * py, s * px + c * py
            ax = arb(geometry.base[i][0].numerator) / geometry.base[i][0].denominator - a1x
            ay = arb(geometry.base[i][1].numerator) / geometry.base[i][1].denominator - a1y
            m.append((2 * (ex - ax), 2 * (ey - ay)))
            # |e_i - a_i|^2 = |p_i|^2 + |a_i|^2 - 2 a_i . e_i
            k.append(arb(r[i]) - arb(r[0]) - (px * px + py * py) - (ax * ax + ay * ay) + 2 * (ax * ex + ay * ey))
        (m2x, m2y), (m3x, m3y) = m
        D = m2x * m3y - m2y * m3x
        Nx = k[0] * m3y - k[1] * m2y
        Ny = m2x * k[1] - m3x * k[0]
        f = Nx * Nx + Ny * Ny - arb(r[0]) * D * D
        coeffs = list(f.coeffs())
    finally:
        ctx.cap = old
    return [coeffs[j] * math.factorial(j) for j in range(4)]


@pytest.fixture(scope="module", params=["paper", "second"])
def geometry(request, paper_geometry):
    return paper_geometry if request.param == "paper" else load_geometry(SECOND_DESIGN)


def test_series_agree_with_arb_at_points(geometry):
    k = reduced_constants(geometry)
    rng = np.random.default_rng(3)
    q = rng.uniform(10, 32, (60, 3))
    r = q * q
    phi = rng.uniform(-math.pi, math.pi, 60)
    enc = derivative_enclosures(k, r, r, phi, phi)
    for i in range(60):
        ref = _reference(geometry, r[i], phi[i])
        for d in range(4):
            lo, hi = enc[d][0][i], enc[d][1][i]
            assert lo <= hi
            assert arb(lo) <= ref[d] + 1e-6 and ref[d] - 1e-6 <= arb(hi), (d, i, lo, hi, ref[d])
            # terms of f reach 1e10 and cancel: an absolute unit of width is tight at that scale
            assert hi - lo <= 1.0 + 1e-6 * abs(float(ref[d].mid())), "a point enclosure should be tight"


def test_enclosures_hold_sampled_values(geometry):
    k = reduced_constants(geometry)
    rng = np.random.default_rng(4)
    n = 40
    q_lo = rng.uniform(10, 31, (n, 3))
    q_hi = q_lo + 10.0 ** rng.uniform(-3, 0, (n, 3))
    p_lo = rng.uniform(-math.pi, 2.5, n)
    p_hi = p_lo + 10.0 ** rng.uniform(-3, -0.3, n)
    enc = derivative_enclosures(k, q_lo ** 2, q_hi ** 2, p_lo, p_hi)
    for i in range(n):
        for _ in range(4):
            qq = rng.uniform(q_lo[i], q_hi[i])
            ph = rng.uniform(p_lo[i], p_hi[i])
            ref = _reference(geometry, qq * qq, ph)
            for d in range(4):
                assert enc[d][0][i] <= float(ref[d].mid()) <= enc[d][1][i], (d, i)


def test_d_sign_is_the_sign_of_the_determinant(geometry):
    k = reduced_constants(geometry)
    phi = np.linspace(-3.1, 3.1, 400)
    sign = d_sign(k, phi - 1e-3, phi + 1e-3)
    for p, s in zip(phi, sign):  # D = m_2 x m_3 does not depend on r: computed here in floats, away from its zeros
        c, sn = math.cos(p), math.sin(p)
        m = []
        for i in (1, 2):
            px, py = (float(v) for v in geometry.platform_point(i))
            ax = float(geometry.base[i][0] - geometry.base[0][0])
            ay = float(geometry.base[i][1] - geometry.base[0][1])
            m.append((2 * (c * px - sn * py - ax), 2 * (sn * px + c * py - ay)))
        D = m[0][0] * m[1][1] - m[0][1] * m[1][0]
        assert s == 0 or s == np.sign(D), (p, s, D)
    assert (sign != 0).mean() > 0.9


def test_a_dropped_term_is_caught(geometry, monkeypatch):
    """Mutation: f without the - r_1 D^2 term no longer agrees with the reference."""
    original = re_mod._combine

    def without_d2(terms, r):
        U, V, W, P2, P3, P0, D2 = terms
        zero = [(np.zeros_like(lo), np.zeros_like(hi)) for lo, hi in D2]
        return original((U, V, W, P2, P3, P0, zero), r)

    monkeypatch.setattr(re_mod, "_combine", without_d2)
    k = reduced_constants(geometry)
    r = np.array([[400.0, 500.0, 600.0]])
    phi = np.array([0.7])
    lo, hi = re_mod.derivative_enclosures(k, r, r, phi, phi)[0]
    ref = _reference(geometry, r[0], 0.7)[0]
    assert not (arb(lo[0]) <= ref + 1e-6 and ref - 1e-6 <= arb(hi[0]))
