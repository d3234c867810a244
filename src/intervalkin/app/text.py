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

from intervalkin.solve.dkp import DkpResult, _fmt_fraction

__all__ = ['format_dkp_table']


# --------------------------------------------------------------------------------------
# Human output
# --------------------------------------------------------------------------------------
def format_dkp_table(result: DkpResult) -> str:
    """A human table: solutions numbered from 1 in increasing phi.

    Columns: x, y, phi (box midpoints, 12 decimals), the largest enclosure
    width, sign of det A, aspect, status; then whether completeness was proved.
    """
    rho = ", ".join(_fmt_fraction(r) for r in result.rho)
    lines = [f"rho = ({rho}): {result.count} solution(s)"]
    head = f"{'#':>2}  {'x':>18}  {'y':>18}  {'phi (rad)':>16}  {'width':>8}  {'det A':>5}  {'aspect':>6}  status"
    lines.append(head)
    lines.append("-" * len(head))
    for i, s in enumerate(result.solutions, 1):
        x, y, phi = s.midpoint
        sign = {1: "+", -1: "-"}.get(s.det_sign, "?")
        line = (f"{i:>2}  {x:>18.12f}  {y:>18.12f}  {phi:>16.12f}  {s.width:>8.1e}  {sign:>5}  "
                f"{s.aspect or '-':>6}  {s.status}")
        if s.status != "unique":
            line += f" ({s.reason})"
        lines.append(line)
    if result.complete:
        lines.append(f"completeness PROVED: no other solutions ({result.completeness_reason})")
    else:
        lines.append(f"completeness NOT proved: {result.completeness_reason}")
    return "\n".join(lines)
