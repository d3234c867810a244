"""The reduced equation of the direct kinematics as a function of the joint vector.

For fixed leg lengths, eliminating the position of B1 (two linear equations, then
the circle of leg 1; :mod:`intervalkin.kinematics.sextic`) leaves one equation in
the orientation alone,

    f(phi; r) = |N(phi; r)|^2 - r_1 D(phi)^2 = 0,        r_i = rho_i^2,

a real trigonometric polynomial of degree 3 in phi.  N is affine in r and D does
not depend on r, so every Fourier coefficient of f is a polynomial of degree at
most 2 in r = (r_1, r_2, r_3):

    f(phi; r) = sum_h  c_h(r) * basis_h(phi),
    basis = (1, cos phi, sin phi, cos 2 phi, sin 2 phi, cos 3 phi, sin 3 phi),
    c_h(r) = sum_m  C[h, m] * monomial_m(r),
    monomials = (1, r1, r2, r3, r1^2, r1 r2, r1 r3, r2^2, r2 r3, r3^2).

The 7 x 10 matrix C is computed once per geometry, in arb from the exact
geometry, by polarisation: f is evaluated (with the same Laurent-polynomial
reduction the certified solver uses) at r = 0, +-e_i and e_i + e_j, which
determine a quadratic exactly.  Each entry is then enclosed by two floats.

The determinant D(phi) = m_2 x m_3 of the 2 x 2 position system does not depend on r:
D(phi) = d_0 + d_1 cos phi + d_2 sin phi (``denominator``).

Near the zeros of D (``aligned_numerator``): there m_3 is parallel to m_2, N to the normal of m_2, and
f = |N|^2 >= 0 has a double root on a whole plane of r-space; with s = m_2 x N (affine in r),
f >= s^2 / |m_2|^2 - r_1 D^2 everywhere, with equality where D = 0 (proofs/lemma-gap-at-d-zeros.md).

What is certified: ``reduced_equation(geometry)`` returns float intervals
that contain the exact entries of C.  The polarisation identity is exact for a
polynomial of degree 2, and ``tests/solve/test_simple_roots.py`` compares the form
with the direct reduction at random r and phi in arb.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from flint import arb, ctx

from intervalkin.core.exact import arb_to_bounds
from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import Interval
from intervalkin.kinematics.sextic import aligned_laurent, reduction

__all__ = ["MONOMIALS", "HARMONICS", "ReducedEquation", "reduced_equation", "denominator", "AlignedNumerator",
           "aligned_numerator"]

#: Exponent pairs of the monomials in r (() is the constant, (i,) is r_i, (i, j) is r_i r_j).
MONOMIALS: tuple[tuple[int, ...], ...] = ((), (0,), (1,), (2,), (0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))
#: (order k, 0 for cos / 1 for sin) of each basis function; (0, 0) is the constant.
HARMONICS: tuple[tuple[int, int], ...] = ((0, 0), (1, 0), (1, 1), (2, 0), (2, 1), (3, 0), (3, 1))

_PRECISION = 256


@dataclass(frozen=True, eq=False)
class ReducedEquation:
    """f(phi; r) = sum_h c_h(r) basis_h(phi), c_h quadratic in r = rho^2.

    Attributes
    ----------
    coefficients : Interval of shape (7, 10), enclosures of C[h, m] (harmonic h of
        :data:`HARMONICS`, monomial m of :data:`MONOMIALS`).
    """

    coefficients: Interval

    @property
    def midpoint(self) -> np.ndarray:
        """Float values of C (7, 10), for predictors only."""
        return self.coefficients.mid()


def _fourier(f: dict) -> list:
    """Real Fourier coefficients (a0, a1, b1, a2, b2, a3, b3) of a real Laurent polynomial in exp(i phi).

    f_k e^{ik phi} + f_{-k} e^{-ik phi} = 2 Re(f_k) cos k phi - 2 Im(f_k) sin k phi when f_{-k} = conj(f_k).
    """
    out = [f[0].real]
    for k in (1, 2, 3):
        c = f.get(k)
        out += [2 * c.real, -2 * c.imag] if c is not None else [arb(0), arb(0)]
    return out


@functools.lru_cache(maxsize=32)
def reduced_equation(geometry: Geometry) -> ReducedEquation:
    """The coefficient matrix C of f(phi; r) for ``geometry``, enclosed in float intervals."""
    with ctx.workprec(_PRECISION):
        cache: dict[tuple[int, int, int], list] = {}

        def at(r: tuple[int, int, int]) -> list:
            if r not in cache:
                cache[r] = _fourier(reduction(geometry, [arb(v) for v in r]).f)
            return cache[r]

        unit = ((1, 0, 0), (0, 1, 0), (0, 0, 1))
        f0 = at((0, 0, 0))
        plus = [at(e) for e in unit]
        minus = [at(tuple(-v for v in e)) for e in unit]
        linear = [[(p - m) / 2 for p, m in zip(plus[i], minus[i])] for i in range(3)]
        square = [[(p + m) / 2 - c for p, m, c in zip(plus[i], minus[i], f0)] for i in range(3)]
        columns = [f0, *linear]
        for i, j in MONOMIALS[4:]:
            if i == j:
                columns.append(square[i])
            else:
                both = at(tuple(a + b for a, b in zip(unit[i], unit[j])))
                # f(e_i + e_j) = f0 + L_i + L_j + S_i + S_j + (coefficient of r_i r_j)
                columns.append([b - c - li - lj - si - sj for b, c, li, lj, si, sj in
                                zip(both, f0, linear[i], linear[j], square[i], square[j])])
        lo = np.empty((7, 10))
        hi = np.empty((7, 10))
        for m, col in enumerate(columns):
            for h, value in enumerate(col):
                lo[h, m], hi[h, m] = arb_to_bounds(value)
    return ReducedEquation(Interval(lo, hi))


@functools.lru_cache(maxsize=32)
def denominator(geometry: Geometry) -> Interval:
    """Enclosures (3,) of (d_0, d_1, d_2) with D(phi) = d_0 + d_1 cos phi + d_2 sin phi, from the exact geometry.

    D is the Laurent polynomial of :func:`intervalkin.kinematics.sextic.reduction` (harmonics -1..1),
    independent of r; its real Fourier coefficients are read as in :func:`_fourier`.
    """
    with ctx.workprec(_PRECISION):
        D = reduction(geometry, [arb(0), arb(0), arb(0)]).D
        d1 = D.get(1)
        values = [D[0].real, 2 * d1.real, -2 * d1.imag] if d1 is not None else [D[0].real, arb(0), arb(0)]
        bounds = [arb_to_bounds(v) for v in values]
    return Interval(np.array([b[0] for b in bounds]), np.array([b[1] for b in bounds]))


@dataclass(frozen=True, eq=False)
class AlignedNumerator:
    """s(phi; r) = sum_h basis_h(phi) (S[h, 0] + sum_i S[h, i] r_i) and |m_2(phi)|^2 = sum_h basis_h(phi) L[h].

    basis = (1, cos phi, sin phi, cos 2 phi, sin 2 phi, cos 3 phi, sin 3 phi), as in
    :data:`intervalkin.kinematics.reduced_equation.HARMONICS`.

    Attributes
    ----------
    coefficients : Interval (7, 4), enclosures of S.
    leg_square : Interval (7,), enclosures of L.
    """

    coefficients: Interval
    leg_square: Interval


@functools.lru_cache(maxsize=32)
def aligned_numerator(geometry: Geometry) -> AlignedNumerator:
    """The coefficients of s = m_2 x N and of |m_2|^2 for ``geometry``: near the zeros of D the reduced equation
    is bounded below by s^2 / |m_2|^2 - r_1 D^2, which a box enclosure of f cannot see (proofs/lemma-gap-at-d-zeros.md).
    s is affine in r: its values at r = 0 and r = e_i determine it exactly."""
    with ctx.workprec(_PRECISION):
        base, leg = aligned_laurent(geometry, [arb(0)] * 3)
        base = _fourier(base)
        columns = [base] + [[x - b for x, b in zip(_fourier(aligned_laurent(geometry, [arb(int(i == j)) for j in range(3)])[0]), base)]
                            for i in range(3)]
        lo, hi = np.empty((7, 4)), np.empty((7, 4))
        for m, col in enumerate(columns):
            for h, value in enumerate(col):
                lo[h, m], hi[h, m] = arb_to_bounds(value)
        bounds = [arb_to_bounds(v) for v in _fourier(leg)]
    return AlignedNumerator(Interval(lo, hi), Interval(np.array([b[0] for b in bounds]), np.array([b[1] for b in bounds])))
