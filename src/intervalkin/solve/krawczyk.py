"""Certified direct kinematics of the 3-RPR: every assembly mode of a joint vector.

Problem
-------
Given exact leg lengths rho = (rho_1, rho_2, rho_3), find every pose
X = (x, y, phi), phi taken modulo 2 pi, with

    F_i(X) = |B_i(X) - A_i|^2 - rho_i^2 = 0,   i = 1, 2, 3        (paper eq. 1-3)

(B_1 = (x, y), B_i = B_1 + R(phi) p_i).  The joint limits play no part here: they
only say which joint vectors may be asked.

Reduction to one equation in phi (DESIGN.md section 3)
------------------------------------------------------
Write z = B_1 - A_1, a_i = A_i - A_1 and e_i = R(phi) p_i.  For fixed phi,
F_i - F_1 is linear in z:

    m_i . z = k_i,   m_i = 2 (e_i - a_i),   k_i = rho_i^2 - rho_1^2 - |e_i - a_i|^2,

i = 2, 3.  With D = m_2 x m_3 (2-D cross product) Cramer's rule gives
D z = N, N = (k_2 m_3y - k_3 m_2y, m_2x k_3 - m_3x k_2), and substituting into
F_1 = |z|^2 - rho_1^2 gives the reduced equation

    f(phi) = |N(phi)|^2 - rho_1^2 D(phi)^2 = 0.

In complex notation (omega = exp(i phi), e_i = p_i omega) D has harmonics
-1..1, N has harmonics -1..2 and f is a real trigonometric polynomial of degree
3 (the harmonics of order 4 cancel because N has no omega^-2 term).  With a
shift phi_0 and t = tan((phi - phi_0) / 2),

    P(t) = (1 + t^2)^3 f(phi_0 + 2 atan t)

is a real polynomial of degree at most 6 whose leading coefficient is
f(phi_0 + pi): phi_0 is chosen so that this coefficient is PROVED non-zero, which
removes the angle lost by the substitution (t infinite) and makes deg P = 6.

Facts the proof uses (see proofs/lemma-dkp-completeness.md):

* every solution has f(phi) = 0: M z = k gives N = adj(M) k = adj(M) M z = D z,
  so |N|^2 = D^2 |z|^2 = rho_1^2 D^2 (this holds also where D = 0);
* where D(phi) != 0, a root phi of f gives exactly one solution,
  z = N / D, at that phi;
* where D(phi) = 0 the reduction says nothing useful (the 2x2 system is singular;
  f has a root there exactly when N = 0 too, and that root is double), so every
  real root must come with a proof that D does not vanish on its enclosure.

Certification
-------------
At a working precision p (64, 128, 256, 512 bits, ``ctx.prec`` scoped):

1. The coefficients of P are arb balls computed from the exact geometry
   (:meth:`Surd.arb`, Fractions) and the exact rho_i^2 (fmpq).
2. ``acb_poly.roots`` isolates the six complex roots in pairwise disjoint
   rectangles, each PROVED to contain exactly one root (flint's
   ``acb_poly_validate_roots``).  A rectangle R holds a REAL root when its
   imaginary part meets 0 and its mirror image conj(R) meets no other rectangle
   (the mirror root must then be the root of R itself); it holds a non-real root
   when its imaginary part excludes 0.  Otherwise the precision is raised.
3. For each real root, D is PROVED non-zero on the phi enclosure.
4. Each real root is lifted (z = N / D at high precision, Newton refinement on
   the original system) and a box X is PROVED by the Krawczyk test on the
   ORIGINAL 3x3 system to contain exactly one solution:
   K(X) = m - Y F(m) + (I - Y F'(X)) (X - m) strictly inside X in every
   coordinate, Y a float inverse of F'(m) (proofs/lemma-krawczyk-uniqueness.md).
5. The boxes are PROVED pairwise disjoint (modulo 2 pi in phi).

When all of this succeeds, the boxes hold n distinct solutions and the
reduction proves there are exactly n, so there are NO OTHER solutions:
``complete`` is True.  If any step fails at the ceiling precision, the result
says so (``complete`` False with a reason) and lists what could be proved; boxes
that could not be proved are listed with status ``"unknown"``.  A joint vector on
the image g(S) of the singular surface (a double root) always ends this way:
the solver never returns an unproved count.

The sign of det A is proved on each unique box by an arb evaluation over the box
(:func:`kinematics.det_a_arb`); should that enclosure meet 0, the Krawczyk
inclusion itself proves every Jacobian in the box non-singular, so the sign at
the midpoint (evaluated in arb) is the sign over the whole box.
"""

from __future__ import annotations

import math

import numpy as np

from intervalkin.core.exact import arb_to_bounds
from intervalkin.core.geometry import Geometry
from intervalkin.kinematics.formulas import (
    approx_jacobian,
    det_a_arb,
    jacobian_arb,
    residual_arb,
)


# --------------------------------------------------------------------------------------
# Krawczyk on the original 3x3 system
# --------------------------------------------------------------------------------------
def _krawczyk(geometry: Geometry, rho_sq, start: np.ndarray, prec: int):
    """Try to prove a unique solution near ``start`` (float (x, y, phi)).

    Returns (K balls [x, y, phi], det_sign) on success, or (None, reason).
    """
    from flint import arb

    m = [arb(float(v)) for v in start]
    Yf = None
    delta = None
    # Newton refinement in arb with a float inverse (converges linearly, rate ~ cond * eps).
    for it in range(12):
        mf = np.array([float(v.mid()) for v in m])
        if it == 0 or it % 3 == 0:
            J = approx_jacobian(geometry, mf)
            if not np.all(np.isfinite(J)) or abs(np.linalg.det(J)) == 0.0:
                return None, "Jacobian singular at the approximate solution"
            Yf = np.linalg.inv(J)
        F = residual_arb(geometry, m[0], m[1], m[2], rho_sq)
        delta = [sum(arb(float(Yf[r, c])) * F[c] for c in range(3)) for r in range(3)]
        step = max(abs(float(d.mid())) for d in delta)
        m = [(mi - di).mid() for mi, di in zip(m, delta)]
        scale = 1.0 + max(abs(float(v.mid())) for v in m)
        if step <= scale * 2.0 ** (-prec + 8):
            break
    # normalise phi into (-pi, pi]
    pi = arb.pi()
    if m[2] > pi:
        m[2] = (m[2] - 2 * pi).mid()
    elif not (m[2] > -pi):
        m[2] = (m[2] + 2 * pi).mid()
    mf = np.array([float(v.mid()) for v in m])
    J = approx_jacobian(geometry, mf)
    try:
        Yf = np.linalg.inv(J)
    except np.linalg.LinAlgError:
        return None, "Jacobian singular at the approximate solution"
    if not np.all(np.isfinite(Yf)):
        return None, "Jacobian singular at the approximate solution"
    Y = [[arb(float(Yf[r, c])) for c in range(3)] for r in range(3)]
    F = residual_arb(geometry, m[0], m[1], m[2], rho_sq)
    YF = [sum(Y[r][c] * F[c] for c in range(3)) for r in range(3)]
    size = max(float(abs(v).upper()) for v in YF)
    scale = 1.0 + float(np.max(np.abs(mf)))
    r0 = max(1e3 * size, scale * 2.0 ** (-prec + 24))
    reason = "Krawczyk image not inside the box (Jacobian singular or nearly singular on the box)"
    radii = sorted({min(r, 2e-10) for r in (r0, r0 * 1e2, r0 * 1e4)})
    for r in radii:
        X = [mi + arb(0, r) for mi in m]
        JX = jacobian_arb(geometry, X[0], X[1], X[2])
        K = []
        ok = True
        for row in range(3):
            acc = m[row] - YF[row]
            for col in range(3):
                cij = (1 if row == col else 0) - sum(Y[row][l] * JX[l][col] for l in range(3))
                acc += cij * arb(0, r)
            if not X[row].contains_interior(acc):
                ok = False
                break
            K.append(acc)
        if not ok:
            continue
        # a box holding the seam is written around +pi (the representative in (-pi, pi])
        if K[2].contains(-pi):
            K[2] = K[2] + 2 * pi
        det = det_a_arb(geometry, K[0], K[1], K[2])
        if det > 0:
            sign = 1
        elif det < 0:
            sign = -1
        else:
            # K inside X proves every Jacobian on X non-singular: the sign is constant.
            dm = det_a_arb(geometry, m[0], m[1], m[2])
            sign = 1 if dm > 0 else (-1 if dm < 0 else 0)
        return (K, sign), ""
    return None, reason


def _box_of(K) -> np.ndarray:
    return np.array([arb_to_bounds(k) for k in K], dtype=np.float64)


def _disjoint(b1: np.ndarray, b2: np.ndarray) -> bool:
    """PROVED: the boxes share no point of R^2 x S^1 (phi modulo 2 pi)."""
    from flint import arb

    for j in (0, 1):
        if b1[j, 1] < b2[j, 0] or b2[j, 1] < b1[j, 0]:
            return True
    m1 = (arb(b1[2, 0]) + arb(b1[2, 1])) / 2
    m2 = (arb(b2[2, 0]) + arb(b2[2, 1])) / 2
    h = (arb(b1[2, 1]) - arb(b1[2, 0]) + arb(b2[2, 1]) - arb(b2[2, 0])) / 2
    diff = m1 - m2
    kk = round(float(diff.mid()) / _TWO_PI)
    d = diff - 2 * kk * arb.pi()
    return bool(abs(d) > h)


_TWO_PI = 2.0 * math.pi
