"""Krawczyk exclusion in arb: a pose box PROVED to hold no singular pose with its joint vector in R.

Let R = R_1 x R_2 x R_3 be a joint box and X a box of poses (x, y, phi) (three balls).
For an axis k with (i, j) the other two and p = (r_i, r_j),

    E_k(X; p) = (rho_i^2(X) - r_i^2, rho_j^2(X) - r_j^2, det A(X)).

A singular pose X* in X with g(X*) in R is a zero of E_k(.; p) for p = (rho_i(X*), rho_j(X*))
in R_i x R_j, for each of the three axes.  Row by row the mean-value theorem gives
E_k(X*; p) - E_k(m; p) = J (X* - m) with J in the enclosure E_k'(X) (E_k' does not depend
on p), so for ANY real matrix Y

    X* = m - Y E_k(m; p) + (I - Y J)(X* - m)  lies in  K_k = m - Y E_k(m; P) + (I - Y E_k'(X))(X - m)

(P the balls of r_i^2, r_j^2 over R).  Hence X* lies in X ∩ K_0 ∩ K_1 ∩ K_2, and repeating
with that smaller box (a new E' and Y) keeps it.  When some intersection is empty (the
balls are proved disjoint in one coordinate) there is no such X*: :func:`excluded`.  This
is part 6 of proofs/lemma-fold-joint-box.md redone in arb; proofs/lemma-clear-joint-box.md,
"Exclusion in the checker", says how the torus search uses it.  Y is the float midpoint of
an arb inverse of the midpoint of E_k'(X): its only role is to make K small.
Standard library and python-flint only.
"""

from __future__ import annotations

from flint import arb, arb_mat

from intervalkin.checker.model import ArbModel, leg_sq
from intervalkin.checker.taylor import slope_enclosure

__all__ = ["EXCLUSION_ROUNDS", "excluded"]

#: Intersections X <- X ∩ K_0 ∩ K_1 ∩ K_2 tried before the box is given up (left undecided).
EXCLUSION_ROUNDS = 4
_ZERO, _ONE = arb(0), arb(1)
_UNIT = ((_ONE, _ZERO, _ZERO), (_ZERO, _ONE, _ZERO), (_ZERO, _ZERO, _ONE))


def _inverse_mid(J: list):
    """The float midpoint of an arb inverse of the midpoint of J, or None (not invertible in arb)."""
    try:
        inv = arb_mat([[v.mid() for v in row] for row in J]).inv()
    except (ZeroDivisionError, ValueError):
        return None
    return [[inv[r, c].mid() for c in range(3)] for r in range(3)]


def excluded(model: ArbModel, X: list, r_sq: list, rounds: int = EXCLUSION_ROUNDS) -> bool:
    """PROVED: the balls X = (x, y, phi) hold no pose with det A = 0 and rho_l^2 in r_sq[l] (l = 0, 1, 2).

    r_sq : three balls enclosing R_l^2.  False means only "not proved" (module docstring).
    """
    fs = [leg_sq(model, l) for l in range(3)] + [model.det]
    X = list(X)
    for _ in range(rounds):
        J = [[slope_enclosure(f, X, e) for e in _UNIT] for f in fs]  # rows: rho_0^2, rho_1^2, rho_2^2, det
        M = [v.mid() for v in X]
        D = [x - m for x, m in zip(X, M)]
        r = model.rho_sq(*M)
        e = [r[l] - r_sq[l] for l in range(3)] + [model.det(*M)]
        new = list(X)
        for k in range(3):
            rows = [l for l in range(3) if l != k] + [3]
            Jk = [J[l] for l in rows]
            Y = _inverse_mid(Jk)
            if Y is None:
                continue
            for a in range(3):
                K = M[a] - sum(Y[a][b] * e[rows[b]] for b in range(3)) + sum(
                    ((_ONE if a == c else _ZERO) - sum(Y[a][b] * Jk[b][c] for b in range(3))) * D[c]
                    for c in range(3))
                if not new[a].overlaps(K):
                    return True
                new[a] = new[a].intersection(K)
        X = new
    return False
