"""The independent checker of intervalkin certificate files (``intervalkin verify DIR``).

A certificate folder (written by :func:`intervalkin.certify.writer.write_certificates`;
schema in that module) states claims with their evidence.  This module re-proves
every claim from the files alone, in arb ball arithmetic (python-flint), and
prints one line per claim.  Its trusted base is small on purpose:

* the Python standard library and python-flint (arb, acb, arb_poly, acb_poly,
  arb_mat; ``acb_poly.roots`` for certified complex root isolation);
* :mod:`intervalkin.core.geometry` (reads the geometry TOML stored in the files as
  exact decimals; constants as exact rationals and surds) and
  :mod:`intervalkin.core.errors`;
* the few formulas written out below (rho_i^2, det A, F, F', the reduced
  sextic), re-derived here on purpose instead of imported from
  :mod:`intervalkin.kinematics` or :mod:`intervalkin.solve.dkp`.

It never imports the paving, predicate, joint, region, dkp or analysis code
(``tests/test_certificates.py::test_checker_imports_none_of_the_checked_modules``).
What each claim type proves, and what it still trusts, is in
``proofs/lemma-checker.md``.

Re-proved per claim type
------------------------
``dkp`` / ``joint_cell``
    Each solution box holds exactly one solution of the ORIGINAL system
    F_i = |B_i - A_i|^2 - rho_i^2 (Krawczyk, the checker's own preconditioner,
    strict interior inclusion); det A has the declared sign on the whole box;
    the boxes are pairwise disjoint with phi read modulo 2 pi; and, for a claim
    of completeness, the checker rebuilds the reduced sextic in t = tan((phi -
    phi0)/2) by its own real-polynomial derivation, proves its leading
    coefficient non-zero, isolates its roots (``acb_poly.roots``), counts the
    real ones, proves the 2x2 system regular at each, and requires that count
    to equal the number of boxes.  A ``joint_cell`` claim also checks that the
    witness lies in the joint limits and that its count and aspect split are
    the ones declared.
``aspect_distinct``
    Each box lies in W (rho_min_i^2 <= rho_i^2 <= rho_max_i^2 on the whole box)
    and det A has the declared sign on the whole box (box subdivided in arb
    when the natural enclosure is too wide); the two signs are opposite.
``region_distinct``
    The joint vector's listed solutions are re-proved (Krawczyk, one aspect,
    pairwise disjoint), each solution box lies in its stated paving box, and
    that paving box's W and det-sign labels are re-proved in arb.  The
    "off S_c" label and the box-to-piece map are NOT re-checked (they need the
    joint-space enclosure of g(S)); the claim text says so.
``box_labels``
    Every INSIDE / OUTSIDE label of the sampled boxes (W and det_positive) is
    re-proved in arb over the whole box, subdividing when needed; BOUNDARY
    labels claim nothing.  The sample indices are re-derived from the seed.
``trajectory``
    The joint vector's complete solution list is re-proved as for ``dkp`` (it
    fixes the solution numbers: increasing phi in [-pi, pi]); the start and
    goal enclosures each hold exactly one solution (Krawczyk), lie in the
    listed solutions ``from`` and ``to``, and carry det A of the stated sign.
    For every piece [t0, t1] of every straight segment A + t (B - A) (A, B
    the segment's end enclosures), the ball A + [t0, t1] (B - A) is formed in
    arb and det A is proved of the aspect's sign and rho_min_i^2 <= rho_i^2 <=
    rho_max_i^2 proved on it (the t range bisected while undecided, within
    :data:`PIECE_BUDGET`); the pieces tile [0, 1]; consecutive segments share
    their end enclosure; the start enclosure lies in the first segment's
    start, and the goal enclosure shifted by 2 pi phi_turns (phi unwrapped)
    in the last segment's end.
``counts``
    Each declared lower bound is recomputed from the referenced claims that
    verified (rules in :func:`_count_bound`); a declared lower bound larger than
    the recomputed one, or a count declared exact, is refused.
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any

from intervalkin.checker.model import _balls, _Model
from intervalkin.checker.parse import _box, _float, _get, _q, _Refused


# --------------------------------------------------------------------------------------
# Direct kinematics: Krawczyk, disjointness, the reduced sextic
# --------------------------------------------------------------------------------------
def _krawczyk(model: _Model, box, rho_sq) -> bool:
    """PROVED: F has exactly one zero in ``box`` (proofs/lemma-krawczyk-uniqueness.md).

    K(X) = m - Y F(m) + (I - Y F'(X)) (X - m), m a binary64 point of the box, Y
    the midpoint of an arb inverse of F'(m) (computed here: the file cannot
    choose it), K evaluated in arb; K strictly inside the box in every
    coordinate proves the claim.
    """
    from flint import arb, arb_mat

    X = _balls(box)
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


def _disjoint_mod_2pi(b1, b2) -> bool:
    """PROVED: the boxes share no pose of R^2 x S^1 (phi read modulo 2 pi); phi widths < pi."""
    from flint import arb

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


def _reduced_sextic(model: _Model, rho_sq, phi0: float) -> list:
    """Coefficients (arb, low to high) of P(t) = (1 + t^2)^3 f(phi0 + 2 atan t).

    Own derivation, in real polynomials (dkp.py uses Laurent polynomials in
    exp(i phi)): z = B1 - A1, a_i = A_i - A1, e_i = R(phi) p_i.  For i = 2, 3,
    F_i - F_1 = m_i . z - k_i with m_i = 2 (e_i - a_i) and
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
    from flint import arb, arb_poly

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
        a_sq = _q((g.base[i][0] - g.base[0][0]) ** 2 + (g.base[i][1] - g.base[0][1]) ** 2)
        const = rho_sq[i] - rho_sq[0] - _q(g.platform_radius_sq(i)) - a_sq
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
        raise _Refused("internal check: the quartic-in-w numerator is not divisible by 1 + t^2")
    return P[:7]


def _count_solutions(model: _Model, rho_sq, phi0: float, maxprec: int) -> int:
    """PROVED number of poses (phi modulo 2 pi) with F = 0 (proofs/lemma-dkp-completeness.md)."""
    from flint import acb_poly, arb

    P = _reduced_sextic(model, rho_sq, phi0)
    if P[6].contains(0):
        raise _Refused(f"leading coefficient f(phi0 + pi) of the reduced sextic not proved non-zero (phi0 = {phi0!r})")
    try:
        roots = acb_poly(P).roots(maxprec=maxprec)
    except ValueError:
        raise _Refused("the roots of the reduced sextic could not be isolated "
                       "(double root: q on or near g(S))") from None
    if len(roots) != 6:
        raise _Refused(f"root isolation returned {len(roots)} roots for a polynomial of degree 6")
    n_real = 0
    for i, z in enumerate(roots):
        if not z.imag.contains(0):
            continue
        mirror = z.conjugate()
        if any(mirror.overlaps(v) for j, v in enumerate(roots) if j != i):
            raise _Refused(f"could not decide whether the root near t = {complex(z.mid())} is real")
        phi = arb(phi0) + 2 * z.real.atan()
        if model.D(phi).contains(0):
            raise _Refused(f"the 2x2 system may be singular at the root phi ~ {float(phi.mid()):.6g}")
        n_real += 1
    return n_real


def _check_solve(model: _Model, rho: tuple[Fraction, ...], sols: list, complete: bool, phi0: Any, prec: int) -> dict:
    """Re-prove a list of solution boxes of q = rho, and completeness when claimed.

    Returns the facts used by ``counts``: n, n_wa1, n_wa2, complete.
    """
    rho_sq = [_q(r * r) for r in rho]
    boxes, signs = [], []
    for k, s in enumerate(sols):
        if not isinstance(s, dict):
            raise _Refused(f"solution {k}: expected an object")
        b = _box(_get(s, "box"), f"solution {k} box")
        sign = _get(s, "det_sign")
        if sign not in (1, -1):
            raise _Refused(f"solution {k}: det_sign must be 1 or -1, got {sign!r}")
        if not b[2][1] - b[2][0] < 1.0:
            raise _Refused(f"solution {k}: phi width {b[2][1] - b[2][0]!r} is not < 1 rad")
        if not _krawczyk(model, b, rho_sq):
            raise _Refused(f"solution {k}: the Krawczyk test does not prove a unique solution in the box")
        d = model.det(*_balls(b))
        if not (d > 0 if sign > 0 else d < 0):
            raise _Refused(f"solution {k}: det A is not proved {'> 0' if sign > 0 else '< 0'} on the box ({d.str(5)})")
        boxes.append(b)
        signs.append(sign)
    for a in range(len(boxes)):
        for c in range(a + 1, len(boxes)):
            if not _disjoint_mod_2pi(boxes[a], boxes[c]):
                raise _Refused(f"solutions {a} and {c}: boxes not proved disjoint (phi modulo 2 pi)")
    n1 = sum(1 for s in signs if s > 0)
    facts = {"n": len(boxes), "n_wa1": n1, "n_wa2": len(boxes) - n1, "complete": False}
    if complete:
        p0 = _float(phi0, "phi0")
        n_real = _count_solutions(model, rho_sq, p0, maxprec=max(4 * prec, 256))
        if n_real != len(boxes):
            raise _Refused(f"the reduced sextic has {n_real} real roots but {len(boxes)} solution boxes are listed")
        facts["complete"] = True
    return facts
