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
(:func:`intervalkin.kinematics.formulas.det_a_arb`); should that enclosure meet
0, the Krawczyk inclusion itself proves every Jacobian in the box non-singular,
so the sign at the midpoint (evaluated in arb) is the sign over the whole box.

The reduction is written in :mod:`intervalkin.kinematics.sextic`, the Krawczyk
test in :mod:`intervalkin.solve.krawczyk`, the result types in
:mod:`intervalkin.solve.solutions`; this module reads the joint vector and
runs the certification above, raising the precision until it succeeds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from decimal import Decimal, InvalidOperation
from fractions import Fraction
from typing import Sequence

import numpy as np
from flint import acb_poly, arb, ctx, fmpq

from intervalkin.core.errors import InputError
from intervalkin.core.exact import exact_text
from intervalkin.core.geometry import Geometry
from intervalkin.kinematics.sextic import (
    Reduction,
    choose_shift,
    laurent_value,
    reduction,
    sextic_coefficients,
)
from intervalkin.solve.krawczyk import box_bounds, disjoint_mod_2pi, krawczyk
from intervalkin.solve.solutions import DkpResult, DkpSolution

__all__ = ['PRECISIONS', 'MAX_WIDTH', 'parse_joint_vector', 'solve']

#: Working precisions tried in turn (bits); the last one is the ceiling.
PRECISIONS: tuple[int, ...] = (64, 128, 256, 512)
#: Every unique enclosure is narrower than this in each coordinate.
MAX_WIDTH = 1e-9


# --------------------------------------------------------------------------------------
# Input
# --------------------------------------------------------------------------------------
def parse_joint_vector(geometry: Geometry, values: Sequence) -> tuple[Fraction, Fraction, Fraction]:
    """Read three leg lengths exactly and check them against the joint limits.

    Parameters
    ----------
    geometry : Geometry
        Supplies the limits [rho_min_i, rho_max_i].
    values : sequence of three values
        Exact numbers (Fraction or int, taken as they are) or decimal text such
        as ``"14.98"`` (read exactly: 14.98 is 1498/100); any other value is
        read through its text (a float 14.98 through ``"14.98"``).

    Returns
    -------
    (rho_1, rho_2, rho_3) : three Fractions.

    Raises
    ------
    InputError
        Wrong number of values, a non-number, NaN or infinity, or a value
        outside its leg's limits; the one-line message names the leg, the
        allowed range and what came in.
    """
    if len(values) != 3:
        raise InputError(f"joint vector: expected 3 leg lengths, got {len(values)}")
    out = []
    for i, text in enumerate(values):
        leg = f"rho_{i + 1}"
        lo, hi = geometry.rho_min[i], geometry.rho_max[i]
        allowed = f"[{exact_text(lo)}, {exact_text(hi)}]"
        if isinstance(text, (Fraction, int)) and not isinstance(text, bool):
            v = Fraction(text)
        else:
            try:
                d = Decimal(str(text).strip())
            except (InvalidOperation, ValueError):
                raise InputError(f"{leg}: expected a decimal number in {allowed}, got {text!r}") from None
            if not d.is_finite():
                raise InputError(f"{leg}: expected a finite number in {allowed}, got {text!r}")
            v = Fraction(d)
        if not lo <= v <= hi:
            raise InputError(f"{leg}: {text} is outside the joint limits {allowed}")
        out.append(v)
    return (out[0], out[1], out[2])


# --------------------------------------------------------------------------------------
# One attempt at one precision
# --------------------------------------------------------------------------------------
def _solution(K, sign: int) -> DkpSolution:
    aspect = "WA1" if sign > 0 else ("WA2" if sign < 0 else None)
    return DkpSolution(box=box_bounds(K), det_sign=sign, aspect=aspect, status="unique")


def _add_if_disjoint(sols: list, s: DkpSolution) -> None:
    """Append ``s`` unless it may overlap a box already in ``sols``."""
    if all(disjoint_mod_2pi(s.box, o.box) for o in sols):
        sols.append(s)


def _lift(red: Reduction, pm) -> np.ndarray:
    """The float pose (x, y, phi) of the solution at the angle ``pm`` (an arb point): z = N / D."""
    Nm = laurent_value(red.N, pm)
    Dm = laurent_value(red.D, pm).real
    x = red.a1[0] + Nm.real / Dm
    y = red.a1[1] + Nm.imag / Dm
    return np.array([float(x.mid()), float(y.mid()), math.remainder(float(pm.mid()), math.tau)])


@dataclass
class _Attempt:
    solutions: list
    complete: bool
    reason: str
    candidates: list  # float starting points, for the fallback


def _attempt(geometry: Geometry, rho, rho_sq, prec: int) -> _Attempt:
    red = reduction(geometry, rho_sq)
    shift = choose_shift(red)
    if shift is None:
        return _Attempt([], False, "reduced equation f(phi) could not be proved non-zero at any trial angle "
                        "(it may vanish identically: architecturally singular manipulator)", [])
    phi0, _lead = shift
    coeffs = sextic_coefficients(red, phi0)
    if coeffs[6].contains(0):  # the leading coefficient is f(phi0 + pi): must be proved non-zero
        return _Attempt([], False, f"leading coefficient of the reduced sextic not proved non-zero at {prec} bits",
                        _float_candidates(coeffs, phi0, red))
    try:
        roots = acb_poly(coeffs).roots(maxprec=2 * prec)
    except ValueError:
        cand = _float_candidates(coeffs, phi0, red)
        return _Attempt([], False, f"roots of the reduced sextic not isolated at {prec} bits "
                        "(multiple or clustered roots: q on or near the image of the singular surface, "
                        "or a singular 2x2 system at a root)", cand)
    real_t = []
    for i, z in enumerate(roots):
        if not z.imag.contains(0):
            continue
        mirror = z.conjugate()
        if any(mirror.overlaps(w) for j, w in enumerate(roots) if j != i):
            return _Attempt([], False, f"could not decide whether a root near t = {complex(z.mid())} is real "
                            f"at {prec} bits", _float_candidates(coeffs, phi0, red))
        real_t.append(z.real)
    n_real = len(real_t)
    starts = []
    for t in real_t:
        phi = arb(phi0) + 2 * t.atan()
        if laurent_value(red.D, phi).real.contains(0):
            return _Attempt([], False, f"2x2 linear system may be singular at a root phi ~ {float(phi.mid()):.6g} "
                            f"of the reduced equation ({prec} bits)", _float_candidates(coeffs, phi0, red))
        starts.append(_lift(red, phi.mid()))
    sols = []
    failures = []
    for s in starts:
        got, why = krawczyk(geometry, rho_sq, s, prec)
        if got is None:
            failures.append((s, why))
        else:
            sols.append(_solution(*got))
    for a in range(len(sols)):
        for b in range(a + 1, len(sols)):
            if not disjoint_mod_2pi(sols[a].box, sols[b].box):
                kept: list = []
                for s in sols:
                    _add_if_disjoint(kept, s)
                return _Attempt(kept, False, f"two certified boxes could not be separated at {prec} bits",
                                [f[0] for f in failures])
    if failures:
        return _Attempt(sols, False, f"{len(failures)} of {n_real} real roots not certified by Krawczyk at "
                        f"{prec} bits: {failures[0][1]}", [f[0] for f in failures])
    if any(s.width >= MAX_WIDTH for s in sols):
        return _Attempt(sols, False, f"an enclosure is not narrower than {MAX_WIDTH:g}", [])
    return _Attempt(sols, True, f"{n_real} real roots of the reduced sextic (t = tan((phi - {phi0:g})/2), "
                    f"leading coefficient f({phi0:g} + pi) != 0) isolated at {prec} bits, 2x2 system regular at "
                    f"each, {len(sols)} disjoint Krawczyk boxes", [])


def _float_candidates(coeffs, phi0: float, red: Reduction) -> list:
    """Approximate solutions from the float roots of P (for the fallback only)."""
    c = np.array([float(v.mid()) for v in coeffs])[::-1]
    while len(c) > 1 and c[0] == 0.0:
        c = c[1:]
    if len(c) < 2:
        return []
    out = []
    for t in np.roots(c):
        if abs(t.imag) > 1e-4 * (1.0 + abs(t)):
            continue
        pm = arb(phi0 + 2.0 * math.atan(t.real))
        if laurent_value(red.D, pm).real.contains(0):
            continue
        out.append(_lift(red, pm))
    return out


# --------------------------------------------------------------------------------------
# Public solver
# --------------------------------------------------------------------------------------
def solve(geometry: Geometry, rho: Sequence[Fraction]) -> DkpResult:
    """Every real solution of the direct kinematic problem, proved.

    Parameters
    ----------
    geometry : Geometry
    rho : three Fractions (or ints)
        Exact leg lengths; rho_i^2 is formed exactly (fmpq).  Use
        :func:`parse_joint_vector` to read decimal strings and check the limits.

    Returns
    -------
    DkpResult
        Solutions sorted by increasing phi.  Each ``"unique"`` solution is a box
        narrower than 1e-9 PROVED (Krawczyk, arb) to contain exactly one solution
        of the original equations F_i = |B_i - A_i|^2 - rho_i^2 = 0, with the
        sign of det A PROVED on it.  ``complete`` True means it is also PROVED
        that there are no other solutions with phi anywhere on the circle (the
        certified real-root count of the reduced sextic equals the number of
        disjoint unique boxes, and the lost angle and the singular-2x2 angles are
        excluded).  Precision is raised 64 -> 128 -> 256 -> 512 bits; past the
        ceiling the result has ``complete`` False, a reason, the unique boxes that
        could still be proved and ``"unknown"`` entries for the rest.

    Examples
    --------
    >>> from intervalkin.core.geometry import default_geometry
    >>> g = default_geometry()
    >>> r = solve(g, parse_joint_vector(g, ["14.98", "15.38", "12.0"]))
    >>> r.count, r.complete, [s.aspect for s in r.solutions]
    (6, True, ['WA2', 'WA1', 'WA1', 'WA2', 'WA2', 'WA1'])
    """
    rho_f = tuple(Fraction(r) for r in rho)
    if len(rho_f) != 3:
        raise InputError(f"joint vector: expected 3 leg lengths, got {len(rho_f)}")
    if any(r <= 0 for r in rho_f):
        raise InputError(f"joint vector: leg lengths must be positive, got {[str(r) for r in rho_f]}")
    old = ctx.prec
    last = None
    try:
        for prec in PRECISIONS:
            ctx.prec = prec
            rho_sq = [arb(fmpq((r * r).numerator, (r * r).denominator)) for r in rho_f]
            att = _attempt(geometry, rho_f, rho_sq, prec)
            if att.complete:
                return _result(rho_f, att.solutions, True, att.reason, prec)
            last = (att, prec, rho_sq)
        att, prec, rho_sq = last  # type: ignore[misc]
        sols = list(att.solutions)
        for start in att.candidates:
            got, why = krawczyk(geometry, rho_sq, start, prec)
            if got is not None:
                _add_if_disjoint(sols, _solution(*got))
                continue
            box = np.array([[v - 1e-6, v + 1e-6] for v in start])
            _add_if_disjoint(sols, DkpSolution(box=box, det_sign=0, aspect=None, status="unknown", reason=why))
        return _result(rho_f, sols, False, att.reason, prec)
    finally:
        ctx.prec = old


def _result(rho, sols, complete, reason, prec) -> DkpResult:
    ordered = tuple(sorted(sols, key=lambda s: float(s.midpoint[2])))
    return DkpResult(rho=rho, solutions=ordered, complete=complete, completeness_reason=reason, precision=prec)
