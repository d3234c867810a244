"""Joint-space boxes on which the direct kinematics keeps one structure.

The claim
---------
For a box R of joint vectors (rho_1, rho_2, rho_3), write r = rho^2 and let
f(phi; r) be the reduced equation (:mod:`intervalkin.kinematics.reduced_equation`).
R is *clear* when no (phi, r) with r in R^2 := {rho^2 : rho in R} has

    f(phi; r) = 0   and   df/dphi(phi; r) = 0,

that is, when every real root of f(.; r) is simple, for every r in R.  Then
(proofs/lemma-simple-roots-constant-count.md):

* the roots of f(.; r) move continuously with r and none appears, disappears or
  merges, so their number is the same at every point of R (R is connected);
* a root phi* with D(phi*) = 0 (the 2x2 position system singular) is always a
  multiple root of f, so every root of a clear box has D != 0 and carries exactly
  one solution z = N / D: the number of direct-kinematic solutions is constant on R;
* a solution with det A = 0 is a multiple root of f (on D != 0, f = D^2 g with
  g(phi) = |z(phi)|^2 - r_1, and det A is proportional to D g'), so every
  solution stays non-singular on R and keeps its sign of det A: the split of the
  solutions between the aspects is constant on R too.

So a clear box lies off g(S), and one certified solve at any point of it gives
its count and aspect split.

The test
--------
The circle of orientations is covered by pieces Phi (a piece covering phi = +-pi
included).  On a piece, the pair (R, Phi) is settled when 0 is excluded from an
enclosure of f over R x Phi (no root there), or from an enclosure of df/dphi
(f is strictly monotone in phi on Phi for every r: its roots there are simple).
Unsettled pieces are bisected, a bounded number of times; a box with an
unsettled piece at the end is undecided (it may meet g(S)).

Enclosures are mean-value forms about the centre (r_c, phi_m) of R^2 x Phi,

    f(R, Phi) in f(r_c, phi_m) + sum_i d_i f(R, Phi) (R_i - r_c,i) + d_phi f(R, Phi) (Phi - phi_m),

where for fixed phi the quadratic in r is expanded exactly about r_c (the
second-order part bounded once per box), intersected with the natural form in
phi.  The arithmetic is midpoint-radius (:class:`intervalkin.core.ball.Ball`,
proofs/lemma-ball-arithmetic.md): the work is small dot products over millions of
(box, piece) pairs, vectorised with numpy.  The same form with f replaced by
df/dphi encloses the slope.
"""

from __future__ import annotations

import numpy as np

from intervalkin.core.ball import Ball, cos_sin_at, cos_sin_multiple
from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import PI_HI, Interval
from intervalkin.kinematics.reduced_equation import HARMONICS, MONOMIALS, reduced_equation

__all__ = ["initial_pieces", "open_pieces", "ReducedBoxes", "trig_basis", "basis_waves", "PIECES", "HALVINGS"]

#: Pieces of the orientation circle tried first on every box.
PIECES = 24
#: Bisections of an unsettled piece before the box is called undecided.
HALVINGS = 7
#: A box with more unsettled pieces than this at some round is undecided at once (it straddles g(S)).
_CROWD = 24
#: Boxes tested together (memory: about 40 kB per box at the first round).
_CHUNK = 4096
#: Rows of (box, piece) pairs an enclosure takes at once: past about 2^16 its temporaries leave the cache and
#: a row costs twice as much.
_ROWS = 2**14
#: Pieces narrower than this are not bisected further (float resolution of phi, with margin).
_MIN_WIDTH = 2.0**-30


def trig_basis(phi: Ball, deriv: int = 0, waves: dict | None = None,
               out: tuple[np.ndarray, np.ndarray] | None = None) -> Ball:
    """(m, 7) balls of the deriv-th phi-derivative of the basis (1, cos phi, sin phi, ...) over phi (m,).

    ``waves``: :func:`basis_waves` of ``phi.mid``, when several bases are taken about the same midpoints (the
    same floats: the same balls, without computing cos and sin again).  ``out``: (mid, rad) arrays (m, 7),
    possibly views of larger ones, to write the basis into."""
    mid, rad = (np.empty(phi.mid.shape + (7,)), np.empty(phi.mid.shape + (7,))) if out is None else out
    col = 0
    for k, is_sin in HARMONICS:
        if k == 0:
            mid[..., col] = 1.0 if deriv == 0 else 0.0
            rad[..., col] = 0.0
            col += 1
            continue
        if is_sin:
            continue
        c, s = cos_sin_multiple(phi, k, deriv, None if waves is None else waves[k])
        mid[..., col], mid[..., col + 1] = c.mid, s.mid
        rad[..., col], rad[..., col + 1] = c.rad, s.rad
        col += 2
    return Ball(mid, rad)


def basis_waves(mid: np.ndarray) -> dict:
    """{k: (cos k mid, sin k mid)} for the harmonics of the basis: what :func:`trig_basis` shares between bases
    about the same midpoints."""
    return {k: cos_sin_at(mid, k) for k, is_sin in HARMONICS if k and not is_sin}


class ReducedBoxes:
    """Per-box data of the Taylor form in r (computed once, gathered per piece).

    For fixed phi, f(phi; r) = sum_h c_h(r) basis_h(phi) with c_h quadratic in r,
    so for r = r_c + d, exactly,

        f = c(r_c) . w + sum_i (d c / d r_i)(r_c) . w  d_i + sum_h w_h Q_h(d),

    w = basis(phi) and Q_h the quadratic part of c_h.  Over a piece Phi, w is a
    ball; the coefficients sum_h w_h Q_h of the monomials d_i d_j are computed per
    piece, and |d_i| <= h_i (the half-width of R_i^2) bounds them.

    Public because :mod:`intervalkin.solve.window_model` encloses higher phi-derivatives
    with it, and evaluates it on point boxes (lo = hi: R^2 is then the rounded square).
    """

    def __init__(self, geometry: Geometry, boxes: np.ndarray):
        C = Ball.from_interval(reduced_equation(geometry).coefficients)  # (7, 10)
        r = [Ball.from_interval(Interval(boxes[:, i, 0], boxes[:, i, 1]).sqr()) for i in range(3)]
        rc = [Ball.point(ri.mid) for ri in r]
        self.half = np.stack([ri.rad for ri in r], axis=1)  # (n, 3)
        n = len(boxes)
        ones, zeros = Ball.point(np.ones(n)), Ball.point(np.zeros(n))
        rows: list[list[Ball]] = [[], [], [], []]  # monomials at r_c, then their r_i-derivatives
        for e in MONOMIALS:
            rows[0].append(ones if not e else rc[e[0]] if len(e) == 1 else rc[e[0]] * rc[e[1]])
            for i in range(3):
                if i not in e:
                    rows[1 + i].append(zeros)
                elif len(e) == 1:
                    rows[1 + i].append(ones)
                elif e[0] == e[1]:
                    rows[1 + i].append(rc[i].scale(2.0))
                else:
                    rows[1 + i].append(rc[e[1] if e[0] == i else e[0]])
        monos = _stack([_stack(row) for row in rows], axis=1)  # (n, 4, 10)
        Ct = Ball(C.mid.T.copy(), C.rad.T.copy())  # (10, 7)
        self.taylor = monos.matmul(Ct)  # (n, 4, 7): c(r_c) and its three r-derivatives
        # the same, each box's matrix transposed and contiguous (7, 4), for the stacked products of the enclosures
        self.taylor_t = Ball(np.ascontiguousarray(self.taylor.mid.transpose(0, 2, 1)),
                             np.ascontiguousarray(self.taylor.rad.transpose(0, 2, 1)))
        # second-order part, sum_h w_h Q_h(d): the quadratic coefficients as rows (6, 7), d-bounds per box
        quad = [m for m, e in enumerate(MONOMIALS) if len(e) == 2]
        self.quad_t = Ball(C.mid[:, quad].copy(), C.rad[:, quad].copy())  # (7, 6): basis index, monomial
        h = self.half
        self.quad_square = np.array([MONOMIALS[m][0] == MONOMIALS[m][1] for m in quad])
        self.quad_bound = np.stack([h[:, MONOMIALS[m][0]] * h[:, MONOMIALS[m][1]] for m in quad], axis=1) * (1.0 + 2.0**-40)
        # point boxes (lo = hi, R^2 the rounded square): the coefficients c_h(R^2) as balls directly,
        # the monomials of the balls r times C, which encloses them with the square's tiny width included
        self.at_points = bool(np.all(boxes[:, :, 0] == boxes[:, :, 1]))
        if self.at_points:
            value = [ones if not e else r[e[0]] if len(e) == 1 else r[e[0]] * r[e[1]] for e in MONOMIALS]
            self.values = _stack(value).matmul(Ct)  # (n, 7)

    def enclosure(self, owner: np.ndarray, lo: np.ndarray, hi: np.ndarray, deriv: int) -> Interval:
        """Enclosure of d^deriv f / dphi^deriv over (box owner, piece [lo, hi]).

        Mean value in phi, f(R, phi_m) + d_phi f(R, Phi) (Phi - phi_m), intersected
        with the natural form f(R, Phi); each with the exact Taylor form in r.  The three
        bases (at phi_m, and over Phi for the slope and the natural form) share their cos and sin,
        and go through the Taylor form together.  Long arrays are taken in blocks of :data:`_ROWS` rows
        (the temporaries of a block stay in cache; the enclosures are the same).
        """
        if len(owner) > _ROWS:
            parts = [self.enclosure(owner[i:i + _ROWS], lo[i:i + _ROWS], hi[i:i + _ROWS], deriv)
                     for i in range(0, len(owner), _ROWS)]
            return Interval(np.concatenate([e.lo for e in parts]), np.concatenate([e.hi for e in parts]))
        piece = Ball.from_interval(Interval(lo, hi))
        waves = basis_waves(piece.mid)
        bases = Ball(np.empty((len(owner), 3, 7)), np.empty((len(owner), 3, 7)))
        for slot, (phi, d) in enumerate(((Ball.point(piece.mid), deriv), (piece, deriv + 1), (piece, deriv))):
            trig_basis(phi, d, waves, (bases.mid[:, slot], bases.rad[:, slot]))
        if self.at_points:
            at_mid, slope, natural = (bases[:, i].dot(self.values[owner]) for i in range(3))
        else:
            both = self._over_r(owner, bases)  # (m, 3)
            at_mid, slope, natural = (both[:, i] for i in range(3))
        mv = (at_mid + slope * Ball(np.zeros_like(piece.mid), piece.rad)).to_interval()
        return mv.intersect(natural.to_interval())

    def _over_r(self, owner: np.ndarray, w: Ball) -> Ball:
        """sum_h c_h(r) w_h over R^2 of box owner[i], for each basis row w[i, l] (m, l, 7): balls (m, l)."""
        t = w.row_matmul(self.taylor_t[owner])  # (m, l, 4): c(r_c) . w and its three r-derivatives
        half = self.half[owner]
        spread = np.einsum("mli,mi->ml", np.abs(t.mid[..., 1:]) + t.rad[..., 1:], half)
        q = w.matmul(self.quad_t)  # (m, l, 6)
        bound = self.quad_bound[owner]
        # d_i^2 lies in [0, h_i^2]: q d_i^2 in q h^2 / 2 +- |q| h^2 / 2; d_i d_j in [-h_i h_j, h_i h_j]
        sq = self.quad_square
        centre = np.einsum("mlk,mk->ml", q.mid[..., sq], 0.5 * bound[:, sq])
        second = (np.einsum("mlk,mk->ml", np.abs(q.mid[..., sq]) + 2.0 * q.rad[..., sq], 0.5 * bound[:, sq])
                  + np.einsum("mlk,mk->ml", np.abs(q.mid[..., ~sq]) + q.rad[..., ~sq], bound[:, ~sq]))
        mid = t.mid[..., 0] + centre
        extra = (spread + second + 2.0**-40 * np.abs(centre)) * (1.0 + 2.0**-40) + 2.0**-1000
        return Ball(mid, t.rad[..., 0] + extra)

    def r_slope(self, owner: np.ndarray, lo: np.ndarray, hi: np.ndarray, axis: int, deriv: int = 0,
                mean_value: bool = False) -> Interval:
        """Enclosure of d^(1 + deriv) f / d r_axis d phi^deriv over (box owner, piece [lo, hi]), r_axis = rho_axis^2.

        d c_h / d r_axis is affine in r: its value at r_c (a row of the Taylor data) plus
        sum_i (d^2 c_h / d r_axis d r_i) d_i with |d_i| <= h_i; natural form in phi (the basis
        differentiated ``deriv`` times).  With ``mean_value``, intersected with the mean-value form in phi (the
        value at the piece's midpoint plus the next phi-derivative over the piece times the offset): the natural
        form multiplies the basis' width by the large coefficients of f, which mostly cancel.
        """
        piece = Ball.from_interval(Interval(lo, hi))
        natural = self._r_slope_ball(owner, piece, axis, deriv).to_interval()
        if not mean_value:
            return natural
        at_mid = self._r_slope_ball(owner, Ball.point(piece.mid), axis, deriv)
        rate = self._r_slope_ball(owner, piece, axis, deriv + 1)
        return natural.intersect((at_mid + rate * Ball(np.zeros_like(piece.mid), piece.rad)).to_interval())

    def _r_slope_ball(self, owner: np.ndarray, phi: Ball, axis: int, deriv: int) -> Ball:
        """:meth:`r_slope`'s natural form over the balls ``phi``, as balls."""
        taylor = self.taylor[owner]
        half = self.half[owner]
        w = trig_basis(phi, deriv)
        t = w.dot_rows(taylor)  # (m, 4)
        q = w.matmul(self.quad_t)  # (m, 6)
        quad = [e for e in MONOMIALS if len(e) == 2]
        spread = np.zeros(len(owner))
        for i in range(3):
            k = quad.index((min(axis, i), max(axis, i)))
            factor = 2.0 if i == axis else 1.0  # d^2 (r_a^2) / d r_a^2 = 2
            spread += factor * (np.abs(q.mid[:, k]) + q.rad[:, k]) * half[:, i]
        return Ball(t.mid[:, 1 + axis], t.rad[:, 1 + axis] + spread * (1.0 + 2.0**-40) + 2.0**-1000)


def _stack(parts: list[Ball], axis: int = -1) -> Ball:
    shape = np.broadcast_shapes(*(p.mid.shape for p in parts))
    return Ball(np.stack([np.broadcast_to(p.mid, shape) for p in parts], axis=axis),
                np.stack([np.broadcast_to(p.rad, shape) for p in parts], axis=axis))


def initial_pieces(n: int, pieces: int = PIECES) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(owner, lo, hi): ``pieces`` equal pieces of the orientation circle for each of n boxes.

    The outer cuts are -PI_HI and PI_HI, so the pieces cover the whole circle.
    """
    cuts = np.linspace(-PI_HI, PI_HI, pieces + 1)
    cuts[0], cuts[-1] = -PI_HI, PI_HI
    return np.repeat(np.arange(n), pieces), np.tile(cuts[:-1], n), np.tile(cuts[1:], n)


def open_pieces(geometry: Geometry, boxes: np.ndarray, owner: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                halvings: int = HALVINGS) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The pieces the simple-roots test leaves open, after up to ``halvings`` bisections.

    Parameters
    ----------
    boxes : (n, 3, 2) joint boxes (rho > 0).
    owner, lo, hi : (m,) pieces [lo, hi] of the orientation circle, each of box ``owner``
        (sorted by owner).  Every piece is a claim to settle: "no (phi, r) with phi in the
        piece and r in the box's R^2 has f = 0 and df/dphi = 0".

    Returns
    -------
    (owner, lo, hi) of the sub-pieces NOT settled.  Every point of an input piece lies in
    a settled sub-piece or in a returned one.  A box whose open sub-pieces number more
    than the crowd limit after a round stops being bisected (its pieces are returned as
    they are): it straddles g(S), and a smaller box will do better than finer pieces.
    """
    owner = np.asarray(owner, dtype=np.int64)
    if owner.size == 0:
        return owner, np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    n = len(boxes)
    if n > _CHUNK:  # bounded memory: the pieces of one chunk of boxes are in flight at a time
        parts = []
        for k in range(0, n, _CHUNK):
            sel = (owner >= k) & (owner < k + _CHUNK)
            o, a, b = open_pieces(geometry, boxes[k:k + _CHUNK], owner[sel] - k, lo[sel], hi[sel], halvings)
            parts.append((o + k, a, b))
        return tuple(np.concatenate([p[i] for p in parts]) for i in range(3))  # type: ignore[return-value]
    data = ReducedBoxes(geometry, np.asarray(boxes, dtype=np.float64))
    done_owner, done_lo, done_hi = [], [], []
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    for round_ in range(halvings + 1):
        f = data.enclosure(owner, lo, hi, 0)
        open_ = (f.lo <= 0) & (f.hi >= 0)
        if np.any(open_):
            idx = np.flatnonzero(open_)
            slope = data.enclosure(owner[idx], lo[idx], hi[idx], 1)
            open_[idx] = (slope.lo <= 0) & (slope.hi >= 0)
        owner, lo, hi = owner[open_], lo[open_], hi[open_]
        crowded = np.bincount(owner, minlength=n) > _CROWD
        stop = crowded[owner] | (hi - lo < _MIN_WIDTH)
        if round_ == halvings:
            stop[:] = True
        done_owner.append(owner[stop])
        done_lo.append(lo[stop])
        done_hi.append(hi[stop])
        owner, lo, hi = owner[~stop], lo[~stop], hi[~stop]
        if owner.size == 0:
            break
        mid = np.minimum(np.maximum(0.5 * lo + 0.5 * hi, lo), hi)
        owner = np.concatenate([owner, owner])
        lo, hi = np.concatenate([lo, mid]), np.concatenate([mid, hi])
    o, a, b = np.concatenate(done_owner), np.concatenate(done_lo), np.concatenate(done_hi)
    order = np.argsort(o, kind="stable")
    return o[order], a[order], b[order]
