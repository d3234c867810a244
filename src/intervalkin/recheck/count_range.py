"""Proved ranges of the number of direct-kinematics solutions at every point of a joint box.

For a closed joint box R (leg lengths q, r = q^2) and a closed arc I of orientations, this module
proves integers lo <= hi such that, at every q in R, the number of solutions with orientation in
I lies in [lo, hi] (``hi`` is :data:`NO_BOUND` where no bound was proved).  The arc is cut into
pieces, and on each piece P the first of these holds for every r in R^2 (d = 0 .. 3):

    the d-th phi-derivative of f(phi; r) has one strict sign on P.

Consecutive pieces with the same order and sign form a *run*, on which that sign holds throughout.
Rolle's theorem then bounds the roots of f(.; r) in a run, counted with multiplicity, by d (d = 0: no
root).  When the signs of f at both ends of the run are proved non-zero over R^2, the number with
multiplicity is odd exactly when they differ, so the bound drops to d - 1 when its parity is
wrong.  The solutions at q number at most the roots of f(.; q^2) with multiplicity (a root with
D != 0 carries one solution, a root with D = 0 is multiple and carries at most two), and every
root lies in some (closed) run: the sum of the runs' bounds is ``hi``.  Between two consecutive
points where f has proved opposite signs, on an arc where D != 0 is proved, f has a root that
carries exactly one solution; the number of such arcs is ``lo``.  The argument is
``proofs/lemma-count-range.md``.

Pieces are found by bisection, vectorised over every (box, piece): a piece on which no derivative
order up to 3 has a proved sign is cut in two, at most ``depth`` times; a piece where only the
second or third derivative has one is cut too, until the last :data:`HIGH_ORDER_LEVELS` halvings.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.workers import Workers
from intervalkin.recheck.arith import PI_HI, PI_LO, down, up
from intervalkin.recheck.reduced_equation import ReducedConstants, d_sign, derivative_enclosures, reduced_constants, \
    sign_at_points

__all__ = ["NO_BOUND", "PIECES", "DEPTH", "HIGH_ORDER_LEVELS", "GRID", "CountRanges", "count_ranges", "excludes_count",
           "count_lower", "cut_angles", "cut_signs", "arc_ranges", "run_bounds",
           "r_box", "sign_changes", "supported"]

#: ``hi`` of a box where some piece kept no proved bound.
NO_BOUND = 99
#: Equal pieces the whole circle starts from.
PIECES = 32
#: Halvings of a piece before it is given up.
DEPTH = 7
#: Pieces that need the second or third derivative are accepted only in the last this-many halvings.
HIGH_ORDER_LEVELS = 3


@dataclass(frozen=True)
class CountRanges:
    """lo, hi (n,) int64: at every point of box i the number of solutions (in the arc asked) lies in
    [lo[i], hi[i]]; hi is :data:`NO_BOUND` where no upper bound was proved."""

    lo: np.ndarray
    hi: np.ndarray

    def excludes(self, count: int) -> np.ndarray:
        """(n,) bool: PROVED that no point of the box has ``count`` solutions (in the arc)."""
        return (count < self.lo) | (count > self.hi)


def supported(geometry: Geometry) -> bool:
    """The solution bound at a root with D = 0 needs m_i = 2 (R(phi) p_i - a_i) != 0 for one leg i in {2, 3}
    at every phi: true unless |p_i| = |A_i - A_1| for both (exact rational comparison)."""
    base = geometry.base
    equal = 0
    for i in (1, 2):
        ax, ay = base[i][0] - base[0][0], base[i][1] - base[0][1]
        equal += geometry.platform_radius_sq(i) == ax * ax + ay * ay
    return equal < 2


def r_box(q_lo: np.ndarray, q_hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Enclosure of r = q^2 over boxes of leg lengths q > 0 (rounded outward)."""
    q_lo, q_hi = np.asarray(q_lo, dtype=np.float64), np.asarray(q_hi, dtype=np.float64)
    if not (np.all(np.isfinite(q_lo)) and np.all(np.isfinite(q_hi)) and np.all(q_lo > 0) and np.all(q_lo <= q_hi)):
        raise ValueError("joint boxes must have finite bounds with 0 < lo <= hi")
    return np.maximum(down(q_lo * q_lo), 0.0), up(q_hi * q_hi)


def _signs(k: ReducedConstants, r_lo, r_hi, box, phi: np.ndarray) -> np.ndarray:
    """The proved sign of f at each point phi (over box's r), pi and -pi taken as [PI_LO, PI_HI] up to sign."""
    lo, hi = phi.copy(), phi.copy()
    seam = np.abs(phi) >= PI_LO
    lo[seam], hi[seam] = -PI_HI, -PI_LO  # f is 2 pi-periodic: f(pi) = f(-pi)
    return sign_at_points(k, r_lo[box], r_hi[box], lo, hi)


def _pieces(k: ReducedConstants, r_lo, r_hi, box, a, b, pieces: int, depth: int):
    """Cut each arc [a[j], b[j]] into pieces on which some derivative order d <= 3 of f has a proved sign.

    Returns (owner, lo, hi, order, sign, s_lo, s_hi, failed): per piece its arc, ends, the least such d
    and the sign of f^(d) there, the proved signs of f at its ends (0: not proved); ``failed`` (m,)
    marks arcs with a piece left without a sign after ``depth`` halvings."""
    m = box.size
    edges = a[:, None] + (b - a)[:, None] * (np.arange(pieces + 1) / pieces)[None, :]
    edges[:, 0], edges[:, -1] = a, b
    owner = np.repeat(np.arange(m), pieces)
    lo_phi, hi_phi = edges[:, :-1].ravel(), edges[:, 1:].ravel()
    sign_e = _signs(k, r_lo, r_hi, np.repeat(box, pieces + 1), edges.ravel()).reshape(m, pieces + 1)
    s_lo, s_hi = sign_e[:, :-1].ravel(), sign_e[:, 1:].ravel()
    out = []
    failed = np.zeros(m, dtype=bool)
    for level in range(depth + 1):
        if owner.size == 0:
            break
        b_of = box[owner]
        # the seam's enclosure keeps the arc ends at +-pi inside the interval
        plo = np.where(lo_phi <= -PI_LO, -PI_HI, lo_phi)
        phi_ = np.where(hi_phi >= PI_LO, PI_HI, hi_phi)
        order = np.full(owner.size, -1)
        sign = np.zeros(owner.size, dtype=np.int8)
        # f itself first, from the first two Taylor coefficients only (most pieces hold no root); the same
        # enclosure of f as the full call would give, since truncation leaves the kept coefficients as they are
        f0 = derivative_enclosures(k, r_lo[b_of], r_hi[b_of], plo, phi_, 1)[0]
        pos, neg = f0[0] > 0, f0[1] < 0
        order[pos | neg] = 0
        sign[pos], sign[neg] = 1, -1
        more = np.flatnonzero(~(pos | neg))
        if more.size:
            enc = derivative_enclosures(k, r_lo[b_of[more]], r_hi[b_of[more]], plo[more], phi_[more])
            o, sg = order[more], sign[more]
            for d in range(len(enc) - 1, 0, -1):
                pos, neg = enc[d][0] > 0, enc[d][1] < 0
                o = np.where(pos | neg, d, o)
                sg = np.where(pos, 1, np.where(neg, -1, sg)).astype(np.int8)
            order[more], sign[more] = o, sg
        # a piece where only the second or third derivative has a sign may hold no root, or one: halve it while
        # the depth allows, so that Rolle's bound of 2 or 3 is only paid where the roots are close together
        done = (order >= 0) & ((order <= 1) | (level >= depth - HIGH_ORDER_LEVELS))
        out.append((owner[done], lo_phi[done], hi_phi[done], order[done], sign[done], s_lo[done], s_hi[done]))
        rest = ~done
        if level == depth:
            failed[owner[rest]] = True
            break
        owner, lo_phi, hi_phi, s_lo, s_hi = owner[rest], lo_phi[rest], hi_phi[rest], s_lo[rest], s_hi[rest]
        mid = np.clip(lo_phi + (hi_phi - lo_phi) / 2, lo_phi, hi_phi)
        s_mid = _signs(k, r_lo, r_hi, box[owner], mid)
        owner = np.concatenate([owner, owner])
        lo_phi, hi_phi = np.concatenate([lo_phi, mid]), np.concatenate([mid, hi_phi])
        s_lo, s_hi = np.concatenate([s_lo, s_mid]), np.concatenate([s_mid, s_hi])
    cols = [np.concatenate(c) for c in zip(*out)] if out else [np.zeros(0)] * 7
    owner, lo_phi, hi_phi, order, sign, s_lo, s_hi = cols
    at = np.lexsort((lo_phi, owner))
    return (*(c[at] for c in (owner, lo_phi, hi_phi, order, sign, s_lo, s_hi)), failed)


def run_bounds(order: np.ndarray, e_lo: np.ndarray, e_hi: np.ndarray) -> np.ndarray:
    """Rolle's bound on the roots, with multiplicity, of a run whose ``order``-th derivative has a strict sign:
    ``order`` itself, lowered by one when both end signs of f are proved (non-zero) and the parity they give
    (odd exactly when they differ) is not that of ``order``; 0 for order 0 (f itself has a sign)."""
    known = (e_lo != 0) & (e_hi != 0)
    odd = known & (e_lo != e_hi)
    return np.where(known & ((order % 2) != odd) & (order > 0), order - 1, order)


def sign_changes(k: ReducedConstants, owner, lo_phi, hi_phi, s_lo, s_hi, m: int) -> np.ndarray:
    """(m,) the number of spans between consecutive points of proved sign where f changes sign and D != 0 is
    proved on the whole span.  Each such span holds a root of f (of odd multiplicity) with D != 0, so one
    solution z = N / D; the spans meet only at their ends, where f != 0, so the solutions differ."""
    ends = np.concatenate([lo_phi, hi_phi])
    signs = np.concatenate([s_lo, s_hi])
    who = np.concatenate([owner, owner])
    keep = signs != 0
    ends, signs, who = ends[keep], signs[keep], who[keep]
    at = np.lexsort((ends, who))
    ends, signs, who = ends[at], signs[at], who[at]
    out = np.zeros(m, dtype=np.int64)
    if ends.size < 2:
        return out
    change = (who[1:] == who[:-1]) & (signs[1:] != signs[:-1])
    j = np.flatnonzero(change)
    if j.size:
        a = np.where(ends[j] <= -PI_LO, -PI_HI, ends[j])
        b = np.where(ends[j + 1] >= PI_LO, PI_HI, ends[j + 1])
        ok = d_sign(k, a, b) != 0
        np.add.at(out, who[j][ok], 1)
    return out


def arc_ranges(k: ReducedConstants, r_lo: np.ndarray, r_hi: np.ndarray, box: np.ndarray, a: np.ndarray,
               b: np.ndarray, pieces: int = 1, depth: int = DEPTH) -> CountRanges:
    """Ranges of the number of solutions with orientation in the closed arc [a[j], b[j]] (a <= b, inside
    [-pi, pi], with +-pi meaning the seam) at every r in the box ``box[j]`` of (r_lo, r_hi) (n, 3).

    Consecutive pieces of one arc on which the same derivative order has the same sign are taken as one
    *run* (the sign holds on the union of closed pieces), and Rolle's bound is applied to the run."""
    m = box.size
    if m == 0:  # a batch of boxes whose every arc was decided without a range (no solution on any grid step)
        return CountRanges(np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64))
    owner, lo_phi, hi_phi, order, sign, s_lo, s_hi, failed = _pieces(k, r_lo, r_hi, box, a, b, pieces, depth)
    # f has the sign of a d = 0 piece at both of its ends
    s_lo = np.where(order == 0, sign, s_lo)
    s_hi = np.where(order == 0, sign, s_hi)
    n = owner.size
    same_prev = np.zeros(n, dtype=bool)
    if n > 1:
        same_prev[1:] = ((owner[1:] == owner[:-1]) & (order[1:] == order[:-1]) & (sign[1:] == sign[:-1])
                         & (lo_phi[1:] == hi_phi[:-1]))
        # a sign proved at a shared cut by either side holds for both
        shared = (owner[1:] == owner[:-1]) & (lo_phi[1:] == hi_phi[:-1])
        s_lo[1:] = np.where(shared & (s_lo[1:] == 0), s_hi[:-1], s_lo[1:])
        s_hi[:-1] = np.where(shared & (s_hi[:-1] == 0), s_lo[1:], s_hi[:-1])
    start = np.flatnonzero(~same_prev)
    stop = np.r_[start[1:], n] - 1
    r_owner, r_order = owner[start], order[start]
    e_lo, e_hi = s_lo[start], s_hi[stop]
    bound = run_bounds(r_order, e_lo, e_hi)
    hi_count = np.zeros(m, dtype=np.int64)
    np.add.at(hi_count, r_owner, bound)
    lo_count = sign_changes(k, owner, lo_phi, hi_phi, s_lo, s_hi, m)
    hi_count[failed] = NO_BOUND
    return CountRanges(lo_count, np.minimum(hi_count, NO_BOUND))


def _ranges_part(geometry: Geometry, q_lo: np.ndarray, q_hi: np.ndarray, pieces: int, depth: int) -> tuple:
    r_lo, r_hi = r_box(q_lo, q_hi)
    n = q_lo.shape[0]
    got = arc_ranges(reduced_constants(geometry), r_lo, r_hi, np.arange(n), np.full(n, -np.pi), np.full(n, np.pi),
                     pieces, depth)
    return got.lo, got.hi


#: Fixed candidate cut angles on the circle.
GRID = 64


def cut_angles(grid: int = GRID) -> np.ndarray:
    """The candidate cut angles -pi + (j + 1/2) 2 pi / grid (binary64 values, taken as exact), inside (-pi, pi)."""
    return -np.pi + (np.arange(grid) + 0.5) * (2 * np.pi / grid)


def cut_signs(k: ReducedConstants, q_lo: np.ndarray, q_hi: np.ndarray, grid: int = GRID) -> np.ndarray:
    """(n, grid) int8: the proved sign of f at each candidate cut over each joint box (0: not proved)."""
    q_lo, q_hi = np.atleast_2d(q_lo), np.atleast_2d(q_hi)
    r_lo, r_hi = r_box(q_lo, q_hi)
    n = q_lo.shape[0]
    ang = np.tile(cut_angles(grid), n)
    s = sign_at_points(k, np.repeat(r_lo, grid, axis=0), np.repeat(r_hi, grid, axis=0), ang, ang)
    return s.reshape(n, grid)


def count_lower(k: ReducedConstants, q_lo: np.ndarray, q_hi: np.ndarray, grid: int = GRID) -> np.ndarray:
    """(n,) a lower bound of the number of solutions at every point of each box from the signs of f at the cut
    angles alone: two consecutive angles (not across the seam) where f has proved, different signs over the box,
    with D != 0 proved between them, hold one solution (as in :func:`arc_ranges`).  No bisection: about a sixth
    of the time of a range."""
    q_lo, q_hi = np.atleast_2d(q_lo), np.atleast_2d(q_hi)
    signs = cut_signs(k, q_lo, q_hi, grid)
    owner, at = np.nonzero(signs)
    ang = cut_angles(grid)[at]
    s = signs[owner, at].astype(np.int64)
    return sign_changes(k, owner, ang, ang, s, s, q_lo.shape[0])


def excludes_count(geometry: Geometry, q_lo: np.ndarray, q_hi: np.ndarray, count: int,
                   workers: Workers | None = None) -> np.ndarray:
    """(n,) bool: PROVED that no point of box i has ``count`` solutions: :func:`count_lower` above ``count``, else
    the range of :func:`count_ranges` (on ``workers``) excludes it.  Next to a cell with more solutions the cut
    signs alone decide most boxes (90 % of the walls of the paper's barriers around its cells without solutions)."""
    q_lo, q_hi = np.atleast_2d(q_lo), np.atleast_2d(q_hi)
    if q_lo.shape[0] == 0:
        return np.zeros(0, dtype=bool)
    out = count_lower(reduced_constants(geometry), q_lo, q_hi) > count
    rest = np.flatnonzero(~out)
    if rest.size:
        out[rest] = count_ranges(geometry, q_lo[rest], q_hi[rest], workers=workers).excludes(count)
    return out


def count_ranges(geometry: Geometry, q_lo: np.ndarray, q_hi: np.ndarray, pieces: int = PIECES,
                 depth: int = DEPTH, workers: Workers | None = None) -> CountRanges:
    """At every point of each joint box [q_lo[i], q_hi[i]] (n, 3), the number of solutions lies in [lo, hi].

    ``workers`` (:class:`~intervalkin.core.workers.Workers`) may share the boxes between processes: each box's
    range is computed on its own, so the answer is the same.  Raises ValueError for a geometry
    :func:`supported` refuses and for malformed boxes."""
    if not supported(geometry):
        raise ValueError("count ranges need |p_i| != |A_i - A_1| for leg 2 or leg 3")
    q_lo, q_hi = np.atleast_2d(q_lo), np.atleast_2d(q_hi)
    r_box(q_lo, q_hi)  # validates every box before any part is sent away
    n = q_lo.shape[0]
    workers = workers or Workers(1)  # one process: the single part is computed here
    got = workers.run(_ranges_part, [(geometry, q_lo[a:b], q_hi[a:b], pieces, depth) for a, b in workers.parts(n)])
    if not got:
        return CountRanges(np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64))
    return CountRanges(np.concatenate([g[0] for g in got]), np.concatenate([g[1] for g in got]))
