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


Bounds that read f through f |m_2|^2 = s^2 - D^2 V (proofs/lemma-line-misses-circle.md), where its terms do
not cancel (:func:`aligned_terms` encloses s, |m_2|^2, D, k_2 over a box and a piece): :func:`gap_positive` and
:func:`line_misses_circle` settle pieces f > 0, :func:`aligned_r_slopes` encloses df/dr_l near the zeros of D,
where the Taylor form cannot sign it; :mod:`intervalkin.solve.root_directions` signs it at the roots of f.

Everything here is vectorised over windows, pieces and brackets.
"""

from __future__ import annotations

import numpy as np

from intervalkin.core.ball import Ball, cos_sin_multiple
from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import PI_HI, Interval, certainly_negative, certainly_positive, sign_label
from intervalkin.kinematics.reduced_equation import aligned_numerator, denominator
from intervalkin.solve.simple_roots import basis_waves, trig_basis

__all__ = ["denominator_enclosure", "gap_positive", "line_misses_circle", "aligned_terms", "aligned_r_slopes",
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
    balls (s and |m_2|^2 by the centred and natural forms of :func:`aligned_terms`); everything is outward-rounded."""
    _, leg, s, d, _, r = aligned_terms(geometry, boxes, owner, lo, hi, with_slopes=False)
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
    _, leg, _, d, k, r = aligned_terms(geometry, boxes, owner, lo, hi, with_s=False, with_slopes=False)
    v = r[0] * leg - k.sqr()
    return certainly_negative(v) & (sign_label(d) != 0)


def aligned_terms(geometry: Geometry, boxes: np.ndarray, owner: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                  with_s: bool = True, with_slopes: bool = True):
    """Over R^2 x [lo, hi], R = boxes[owner]: (ds/dr_l (m, 3) balls, L, s, D, k_2, r_i) of f L = s^2 - D^2 V
    (the r-slopes and s are None when not asked for: the bounds on L and k alone skip them).

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

    slopes = s = None
    if with_s or with_slopes:
        nat, mid, der = tight(aligned.coefficients)
        if with_slopes:
            slopes = Ball.from_interval((mid[:, 1:] + der[:, 1:] * step).to_interval()
                                        .intersect(nat[:, 1:].to_interval()))
        if with_s:
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
    slopes, leg, s, d, k, _ = aligned_terms(geometry, boxes, owner, lo, hi)
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
