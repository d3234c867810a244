"""A straight motion certified to stay in one aspect and in the joint limits.

The motion is P(t) = A + t (B - A), t in [0, 1], where A and B are known
through enclosures (the exact solutions of the direct kinematics at the ends of
a trajectory, or float waypoints, whose enclosures are points).  [0, 1] is cut
into pieces [t0, t1]; the interval expression A + [t0, t1] (B - A) (outward
rounded, A and B as intervals) is a box holding the piece of the segment for
every A and B in their enclosures, and on that box
:func:`~intervalkin.kinematics.enclosures.det_a_interval` is proved of the
aspect's sign and :func:`~intervalkin.kinematics.enclosures.rho_sq_interval`
within [rho_min^2, rho_max^2] for every leg.  A piece that is undecided is
halved; a piece proved wrong (det A of the other sign, or a leg beyond a limit,
on the whole piece) ends the attempt with that reason, and so does a piece
halved :data:`MAX_BISECTIONS` times or more than :data:`MAX_PIECES` pieces
(proofs/lemma-trajectory-certificate.md).

A certified segment never meets det A = 0: the platform moves without a type-2
singularity and without leaving the joint limits.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from intervalkin.core.errors import InputError
from intervalkin.core.exact import fraction_bounds
from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import Interval
from intervalkin.kinematics.enclosures import det_a_interval, rho_sq_interval

__all__ = ['MAX_BISECTIONS', 'MAX_PIECES', 'SegmentCertificate', 'piece_boxes', 'certify_segment']

#: A piece of a segment is halved at most this many times (piece length >= 2**-MAX_BISECTIONS).
MAX_BISECTIONS = 40
#: At most this many pieces per segment before giving up.
MAX_PIECES = 1 << 16


@dataclass(frozen=True, eq=False)
class SegmentCertificate:
    """The straight motion from A to B, and the pieces on which it was proved.

    Attributes
    ----------
    start, end : ndarray (3, 2)
        Interval enclosures (lo, hi) of the exact end points A and B (x, y, phi
        unwrapped); degenerate for float waypoints.
    pieces : ndarray (k, 2)
        Parameter ranges [t0, t1], sorted, covering [0, 1] exactly (consecutive
        pieces share their end point), each proved (when ``certified``).
    certified : bool
        True when every piece was proved: det A has the sign ``sign`` and every
        leg length is within its limits on the whole segment, for every A and B
        in their enclosures.
    reason : str
        Why not, with the failing parameter range ("" when certified).
    """

    start: np.ndarray
    end: np.ndarray
    sign: int
    pieces: np.ndarray
    certified: bool
    reason: str = ""

    def boxes(self, pieces: np.ndarray | None = None) -> np.ndarray:
        """Boxes (k, 3, 2) enclosing the pieces (all of them, or the (k, 2) ``pieces`` given) of the segment."""
        p = self.pieces if pieces is None else pieces
        return piece_boxes(self.start, self.end, p[:, 0], p[:, 1])


def piece_boxes(start: np.ndarray, end: np.ndarray, t0: np.ndarray, t1: np.ndarray) -> np.ndarray:
    """Enclosures of {A + t (B - A) : A in start, B in end, t in [t0, t1]} as (k, 3, 2) boxes.

    Written A + T (B - A) with outward-rounded interval operations: the width is
    about (t1 - t0) |B - A| plus the widths of the end enclosures, not
    (t1 - t0) (|A| + |B|) as the form (1 - T) A + T B would give.
    """
    a = Interval(start[:, 0][None, :], start[:, 1][None, :])
    b = Interval(end[:, 0][None, :], end[:, 1][None, :])
    t = Interval(np.asarray(t0, dtype=np.float64)[:, None], np.asarray(t1, dtype=np.float64)[:, None])
    p = a + t * (b - a)
    lo, hi = np.broadcast_arrays(p.lo, p.hi)
    return np.stack([lo, hi], axis=-1)


def _limit_bounds(geometry: Geometry, inner: bool) -> tuple[np.ndarray, np.ndarray]:
    """Float bounds of each rho_min^2 and rho_max^2, rounded inward (``inner``) or outward.

    Inner bounds (an upper bound of rho_min^2, a lower bound of rho_max^2) prove a
    leg within its limits; outer bounds prove it beyond them.
    """
    lo = np.array([fraction_bounds(Fraction(v) ** 2)[1 if inner else 0] for v in geometry.rho_min])
    hi = np.array([fraction_bounds(Fraction(v) ** 2)[0 if inner else 1] for v in geometry.rho_max])
    return lo, hi


def _boxes_certified(geometry: Geometry, boxes: np.ndarray, sign: int) -> np.ndarray:
    """(k,) bool: det A proved of sign ``sign`` and every leg proved within its limits on each box."""
    d = det_a_interval(geometry, boxes)
    ok = (d.lo > 0) if sign > 0 else (d.hi < 0)
    lo_sq, hi_sq = _limit_bounds(geometry, inner=True)
    r = rho_sq_interval(geometry, boxes)
    ok &= np.all((r.lo >= lo_sq) & (r.hi <= hi_sq), axis=1)
    return np.asarray(ok, dtype=bool)


def _boxes_refuted(geometry: Geometry, boxes: np.ndarray, sign: int) -> np.ndarray:
    """(k,) bool: det A proved of the WRONG sign, or some leg proved beyond a limit, on the whole box."""
    d = det_a_interval(geometry, boxes)
    bad = (d.hi < 0) if sign > 0 else (d.lo > 0)
    lo_sq, hi_sq = _limit_bounds(geometry, inner=False)
    r = rho_sq_interval(geometry, boxes)
    bad |= np.any((r.hi < lo_sq) | (r.lo > hi_sq), axis=1)
    return np.asarray(bad, dtype=bool)


def certify_segment(
    geometry: Geometry,
    start: np.ndarray,
    end: np.ndarray,
    sign: int,
    max_bisections: int = MAX_BISECTIONS,
    max_pieces: int = MAX_PIECES,
) -> SegmentCertificate:
    """Prove that the straight motion from ``start`` to ``end`` stays in one aspect and in the limits.

    Parameters
    ----------
    start, end : array (3,) of floats (exact points) or (3, 2) enclosures (lo, hi)
        of the end points (x, y, phi); phi in radians, unwrapped (any real).
    sign : +1 (aspect WA1, det A > 0) or -1 (WA2, det A < 0).
    max_bisections, max_pieces : the budget; past it the answer is "not certified".

    Returns
    -------
    SegmentCertificate
        ``certified`` True means: for every A in ``start``, every B in ``end`` and
        every t in [0, 1], det A(P(t)) has the sign ``sign`` and
        rho_min_i <= rho_i(P(t)) <= rho_max_i, P(t) = A + t (B - A).  False means
        not proved (the motion may still be fine); ``reason`` says where.

    Examples
    --------
    >>> from intervalkin.core.geometry import default_geometry
    >>> g = default_geometry()
    >>> c = certify_segment(g, [-14.9, 1.6, 0.25], [-14.0, 1.0, 0.3], +1)
    >>> c.certified, float(c.pieces[0, 0]), float(c.pieces[-1, 1])
    (True, 0.0, 1.0)
    """
    if sign not in (1, -1):
        raise InputError(f"sign: expected +1 or -1, got {sign!r}")
    a = _as_enclosure(start, "start")
    b = _as_enclosure(end, "end")
    t0 = np.array([0.0])
    t1 = np.array([1.0])
    level = np.array([0])
    done: list[np.ndarray] = []
    total = 0
    while t0.size:
        ok = _boxes_certified(geometry, piece_boxes(a, b, t0, t1), sign)
        done.append(np.stack([t0[ok], t1[ok]], axis=1))
        bad = ~ok
        if not np.any(bad):
            break
        t0, t1, level = t0[bad], t1[bad], level[bad]
        refuted = _boxes_refuted(geometry, piece_boxes(a, b, t0, t1), sign)
        if np.any(refuted):
            k = int(np.argmax(refuted))
            why = (f"the motion leaves the aspect or the joint limits: on t in [{t0[k]:.17g}, {t1[k]:.17g}] "
                   "det A is proved of the wrong sign or a leg proved beyond its limit")
            return SegmentCertificate(a, b, sign, _sorted_pieces(done), False, why)
        if np.any(level >= max_bisections):
            k = int(np.argmax(level >= max_bisections))
            why = (f"piece t in [{t0[k]:.17g}, {t1[k]:.17g}] not proved after {max_bisections} bisections "
                   "(det A of the wrong or undecided sign, or a leg at or beyond its limit)")
            return SegmentCertificate(a, b, sign, _sorted_pieces(done), False, why)
        total += 2 * t0.size
        if total > max_pieces:
            k = 0
            why = (f"more than {max_pieces} pieces needed; first unproved piece t in "
                   f"[{t0[k]:.17g}, {t1[k]:.17g}]")
            return SegmentCertificate(a, b, sign, _sorted_pieces(done), False, why)
        tm = 0.5 * t0 + 0.5 * t1
        t0, t1 = np.concatenate([t0, tm]), np.concatenate([tm, t1])
        level = np.concatenate([level, level]) + 1
    pieces = _sorted_pieces(done)
    # the pieces must tile [0, 1] exactly (a soundness invariant of the bisection)
    assert pieces[0, 0] == 0.0 and pieces[-1, 1] == 1.0 and np.all(pieces[1:, 0] == pieces[:-1, 1])
    return SegmentCertificate(a, b, sign, pieces, True, "")


def _sorted_pieces(done: list[np.ndarray]) -> np.ndarray:
    p = np.concatenate(done, axis=0) if done else np.zeros((0, 2))
    return p[np.argsort(p[:, 0], kind="stable")]


def _as_enclosure(p, name: str) -> np.ndarray:
    a = np.asarray(p, dtype=np.float64)
    if a.shape == (3,):
        a = np.stack([a, a], axis=1)
    if a.shape != (3, 2) or not np.all(np.isfinite(a)) or np.any(a[:, 0] > a[:, 1]):
        raise InputError(f"{name}: expected a point (3,) or an enclosure (3, 2) with lo <= hi, got {a.tolist()}")
    return a
