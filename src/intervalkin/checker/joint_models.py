"""``joint_fold_model`` claims: one sheet of g(S) across a joint box, re-proved in arb.

A claim names a joint box R (exact rationals), an axis k, a pose box X (binary64) and
the connectivity criterion used (proofs/lemma-fold-joint-box.md, proofs/lemma-joint-claims.md).
With (i, j) the other two axes and, for p = (r_i, r_j),

    E(X; p) = (rho_i^2(X) - r_i^2, rho_j^2(X) - r_j^2, det A(X)),

the checker proves, from the geometry alone:

1. R lies in the joint limits and X holds a 2 pi-translate of every singular pose whose
   joint vector lies in R (:func:`~intervalkin.checker.joint_torus.torus_search`, cover mode);
2. the parametric Krawczyk image K = m - Y E(m; R_i x R_j) + C (X - m) lies strictly inside X
   (m the binary64 midpoint of X, Y the midpoint of an arb inverse of E'(m) chosen here,
   C = I - Y E'(X) in arb): for every p, E(.; p) has exactly one zero X*(p) in X, and
   g(S) meets R in the graph q_k = h(q_i, q_j) = rho_k(X*(q_i, q_j));
3. the stated criterion, which makes each of the two sides B = {q_k < h} and
   T = {q_k > h} of R connected: ``height_inside`` (rho_k over a contracted image lies
   strictly inside R_k), ``normal_signs`` (the signs of w_i, w_j, w_k certified over it,
   w = (u_2 x u_3, u_3 x u_1, u_1 x u_2)), or ``edge_heights`` along b (signs of w_b and w_k
   certified; h > lo_k on the edge where h is largest along b, h < hi_k on the opposite one);
4. each stated witness lies in R and on its stated side (:meth:`FoldProof.side`).

The contracted images X_{n+1} = X_n ∩ K(X_n; P) use the same Y and C (valid over any box
inside X) and keep X*(p) for every p in P.  Standard library and python-flint only.
"""

from __future__ import annotations

from fractions import Fraction

from flint import arb, arb_mat

from intervalkin.checker.joint_torus import JointBox, torus_search
from intervalkin.checker.model import ArbModel, balls, exact_ball, leg_sq
from intervalkin.checker.parse import Refused, get, parse_exact, read_box, read_int
from intervalkin.checker.taylor import slope_enclosure, value_enclosure

__all__ = ["CRITERIA", "SIDE_STEPS", "FoldProof", "read_joint_box", "read_joint_point", "in_joint_box",
           "check_joint_fold_model"]

#: The connectivity criteria of proofs/lemma-fold-joint-box.md, point 3 (a), (b), (c).
CRITERIA = ("height_inside", "normal_signs", "edge_heights")
#: Contraction steps of the side test and of the height enclosures.
SIDE_STEPS = 6
#: Steps of the side test with Y and C taken again over the shrunk balls, where the first ones leave it open.
FRESH_STEPS = 3
#: Sub-boxes per axis over which E'(X) is enclosed, tried in turn until the Krawczyk test passes.
SPLITS = (1, 2, 4)
_ZERO, _ONE = arb(0), arb(1)
_UNIT = ((_ONE, _ZERO, _ZERO), (_ZERO, _ONE, _ZERO), (_ZERO, _ZERO, _ONE))


def read_joint_box(obj, what: str = "box") -> JointBox:
    """[[lo, hi]] * 3 of exact strings, 0 < lo < hi."""
    if not isinstance(obj, list) or len(obj) != 3:
        raise Refused(f"{what}: expected three [lo, hi] pairs of exact strings, got {obj!r}")
    out = []
    for a, pair in enumerate(obj):
        if not isinstance(pair, list) or len(pair) != 2:
            raise Refused(f"{what}[{a}]: expected [lo, hi], got {pair!r}")
        lo, hi = (parse_exact(v, f"{what}[{a}]") for v in pair)
        if not 0 < lo < hi:
            raise Refused(f"{what}[{a}]: expected 0 < lo < hi, got [{lo}, {hi}]")
        out.append((lo, hi))
    return tuple(out)


def read_joint_point(obj, what: str) -> tuple[Fraction, Fraction, Fraction]:
    """Three exact strings (a joint vector)."""
    if not isinstance(obj, list) or len(obj) != 3:
        raise Refused(f"{what}: expected three exact strings, got {obj!r}")
    return tuple(parse_exact(v, f"{what}[{a}]") for a, v in enumerate(obj))  # type: ignore[return-value]


def in_joint_box(q, box: JointBox) -> bool:
    """Whether the point q lies in the closed box (exact comparisons)."""
    return all(lo <= v <= hi for v, (lo, hi) in zip(q, box))


def _others(k: int) -> tuple[int, int]:
    return tuple(a for a in range(3) if a != k)  # type: ignore[return-value]


def _span(lo: Fraction, hi: Fraction):
    return arb.union(exact_ball(lo), exact_ball(hi))


class FoldProof:
    """The Krawczyk proof of one fold model: R, k, X and the checker's own Y and C = I - Y E'(X)."""

    def __init__(self, model: ArbModel, box: JointBox, axis: int, pose):
        self.model, self.box, self.k = model, box, axis
        self.i, self.j = _others(axis)
        self.pose = pose
        self.X = balls(pose)
        m = [lo + (hi - lo) / 2 for lo, hi in pose]
        M = [arb(v) for v in m]
        try:
            inv = arb_mat(self._derivative(M)).inv()
        except (ZeroDivisionError, ValueError):
            raise Refused("E' is not invertible at the midpoint of the pose box") from None
        self.Y = [[inv[r, c].mid() for c in range(3)] for r in range(3)]
        P = (_span(*box[self.i]), _span(*box[self.j]))
        for pieces in SPLITS:  # E'(X) as the hull over pieces x pieces x pieces sub-boxes: tighter, same claim
            J = self._derivative_hull(pose, pieces)
            self.C = [[(_ONE if r == c else _ZERO) - sum(self.Y[r][t] * J[t][c] for t in range(3)) for c in range(3)]
                      for r in range(3)]
            K = self.image(self.X, P)
            bad = [a for a in range(3) if not (K[a] > arb(pose[a][0]) and K[a] < arb(pose[a][1]))]
            if not bad:
                return
        a = bad[0]
        raise Refused(f"the parametric Krawczyk image is not strictly inside the pose box in coordinate {a} "
                      f"(image {K[a].str(5, radius=True)}, box [{pose[a][0]!r}, {pose[a][1]!r}])")

    def _derivative_hull(self, pose, pieces: int) -> list[list]:
        """E' over the pose box, as the union of its enclosures over a grid of pieces^3 sub-boxes (they cover it)."""
        cuts = [[lo + (hi - lo) * s / pieces for s in range(pieces + 1)] for lo, hi in pose]
        for c, (lo, hi) in zip(cuts, pose):
            c[0], c[-1] = lo, hi
        out = None
        for a in range(pieces):
            for b in range(pieces):
                for c in range(pieces):
                    sub = balls(((cuts[0][a], cuts[0][a + 1]), (cuts[1][b], cuts[1][b + 1]),
                                 (cuts[2][c], cuts[2][c + 1])))
                    J = self._derivative(sub)
                    out = J if out is None else [[u.union(v) for u, v in zip(ru, rv)] for ru, rv in zip(out, J)]
        return out

    def _derivative(self, X) -> list[list]:
        """E'(X) over balls X: the gradients of rho_i^2, rho_j^2 and det A, each partial derivative the
        natural form intersected with its mean-value form (:func:`~intervalkin.checker.taylor.slope_enclosure`)."""
        fs = (leg_sq(self.model, self.i), leg_sq(self.model, self.j), self.model.det)
        return [[slope_enclosure(f, X, e) for e in _UNIT] for f in fs]

    def image(self, X: list, P: tuple, YC: tuple | None = None) -> list:
        """The Krawczyk image of the balls X (inside the pose box) for parameter balls P = (r_i, r_j), with the
        proof's Y and C, or with ``YC`` = (Y, C = I - Y E'(X')) for a box X' holding X."""
        Y, C = (self.Y, self.C) if YC is None else YC
        M = [v.mid() for v in X]
        r = self.model.rho_sq(*M)
        E = [r[self.i] - P[0] * P[0], r[self.j] - P[1] * P[1], self.model.det(*M)]
        D = [x - m for x, m in zip(X, M)]
        return [M[a] - sum(Y[a][b] * E[b] for b in range(3)) + sum(C[a][b] * D[b] for b in range(3))
                for a in range(3)]

    def _preconditioner(self, X: list) -> tuple | None:
        """(Y, C) taken again over the balls X: Y the midpoint of the inverse of E' at X's midpoint (any Y will
        do), C = I - Y E'(X); None where E' at the midpoint is not invertible."""
        try:
            inv = arb_mat(self._derivative([arb(v.mid()) for v in X])).inv()
        except (ZeroDivisionError, ValueError):
            return None
        Y = [[inv[r, c].mid() for c in range(3)] for r in range(3)]
        J = self._derivative(X)
        C = [[(_ONE if r == c else _ZERO) - sum(Y[r][t] * J[t][c] for t in range(3)) for c in range(3)]
             for r in range(3)]
        return Y, C

    def contract(self, P: tuple, steps: int = SIDE_STEPS, X: list | None = None, fresh: bool = False) -> list:
        """Balls holding X*(p) for every p in P: X (the pose box) intersected with successive images, made
        with the proof's Y and C, or (``fresh``) with Y and C taken again over the current balls."""
        X = list(self.X) if X is None else X
        for _ in range(steps):
            YC = self._preconditioner(X) if fresh else None
            if fresh and YC is None:
                break
            K = self.image(X, P, YC)
            if not all(x.overlaps(v) for x, v in zip(X, K)):
                raise Refused("a contracted image is empty: the pose box holds no zero (contradicts the proof)")
            X = [x.intersection(v) for x, v in zip(X, K)]
        return X

    def height_sq(self, P: tuple):
        """An enclosure of h^2 = rho_k^2(X*(p)) over the parameter balls P (natural form ∩ second-order Taylor form)."""
        return value_enclosure(leg_sq(self.model, self.k), self.contract(P))

    def side(self, q) -> int:
        """-1 when q_k < h(q_i, q_j) is PROVED, +1 when q_k > h is, 0 undecided (q: exact, inside R).  Where the
        proof's C leaves it open (its norm near 1 stalls the steps), FRESH_STEPS more with Y and C taken again
        over the shrunk balls (proofs/lemma-fold-joint-box.md, point 5)."""
        P = (exact_ball(q[self.i]), exact_ball(q[self.j]))
        qk2 = exact_ball(q[self.k] * q[self.k])
        X = self.contract(P)
        for fresh in (False, True):
            if fresh:
                X = self.contract(P, FRESH_STEPS, X, fresh=True)
            h2 = value_enclosure(leg_sq(self.model, self.k), X)
            if qk2 < h2 or qk2 > h2:
                return -1 if qk2 < h2 else 1
        return 0

    def normal_signs(self, X: list) -> list[int]:
        """Certified signs of w_l = u_m x u_n over the balls X (0: not proved); natural ∩ Taylor forms."""
        out = []
        for l in range(3):
            w = value_enclosure(_cross(self.model, (l + 1) % 3, (l + 2) % 3), X)
            out.append(1 if w > 0 else -1 if w < 0 else 0)
        return out


def _cross(model: ArbModel, m: int, n: int):
    """u_m x u_n (u_l = B_l - A_l) as a function of (x, y, phi), products only (for jet arguments, checker.taylor)."""
    def u(l, x, y, phi):
        ax, ay = model.A[l]
        if l == 0:
            return x - ax, y - ay
        rx, ry = model.rot_polar(phi, l)
        return x + rx - ax, y + ry - ay

    def f(x, y, phi):
        (mx, my), (nx, ny) = u(m, x, y, phi), u(n, x, y, phi)
        return mx * ny - my * nx
    return f


def _check_criterion(proof: FoldProof, crit) -> str:
    """Re-prove the stated connectivity criterion; returns its description."""
    if not isinstance(crit, dict) or crit.get("name") not in CRITERIA:
        raise Refused(f"criterion: expected {{\"name\": one of {', '.join(CRITERIA)}}}, got {crit!r}")
    name, box, k = crit["name"], proof.box, proof.k
    full = (_span(*box[proof.i]), _span(*box[proof.j]))
    lo2, hi2 = exact_ball(box[k][0] ** 2), exact_ball(box[k][1] ** 2)
    if name == "height_inside":
        h2 = proof.height_sq(full)
        if not (h2 > lo2 and h2 < hi2):
            raise Refused(f"criterion height_inside: rho_k^2 over the contracted image, {h2.str(5, radius=True)}, "
                          f"is not strictly inside R_k^2")
        return "the sheet's height lies strictly inside R_k"
    sg = proof.normal_signs(proof.contract(full))
    if name == "normal_signs":
        if 0 in sg:
            raise Refused(f"criterion normal_signs: the signs of w are not all certified over the image ({sg})")
        return "h is monotone in both parameters (signs of w certified)"
    b = read_int(get(crit, "along"), "criterion along", 0, 2)
    if b == k:
        raise Refused("criterion edge_heights: along must be a parameter axis, not the sheet's axis")
    if sg[b] == 0 or sg[k] == 0:
        raise Refused(f"criterion edge_heights: the signs of w_{b} and w_{k} are not certified over the image ({sg})")
    rising = -sg[b] * sg[k] > 0  # dh/dr_b = -rho_b w_b / (rho_k w_k)
    top, low = (box[b][1], box[b][0]) if rising else (box[b][0], box[b][1])
    for at, want_above in ((top, True), (low, False)):
        P = tuple(exact_ball(at) if ax == b else _span(*box[ax]) for ax in (proof.i, proof.j))
        h2 = proof.height_sq(P)
        if not ((h2 > lo2) if want_above else (h2 < hi2)):
            raise Refused(f"criterion edge_heights: h is not proved {'above lo_k' if want_above else 'below hi_k'} "
                          f"on the edge rho_{b} = {at}")
    return f"h is monotone along rho_{b} and its end edges stay inside R_k"


def check_joint_fold_model(model: ArbModel, claim: dict, prec: int) -> tuple[str, dict]:
    """Re-prove one ``joint_fold_model`` claim (module docstring); facts: {"fold": FoldProof}."""
    box = read_joint_box(get(claim, "box"))
    g = model.geometry
    if not all(g.rho_min[a] <= box[a][0] and box[a][1] <= g.rho_max[a] for a in range(3)):
        raise Refused("box: not inside the joint limits")
    k = read_int(get(claim, "axis"), "axis", 0, 2)
    pose = read_box(get(claim, "pose"), "pose")
    proof = FoldProof(model, box, k, pose)
    how = _check_criterion(proof, get(claim, "criterion"))
    wit = claim.get("witnesses", {})
    if not isinstance(wit, dict) or not set(wit) <= {"below", "above"}:
        raise Refused(f"witnesses: expected {{\"below\": q, \"above\": q}} (either optional), got {wit!r}")
    for name, want in (("below", -1), ("above", 1)):
        if wit.get(name) is None:
            continue
        q = read_joint_point(wit[name], f"witnesses {name}")
        if not in_joint_box(q, box):
            raise Refused(f"witnesses {name}: not inside the box")
        if proof.side(q) != want:
            raise Refused(f"witnesses {name}: not proved {name} the sheet (q_{k} {'<' if want < 0 else '>'} h)")
    ok, detail = torus_search(model, box, pose)
    if not ok:
        raise Refused(f"the pose box is not proved to hold every singular pose of the box: {detail}")
    return (f"g(S) meets the joint box in one sheet q_{k} = h(q_{proof.i}, q_{proof.j}) (the singular poses of the "
            f"box lie in the pose box, {detail}; parametric Krawczyk proved); {how}: the box minus g(S) is two "
            f"connected pieces, below and above the sheet"
            + ("" if not wit else f"; witnesses placed ({', '.join(sorted(n for n in wit if wit[n] is not None))})")), \
        {"fold": proof}
