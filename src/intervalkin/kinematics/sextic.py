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

import functools
import math
from dataclasses import dataclass
from fractions import Fraction

from intervalkin.core.geometry import Geometry


# --------------------------------------------------------------------------------------
# Laurent polynomials in omega = exp(i phi), coefficients acb: dict {power: acb}
# --------------------------------------------------------------------------------------
def _lmul(p: dict, q: dict) -> dict:
    out: dict = {}
    for i, a in p.items():
        for j, b in q.items():
            k = i + j
            out[k] = out[k] + a * b if k in out else a * b
    return out


def _ladd(p: dict, q: dict, sq: int = 1) -> dict:
    out = dict(p)
    for k, b in q.items():
        out[k] = out[k] + sq * b if k in out else sq * b
    return out


def _lscale(p: dict, c) -> dict:
    return {k: c * v for k, v in p.items()}


def _lconj(p: dict) -> dict:
    """conj(L(omega)) on |omega| = 1: coefficients conjugated, powers negated."""
    return {-k: v.conjugate() for k, v in p.items()}


def _leval(p: dict, phi):
    """L(exp(i phi)) as an acb, phi an arb ball."""
    from flint import acb

    w = acb(0, phi).exp()
    wi = acb(0, -phi).exp()
    total = acb(0)
    for k, c in p.items():
        if k >= 0:
            total += c * w**k
        else:
            total += c * wi ** (-k)
    return total


@dataclass(frozen=True, eq=False)
class _Reduction:
    """D, N and f as Laurent polynomials at one precision (z = B1 - A1 = N / D)."""

    D: dict
    N: dict
    f: dict
    a1: tuple  # (A1x, A1y) as arb


@functools.lru_cache(maxsize=16)
def _basis(prec: int):
    """B_j(t) = (1 + i t)^j (1 - i t)^(6 - j), j = 0..6, exact Gaussian-integer acb_polys."""
    from flint import acb, acb_poly

    up = acb_poly([1, acb(0, 1)])
    dn = acb_poly([1, acb(0, -1)])
    return [up**j * dn ** (6 - j) for j in range(7)]


@functools.lru_cache(maxsize=32)
def _constants(geometry: Geometry, prec: int):
    """p_i and a_i = A_i - A_1 as acb, A_1 as arb: from the exact geometry."""
    from flint import acb, arb, fmpq

    def q(v: Fraction):
        return arb(fmpq(v.numerator, v.denominator))

    p = []
    for i in range(3):
        px, py = geometry.platform_point(i)
        p.append(acb(px.arb(), py.arb()))
    a1x, a1y = geometry.base[0]
    a = [acb(q(ax - a1x), q(ay - a1y)) for ax, ay in geometry.base]
    return p, a, (q(a1x), q(a1y))


def _reduce(geometry: Geometry, rho_sq) -> _Reduction:
    """The reduced equation at the current precision (rho_sq: exact arb squares)."""
    from flint import acb, ctx

    p, a, a1 = _constants(geometry, ctx.prec)
    E = {i: {1: p[i], 0: -a[i]} for i in (1, 2)}  # e_i - a_i
    m = {i: _lscale(E[i], 2) for i in (1, 2)}
    k = {i: _ladd({0: acb(rho_sq[i] - rho_sq[0])}, _lmul(E[i], _lconj(E[i])), -1) for i in (1, 2)}
    w = _lmul(_lconj(m[1]), m[2])  # D = Im(conj(m2) m3)
    D = _lscale(_ladd(w, _lconj(w), -1), acb(0, -0.5))
    N = _lscale(_ladd(_lmul(k[1], m[2]), _lmul(k[2], m[1]), -1), acb(0, -1))
    f = _ladd(_lmul(N, _lconj(N)), _lscale(_lmul(D, D), acb(rho_sq[0])), -1)
    for kk in (4, -4):  # structurally absent (N has no omega^-2 term)
        f.pop(kk, None)
    return _Reduction(D=D, N=N, f=f, a1=a1)


def _poly_t(red: _Reduction, phi0: float):
    """Coefficients (arb, low to high) of P(t) = (1 + t^2)^3 f(phi0 + 2 atan t)."""
    from flint import acb, acb_poly, arb, ctx

    basis = _basis(ctx.prec)
    rot = acb(0, arb(phi0)).exp()
    total = acb_poly([])
    for kk in range(-3, 4):
        c = red.f.get(kk)
        if c is None:
            continue
        total += basis[3 + kk] * (c * rot**kk) if kk >= 0 else basis[3 + kk] * (c * rot.conjugate() ** (-kk))
    return [total[j].real for j in range(7)]


def _choose_shift(red: _Reduction) -> tuple[float, object] | None:
    """phi0 (a float, exact in arb) with f(phi0 + pi) PROVED non-zero, preferring 0."""
    from flint import arb

    pi = arb.pi()
    best = None
    for j in range(12):
        phi0 = 0.0 if j == 0 else round(j * math.pi / 6, 6)
        v = _leval(red.f, arb(phi0) + pi).real
        if v.contains(0):
            continue
        lower = abs(float(v.mid()))
        if best is None or lower > best[2]:
            best = (phi0, v, lower)
        if j == 0 and best is not None:
            # keep phi0 = 0 unless f(pi) is small compared with the scale of f
            scale = max(abs(float(c.real.mid())) + abs(float(c.imag.mid())) for c in red.f.values())
            if lower > 1e-3 * scale:
                return best[0], best[1]
    return None if best is None else (best[0], best[1])
