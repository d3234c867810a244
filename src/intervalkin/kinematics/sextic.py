"""The direct kinematics reduced to one polynomial: the sextic P(t), in arb (used by solve.dkp).

For exact leg lengths rho the direct kinematics asks for every pose X = (x, y, phi) with

    F_i(X) = |B_i(X) - A_i|^2 - rho_i^2 = 0,   i = 1, 2, 3            (paper eq. 1-3)

(B_1 = (x, y), B_i = B_1 + R(phi) p_i).  This module eliminates (x, y) (DESIGN.md
section 3).  Write z = B_1 - A_1, a_i = A_i - A_1 and e_i = R(phi) p_i.  For fixed phi,
F_i - F_1 (i = 2, 3) is linear in z:

    m_i . z = k_i,   m_i = 2 (e_i - a_i),   k_i = rho_i^2 - rho_1^2 - |e_i - a_i|^2.

With D = m_2 x m_3 (2-D cross product), Cramer's rule gives D z = N with
N = (k_2 m_3y - k_3 m_2y, m_2x k_3 - m_3x k_2), and F_1 = |z|^2 - rho_1^2 becomes

    f(phi) = |N(phi)|^2 - rho_1^2 D(phi)^2 = 0.

Every solution satisfies it (N = adj(M) M z = D z, also where D = 0); where D(phi) != 0 a
root phi gives exactly one solution z = N / D.  In omega = exp(i phi) (e_i = p_i omega)
D, N and f are Laurent polynomials with acb coefficients (``reduction``): D has harmonics
-1..1, N has -1..2, and f is a real trigonometric polynomial of degree 3 (the terms of
order 4 cancel: N has no omega^-2 term, so they are dropped structurally).  With a shift
phi_0 and t = tan((phi - phi_0) / 2),

    P(t) = (1 + t^2)^3 f(phi_0 + 2 atan t)                              (``sextic_coefficients``)

is a real polynomial of degree at most 6 with leading coefficient f(phi_0 + pi);
``choose_shift`` picks phi_0 with that coefficient PROVED non-zero, so that no root is
lost at t = infinity and deg P = 6.

What is certified: the coefficients of P are arb balls that contain the exact
coefficients, computed at the current ``ctx.prec`` from the exact geometry (Fractions and
:meth:`Surd.arb`) and the exact rho_i^2.  Isolating the roots, proving D != 0 on them and
lifting them to poses is :mod:`intervalkin.solve.dkp`'s work (proofs/lemma-dkp-completeness.md).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from fractions import Fraction

from intervalkin.core.geometry import Geometry

__all__ = ['Reduction', 'reduction', 'aligned_laurent', 'laurent_value', 'sextic_coefficients', 'choose_shift']


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


def laurent_value(p: dict, phi):
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
class Reduction:
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


def reduction(geometry: Geometry, rho_sq) -> Reduction:
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
    return Reduction(D=D, N=N, f=f, a1=a1)


def aligned_laurent(geometry: Geometry, rho_sq) -> tuple[dict, dict]:
    """(m_2 x N, |m_2|^2) as Laurent polynomials at the current precision (rho_sq: exact arb squares).

    Where D = 0, N is parallel to the normal of m_2 and f = |N|^2 = (m_2 x N)^2 / |m_2|^2; everywhere
    f >= (m_2 x N)^2 / |m_2|^2 - r_1 D^2 (proofs/lemma-gap-at-d-zeros.md).
    """
    from flint import acb, ctx

    p, a, _ = _constants(geometry, ctx.prec)
    m2 = _lscale({1: p[1], 0: -a[1]}, 2)
    along = _lmul(_lconj(m2), reduction(geometry, rho_sq).N)  # m x n = Im(conj(m) n) for plane vectors as complex numbers
    return _lscale(_ladd(along, _lconj(along), -1), acb(0, -0.5)), _lmul(m2, _lconj(m2))


def sextic_coefficients(red: Reduction, phi0: float):
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


def choose_shift(red: Reduction) -> tuple[float, object] | None:
    """phi0 (a float, exact in arb) with f(phi0 + pi) PROVED non-zero, preferring 0."""
    from flint import arb

    pi = arb.pi()
    best = None
    for j in range(12):
        phi0 = 0.0 if j == 0 else round(j * math.pi / 6, 6)
        v = laurent_value(red.f, arb(phi0) + pi).real
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

