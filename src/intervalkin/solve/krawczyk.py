"""The Krawczyk test on the original 3x3 system: a box PROVED to hold exactly one assembly mode.

For a joint vector q, F_i(X) = |B_i(X) - A_i|^2 - rho_i^2 (paper eq. 1-3) and
F'(X) = A(X).  Given an approximate solution, :func:`krawczyk` refines it by
Newton's method in arb (with a float inverse of the Jacobian), then forms, for
boxes X of growing radius r around the refined point m,

    K(X) = m - Y F(m) + (I - Y F'(X)) (X - m),

with Y a float inverse of F'(m) turned into exact balls, F(m) and F'(X) in arb.
If K(X) lies in the interior of X in every coordinate, X holds exactly one zero
of F and every Jacobian on X is non-singular (proofs/lemma-krawczyk-uniqueness.md);
the returned enclosure is K(X), the box that holds the solution.  The sign of
det A is then proved on it: over the whole box by an arb evaluation or, when
that enclosure meets 0, by its constant sign on X at the midpoint.

:func:`disjoint_mod_2pi` proves two such boxes apart as sets of poses, phi read modulo
2 pi, which is what makes a list of unique boxes a list of distinct solutions.
"""

from __future__ import annotations

import math

import numpy as np
from flint import arb

from intervalkin.core.exact import arb_to_bounds
from intervalkin.core.geometry import Geometry
from intervalkin.kinematics.formulas import (
    approx_jacobian,
    det_a_arb,
    jacobian_arb,
    residual_arb,
)

__all__ = ['krawczyk', 'box_bounds', 'disjoint_mod_2pi']


def krawczyk(geometry: Geometry, rho_sq, start: np.ndarray, prec: int):
    """Try to prove a unique solution near ``start`` (float (x, y, phi)).

    Returns (K balls [x, y, phi], det_sign) on success, or (None, reason).
    """
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


def box_bounds(K) -> np.ndarray:
    """Float bounds (3, 2) of the balls K, rounded outward."""
    return np.array([arb_to_bounds(k) for k in K], dtype=np.float64)


def disjoint_mod_2pi(b1: np.ndarray, b2: np.ndarray) -> bool:
    """PROVED: the boxes share no point of R^2 x S^1 (phi modulo 2 pi).

    Only the multiple of 2 pi nearest the difference of the phi centres is tried:
    for the narrow boxes of the solver (phi widths far below pi) every other
    multiple leaves the two phi ranges apart.
    """
    for j in (0, 1):
        if b1[j, 1] < b2[j, 0] or b2[j, 1] < b1[j, 0]:
            return True
    m1 = (arb(b1[2, 0]) + arb(b1[2, 1])) / 2
    m2 = (arb(b2[2, 0]) + arb(b2[2, 1])) / 2
    h = (arb(b1[2, 1]) - arb(b1[2, 0]) + arb(b2[2, 1]) - arb(b2[2, 0])) / 2
    diff = m1 - m2
    kk = round(float(diff.mid()) / math.tau)
    d = diff - 2 * kk * arb.pi()
    return bool(abs(d) > h)
