"""The independent checker of intervalkin certificate files (``intervalkin verify DIR``).

A certificate folder (written by :func:`intervalkin.certificates.write_certificates`;
schema in that module) states claims with their evidence.  This module re-proves
every claim from the files alone, in arb ball arithmetic (python-flint), and
prints one line per claim.  Its trusted base is small on purpose:

* the Python standard library and python-flint (arb, acb, arb_poly, acb_poly,
  arb_mat; ``acb_poly.roots`` for certified complex root isolation);
* :mod:`intervalkin.geometry` (reads the geometry TOML stored in the files as
  exact decimals; constants as exact rationals and surds) and
  :mod:`intervalkin.errors`;
* the few formulas written out below (rho_i^2, det A, F, F', the reduced
  sextic), re-derived here on purpose instead of imported from
  :mod:`intervalkin.kinematics` or :mod:`intervalkin.dkp`.

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

import decimal
import hashlib
import json
import math
import tomllib
from collections import deque
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import Any, Callable

from .errors import GeometryError, InputError
from .geometry import Geometry, parse_geometry

__all__ = [
    "FORMAT",
    "VERSION",
    "KINDS",
    "CertificateFormatError",
    "CheckResult",
    "verify_directory",
    "format_results",
    "sample_indices",
    "parse_exact",
    "check_claim",
    "box_label_proved",
]

FORMAT = "intervalkin-certificate"
VERSION = 1
#: Claim files, in the order they are checked (``counts`` last: it uses the others).
KINDS = ("dkp", "joint_cell", "aspect_distinct", "region_distinct", "box_labels", "trajectory", "counts")
INDEX = "index.json"

#: Sub-box evaluations allowed per re-proved box label (the box is bisected while undecided).
LABEL_BUDGET = 20000
#: Evaluations allowed per piece of a trajectory segment (the piece's t range is bisected while undecided).
PIECE_BUDGET = 2000
#: Precisions (bits) accepted in a file.
_PREC_RANGE = (53, 4096)


class CertificateFormatError(InputError):
    """A certificate folder is missing, unreadable or not in the documented format."""


@dataclass(frozen=True)
class CheckResult:
    """The checker's verdict on one claim.

    ``verified`` is True only when every step of the claim was re-proved;
    ``message`` says what was proved, or the first step that failed.
    """

    file: str
    claim: str
    kind: str
    verified: bool
    message: str

    def line(self) -> str:
        head = f"{self.file}#{self.claim} ({self.kind})"
        return f"verified: {head}: {self.message}" if self.verified else f"FAILED: {head} because {self.message}"


class _Refused(Exception):
    """A claim that could not be re-proved (the message says which step failed)."""


# --------------------------------------------------------------------------------------
# Exact inputs
# --------------------------------------------------------------------------------------
def parse_exact(text: Any, what: str = "value") -> Fraction:
    """An exact rational from a string "p/q" or a decimal "14.98" (JSON numbers are refused)."""
    if not isinstance(text, str):
        raise _Refused(f"{what}: expected an exact string such as \"1498/100\" or \"14.98\", got {text!r}")
    try:
        if "/" in text:
            return Fraction(text.strip())
        d = decimal.Decimal(text.strip())
    except (ValueError, ZeroDivisionError, decimal.InvalidOperation):
        raise _Refused(f"{what}: {text!r} is not an exact rational") from None
    if not d.is_finite():
        raise _Refused(f"{what}: {text!r} is not finite")
    return Fraction(d)


def _float(v: Any, what: str) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise _Refused(f"{what}: expected a number, got {v!r}")
    f = float(v)
    if not math.isfinite(f):
        raise _Refused(f"{what}: {v!r} is not finite")
    return f


def _box(obj: Any, what: str = "box", number=None) -> tuple[tuple[float, float], ...]:
    """[[xlo, xhi], [ylo, yhi], [philo, phihi]] as binary64 numbers (or ``number``-parsed strings), lo <= hi."""
    number = _float if number is None else number
    if not isinstance(obj, list) or len(obj) != 3:
        raise _Refused(f"{what}: expected [[xlo, xhi], [ylo, yhi], [philo, phihi]], got {obj!r}")
    out = []
    for j, pair in enumerate(obj):
        if not isinstance(pair, list) or len(pair) != 2:
            raise _Refused(f"{what}[{j}]: expected [lo, hi], got {pair!r}")
        lo, hi = number(pair[0], f"{what}[{j}][0]"), number(pair[1], f"{what}[{j}][1]")
        if not lo <= hi:
            raise _Refused(f"{what}[{j}]: empty interval [{lo!r}, {hi!r}]")
        out.append((lo, hi))
    return tuple(out)


def _int(v: Any, what: str, lo: int | None = None, hi: int | None = None) -> int:
    if isinstance(v, bool) or not isinstance(v, int):
        raise _Refused(f"{what}: expected an integer, got {v!r}")
    if (lo is not None and v < lo) or (hi is not None and v > hi):
        raise _Refused(f"{what}: {v} is outside [{lo}, {hi}]")
    return v


def _get(claim: dict, key: str) -> Any:
    if key not in claim:
        raise _Refused(f"missing field {key!r}")
    return claim[key]


def sample_indices(seed: int, population: int, size: int) -> list[int]:
    """The sampled box indices: draw j gives sha256("intervalkin-sample:{seed}:{j}") mod population.

    Duplicates are skipped until ``min(size, population)`` distinct indices are
    drawn.  Defined with the standard library only, so that a reader can check
    that a sample was not chosen by hand.
    """
    want = min(size, population)
    out: list[int] = []
    seen: set[int] = set()
    j = 0
    while len(out) < want:
        h = hashlib.sha256(f"intervalkin-sample:{seed}:{j}".encode()).digest()
        k = int.from_bytes(h[:8], "big") % population
        if k not in seen:
            seen.add(k)
            out.append(k)
        j += 1
    return out


# --------------------------------------------------------------------------------------
# The manipulator in arb (formulas written out again, see the module docstring)
# --------------------------------------------------------------------------------------
def _q(v: Fraction):
    from flint import arb, fmpq

    return arb(fmpq(v.numerator, v.denominator))


def _sqr(v):
    """v^2 as a ball, without the sign loss of v * v when v straddles 0."""
    from flint import arb

    if v > 0 or v < 0:
        return v * v
    u = v.abs_upper()
    return arb.union(arb(0), u * u)


def _ball(lo: float, hi: float):
    """A ball containing the real interval [lo, hi] (binary64 bounds)."""
    from flint import arb

    return arb.union(arb(lo), arb(hi))


class _Model:
    """Constants of one geometry at the current precision, and the arb formulas.

    Notation (DESIGN.md sections 1-2): B1 = (x, y), r_i = R(phi) p_i,
    u_i = B1 + r_i - A_i, rho_i^2 = |u_i|^2, F_i = rho_i^2 - (given rho_i)^2,
    row i of A = dF/dX = 2 (u_ix, u_iy, r_i x u_i) with a x b = a_x b_y - a_y b_x.
    """

    def __init__(self, geometry: Geometry):
        from flint import arb

        self.geometry = geometry
        self.A = [(_q(ax), _q(ay)) for ax, ay in geometry.base]
        self.p = [tuple(c.arb() for c in geometry.platform_point(i)) for i in range(3)]
        # polar form of p_i (one occurrence of phi per coordinate: tighter over wide boxes)
        self.L = [_q(geometry.platform_radius_sq(i)).sqrt() for i in range(3)]
        self.alpha = [arb(0)] + [arb.atan2(self.p[i][1], self.p[i][0]) for i in (1, 2)]
        self.rmin2 = [_q(v * v) for v in geometry.rho_min]
        self.rmax2 = [_q(v * v) for v in geometry.rho_max]

    # --- r_i in two forms -------------------------------------------------------------
    def rot(self, phi, i: int):
        """r_i = R(phi) p_i from the Cartesian platform coordinates (for points and thin boxes)."""
        c, s = phi.cos(), phi.sin()
        px, py = self.p[i]
        return px * c - py * s, px * s + py * c

    def rot_polar(self, phi, i: int):
        """r_i = L_i (cos(phi + alpha_i), sin(phi + alpha_i)) (for wide boxes)."""
        t = phi + self.alpha[i]
        return self.L[i] * t.cos(), self.L[i] * t.sin()

    # --- formulas -----------------------------------------------------------------------
    def rho_sq(self, x, y, phi) -> list:
        """rho_i^2 = (x + r_ix - A_ix)^2 + (y + r_iy - A_iy)^2, enclosed over balls."""
        out = []
        for i in range(3):
            ax, ay = self.A[i]
            if i == 0:
                out.append(_sqr(x - ax) + _sqr(y - ay))
            else:
                rx, ry = self.rot_polar(phi, i)
                out.append(_sqr(x + rx - ax) + _sqr(y + ry - ay))
        return out

    def det(self, x, y, phi):
        """det A = 8 [u1x (d2y w3 - w2 d3y) - u1y (d2x w3 - w2 d3x)].

        Row 1 of A is 2 (u_1, 0) (r_1 = 0); subtracting it from rows 2 and 3 leaves
        2 (d_i, w_i) with d_i = u_i - u_1 = r_i - A_i + A_1 and
        w_i = r_i x u_i = r_i x (B1 - A_i) (r_i x r_i = 0); expanding along the
        third column gives the formula (degree 2 in x, y: the cubic terms cancel).
        """
        a1x, a1y = self.A[0]
        u1x, u1y = x - a1x, y - a1y
        d, w = [], []
        for i in (1, 2):
            ax, ay = self.A[i]
            rx, ry = self.rot_polar(phi, i)
            d.append((rx - ax + a1x, ry - ay + a1y))
            w.append(rx * (y - ay) - ry * (x - ax))
        (d2x, d2y), (d3x, d3y) = d
        w2, w3 = w
        return 8 * (u1x * (d2y * w3 - w2 * d3y) - u1y * (d2x * w3 - w2 * d3x))

    def residual(self, x, y, phi, rho_sq) -> list:
        """F_i = |B_i - A_i|^2 - rho_i^2 (the original system, paper eq. 1-3)."""
        out = []
        for i in range(3):
            ax, ay = self.A[i]
            rx, ry = (0, 0) if i == 0 else self.rot(phi, i)
            out.append((x + rx - ax) ** 2 + (y + ry - ay) ** 2 - rho_sq[i])
        return out

    def jacobian(self, x, y, phi) -> list[list]:
        """F' = A, rows 2 (u_ix, u_iy, r_i x u_i) (r_1 = 0)."""
        rows = []
        for i in range(3):
            ax, ay = self.A[i]
            if i == 0:
                ux, uy = x - ax, y - ay
                rows.append([2 * ux, 2 * uy, 0 * ux])
            else:
                rx, ry = self.rot(phi, i)
                ux, uy = x + rx - ax, y + ry - ay
                rows.append([2 * ux, 2 * uy, 2 * (rx * uy - ry * ux)])
        return rows

    def D(self, phi):
        """D(phi) = m_2 x m_3, m_i = 2 (r_i - (A_i - A_1)): the determinant of the 2x2 system."""
        a1x, a1y = self.A[0]
        m = []
        for i in (1, 2):
            rx, ry = self.rot(phi, i)
            ax, ay = self.A[i]
            m.append((2 * (rx - (ax - a1x)), 2 * (ry - (ay - a1y))))
        return m[0][0] * m[1][1] - m[0][1] * m[1][0]


# --------------------------------------------------------------------------------------
# Certified answers over boxes (subdivided while undecided)
# --------------------------------------------------------------------------------------
def _holds_on_box(box, test: Callable, budget: int = LABEL_BUDGET) -> bool:
    """True when ``test`` (True = certain) holds on sub-boxes that cover ``box``.

    Bisects the widest side (phi weighted by the platform size, since a turn of
    d phi moves B_i by about L_i d phi) until each sub-box is decided or the
    budget of evaluations is spent (then False: not proved).
    """
    stack = [tuple(box)]
    evals = 0
    while stack:
        b = stack.pop()
        evals += 1
        if evals > budget:
            return False
        if test(b):
            continue
        widths = [b[0][1] - b[0][0], b[1][1] - b[1][0], 20.0 * (b[2][1] - b[2][0])]
        k = max(range(3), key=lambda j: widths[j])
        lo, hi = b[k]
        mid = lo + (hi - lo) / 2
        if not lo < mid < hi:
            return False
        left, right = list(b), list(b)
        left[k], right[k] = (lo, mid), (mid, hi)
        stack += [tuple(left), tuple(right)]
    return True


def _balls(b):
    return [_ball(lo, hi) for lo, hi in b]


def _in_w(model: _Model, b) -> bool:
    r = model.rho_sq(*_balls(b))
    return all(r[i] >= model.rmin2[i] and r[i] <= model.rmax2[i] for i in range(3))


def _out_w(model: _Model, b) -> bool:
    r = model.rho_sq(*_balls(b))
    return any(r[i] < model.rmin2[i] or r[i] > model.rmax2[i] for i in range(3))


def _det_positive(model: _Model, b) -> bool:
    return bool(model.det(*_balls(b)) > 0)


def _det_negative(model: _Model, b) -> bool:
    return bool(model.det(*_balls(b)) < 0)


def _prove_label(model: _Model, box, name: str, value: int) -> bool | None:
    """Re-prove one label (1 OUTSIDE, 2 INSIDE) of W or det_positive; None when it claims nothing."""
    tests = {
        ("W", 2): _in_w,
        ("W", 1): _out_w,
        ("det_positive", 2): _det_positive,
        ("det_positive", 1): _det_negative,
    }
    if value == 3:
        return None
    if (name, value) not in tests:
        raise _Refused(f"label {name} = {value!r}: not a label this checker knows (W, det_positive: 1, 2 or 3)")
    fn = tests[(name, value)]
    return _holds_on_box(box, lambda b: fn(model, b))


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


# --------------------------------------------------------------------------------------
# One checker per claim type
# --------------------------------------------------------------------------------------
def _rho(claim: dict, key: str = "rho") -> tuple[Fraction, Fraction, Fraction]:
    v = _get(claim, key)
    if not isinstance(v, list) or len(v) != 3:
        raise _Refused(f"{key}: expected three exact strings, got {v!r}")
    r = tuple(parse_exact(t, f"{key}[{i}]") for i, t in enumerate(v))
    if any(x <= 0 for x in r):
        raise _Refused(f"{key}: leg lengths must be positive")
    return r  # type: ignore[return-value]


def _strictly_in_limits(g: Geometry, rho) -> bool:
    return all(g.rho_min[i] < rho[i] < g.rho_max[i] for i in range(3))


def _check_dkp(model: _Model, claim: dict, prec: int) -> tuple[str, dict]:
    rho = _rho(claim)
    complete = _get(claim, "complete")
    if not isinstance(complete, bool):
        raise _Refused("complete: expected true or false")
    sols = _get(claim, "solutions")
    if not isinstance(sols, list):
        raise _Refused("solutions: expected a list")
    facts = _check_solve(model, rho, sols, complete, claim.get("phi0"), prec)
    declared = claim.get("count")
    if declared is not None and declared != facts["n"]:
        raise _Refused(f"declared count {declared!r} but {facts['n']} solution boxes are listed")
    facts.update(rho=rho, in_limits=_strictly_in_limits(model.geometry, rho))
    q = ", ".join(str(r) for r in rho)
    if complete:
        msg = (f"q = ({q}) has exactly {facts['n']} solutions ({facts['n_wa1']} with det A > 0, "
               f"{facts['n_wa2']} with det A < 0), one in each box")
    else:
        msg = f"q = ({q}): each of the {facts['n']} boxes holds exactly one solution (completeness not claimed)"
    return msg, facts


def _check_joint_cell(model: _Model, claim: dict, prec: int) -> tuple[str, dict]:
    rho = _rho(claim, "witness")
    g = model.geometry
    if not all(g.rho_min[i] <= rho[i] <= g.rho_max[i] for i in range(3)):
        raise _Refused("witness: not within the joint limits")
    sols = _get(claim, "solutions")
    if not isinstance(sols, list):
        raise _Refused("solutions: expected a list")
    facts = _check_solve(model, rho, sols, True, _get(claim, "phi0"), prec)
    for key, val in (("count", facts["n"]), ("n_wa1", facts["n_wa1"]), ("n_wa2", facts["n_wa2"])):
        if _get(claim, key) != val:
            raise _Refused(f"declared {key} = {claim[key]!r} but the checker proves {val}")
    facts.update(rho=rho, in_limits=_strictly_in_limits(g, rho))
    q = ", ".join(str(r) for r in rho)
    return (f"witness q = ({q}) of cell {claim.get('cell')!r} has exactly {facts['n']} solutions, split "
            f"{facts['n_wa1']} (WA1) + {facts['n_wa2']} (WA2), none singular"), facts


_SIGN = {"WA1": 1, "WA2": -1}


def _check_aspect_distinct(model: _Model, claim: dict, prec: int) -> tuple[str, dict]:
    items = _get(claim, "boxes")
    if not isinstance(items, list) or len(items) < 2:
        raise _Refused("boxes: expected at least two witness boxes")
    signs = set()
    for k, it in enumerate(items):
        b = _box(_get(it, "box"), f"boxes[{k}]")
        aspect = _get(it, "aspect")
        if aspect not in _SIGN:
            raise _Refused(f"boxes[{k}]: aspect must be WA1 or WA2, got {aspect!r}")
        if not _holds_on_box(b, lambda s: _in_w(model, s)):
            raise _Refused(f"boxes[{k}]: not proved inside W (joint limits on the whole box)")
        test = _det_positive if _SIGN[aspect] > 0 else _det_negative
        if not _holds_on_box(b, lambda s: test(model, s)):
            raise _Refused(f"boxes[{k}]: det A not proved {'> 0' if _SIGN[aspect] > 0 else '< 0'} on the whole box")
        signs.add(_SIGN[aspect])
    if signs != {1, -1}:
        raise _Refused("the boxes do not have opposite signs of det A")
    return "two boxes inside W with opposite certified signs of det A: they lie in different aspects", {"signs": signs}


def _check_region_distinct(model: _Model, claim: dict, prec: int) -> tuple[str, dict]:
    rho = _rho(claim)
    aspect = _get(claim, "aspect")
    if aspect not in _SIGN:
        raise _Refused(f"aspect must be WA1 or WA2, got {aspect!r}")
    sols = _get(claim, "solutions")
    if not isinstance(sols, list) or len(sols) < 2:
        raise _Refused("solutions: expected at least two solutions of one aspect")
    for k, s in enumerate(sols):
        if _get(s, "det_sign") != _SIGN[aspect]:
            raise _Refused(f"solution {k}: det_sign {s.get('det_sign')!r} is not the sign of {aspect}")
    facts = _check_solve(model, rho, sols, False, None, prec)
    pieces = []
    for k, s in enumerate(sols):
        b = _box(s["box"], f"solution {k} box")
        pb = _get(s, "paving_box")
        pbox = _box(_get(pb, "box"), f"solution {k} paving box")
        if not all(plo <= lo and hi <= phi for (lo, hi), (plo, phi) in zip(b, pbox)):
            raise _Refused(f"solution {k}: the solution box is not inside the stated paving box")
        labels = _get(pb, "labels")
        want = {"W": 2, "det_positive": 2 if _SIGN[aspect] > 0 else 1}
        for name, val in want.items():
            if labels.get(name) != val:
                raise _Refused(f"solution {k}: paving box label {name} = {labels.get(name)!r}, expected {val}")
            if not _prove_label(model, pbox, name, val):
                raise _Refused(f"solution {k}: paving box label {name} = {val} not re-proved in arb")
        pieces.append(_int(_get(s, "piece"), f"solution {k} piece", 0))
    if len(set(pieces)) != len(pieces):
        raise _Refused(f"two solutions are declared in one piece {pieces}: that would contradict Theorem 1")
    q = ", ".join(str(r) for r in rho)
    return (f"q = ({q}) has {len(sols)} distinct solutions in {aspect}, each in a paving box re-proved inside "
            f"{aspect}; the library puts those boxes in pieces {pieces} off S_c (not re-checked here), which "
            "by Theorem 1 then lie in pairwise different basic regions"), facts


def _check_box_labels(model: _Model, claim: dict, prec: int) -> tuple[str, dict]:
    seed = _int(_get(claim, "seed"), "seed")
    population = _int(_get(claim, "population"), "population", 1)
    boxes = _get(claim, "boxes")
    if not isinstance(boxes, list):
        raise _Refused("boxes: expected a list")
    size = _int(_get(claim, "sample_size"), "sample_size", 0)
    if min(size, population) != len(boxes):
        raise _Refused(f"{len(boxes)} boxes listed for a sample of {min(size, population)}")
    expect = sample_indices(seed, population, size)
    got = [b.get("index") if isinstance(b, dict) else None for b in boxes]
    if got != expect:
        raise _Refused("the sampled indices are not the ones the seed gives (sample_indices)")
    proved = 0
    for k, it in enumerate(boxes):
        b = _box(_get(it, "box"), f"boxes[{k}]")
        labels = _get(it, "labels")
        if not isinstance(labels, dict):
            raise _Refused(f"boxes[{k}]: labels: expected an object")
        for name, val in sorted(labels.items()):
            ok = _prove_label(model, b, name, val)
            if ok is None:
                continue
            if not ok:
                raise _Refused(f"box index {it['index']}: label {name} = {val} not re-proved in arb")
            proved += 1
    return f"{proved} INSIDE/OUTSIDE labels of {len(boxes)} sampled boxes (seed {seed}) re-proved in arb", {}


def _hex(v: Any, what: str) -> float:
    """A binary64 number written exactly as a hex string ("0x1.8p+3", float.hex)."""
    if not isinstance(v, str):
        raise _Refused(f"{what}: expected an exact hex float string such as \"0x1.8p+3\", got {v!r}")
    try:
        f = float.fromhex(v)
    except ValueError:
        raise _Refused(f"{what}: {v!r} is not a hex float") from None
    if not math.isfinite(f):
        raise _Refused(f"{what}: {v!r} is not finite")
    return f


def _hex_box(obj: Any, what: str) -> tuple[tuple[float, float], ...]:
    """[[xlo, xhi], [ylo, yhi], [philo, phihi]] as hex strings, lo <= hi."""
    return _box(obj, what, number=_hex)


def _inside(inner, outer) -> bool:
    return all(olo <= lo and hi <= ohi for (lo, hi), (olo, ohi) in zip(inner, outer))


def _piece_verdict(model: _Model, a: list, b: list, t0: float, t1: float, sign: int) -> int:
    """1: proved on the piece (det A of sign ``sign``, every leg within its limits); -1: proved false
    on the whole piece; 0: undecided.  The piece {A + t (B - A)} is enclosed by A + [t0, t1] (B - A)
    in arb, A and B the balls of the end enclosures."""
    T = _ball(t0, t1)
    P = [a[j] + T * (b[j] - a[j]) for j in range(3)]
    d = model.det(*P)
    r = model.rho_sq(*P)
    if (d < 0 if sign > 0 else d > 0) or any(r[i] < model.rmin2[i] or r[i] > model.rmax2[i] for i in range(3)):
        return -1
    if (d > 0 if sign > 0 else d < 0) and all(r[i] >= model.rmin2[i] and r[i] <= model.rmax2[i] for i in range(3)):
        return 1
    return 0


def _prove_piece(model: _Model, a: list, b: list, t0: float, t1: float, sign: int) -> str:
    """"" when the piece [t0, t1] is proved (bisected in t while undecided), else why not.

    Sub-pieces are taken breadth first, so that a stretch proved wrong is found
    (and named) before the bisection closes in on a crossing of a boundary.
    """
    stack = deque([(t0, t1)])
    evals = 0
    while stack:
        lo, hi = stack.popleft()
        evals += 1
        if evals > PIECE_BUDGET:
            return f"not proved within {PIECE_BUDGET} sub-pieces (undecided near t = {lo!r})"
        v = _piece_verdict(model, a, b, lo, hi, sign)
        if v > 0:
            continue
        if v < 0:
            return (f"on t in [{lo!r}, {hi!r}] det A is proved of the wrong sign or a leg proved "
                    "beyond its limit")
        mid = lo + (hi - lo) / 2
        if not lo < mid < hi:
            return f"undecided at t = {lo!r} (cannot bisect further)"
        stack += [(lo, mid), (mid, hi)]
    return ""


def _check_trajectory(model: _Model, claim: dict, prec: int) -> tuple[str, dict]:
    from flint import arb

    g = model.geometry
    rho = _rho(claim)
    aspect = _get(claim, "aspect")
    if aspect not in _SIGN:
        raise _Refused(f"aspect must be WA1 or WA2, got {aspect!r}")
    sign = _SIGN[aspect]
    if _get(claim, "det_sign") != sign:
        raise _Refused(f"det_sign {claim.get('det_sign')!r} is not the sign of {aspect}")
    # 1. the solutions of rho and their numbers (increasing phi in [-pi, pi], as intervalkin dkp)
    sols = _get(claim, "solutions")
    if not isinstance(sols, list) or not sols:
        raise _Refused("solutions: expected the complete list of solutions of rho")
    _check_solve(model, rho, sols, True, _get(claim, "phi0"), prec)
    listed = [_box(s["box"], f"solution {k} box") for k, s in enumerate(sols)]
    pi = arb.pi()
    for k, b in enumerate(listed):
        if not (arb(b[2][0]) >= -pi and arb(b[2][1]) <= pi):
            raise _Refused(f"solution {k}: phi not proved within [-pi, pi]: solution numbers undefined")
        if k and not listed[k - 1][2][1] < b[2][0]:
            raise _Refused(f"solutions {k - 1} and {k}: not listed in increasing phi: solution numbers undefined")
    n = len(listed)
    i_from = _int(_get(claim, "from"), "from", 1, n)
    i_to = _int(_get(claim, "to"), "to", 1, n)
    if i_from == i_to:
        raise _Refused("from and to name the same solution")
    start = _box(_get(claim, "start_box"), "start_box")
    goal = _box(_get(claim, "goal_box"), "goal_box")
    # the end solutions: one solution each (Krawczyk), det A of the aspect's sign, inside solutions from / to
    rho_sq = [_q(r * r) for r in rho]
    for name, b in (("start_box", start), ("goal_box", goal)):
        if not b[2][1] - b[2][0] < 1.0:
            raise _Refused(f"{name}: phi width {b[2][1] - b[2][0]!r} is not < 1 rad")
        if not _krawczyk(model, b, rho_sq):
            raise _Refused(f"{name}: the Krawczyk test does not prove a unique solution of q in the box")
        d = model.det(*_balls(b))
        if not (d > 0 if sign > 0 else d < 0):
            raise _Refused(f"{name}: det A is not proved {'> 0' if sign > 0 else '< 0'} (the sign of {aspect}) "
                           f"on the box ({d.str(5)})")
    if not _inside(start, listed[i_from - 1]):
        raise _Refused(f"start_box is not inside the box of solution {i_from}")
    if not _inside(goal, listed[i_to - 1]):
        raise _Refused(f"goal_box is not inside the box of solution {i_to}")
    # 2. the segments: pieces tile [0, 1], each proved; consecutive segments share their end points
    segs = _get(claim, "segments")
    if not isinstance(segs, list) or not segs:
        raise _Refused("segments: expected a non-empty list")
    ends = []
    n_pieces = 0
    for k, s in enumerate(segs):
        A = _hex_box(_get(s, "start"), f"segment {k + 1} start")
        B = _hex_box(_get(s, "end"), f"segment {k + 1} end")
        pieces = _get(s, "pieces")
        if not isinstance(pieces, list) or not pieces:
            raise _Refused(f"segment {k + 1}: pieces: expected a non-empty list of [t0, t1]")
        ts = []
        for j, p in enumerate(pieces):
            if not isinstance(p, list) or len(p) != 2:
                raise _Refused(f"segment {k + 1} piece {j}: expected [t0, t1], got {p!r}")
            ts.append((_hex(p[0], f"segment {k + 1} piece {j} t0"), _hex(p[1], f"segment {k + 1} piece {j} t1")))
        if ts[0][0] != 0.0 or ts[-1][1] != 1.0 or any(not t0 < t1 for t0, t1 in ts) \
                or any(ts[j][1] != ts[j + 1][0] for j in range(len(ts) - 1)):
            raise _Refused(f"segment {k + 1}: the pieces do not tile [0, 1] (sorted, each t0 < t1, "
                           "consecutive pieces sharing their end point)")
        a, b = _balls(A), _balls(B)
        for t0, t1 in ts:
            why = _prove_piece(model, a, b, t0, t1, sign)
            if why:
                raise _Refused(f"segment {k + 1}, piece [{t0!r}, {t1!r}]: {why}")
        n_pieces += len(ts)
        ends.append((A, B))
    for k in range(len(ends) - 1):
        if ends[k][1] != ends[k + 1][0]:
            raise _Refused(f"segments {k + 1} and {k + 2} do not share their end point: the path is not continuous")
    wps = _get(claim, "waypoints")
    if not isinstance(wps, list) or len(wps) != len(ends) + 1:
        raise _Refused(f"waypoints: expected {len(ends) + 1} points (one more than the segments)")
    for k, w in enumerate(wps):
        if not isinstance(w, list) or len(w) != 3:
            raise _Refused(f"waypoint {k}: expected [x, y, phi] as hex floats, got {w!r}")
        pt = tuple((v, v) for v in (_hex(c, f"waypoint {k}") for c in w))
        if not _inside(pt, ends[k][0] if k < len(ends) else ends[-1][1]):
            raise _Refused(f"waypoint {k} is not in the enclosure of the segment end point it names")
    # 3. the path starts at the start solution and ends at the goal solution (phi + 2 pi phi_turns)
    if not _inside(start, ends[0][0]):
        raise _Refused("start_box is not inside the start enclosure of segment 1")
    turns = _int(_get(claim, "phi_turns"), "phi_turns", -1000, 1000)
    shift = 2 * turns * pi
    (elo, ehi) = ends[-1][1][2]
    if not (_inside(goal[:2], ends[-1][1][:2]) and arb(goal[2][0]) + shift >= arb(elo)
            and arb(goal[2][1]) + shift <= arb(ehi)):
        raise _Refused(f"goal_box (phi + 2 pi * {turns}) is not inside the end enclosure of the last segment")
    q = ", ".join(str(r) for r in rho)
    lims = ", ".join(f"{lo} <= rho_{i + 1} <= {hi}" for i, (lo, hi) in enumerate(zip(g.rho_min, g.rho_max)))
    return (f"q = ({q}): the path of {len(segs)} straight segments ({n_pieces} pieces) from solution {i_from} "
            f"to solution {i_to} keeps det A {'> 0' if sign > 0 else '< 0'} and {lims} on every piece, "
            f"continuous from the exact start to the exact goal: a non-singular motion in {aspect}"), {}


_CHECKERS = {
    "dkp": _check_dkp,
    "joint_cell": _check_joint_cell,
    "aspect_distinct": _check_aspect_distinct,
    "region_distinct": _check_region_distinct,
    "box_labels": _check_box_labels,
    "trajectory": _check_trajectory,
}


def check_claim(geometry: Geometry, kind: str, claim: dict, precision: int = 128) -> tuple[bool, str]:
    """Re-check one claim of a kind other than ``counts`` (what :func:`verify_directory` does per claim).

    Returns (verified, message).  The certificate writers call it before
    writing, so that a file never holds a claim its own checker refuses.
    """
    from flint import ctx

    if kind not in _CHECKERS:
        raise ValueError(f"kind: expected one of {', '.join(_CHECKERS)}, got {kind!r}")
    try:
        prec = _int(claim.get("precision", precision), "precision", *_PREC_RANGE)
        with ctx.workprec(prec):
            msg, _ = _CHECKERS[kind](_Model(geometry), claim, prec)
    except _Refused as exc:
        return False, str(exc)
    except (TypeError, KeyError, AttributeError, ValueError, OverflowError, ZeroDivisionError) as exc:
        return False, f"malformed claim ({type(exc).__name__}: {exc})"
    return True, msg


def box_label_proved(geometry: Geometry, box, name: str, value: int, precision: int = 128) -> bool | None:
    """Whether the checker re-proves label ``name`` = ``value`` (W or det_positive) on ``box`` (3, 2).

    None for BOUNDARY (3), which claims nothing.
    """
    from flint import ctx

    b = _box([[float(lo), float(hi)] for lo, hi in box])
    with ctx.workprec(precision):
        return _prove_label(_Model(geometry), b, name, value)


# --------------------------------------------------------------------------------------
# Counts
# --------------------------------------------------------------------------------------
def _count_bound(name: str, support: list[dict]) -> int:
    """The lower bound the verified support proves (proofs/lemma-checker.md, section counts).

    * ``aspects``: number of distinct det A signs among verified aspect_distinct boxes.
    * ``basic_regions``: over verified complete solves of joint vectors strictly
      inside the joint limits, the sum over their distinct aspect splits
      (n_wa1, n_wa2) of n_wa1 + n_wa2 (Theorem 1 and the constant-split lemma;
      proofs/lemma-theorem1-distinctness.md).
    * ``uniqueness_domains``: over the same solves, max n_wa1 + max n_wa2
      (proofs/lemma-uniqueness-domain-bound.md).
    """
    if name == "aspects":
        signs: set = set()
        for f in support:
            signs |= f.get("signs", set())
        return len(signs)
    solves = [f for f in support if f.get("complete") and f.get("in_limits")]
    if name == "basic_regions":
        splits = {(f["n_wa1"], f["n_wa2"]) for f in solves}
        return sum(a + b for a, b in splits)
    if name == "uniqueness_domains":
        return max((f["n_wa1"] for f in solves), default=0) + max((f["n_wa2"] for f in solves), default=0)
    raise _Refused(f"unknown count {name!r} (known: aspects, basic_regions, uniqueness_domains)")


def _check_count(claim: dict, verified: dict[str, dict]) -> tuple[str, dict]:
    name = _get(claim, "name")
    declared = _int(_get(claim, "lower_bound"), "lower_bound", 0)
    if claim.get("exact") is not False:
        raise _Refused("a count declared exact (or without \"exact\": false) needs an upper bound "
                       "this checker cannot verify")
    refs = _get(claim, "support")
    if not isinstance(refs, list):
        raise _Refused("support: expected a list of claim references \"file#id\"")
    used = [verified[r] for r in refs if r in verified]
    bound = _count_bound(name, used)
    if declared > bound:
        raise _Refused(f"declared lower bound {declared} exceeds {bound}, what the {len(used)} verified "
                       f"supporting claims (of {len(refs)} referenced) prove")
    found = claim.get("found")
    extra = f"; {found} found by the library (not certified)" if found is not None else ""
    return f"{name} >= {declared} (the {len(used)} verified supporting claims prove >= {bound}){extra}", {}


# --------------------------------------------------------------------------------------
# Files
# --------------------------------------------------------------------------------------
def _read_json(path: Path) -> dict:
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise CertificateFormatError(f"{path}: missing") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise CertificateFormatError(f"{path}: cannot read ({exc})") from None
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as exc:
        raise CertificateFormatError(f"{path}: not valid JSON ({exc})") from None
    if not isinstance(doc, dict) or doc.get("format") != FORMAT or doc.get("version") != VERSION:
        raise CertificateFormatError(
            f"{path}: not an {FORMAT} file of version {VERSION} "
            f"(format {doc.get('format') if isinstance(doc, dict) else None!r}, "
            f"version {doc.get('version') if isinstance(doc, dict) else None!r})")
    return doc


def _geometry(text: Any) -> Geometry:
    if not isinstance(text, str):
        raise _Refused("geometry_toml: expected the geometry as TOML text")
    try:
        return parse_geometry(tomllib.loads(text, parse_float=decimal.Decimal), source="certificate")
    except tomllib.TOMLDecodeError as exc:
        raise _Refused(f"geometry_toml: malformed TOML ({exc})") from None
    except GeometryError as exc:
        raise _Refused(f"geometry_toml: {exc}") from None


def verify_directory(path: str | Path) -> list[CheckResult]:
    """Re-check every claim of a certificate folder; one :class:`CheckResult` per claim.

    Raises :class:`CertificateFormatError` when the folder, its ``index.json`` or
    a listed file is missing, unreadable or not in the format (a malformed
    folder is not a failed claim).  A claim whose fields are wrong, or whose
    evidence does not re-prove it, gives a result with ``verified`` False.
    """
    from flint import ctx

    root = Path(path)
    if not root.is_dir():
        raise CertificateFormatError(f"{root}: not a certificate folder (no such directory)")
    index = _read_json(root / INDEX)
    if index.get("kind") != "index":
        raise CertificateFormatError(f"{root / INDEX}: kind must be \"index\", got {index.get('kind')!r}")
    files = index.get("files")
    if not isinstance(files, list) or not all(isinstance(f, str) for f in files):
        raise CertificateFormatError(f"{root / INDEX}: files: expected a list of file names")
    docs = {}
    for name in files:
        if "/" in name or "\\" in name or name in (".", ".."):
            raise CertificateFormatError(f"{root / INDEX}: file name {name!r} must be a plain name in the folder")
        doc = _read_json(root / name)
        if doc.get("kind") not in KINDS:
            raise CertificateFormatError(
                f"{root / name}: kind must be one of {', '.join(KINDS)}, got {doc.get('kind')!r}")
        claims = doc.get("claims")
        if not isinstance(claims, list) or not all(
                isinstance(c, dict) and isinstance(c.get("id"), str) for c in claims):
            raise CertificateFormatError(f"{root / name}: claims: expected a list of objects with a string id")
        ids = [c["id"] for c in claims]
        if len(set(ids)) != len(ids):
            raise CertificateFormatError(f"{root / name}: duplicate claim ids")
        docs[name] = doc

    if not any(doc["claims"] for doc in docs.values()):
        raise CertificateFormatError(f"{root}: the folder holds no claims")
    results: list[CheckResult] = []
    verified: dict[str, dict] = {}
    order = sorted(docs, key=lambda n: KINDS.index(docs[n]["kind"]))
    for name in order:
        doc = docs[name]
        kind = doc["kind"]
        model = None
        file_error = None
        if doc.get("geometry_toml") != index.get("geometry_toml"):
            file_error = f"its geometry differs from the one in {INDEX}"
        elif kind != "counts":
            try:
                geometry = _geometry(doc.get("geometry_toml"))
            except _Refused as exc:
                file_error = str(exc)
        for claim in doc["claims"]:
            cid = claim["id"]
            if file_error is not None:
                results.append(CheckResult(name, cid, kind, False, file_error))
                continue
            try:
                if kind == "counts":
                    msg, facts = _check_count(claim, verified)
                else:
                    prec = _int(claim.get("precision", doc.get("precision", 128)), "precision", *_PREC_RANGE)
                    with ctx.workprec(prec):
                        model = _Model(geometry)
                        msg, facts = _CHECKERS[kind](model, claim, prec)
            except _Refused as exc:
                results.append(CheckResult(name, cid, kind, False, str(exc)))
                continue
            except (TypeError, KeyError, AttributeError, ValueError, OverflowError, ZeroDivisionError) as exc:
                results.append(CheckResult(name, cid, kind, False, f"malformed claim ({type(exc).__name__}: {exc})"))
                continue
            verified[f"{name}#{cid}"] = facts
            results.append(CheckResult(name, cid, kind, True, msg))
    return results


def format_results(results: list[CheckResult]) -> str:
    """One line per claim, then a summary line."""
    lines = [r.line() for r in results]
    bad = sum(1 for r in results if not r.verified)
    lines.append(f"{len(results) - bad} of {len(results)} claims verified" + (f", {bad} FAILED" if bad else ""))
    return "\n".join(lines)
