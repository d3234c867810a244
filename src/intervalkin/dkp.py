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
from decimal import Decimal, InvalidOperation
from fractions import Fraction
from typing import Sequence

import numpy as np

from .errors import InputError
from .geometry import Geometry
from .interval import arb_to_bounds
from .kinematics import approx_inverse_kinematics, approx_jacobian, det_a_arb, jacobian_arb, residual_arb

__all__ = [
    "DkpSolution",
    "DkpResult",
    "parse_joint_vector",
    "solve",
    "format_dkp_table",
    "approx_solve",
    "PRECISIONS",
    "MAX_WIDTH",
]

#: Working precisions tried in turn (bits); the last one is the ceiling.
PRECISIONS: tuple[int, ...] = (64, 128, 256, 512)
#: Every unique enclosure is narrower than this in each coordinate.
MAX_WIDTH = 1e-9

_TWO_PI = 2.0 * math.pi


# --------------------------------------------------------------------------------------
# Input
# --------------------------------------------------------------------------------------
def parse_joint_vector(geometry: Geometry, values: Sequence[str]) -> tuple[Fraction, Fraction, Fraction]:
    """Read three leg lengths as exact decimals and check them against the joint limits.

    Parameters
    ----------
    geometry : Geometry
        Supplies the limits [rho_min_i, rho_max_i].
    values : sequence of three str
        Decimal numbers such as ``"14.98"`` (read exactly: 14.98 is 1498/100).

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
        allowed = f"[{_fmt_fraction(lo)}, {_fmt_fraction(hi)}]"
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


def _fmt_fraction(q: Fraction) -> str:
    if q.denominator == 1:
        return str(q.numerator)
    d = Decimal(q.numerator) / Decimal(q.denominator)
    return format(d.normalize(), "f")


# --------------------------------------------------------------------------------------
# Results
# --------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class DkpSolution:
    """One assembly mode.

    Attributes
    ----------
    box : ndarray of shape (3, 2), float64
        Rows (x, y, phi), columns (lo, hi).  For status ``"unique"`` the box is
        PROVED to contain exactly one solution of F = 0 (phi read modulo 2 pi) and
        is narrower than :data:`MAX_WIDTH`.  The phi interval meets (-pi, pi];
        when it holds the seam it is written around +pi and exceeds pi by less
        than its width (the solution is then within that width of phi = pi).  For ``"unknown"`` the box is where the
        float solver points; nothing is claimed about it.
    det_sign : int
        1 or -1: sign of det A PROVED on the whole box; 0: not proved.
    aspect : str or None
        ``"WA1"`` (det A > 0), ``"WA2"`` (det A < 0) or None.
    status : str
        ``"unique"`` or ``"unknown"``.
    reason : str
        Why an unknown box could not be proved ("" for unique ones).
    """

    box: np.ndarray
    det_sign: int
    aspect: str | None
    status: str
    reason: str = ""

    @property
    def midpoint(self) -> np.ndarray:
        """(x, y, phi) at the box centre (float; approximate)."""
        return 0.5 * (self.box[:, 0] + self.box[:, 1])

    @property
    def width(self) -> float:
        """Largest side of the box."""
        return float(np.max(self.box[:, 1] - self.box[:, 0]))

    def to_json(self) -> dict:
        d = {
            "x": [float(self.box[0, 0]), float(self.box[0, 1])],
            "y": [float(self.box[1, 0]), float(self.box[1, 1])],
            "phi": [float(self.box[2, 0]), float(self.box[2, 1])],
            "det_sign": int(self.det_sign),
            "aspect": self.aspect,
            "status": self.status,
        }
        if self.status != "unique":
            d["reason"] = self.reason
        return d


@dataclass(frozen=True, eq=False)
class DkpResult:
    """Every assembly mode of one joint vector, with the status of the claim.

    Attributes
    ----------
    rho : three Fractions, the exact leg lengths solved for.
    solutions : tuple of DkpSolution, sorted by increasing phi midpoint.
    complete : bool
        True when it is PROVED that the unique boxes hold ALL the real solutions
        (one each, no others anywhere in R^2 x S^1).  False otherwise; then the
        listed unique boxes are still each proved, but the list may miss
        solutions or contain unknown boxes.
    completeness_reason : str
        How completeness was proved, or why it could not be.
    precision : int
        The arb working precision (bits) of the last attempt.
    """

    rho: tuple[Fraction, Fraction, Fraction]
    solutions: tuple[DkpSolution, ...]
    complete: bool
    completeness_reason: str
    precision: int

    @property
    def count(self) -> int:
        """Number of listed solutions (the certified count only when ``complete``)."""
        return len(self.solutions)

    def to_json(self) -> dict:
        """``{"rho", "count", "complete", "solutions"}`` as plain JSON types."""
        return {
            "rho": [float(r) for r in self.rho],
            "count": self.count,
            "complete": bool(self.complete),
            "solutions": [s.to_json() for s in self.solutions],
        }


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


# --------------------------------------------------------------------------------------
# Krawczyk on the original 3x3 system
# --------------------------------------------------------------------------------------
def _krawczyk(geometry: Geometry, rho_sq, start: np.ndarray, prec: int):
    """Try to prove a unique solution near ``start`` (float (x, y, phi)).

    Returns (K balls [x, y, phi], det_sign) on success, or (None, reason).
    """
    from flint import arb

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


def _box_of(K) -> np.ndarray:
    return np.array([arb_to_bounds(k) for k in K], dtype=np.float64)


def _disjoint(b1: np.ndarray, b2: np.ndarray) -> bool:
    """PROVED: the boxes share no point of R^2 x S^1 (phi modulo 2 pi)."""
    from flint import arb

    for j in (0, 1):
        if b1[j, 1] < b2[j, 0] or b2[j, 1] < b1[j, 0]:
            return True
    m1 = (arb(b1[2, 0]) + arb(b1[2, 1])) / 2
    m2 = (arb(b2[2, 0]) + arb(b2[2, 1])) / 2
    h = (arb(b1[2, 1]) - arb(b1[2, 0]) + arb(b2[2, 1]) - arb(b2[2, 0])) / 2
    diff = m1 - m2
    kk = round(float(diff.mid()) / _TWO_PI)
    d = diff - 2 * kk * arb.pi()
    return bool(abs(d) > h)


def _solution(K, sign: int) -> DkpSolution:
    aspect = "WA1" if sign > 0 else ("WA2" if sign < 0 else None)
    return DkpSolution(box=_box_of(K), det_sign=sign, aspect=aspect, status="unique")


# --------------------------------------------------------------------------------------
# One attempt at one precision
# --------------------------------------------------------------------------------------
@dataclass
class _Attempt:
    solutions: list
    complete: bool
    reason: str
    candidates: list  # float starting points, for the fallback


def _attempt(geometry: Geometry, rho, rho_sq, prec: int) -> _Attempt:
    from flint import acb_poly, arb

    red = _reduce(geometry, rho_sq)
    shift = _choose_shift(red)
    if shift is None:
        return _Attempt([], False, "reduced equation f(phi) could not be proved non-zero at any trial angle "
                        "(it may vanish identically: architecturally singular manipulator)", [])
    phi0, _lead = shift
    coeffs = _poly_t(red, phi0)
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
        if _leval(red.D, phi).real.contains(0):
            return _Attempt([], False, f"2x2 linear system may be singular at a root phi ~ {float(phi.mid()):.6g} "
                            f"of the reduced equation ({prec} bits)", _float_candidates(coeffs, phi0, red))
        pm = phi.mid()
        Nm = _leval(red.N, pm)
        Dm = _leval(red.D, pm).real
        x = red.a1[0] + Nm.real / Dm
        y = red.a1[1] + Nm.imag / Dm
        starts.append(np.array([float(x.mid()), float(y.mid()), math.remainder(float(pm.mid()), _TWO_PI)]))
    sols = []
    failures = []
    for s in starts:
        got, why = _krawczyk(geometry, rho_sq, s, prec)
        if got is None:
            failures.append((s, why))
        else:
            sols.append(_solution(*got))
    for a in range(len(sols)):
        for b in range(a + 1, len(sols)):
            if not _disjoint(sols[a].box, sols[b].box):
                return _Attempt(_dedupe(sols), False, f"two certified boxes could not be separated at {prec} bits",
                                [f[0] for f in failures])
    if failures:
        return _Attempt(sols, False, f"{len(failures)} of {n_real} real roots not certified by Krawczyk at "
                        f"{prec} bits: {failures[0][1]}", [f[0] for f in failures])
    if any(s.width >= MAX_WIDTH for s in sols):
        return _Attempt(sols, False, f"an enclosure is not narrower than {MAX_WIDTH:g}", [])
    return _Attempt(sols, True, f"{n_real} real roots of the reduced sextic (t = tan((phi - {phi0:g})/2), "
                    f"leading coefficient f({phi0:g} + pi) != 0) isolated at {prec} bits, 2x2 system regular at "
                    f"each, {len(sols)} disjoint Krawczyk boxes", [])


def _dedupe(sols: list) -> list:
    out: list = []
    for s in sols:
        if all(_disjoint(s.box, o.box) for o in out):
            out.append(s)
    return out


def _float_candidates(coeffs, phi0: float, red: _Reduction) -> list:
    """Approximate solutions from the float roots of P (for the fallback only)."""
    from flint import arb

    c = np.array([float(v.mid()) for v in coeffs])[::-1]
    while len(c) > 1 and c[0] == 0.0:
        c = c[1:]
    if len(c) < 2:
        return []
    out = []
    for t in np.roots(c):
        if abs(t.imag) > 1e-4 * (1.0 + abs(t)):
            continue
        phi = phi0 + 2.0 * math.atan(t.real)
        pm = arb(phi)
        Dm = _leval(red.D, pm).real
        if Dm.contains(0):
            continue
        Nm = _leval(red.N, pm)
        x = red.a1[0] + Nm.real / Dm
        y = red.a1[1] + Nm.imag / Dm
        out.append(np.array([float(x.mid()), float(y.mid()), math.remainder(phi, _TWO_PI)]))
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
    >>> from intervalkin.geometry import default_geometry
    >>> g = default_geometry()
    >>> r = solve(g, parse_joint_vector(g, ["14.98", "15.38", "12.0"]))
    >>> r.count, r.complete, [s.aspect for s in r.solutions]
    (6, True, ['WA2', 'WA1', 'WA1', 'WA2', 'WA2', 'WA1'])
    """
    from flint import arb, ctx, fmpq

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
            got, why = _krawczyk(geometry, rho_sq, start, prec)
            if got is not None:
                s = _solution(*got)
                if all(_disjoint(s.box, o.box) for o in sols):
                    sols.append(s)
                continue
            box = np.array([[v - 1e-6, v + 1e-6] for v in start])
            s = DkpSolution(box=box, det_sign=0, aspect=None, status="unknown", reason=why)
            if all(_disjoint(s.box, o.box) for o in sols):
                sols.append(s)
        return _result(rho_f, sols, False, att.reason, prec)
    finally:
        ctx.prec = old


def _result(rho, sols, complete, reason, prec) -> DkpResult:
    ordered = tuple(sorted(sols, key=lambda s: float(s.midpoint[2])))
    return DkpResult(rho=rho, solutions=ordered, complete=complete, completeness_reason=reason, precision=prec)


# --------------------------------------------------------------------------------------
# An independent float solver (approximate; for tests and heuristics only)
# --------------------------------------------------------------------------------------
def approx_solve(geometry: Geometry, rho: Sequence[float], samples: int = 1 << 16) -> np.ndarray:
    """Approximate solutions (n, 3) by dense phi sampling of the reduced equation.

    Not certified.  Independent of :func:`solve`: it uses only float64 numpy
    (the kinematics constants, not the Laurent reduction), finds the sign
    changes of f(phi) = |N|^2 - rho_1^2 D^2 on a uniform grid, refines each by
    bisection and lifts it with Cramer's rule and a few Newton steps on the 3x3
    system.  Double roots (tangencies) are missed by design.
    """
    from .kinematics import constants

    k = constants(geometry)
    r = np.asarray([float(v) for v in rho])
    a = np.stack([k.ax - k.ax[0], k.ay - k.ay[0]], axis=-1)

    def parts(phi):
        phi = np.asarray(phi, dtype=np.float64)
        ex = [k.radius[i] * np.cos(phi + k.alpha[i]) for i in range(3)]
        ey = [k.radius[i] * np.sin(phi + k.alpha[i]) for i in range(3)]
        vx = [ex[i] - a[i, 0] for i in (1, 2)]
        vy = [ey[i] - a[i, 1] for i in (1, 2)]
        kk = [r[i] ** 2 - r[0] ** 2 - (vx[j] ** 2 + vy[j] ** 2) for j, i in enumerate((1, 2))]
        m2x, m2y, m3x, m3y = 2 * vx[0], 2 * vy[0], 2 * vx[1], 2 * vy[1]
        D = m2x * m3y - m2y * m3x
        Nx = kk[0] * m3y - kk[1] * m2y
        Ny = m2x * kk[1] - m3x * kk[0]
        return D, Nx, Ny

    def f(phi):
        D, Nx, Ny = parts(phi)
        return Nx**2 + Ny**2 - r[0] ** 2 * D**2

    grid = np.linspace(-math.pi, math.pi, samples + 1)
    vals = f(grid)
    idx = np.nonzero(np.sign(vals[:-1]) * np.sign(vals[1:]) <= 0)[0]
    out = []
    for i in idx:
        lo, hi = grid[i], grid[i + 1]
        flo = vals[i]
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            fm = f(mid)
            if np.sign(fm) == np.sign(flo) and fm != 0:
                lo, flo = mid, fm
            else:
                hi = mid
        phi = 0.5 * (lo + hi)
        D, Nx, Ny = parts(phi)
        X = np.array([k.ax[0] + Nx / D, k.ay[0] + Ny / D, phi])
        for _ in range(5):
            res = approx_inverse_kinematics(geometry, X) ** 2 - r**2
            X = X - np.linalg.solve(approx_jacobian(geometry, X), res)
        X[2] = math.remainder(X[2], _TWO_PI)
        if not any(np.max(np.abs(X - Z)) < 1e-7 for Z in out):
            out.append(X)
    return np.array(out).reshape(-1, 3)


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
