"""Direct-kinematic solutions re-proved: one solution per box, and no others.

For a joint vector q = (rho_1, rho_2, rho_3) (exact) and a list of boxes with
declared det A signs, the checker proves:

1. each box holds exactly one solution of the ORIGINAL system
   F_i(X) = |B_i - A_i|^2 - rho_i^2 = 0: the Krawczyk image
   K(X) = m - Y F(m) + (I - Y F'(X)) (X - m) lies strictly inside the box in every
   coordinate, with Y chosen here (never read from the file)
   (proofs/lemma-krawczyk-uniqueness.md);
2. det A has the declared sign on the whole box;
3. the boxes are pairwise disjoint as sets of poses, phi read modulo 2 pi;
4. for a claim of completeness, that there are no other solutions: the reduced
   sextic P(t) in t = tan((phi - phi0) / 2) is rebuilt by a real-polynomial
   derivation of the checker's own (the solver uses Laurent polynomials in
   exp(i phi)), its leading coefficient f(phi0 + pi) is proved non-zero (so no
   solution hides at t = infinity), its roots are isolated by ``acb_poly.roots``,
   the real ones counted, the 2x2 linear system proved regular at each, and that
   count must equal the number of boxes (proofs/lemma-dkp-completeness.md).
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any

from flint import acb_poly, arb, arb_mat, arb_poly

from intervalkin.checker.model import ArbModel, balls, exact_ball, has_sign
from intervalkin.checker.parse import Box, Refused, get, read_box, read_float

__all__ = ['krawczyk_unique', 'disjoint_mod_2pi', 'reduced_sextic', 'count_solutions', 'prove_solution_box',
           'check_solutions']


def krawczyk_unique(model: ArbModel, box: Box, rho_sq) -> bool:
    """PROVED: F has exactly one zero in ``box`` (proofs/lemma-krawczyk-uniqueness.md).

    K(X) = m - Y F(m) + (I - Y F'(X)) (X - m), m a binary64 point of the box, Y
    the midpoint of an arb inverse of F'(m) (computed here: the file cannot
    choose it), K evaluated in arb; K strictly inside the box in every
    coordinate proves the claim.
    """
    X = balls(box)
    m = [lo + (hi - lo) / 2 for lo, hi in box]
    if not all(lo <= mj <= hi for (lo, hi), mj in zip(box, m)):
        return False
    M = [arb(v) for v in m]
    F = model.residual(M[0], M[1], M[2], rho_sq)
    try:
        Yb = arb_mat(model.jacobian(M[0], M[1], M[2])).inv()
    except (ZeroDivisionError, ValueError):
        return False
    Y = [[Yb[r, c].mid() for c in range(3)] for r in range(3)]
    JX = model.jacobian(X[0], X[1], X[2])
    for r in range(3):
        acc = M[r] - sum(Y[r][c] * F[c] for c in range(3))
        for c in range(3):
            cij = (1 if r == c else 0) - sum(Y[r][k] * JX[k][c] for k in range(3))
            acc += cij * (X[c] - M[c])
        lo, hi = box[r]
        if not ((acc - arb(lo)) > 0 and (arb(hi) - acc) > 0):
            return False
    return True


def disjoint_mod_2pi(b1: Box, b2: Box) -> bool:
    """PROVED: the boxes share no pose of R^2 x S^1 (phi read modulo 2 pi); phi widths < pi."""
    for j in (0, 1):
        if b1[j][1] < b2[j][0] or b2[j][1] < b1[j][0]:
            return True
    c1 = (arb(b1[2][0]) + arb(b1[2][1])) / 2
    c2 = (arb(b2[2][0]) + arb(b2[2][1])) / 2
    h = (arb(b1[2][1]) - arb(b1[2][0]) + arb(b2[2][1]) - arb(b2[2][0])) / 2
    if not h < arb.pi():
        return False
    diff = c1 - c2  # the phi differences of the two boxes fill [diff - h, diff + h]
    k = round(float(diff.mid()) / (2 * math.pi))
    # no multiple of 2 pi in that interval: the three nearest are checked, the others are
    # at least 3 pi away from diff (k is within 1/2 + rounding of diff / 2 pi) and h < pi
    return all(bool(abs(diff - 2 * j * arb.pi()) > h) for j in (k - 1, k, k + 1))


def reduced_sextic(model: ArbModel, rho_sq, phi0: float) -> list:
    """Coefficients (arb, low to high) of P(t) = (1 + t^2)^3 f(phi0 + 2 atan t).

    Derivation in real polynomials: z = B1 - A1, a_i = A_i - A1, e_i = R(phi) p_i.
    For i = 2, 3, F_i - F_1 = m_i . z - k_i with m_i = 2 (e_i - a_i) and
    k_i = rho_i^2 - rho_1^2 - |p_i|^2 - |a_i|^2 + 2 a_i . e_i.  With
    phi = phi0 + psi, w = 1 + t^2, cos psi = (1 - t^2)/w, sin psi = 2t/w, the
    vectors E_i = w e_i = (1 - t^2) p'_i + 2t J p'_i (p'_i = R(phi0) p_i, J the
    quarter turn), M_i = w m_i and K_i = w k_i are polynomials of degree 2;
    w^2 D = M_2 x M_3, w^2 N = (K_2 M_3y - K_3 M_2y, M_2x K_3 - M_3x K_2) and
    Q = |w^2 N|^2 - rho_1^2 (w^2 D)^2 = w^4 f = w P.  P is the exact quotient
    of Q by w (long division: each coefficient of P is a signed sum of
    coefficients of Q, so the balls enclose the exact P); the remainder must
    contain 0, a consistency check.
    """
    c0, s0 = arb(phi0).cos(), arb(phi0).sin()
    w = arb_poly([1, 0, 1])
    one_m = arb_poly([1, 0, -1])
    two_t = arb_poly([0, 2])
    a1x, a1y = model.A[0]
    g = model.geometry
    M, K = {}, {}
    for i in (1, 2):
        px, py = model.p[i]
        qx, qy = px * c0 - py * s0, px * s0 + py * c0  # p'_i = R(phi0) p_i
        Ex = one_m * qx - two_t * qy
        Ey = one_m * qy + two_t * qx
        ax, ay = model.A[i][0] - a1x, model.A[i][1] - a1y
        M[i] = (2 * (Ex - w * ax), 2 * (Ey - w * ay))
        a_sq = exact_ball((g.base[i][0] - g.base[0][0]) ** 2 + (g.base[i][1] - g.base[0][1]) ** 2)
        const = rho_sq[i] - rho_sq[0] - exact_ball(g.platform_radius_sq(i)) - a_sq
        K[i] = w * const + 2 * (Ex * ax + Ey * ay)
    Dw = M[1][0] * M[2][1] - M[1][1] * M[2][0]
    Nx = K[1] * M[2][1] - K[2] * M[1][1]
    Ny = M[1][0] * K[2] - M[2][0] * K[1]
    Q = Nx * Nx + Ny * Ny - rho_sq[0] * (Dw * Dw)
    q = [Q[k] if k < len(Q) else arb(0) for k in range(9)]
    P = [arb(0)] * 9
    for k in range(8, 1, -1):  # Q_k = P_{k-2} + P_k
        P[k - 2] = q[k] - P[k]
    r1, r0 = q[1] - P[1], q[0] - P[0]
    if not (r1.contains(0) and r0.contains(0)):
        raise Refused("internal check: the quartic-in-w numerator is not divisible by 1 + t^2")
    return P[:7]


def count_solutions(model: ArbModel, rho_sq, phi0: float, maxprec: int) -> int:
    """PROVED number of poses (phi modulo 2 pi) with F = 0 (proofs/lemma-dkp-completeness.md)."""
    P = reduced_sextic(model, rho_sq, phi0)
    if P[6].contains(0):
        raise Refused(f"leading coefficient f(phi0 + pi) of the reduced sextic not proved non-zero (phi0 = {phi0!r})")
    try:
        roots = acb_poly(P).roots(maxprec=maxprec)
    except ValueError:
        raise Refused("the roots of the reduced sextic could not be isolated "
                      "(double root: q on or near g(S))") from None
    if len(roots) != 6:
        raise Refused(f"root isolation returned {len(roots)} roots for a polynomial of degree 6")
    n_real = 0
    for i, z in enumerate(roots):
        if not z.imag.contains(0):
            continue
        mirror = z.conjugate()
        if any(mirror.overlaps(v) for j, v in enumerate(roots) if j != i):
            raise Refused(f"could not decide whether the root near t = {complex(z.mid())} is real")
        phi = arb(phi0) + 2 * z.real.atan()
        if model.D(phi).contains(0):
            raise Refused(f"the 2x2 system may be singular at the root phi ~ {float(phi.mid()):.6g}")
        n_real += 1
    return n_real


def prove_solution_box(model: ArbModel, box: Box, rho_sq, sign: int, what: str, sign_note: str = "") -> None:
    """Refuse unless ``box`` (phi width < 1 rad) holds exactly one solution and det A has ``sign`` on it.

    ``what`` names the box in the messages; ``sign_note`` follows the sign in them.
    """
    if not box[2][1] - box[2][0] < 1.0:
        raise Refused(f"{what}: phi width {box[2][1] - box[2][0]!r} is not < 1 rad")
    if not krawczyk_unique(model, box, rho_sq):
        raise Refused(f"{what}: the Krawczyk test does not prove a unique solution of q in the box")
    d = model.det(*balls(box))
    if not has_sign(d, sign):
        raise Refused(f"{what}: det A is not proved {'> 0' if sign > 0 else '< 0'}{sign_note} on the box "
                      f"({d.str(5)})")


def check_solutions(model: ArbModel, rho: tuple[Fraction, ...], sols: list, complete: bool, phi0: Any,
                    prec: int) -> dict:
    """Re-prove a list of solution boxes of q = rho, and completeness when claimed.

    Returns the facts used by ``counts``: n, n_wa1, n_wa2, complete.
    """
    rho_sq = [exact_ball(r * r) for r in rho]
    boxes, signs = [], []
    for k, s in enumerate(sols):
        if not isinstance(s, dict):
            raise Refused(f"solution {k}: expected an object")
        b = read_box(get(s, "box"), f"solution {k} box")
        sign = get(s, "det_sign")
        if sign not in (1, -1):
            raise Refused(f"solution {k}: det_sign must be 1 or -1, got {sign!r}")
        prove_solution_box(model, b, rho_sq, sign, f"solution {k}")
        boxes.append(b)
        signs.append(sign)
    for a in range(len(boxes)):
        for c in range(a + 1, len(boxes)):
            if not disjoint_mod_2pi(boxes[a], boxes[c]):
                raise Refused(f"solutions {a} and {c}: boxes not proved disjoint (phi modulo 2 pi)")
    n1 = sum(1 for s in signs if s > 0)
    facts = {"n": len(boxes), "n_wa1": n1, "n_wa2": len(boxes) - n1, "complete": False}
    if complete:
        p0 = read_float(phi0, "phi0")
        n_real = count_solutions(model, rho_sq, p0, maxprec=max(4 * prec, 256))
        if n_real != len(boxes):
            raise Refused(f"the reduced sextic has {n_real} real roots but {len(boxes)} solution boxes are listed")
        facts["complete"] = True
    return facts
