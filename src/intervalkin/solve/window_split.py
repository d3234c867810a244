"""Windows whose D sign or inner end signs are proved at the point (proofs/lemma-window-model.md, 2' and 4').

Two kinds of windows of :mod:`intervalkin.solve.window_model` are not certified over the whole box:

* *D-open windows*: the 2nd or 3rd phi-derivative of f has one strict sign on the window, but D
  may vanish there (``d_sign`` 0).  Rolle's bound does not need D != 0; at a point, each simple
  root counted in the window gets the sign of D proved on the bracket that holds it alone
  (:func:`root_d_signs`).  The window's pieces are cut at phi_D +- :data:`D_GAP` (phi_D a zero
  of D, independent of r), so that a bracket seldom holds phi_D.
* *sub-windows*: neither derivative has one sign on the window, but each piece has a signed
  f', f'' or f''' of its own.  The window is cut into maximal runs of pieces sharing one signed
  derivative of order 1, 2 or 3 (:func:`sub_windows`): at most 1, 2 or 3 roots each.  The sign
  of f at a cut between two runs holds for no certified part of the box (``end_signs`` 0 there)
  and is proved at the point.


Three bounds read f through f |m_2|^2 = s^2 - D^2 V (proofs/lemma-line-misses-circle.md), where its terms do
not cancel: :func:`line_misses_circle` settles pieces f > 0 where the line of legs 1 and 2 misses the circle of
leg 1, :func:`aligned_r_slopes` encloses df/dr_l near the zeros of D, where the Taylor form cannot sign it, and
:func:`root_direction_signs` encloses it at the roots of f alone, where |s| = |D| sqrt(V).  At the double roots
alone, :func:`double_root_signs` pins s further by the phi-derivative of f L, and :func:`simple_on_branches` proves
pieces free of them where f L splits into the branches s -+ D sqrt(V).

Everything here is vectorised over windows, pieces and brackets.
"""

from __future__ import annotations

import numpy as np

from intervalkin.core.ball import Ball, cos_sin_multiple
from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import PI_HI, Interval, certainly_negative, certainly_positive, sign_label
from intervalkin.kinematics.reduced_equation import aligned_numerator, denominator
from intervalkin.solve.simple_roots import basis_waves, trig_basis

__all__ = ["denominator_enclosure", "gap_positive", "line_misses_circle", "aligned_r_slopes", "root_direction_signs",
           "simple_on_branches", "branch_slopes", "double_root_signs", "S_PARTS",
           "D_GAP", "D_HALVINGS", "d_zeros", "cut_at_d_zeros", "sub_windows", "root_d_signs", "sign_changes"]

#: Half-width of the gap cut around each zero of D in a D-open window.
D_GAP = 1e-9
#: Bisections of a root's bracket while proving the sign of D on it.
D_HALVINGS = 12


def denominator_enclosure(geometry: Geometry, lo: np.ndarray, hi: np.ndarray) -> Interval:
    """Enclosure of D(phi) = d_0 + d_1 cos phi + d_2 sin phi over [lo, hi] (mean value form and natural form, and
    the hull of the end values where D' has one sign)."""
    d = Ball.from_interval(denominator(geometry))
    piece = Ball.from_interval(Interval(np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)))

    def value(phi: Ball, deriv: int) -> Ball:
        c, s = cos_sin_multiple(phi, 1, deriv)  # deriv 1: (-sin, cos), and d_0 drops out
        trig = d[1] * c + d[2] * s
        return trig + d[0] if deriv == 0 else trig

    at_mid = value(Ball.point(piece.mid), 0)
    slope = value(piece, 1)
    mv = (at_mid + slope * Ball(np.zeros_like(piece.mid), piece.rad)).to_interval()
    out = mv.intersect(value(piece, 0).to_interval())
    # where D is proved monotone on the piece, its range is the hull of its end values: this keeps a piece
    # that ends next to a zero of D (a gap cut, d_zeros) signed, where the centred form spreads too far
    monotone = sign_label(slope.to_interval()) != 0
    if monotone.any():
        ends = [value(Ball.from_interval(Interval(x, x)), 0).to_interval()
                for x in np.broadcast_arrays(np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64))]
        hull = ends[0].hull(ends[1])
        out = Interval(np.where(monotone, np.maximum(out.lo, hull.lo), out.lo),
                       np.where(monotone, np.minimum(out.hi, hull.hi), out.hi))
    return out


def gap_positive(geometry: Geometry, boxes: np.ndarray, owner: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(m,) bool: f > 0 proved over R^2 x [lo, hi], R = boxes[owner], by f >= s^2 / |m_2|^2 - r_1 D^2
    (:func:`intervalkin.kinematics.reduced_equation.aligned_numerator`): the bound that sees f = |N|^2 > 0 near a zero of D,
    where the Taylor form of f cancels.  s is affine in r, so its range over R^2 is enclosed as a product of
    balls (s and |m_2|^2 by the centred and natural forms of :func:`_aligned_terms`); everything is outward-rounded."""
    _, leg, s, d, _, r = _aligned_terms(geometry, boxes, owner, lo, hi)
    positive_leg = certainly_positive(leg)
    bound = s.sqr() / Interval(np.where(positive_leg, leg.lo, 1.0), np.where(positive_leg, leg.hi, 1.0))
    bound = bound - r[0] * d.sqr()
    return positive_leg & certainly_positive(bound)


def line_misses_circle(geometry: Geometry, boxes: np.ndarray, owner: np.ndarray, lo: np.ndarray,
                       hi: np.ndarray) -> np.ndarray:
    """(m,) bool: f > 0 proved over R^2 x [lo, hi], R = boxes[owner], because there the line m_2 . z = k_2 of
    legs 1 and 2 misses the circle |z|^2 = r_1 of leg 1 and D != 0 (proofs/lemma-line-misses-circle.md).

    With L = |m_2|^2 and k_2 = r_2 - r_1 - L / 4, f L = s^2 - D^2 V where V = r_1 L - k_2^2 (s = m_2 x N): V < 0
    and D != 0 give f >= D^2 |V| / L > 0.  A box enclosure of f misses it where the terms of f cancel; V's
    enclosure is a few interval operations on L, which has one harmonic."""
    _, leg, _, d, k, r = _aligned_terms(geometry, boxes, owner, lo, hi)
    v = r[0] * leg - k.sqr()
    return certainly_negative(v) & (sign_label(d) != 0)


def _aligned_terms(geometry: Geometry, boxes: np.ndarray, owner: np.ndarray, lo: np.ndarray, hi: np.ndarray):
    """Over R^2 x [lo, hi], R = boxes[owner]: (ds/dr_l (m, 3) balls, L, s, D, k_2, r_i) of f L = s^2 - D^2 V.

    s, its r-slopes and L are each the intersection of the natural form and the centred form in phi,
    X(phi_m) + X'(Phi) (Phi - phi_m) (proofs/lemma-mean-value-form.md): the natural form pays the amplitude of every
    harmonic times the piece's width, the centred form only the slope's range, which is far smaller where the
    harmonics cancel (near the zeros of D the amplitudes of s are thousands of times its size)."""
    aligned = aligned_numerator(geometry)
    phi = Ball.from_interval(Interval(np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)))
    waves = basis_waves(phi.mid)
    natural, at_mid, slope = (trig_basis(x, d, waves) for x, d in ((phi, 0), (Ball.point(phi.mid), 0), (phi, 1)))
    step = Ball(np.zeros_like(phi.mid), phi.rad)[:, None]
    box = np.asarray(boxes, dtype=np.float64)[owner]
    r = [Interval(box[:, i, 0], box[:, i, 1]).sqr() for i in range(3)]
    r_balls = [Ball.from_interval(x) for x in r]

    def tight(coef: Interval) -> tuple[Ball, Ball, Ball]:
        c = Ball.from_interval(coef)
        return natural.matmul(c), at_mid.matmul(c), slope.matmul(c)

    def affine(cols: Ball) -> Ball:  # c_0 + sum_i c_i r_i over the box
        out = cols[:, 0]
        for i in range(3):
            out = out + cols[:, 1 + i] * r_balls[i]
        return out

    nat, mid, der = tight(aligned.coefficients)
    slopes = Ball.from_interval((mid[:, 1:] + der[:, 1:] * step).to_interval().intersect(nat[:, 1:].to_interval()))
    s = (affine(mid) + affine(der) * step[:, 0]).to_interval().intersect(affine(nat).to_interval())
    nat, mid, der = tight(Interval(aligned.leg_square.lo[:, None], aligned.leg_square.hi[:, None]))
    leg = (mid + der * step).to_interval().intersect(nat.to_interval())[:, 0]
    k = r[1] - r[0] - leg * 0.25
    return slopes, leg, s, denominator_enclosure(geometry, lo, hi), k, r


def aligned_r_slopes(geometry: Geometry, boxes: np.ndarray, owner: np.ndarray, lo: np.ndarray,
                     hi: np.ndarray) -> list[Interval]:
    """Enclosures of df/dr_l, l = 1, 2, 3, over R^2 x [lo, hi], R = boxes[owner], from f L = s^2 - D^2 V
    (:func:`line_misses_circle`): L and D do not depend on r, so

        df/dr_l = (2 s ds/dr_l - D^2 dV/dr_l) / L,   dV/dr_1 = L + 2 k, dV/dr_2 = -2 k, dV/dr_3 = 0,

    with k = r_2 - r_1 - L / 4.  Near a zero of D, where the roots of f are close to s = 0, the two terms of
    f no longer cancel in this form: s is affine in r and enclosed tightly (proofs/lemma-line-misses-circle.md)."""
    slopes, leg, s, d, k, _ = _aligned_terms(geometry, boxes, owner, lo, hi)
    d2 = d.sqr()
    dv = [leg + k * 2.0, k * -2.0, None]
    positive = certainly_positive(leg)
    leg = Interval(np.where(positive, leg.lo, 1.0), np.where(positive, leg.hi, 1.0))
    out = []
    for i in range(3):
        num = s * slopes[:, i].to_interval() * 2.0
        if dv[i] is not None:
            num = num - d2 * dv[i]
        slope = num / leg
        out.append(Interval(np.where(positive, slope.lo, -np.inf), np.where(positive, slope.hi, np.inf)))
    return out


def _integer_combinations(lo: np.ndarray, hi: np.ndarray, e: np.ndarray) -> Interval:
    """(m, c): enclosures of sum_l e_l x_l for x_l in [lo_l, hi_l] (m, k <= 3) and integer rows e (c, k) with
    entries in -2..2, by two matrix products per end: a float sum of at most six exact products errs by at most
    5 u times the sum of their magnitudes, and the margin taken is 2**-50 = 8 u times it
    (proofs/lemma-line-misses-circle.md, Enclosures)."""
    pos, neg = np.maximum(e, 0).T.astype(np.float64), np.minimum(e, 0).T.astype(np.float64)
    with np.errstate(invalid="ignore"):
        c_lo, c_hi = lo @ pos + hi @ neg, hi @ pos + lo @ neg
        margin = (np.maximum(np.abs(lo), np.abs(hi)) @ np.abs(e).T.astype(np.float64)) * 2.0**-50 + 2.0**-1000
        c_lo, c_hi = c_lo - margin, c_hi + margin
    bad = ~(np.isfinite(c_lo) & np.isfinite(c_hi))
    return Interval(np.where(bad, -np.inf, c_lo), np.where(bad, np.inf, c_hi))


def simple_on_branches(geometry: Geometry, boxes: np.ndarray, owner: np.ndarray, lo: np.ndarray,
                       hi: np.ndarray) -> np.ndarray:
    """(m,) bool: no point of R^2 x [lo, hi], R = boxes[owner], is a double root of f (proofs/lemma-branch-roots.md).

    Where the line of legs 1 and 2 meets the circle of leg 1 (V > 0 proved) and D != 0, f L = s^2 - D^2 V is the
    product of the two branches g_+- = s -+ D sqrt(V), smooth in phi, never zero together.  A double root of f is
    then a double root of one branch, and there is none when both slopes g_+-' (:func:`branch_slopes`) have one
    strict sign over the piece.  Close to a zero of D the root bound of :func:`root_direction_signs` cannot sign
    D_e f (s takes both signs at the roots), but a pattern of pair windows changes only where u = min s f
    vanishes, at a double root: pieces proved free of those say nothing about the directions."""
    ok, plus, minus = branch_slopes(geometry, boxes, owner, lo, hi)
    return ok & (sign_label(plus) != 0) & (sign_label(minus) != 0)


def branch_slopes(geometry: Geometry, boxes: np.ndarray, owner: np.ndarray, lo: np.ndarray,
                  hi: np.ndarray) -> tuple[np.ndarray, Interval, Interval]:
    """((m,) bool, the rows where V > 0, L > 0 and D != 0 are proved over R^2 x [lo, hi]; there, enclosures of
    g_+-' = s' -+ (D' sqrt(V) + D V' / (2 sqrt(V))), with V' = L' (r_1 + k / 2) since V = r_1 L - k^2 and
    k = r_2 - r_1 - L / 4 (elsewhere meaningless))."""
    _, leg, _, d, k, r = _aligned_terms(geometry, boxes, owner, lo, hi)
    v = r[0] * leg - k.sqr()
    ok = certainly_positive(v) & certainly_positive(leg) & (sign_label(d) != 0)
    s_phi, v_phi, d_phi = _phi_slopes(geometry, lo, hi, r, k)
    root_v = Interval(np.where(ok, v.lo, 1.0), np.where(ok, v.hi, 1.0)).sqrt()
    branch = d_phi * root_v + d * v_phi / (root_v * 2.0)
    return ok, s_phi - branch, s_phi + branch


def _phi_slopes(geometry: Geometry, lo: np.ndarray, hi: np.ndarray, r: list[Interval],
                k: Interval) -> tuple[Interval, Interval, Interval]:
    """(s', V', D') over R^2 x [lo, hi] (' = d/dphi; r the enclosures of r_i over R^2, k of k_2): the derivative
    basis times the aligned coefficients, V' = L' (r_1 + k / 2) (lemma-branch-roots.md, part 3)."""
    aligned = aligned_numerator(geometry)
    phi = Ball.from_interval(Interval(np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)))
    basis = trig_basis(phi, 1)
    coef = basis.matmul(Ball.from_interval(aligned.coefficients))
    s_phi = coef[:, 0]
    for i in range(3):
        s_phi = s_phi + coef[:, 1 + i] * Ball.from_interval(r[i])
    leg_phi = basis.matmul(Ball.from_interval(Interval(aligned.leg_square.lo[:, None],
                                                       aligned.leg_square.hi[:, None])))[:, 0].to_interval()
    c, sn = cos_sin_multiple(phi, 1, 1)  # d/dphi of (cos phi, sin phi)
    dd = Ball.from_interval(denominator(geometry))
    return s_phi.to_interval(), leg_phi * (r[0] + k * 0.5), (dd[1] * c + dd[2] * sn).to_interval()


#: Parts of each sign's range of s in :func:`double_root_signs`.
S_PARTS = 16


def double_root_signs(geometry: Geometry, boxes: np.ndarray, owner: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                      directions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """At the DOUBLE roots of f only: ((m, c) int8, the sign of D_e f there (0: not proved), (m,) bool, the pieces
    proved to hold none), for pieces where D != 0 is proved (others: 0 and False).  lemma-double-root-s.md:
    at a double root s^2 = D^2 V and (f L)' = 0, so s is a zero of

        Q(sigma) = 2 sigma s' - 2 (D' / D) sigma^2 - D^2 V'

    in the root bound's range of s; the parts of that range (each sign's side cut in :data:`S_PARTS`) where an
    enclosure of Q holds 0 bound s at the double roots far more tightly than |s| <= |D| sqrt(V), and
    L D_e f = 2 s D_e s - D^2 D_e V is signed over each sign's hull of them."""
    directions = np.asarray(directions, dtype=np.int64)
    m = len(owner)
    signs = np.zeros((m, len(directions)), dtype=np.int8)
    none = np.zeros(m, dtype=bool)
    for a in range(0, m, _ROOT_BLOCK):
        part = slice(a, min(a + _ROOT_BLOCK, m))
        signs[part], none[part] = _double_block(geometry, boxes, owner[part], lo[part], hi[part], directions)
    return signs, none


def _double_block(geometry, boxes, owner, lo, hi, directions):
    slopes, leg, s, d, k, r = _aligned_terms(geometry, boxes, owner, lo, hi)
    m = len(owner)
    v = r[0] * leg - k.sqr()
    bound = (Interval(np.zeros(m), np.maximum(v.hi, 0.0)).sqrt()
             * Interval(np.zeros(m), np.maximum(np.abs(d.lo), np.abs(d.hi)))).hi
    s_lo, s_hi = np.maximum(s.lo, -bound), np.minimum(s.hi, bound)
    ok = (sign_label(d) != 0) & certainly_positive(leg)
    signs = np.zeros((m, len(directions)), dtype=np.int8)
    none = ok & ~(s_lo <= s_hi)  # no root at all
    live = np.flatnonzero(ok & (s_lo <= s_hi))
    if not live.size:
        return signs, none
    s_phi, v_phi, d_phi = _phi_slopes(geometry, lo[live], hi[live], [x[live] for x in r], k[live])
    dl = d[live]
    ratio = (d_phi / dl) * 2.0
    const = dl.sqr() * v_phi
    hulls = []
    for side in (-1, 1):  # sigma <= 0, sigma >= 0: the sign of s at the double root
        a = np.where(side < 0, s_lo[live], np.maximum(s_lo[live], 0.0))
        b = np.where(side < 0, np.minimum(s_hi[live], 0.0), s_hi[live])
        grid = a[:, None] + (b - a)[:, None] * (np.arange(S_PARTS + 1) / S_PARTS)[None, :]
        grid[:, -1] = b  # the parts cover [a, b] exactly: consecutive parts share their float ends
        sigma = Interval(np.minimum(grid[:, :-1], grid[:, 1:]), np.maximum(grid[:, :-1], grid[:, 1:]))
        col = lambda x: Interval(x.lo[:, None], x.hi[:, None])  # noqa: E731
        q = sigma * col(s_phi) * 2.0 - sigma.sqr() * col(ratio) - col(const)
        keep = (q.lo <= 0) & (q.hi >= 0) & (a <= b)[:, None]
        h_lo = np.where(keep, sigma.lo, np.inf).min(axis=1)
        h_hi = np.where(keep, sigma.hi, -np.inf).max(axis=1)
        hulls.append((keep.any(axis=1), h_lo, h_hi))
    none[live] = ~hulls[0][0] & ~hulls[1][0]
    box = np.asarray(boxes, dtype=np.float64)[owner[live]]
    rho2 = [Interval(2.0 * box[:, i, 0], 2.0 * box[:, i, 1]) for i in range(3)]
    ds = [slopes[live, i].to_interval() * rho2[i] for i in range(3)]
    lv, kv = leg[live], k[live]
    dv = [(lv + kv * 2.0) * rho2[0], kv * -2.0 * rho2[1]]
    de_s = _integer_combinations(np.column_stack([x.lo for x in ds]), np.column_stack([x.hi for x in ds]), directions)
    de_v = _integer_combinations(np.column_stack([x.lo for x in dv]), np.column_stack([x.hi for x in dv]),
                                 directions[:, :2])
    d2 = dl.sqr()
    term = Interval(d2.lo[:, None], d2.hi[:, None]) * de_v
    agreed = np.full((live.size, len(directions)), 2, dtype=np.int64)  # 2: no side seen yet
    for held, h_lo, h_hi in hulls:
        sg = sign_label(Interval(np.where(held, h_lo, 0.0)[:, None], np.where(held, h_hi, 0.0)[:, None]) * de_s * 2.0
                        - term).astype(np.int64)
        agreed = np.where(~held[:, None], agreed, np.where((agreed == 2) | (agreed == sg), sg, 0))
    signs[live] = np.where(np.abs(agreed) == 1, agreed, 0)
    return signs, none


#: Pieces per block in :func:`root_direction_signs` (its arrays are pieces x directions).
_ROOT_BLOCK = 16384


def root_direction_signs(geometry: Geometry, boxes: np.ndarray, owner: np.ndarray, lo: np.ndarray,
                         hi: np.ndarray, directions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """At the ROOTS of f only: ((m, c) int8, the sign of D_e f = sum_l e_l 2 rho_l df/dr_l at every root of f in
    R^2 x [lo, hi], R = boxes[owner], for each integer direction e (c, 3) in rho, 0 where not proved; (m,) bool,
    the pieces proved to hold no root of f).

    At a root f L = s^2 - D^2 V = 0, so |s| = |D| sqrt(V) with V >= 0 (proofs/lemma-line-misses-circle.md,
    statement 4): s lies in [-B, B], B = max |D| sqrt(max(V, 0)), and in its range over the piece; beside a zero
    of D, where a root has s near 0 but the piece's range of s does not, the intersection is far narrower, and
    where it is empty no point of the piece is a root.  Then L D_e f = 2 s D_e s - D^2 D_e V (statement 3), with
    one s for every axis, and L > 0 where it is proved."""
    directions = np.asarray(directions, dtype=np.int64)
    if directions.size and np.abs(directions).max() > 2:
        raise ValueError("root_direction_signs: direction entries must lie in -2..2 (their products are exact)")
    m = len(owner)
    signs = np.zeros((m, len(directions)), dtype=np.int8)
    rootless = np.zeros(m, dtype=bool)
    for a in range(0, m, _ROOT_BLOCK):
        part = slice(a, min(a + _ROOT_BLOCK, m))
        signs[part], rootless[part] = _root_block(geometry, boxes, owner[part], lo[part], hi[part], directions)
    return signs, rootless


def _root_block(geometry: Geometry, boxes: np.ndarray, owner: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                directions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    slopes, leg, s, d, k, r = _aligned_terms(geometry, boxes, owner, lo, hi)
    box = np.asarray(boxes, dtype=np.float64)[owner]
    v = r[0] * leg - k.sqr()
    bound = (Interval(np.zeros(len(owner)), np.maximum(v.hi, 0.0)).sqrt()
             * Interval(np.zeros(len(owner)), np.maximum(np.abs(d.lo), np.abs(d.hi)))).hi
    s_lo, s_hi = np.maximum(s.lo, -bound), np.minimum(s.hi, bound)
    rootless = ~(s_lo <= s_hi)
    signs = np.zeros((len(owner), len(directions)), dtype=np.int8)
    # where the bound does not narrow s, this is aligned_r_slopes' enclosure again: not worth a second time
    tight = np.flatnonzero(~rootless & (bound < np.maximum(np.abs(s.lo), np.abs(s.hi))))
    if not tight.size:
        return signs, rootless
    slopes, leg, d, k, box = slopes[tight], leg[tight], d[tight], k[tight], box[tight]
    at_root = Interval(s_lo[tight][:, None], s_hi[tight][:, None])
    rho2 = [Interval(2.0 * box[:, i, 0], 2.0 * box[:, i, 1]) for i in range(3)]
    ds = [slopes[:, i].to_interval() * rho2[i] for i in range(3)]
    dv = [(leg + k * 2.0) * rho2[0], k * -2.0 * rho2[1]]
    de_s = _integer_combinations(np.column_stack([x.lo for x in ds]), np.column_stack([x.hi for x in ds]), directions)
    de_v = _integer_combinations(np.column_stack([x.lo for x in dv]), np.column_stack([x.hi for x in dv]),
                                 directions[:, :2])
    d2 = d.sqr()
    value = at_root * de_s * 2.0 - Interval(d2.lo[:, None], d2.hi[:, None]) * de_v
    signs[tight] = np.where(certainly_positive(leg)[:, None], sign_label(value), 0)
    return signs, rootless


def d_zeros(geometry: Geometry) -> np.ndarray:
    """The zeros of D(phi) = d_0 + d_1 cos phi + d_2 sin phi in (-pi, pi), in floats (used only as cut points)."""
    d = denominator(geometry).mid()
    amp = float(np.hypot(d[1], d[2]))
    if not amp > abs(d[0]):
        return np.zeros(0)
    z = np.arctan2(d[2], d[1]) + np.array([-1.0, 1.0]) * np.arccos(-d[0] / amp)
    return np.sort((z + np.pi) % (2 * np.pi) - np.pi)


def cut_at_d_zeros(geometry: Geometry, window: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                   selected: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The pieces (window, lo, hi) in order, those of the ``selected`` (w,) windows cut at phi_D +- D_GAP."""
    cuts = np.sort(np.ravel(d_zeros(geometry)[:, None] + np.array([-D_GAP, D_GAP])))
    cuts = cuts[np.abs(cuts) < PI_HI]
    inside = selected[window][:, None] & (lo[:, None] < cuts) & (cuts < hi[:, None])
    if not inside.any():
        return window, lo, hi
    c = np.broadcast_to(cuts, inside.shape)
    start = np.concatenate([lo[:, None], np.where(inside, c, np.nan)], axis=1).ravel()
    end = np.concatenate([np.where(inside, c, np.nan), hi[:, None]], axis=1).ravel()
    keep_s, keep_e = ~np.isnan(start), ~np.isnan(end)
    return np.repeat(window, 1 + inside.sum(axis=1)), start[keep_s], end[keep_e]


def sub_windows(window: np.ndarray, channels: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Greedy maximal runs of pieces sharing one signed derivative.

    ``window`` (p,) sorted: the window of each piece (pieces in circle order); ``channels`` (3, p):
    the certified sign of f', f'', f''' over each piece (0: not proved).  Returns ``start`` (p,) bool,
    the first piece of each run; ``order`` (p,) int8, at a run's first piece the lowest order whose
    sign is shared by the whole run (0 elsewhere); ``failed`` (p,) bool, True on every piece of a
    window with a piece of no signed derivative.
    """
    p = window.size
    start, order = np.zeros(p, dtype=bool), np.zeros(p, dtype=np.int8)
    if p == 0:
        return start, order, np.zeros(0, dtype=bool)
    reach = np.full((3, p), -1, dtype=np.int64)  # last piece of the run of one sign of f^(d) through each piece
    for d in range(3):
        c = channels[d]
        new = np.r_[True, (c[1:] != c[:-1]) | (window[1:] != window[:-1])]
        last = np.r_[np.flatnonzero(new)[1:] - 1, p - 1][np.cumsum(new) - 1]
        reach[d] = np.where(c != 0, last, -1)
    far = reach.max(axis=0)
    first = np.flatnonzero(np.r_[True, window[1:] != window[:-1]])
    final = np.r_[first[1:] - 1, p - 1]
    bad = np.zeros(first.size, dtype=bool)
    cur, live = first.copy(), np.arange(first.size)
    while live.size:  # one run per window and step: as many steps as the longest window has runs
        s = cur[live]
        e = far[s]
        bad[live[e < s]] = True
        ok = e >= s
        live, s, e = live[ok], s[ok], e[ok]
        start[s] = True
        order[s] = 1 + np.argmax(reach[:, s] >= e, axis=0)
        cur[live] = e + 1
        live = live[cur[live] <= final[live]]
    return start, order, np.repeat(bad, np.diff(np.r_[first, p]))


def _bracket_d_signs(geometry: Geometry, lo: np.ndarray, hi: np.ndarray, owner: np.ndarray, n: int,
                     halvings: int) -> np.ndarray:
    """(n,) the one sign of D over the union of the intervals [lo, hi] of each owner, bisected; 0: not proved."""
    low, high = np.full(n, 2, dtype=np.int64), np.full(n, -2, dtype=np.int64)
    for round_ in range(halvings + 1):
        sd = sign_label(denominator_enclosure(geometry, lo, hi)).astype(np.int64)
        np.minimum.at(low, owner, np.where(sd != 0, sd, 2))
        np.maximum.at(high, owner, np.where(sd != 0, sd, -2))
        open_ = (sd == 0) & ~((low[owner] == -1) & (high[owner] == 1))  # an owner with both signs: refused
        if round_ == halvings:
            low[owner[open_]] = 0
            break
        owner, lo, hi = owner[open_], lo[open_], hi[open_]
        if owner.size == 0:
            break
        mid = np.minimum(np.maximum(0.5 * lo + 0.5 * hi, lo), hi)
        owner, lo, hi = np.r_[owner, owner], np.r_[lo, mid], np.r_[mid, hi]
    return np.where((low == high) & (np.abs(low) == 1), low, 0)


def sign_changes(pair: np.ndarray, x0: np.ndarray, x1: np.ndarray, s0: np.ndarray, s1: np.ndarray):
    """The sign changes of f along sorted sub-pieces [x0, x1] with end signs s0, s1 (0: not proved), skipping
    unproved signs: (pair, left, right, rising) of each, [left, right] the bracket between the two signs."""
    seq = np.stack([s0, s1], axis=1).ravel()
    xs = np.stack([x0, x1], axis=1).ravel()
    grp = np.repeat(pair, 2)
    nz = seq != 0
    v, g, xs = seq[nz], grp[nz], xs[nz]
    at = np.flatnonzero((v[1:] != v[:-1]) & (g[1:] == g[:-1]))
    return g[at], xs[at], xs[at + 1], v[at + 1] > 0


def root_d_signs(geometry: Geometry, left: np.ndarray, right: np.ndarray, halvings: int = D_HALVINGS) -> np.ndarray:
    """(b,) the sign of D proved over each root bracket [left, right] (across phi = pi when right < left); 0: not proved."""
    wrap = right < left
    lo = np.r_[left, -PI_HI * np.ones(int(wrap.sum()))]
    hi = np.r_[np.where(wrap, PI_HI, right), right[wrap]]
    owner = np.r_[np.arange(left.size), np.flatnonzero(wrap)]
    return _bracket_d_signs(geometry, lo, hi, owner, left.size, halvings)
