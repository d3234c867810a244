"""Certified non-singular trajectories between assembly modes of one aspect.

The paper (section 3.2, Table 1) observes that solutions 2, 3 and 6 of the joint
vector rho = (14.98, 15.38, 12.0) lie in one aspect WA1, so the platform can move
from one to another without meeting a type-2 singularity; section 5.2 and
Figure 13 add that such a motion must pass through an intermediate basic region,
whose image is a joint-space domain with only two solutions.  This module builds
such a motion and PROVES it non-singular.

Construction
------------
1. The two solutions are the certified direct-kinematic boxes of
   :func:`dkp.solve` (numbered from 1 in increasing phi, as ``intervalkin dkp``
   prints them).  Opposite certified signs of det A put them in different
   aspects: then no non-singular path exists and :class:`NoPathError` says so.
2. A shortest path (A*, exact for the metric below) in the face-adjacency graph
   of the paving boxes certified INSIDE the aspect, from the box nearest the
   start solution to the box nearest the goal.  Edge weight: the distance of the
   box centres in the metric ``sqrt(dx^2 + dy^2 + (L dphi)^2)``, dphi taken
   modulo 2 pi and L the root-mean-square distance of the platform points from
   B1 (so a rotation costs about what it moves the platform).
3. Waypoints: the start solution, the centre of the face piece shared by each
   pair of consecutive boxes, the goal solution.  Each straight segment between
   them lies in one certified box.
4. Smoothing: a waypoint is dropped when the straight segment that skips it is
   itself certified (step 5); the farthest certifiable waypoint is searched by
   doubling then bisection.

phi convention
--------------
Waypoints carry an UNWRAPPED phi: phi is continuous along the path, it starts at
the start solution's phi (in (-pi, pi]) and may leave (-pi, pi] when the path
crosses the seam phi = +-pi.  The last waypoint is the goal solution's phi plus
``2 pi * phi_turns``.  Take phi modulo 2 pi to get the usual pose.  The
kinematics are 2 pi periodic in phi, so nothing else changes.

Certificate (proofs/lemma-trajectory-certificate.md)
----------------------------------------------------
The motion is the concatenation of the exact straight segments
P(t) = A + t (B - A), t in [0, 1], between consecutive waypoints, where the
first A and the last B are the EXACT solutions (known through their enclosures)
and the other waypoints are the floats stored.  For each segment, [0, 1] is cut
into pieces [t0, t1]; the interval expression A + [t0, t1] (B - A) (outward
rounded, A and B as intervals) is a box containing the piece of the segment,
and on that box :func:`kinematics.det_a_interval` is proved of the aspect's sign
and :func:`kinematics.rho_sq_interval` proved within [rho_min^2, rho_max^2] for
every leg.  Failing pieces are bisected; past :data:`MAX_BISECTIONS` halvings
the segment is not certified (``certified`` False, with the reason).  This test
does not use the paving at all: the paving only proposes the path.

Also reported, with what each claim rests on:

* the basic regions crossed (when a :class:`~intervalkin.regions.RegionAnalysis`
  is given): region ids of the paving leaves met by points sampled along the
  path at steps below half the finest leaf width, consecutive repeats merged,
  -1 ("layer") where the leaf carries no region (the enclosure of S_c or an
  undecided sheet).  Sampled, so a region touched only between two samples
  could be missed;
* the joint-space image (when a :class:`~intervalkin.joint.JointPaving` is
  given): each piece of each segment is enclosed in a box, its interval image
  g(box) computed, and :meth:`JointPaving.cell_of_boxes` names the cell that
  contains it: a certified statement "this piece maps into cell c", whose count
  is certified.  Pieces whose image may meet g(S) are reported as "layer".
  Unlike ``cell_at`` on rounded joint vectors, this covers every point of the path.

In both sequences a layer stretch between two visits of the same region (or
cell) is merged into it: the path left the certified part and came back, and
what it met meanwhile is not resolved at this depth.  The raw per-sample region
ids are kept in ``Trajectory.sample_region``.
"""

from __future__ import annotations

import heapq
import math
import os
import tempfile
import time
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import TYPE_CHECKING, Sequence

import numpy as np

from .errors import InputError, IntervalkinError
from .geometry import Geometry
from .interval import PI_HI, PI_LO, Interval, fraction_bounds
from .kinematics import approx_det_a, approx_inverse_kinematics, det_a_interval, rho_interval, rho_sq_interval
from .paving import Label, Paving, shares_face

if TYPE_CHECKING:  # pragma: no cover
    from .dkp import DkpResult
    from .joint import JointPaving
    from .regions import RegionAnalysis

__all__ = [
    "NoPathError",
    "check_request",
    "SegmentCertificate",
    "Trajectory",
    "certify_segment",
    "trajectory",
    "render_trajectory",
    "write_trajectory",
    "MAX_BISECTIONS",
]

#: A piece of a segment is halved at most this many times (piece length >= 2**-MAX_BISECTIONS).
MAX_BISECTIONS = 40
#: At most this many pieces per segment before giving up.
MAX_PIECES = 1 << 16
_TWO_PI = 2.0 * math.pi


class NoPathError(IntervalkinError):
    """The request cannot be met: no non-singular path (different aspects), or none found."""


# --------------------------------------------------------------------------------------
# The segment certificate
# --------------------------------------------------------------------------------------
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
        """Boxes (k, 3, 2) enclosing the pieces of the segment (sound)."""
        p = self.pieces if pieces is None else pieces
        return _piece_boxes(self.start, self.end, p[:, 0], p[:, 1])


def _piece_boxes(start: np.ndarray, end: np.ndarray, t0: np.ndarray, t1: np.ndarray) -> np.ndarray:
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


def _limit_bounds(geometry: Geometry) -> tuple[np.ndarray, np.ndarray]:
    """Floats: an upper bound of each rho_min^2 and a lower bound of each rho_max^2."""
    lo = np.array([fraction_bounds(Fraction(v) ** 2)[1] for v in geometry.rho_min])
    hi = np.array([fraction_bounds(Fraction(v) ** 2)[0] for v in geometry.rho_max])
    return lo, hi


def _boxes_certified(geometry: Geometry, boxes: np.ndarray, sign: int) -> np.ndarray:
    """(k,) bool: det A proved of sign ``sign`` and every leg proved within its limits on each box."""
    d = det_a_interval(geometry, boxes)
    ok = (d.lo > 0) if sign > 0 else (d.hi < 0)
    lo_sq, hi_sq = _limit_bounds(geometry)
    for i, r in enumerate(rho_sq_interval(geometry, boxes)):
        ok &= (r.lo >= lo_sq[i]) & (r.hi <= hi_sq[i])
    return np.asarray(ok, dtype=bool)


def _boxes_refuted(geometry: Geometry, boxes: np.ndarray, sign: int) -> np.ndarray:
    """(k,) bool: det A proved of the WRONG sign, or some leg proved beyond a limit, on the whole box."""
    d = det_a_interval(geometry, boxes)
    bad = (d.hi < 0) if sign > 0 else (d.lo > 0)
    lo_sq = np.array([fraction_bounds(Fraction(v) ** 2)[0] for v in geometry.rho_min])
    hi_sq = np.array([fraction_bounds(Fraction(v) ** 2)[1] for v in geometry.rho_max])
    for i, r in enumerate(rho_sq_interval(geometry, boxes)):
        bad |= (r.hi < lo_sq[i]) | (r.lo > hi_sq[i])
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
    >>> from intervalkin.geometry import default_geometry
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
        ok = _boxes_certified(geometry, _piece_boxes(a, b, t0, t1), sign)
        done.append(np.stack([t0[ok], t1[ok]], axis=1))
        bad = ~ok
        if not np.any(bad):
            break
        t0, t1, level = t0[bad], t1[bad], level[bad]
        refuted = _boxes_refuted(geometry, _piece_boxes(a, b, t0, t1), sign)
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


# --------------------------------------------------------------------------------------
# The result
# --------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class Trajectory:
    """A path between two assembly modes of one aspect, with its certificate.

    Attributes
    ----------
    rho : three Fractions, the joint vector.
    i_from, i_to : the solution numbers (1-based, increasing phi, as ``intervalkin dkp``).
    aspect : ``"WA1"`` or ``"WA2"``; ``sign`` its det A sign.
    waypoints : ndarray (m, 3), phi unwrapped (module docstring).  Rows 0 and m-1
        are the float midpoints of the solution enclosures; the certified motion
        starts and ends at the exact solutions (``segments[0].start`` and
        ``segments[-1].end`` are their enclosures).
    phi_turns : the goal is reached at its phi plus 2 pi phi_turns.
    segments : one :class:`SegmentCertificate` per pair of consecutive waypoints.
    certified : bool, all segments certified; ``reason`` otherwise.
    box_path : paving indices of the boxes of the shortest path (before smoothing).
    raw_waypoints : number of waypoints before smoothing.
    depth : depth of the paving used.
    samples : ndarray (s, 3), points along the path (unwrapped); ``sample_rho`` (s, 3)
        their float images g(X) (for plots only); ``sample_segment`` (s,).
    basic_regions : tuple of region ids in order (-1: the layer), or None without analysis.
    sample_region : ndarray (s,) or None.
    joint_cells : tuple of dicts {cell, count, n_wa1, n_wa2} in order (cell -1: layer),
        certified per piece (module docstring), or None without a joint paving.
    sample_count : ndarray (s,) certified count of the cell holding each sample's image, -1 unknown.
    seconds : timings.
    """

    rho: tuple[Fraction, Fraction, Fraction]
    i_from: int
    i_to: int
    aspect: str
    sign: int
    waypoints: np.ndarray
    phi_turns: int
    segments: tuple[SegmentCertificate, ...]
    certified: bool
    reason: str
    box_path: np.ndarray
    raw_waypoints: int
    depth: int
    samples: np.ndarray
    sample_rho: np.ndarray
    sample_segment: np.ndarray
    basic_regions: tuple[int, ...] | None = None
    sample_region: np.ndarray | None = None
    joint_cells: tuple[dict, ...] | None = None
    sample_count: np.ndarray | None = None
    solutions: tuple = ()
    seconds: dict = field(default_factory=dict)

    @property
    def counts_along_path(self) -> list[int] | None:
        """Certified solution counts of the cells crossed, in order (layer entries left out)."""
        if self.joint_cells is None:
            return None
        return [c["count"] for c in self.joint_cells if c["cell"] >= 0]

    @property
    def through_two_solution_cell(self) -> bool | None:
        """True when some piece of the path is PROVED to map into a cell with exactly 2 solutions.

        False only means "not shown at this depth": the image may cross a 2-solution
        cell inside the joint-space layer.  None without a joint paving.
        """
        c = self.counts_along_path
        return None if c is None else (2 in c)

    @property
    def waypoints_wrapped(self) -> np.ndarray:
        """The waypoints with phi taken into [-pi, pi)."""
        w = self.waypoints.copy()
        w[:, 2] = np.mod(w[:, 2] + math.pi, _TWO_PI) - math.pi
        return w

    def to_json(self) -> dict:
        """The ``intervalkin trajectory --json`` object (plain JSON types)."""
        d = {
            "rho": [float(v) for v in self.rho],
            "rho_exact": [f"{v.numerator}/{v.denominator}" for v in self.rho],
            "from": self.i_from,
            "to": self.i_to,
            "aspect": self.aspect,
            "waypoints": self.waypoints.tolist(),
            "phi_convention": "unwrapped: continuous along the path from the start solution's phi; "
                              "the goal is reached at its phi + 2 pi * phi_turns",
            "phi_turns": self.phi_turns,
            "basic_regions": None if self.basic_regions is None
            else [r if r >= 0 else "layer" for r in self.basic_regions],
            "certified": bool(self.certified),
        }
        if not self.certified:
            d["reason"] = self.reason
        if self.joint_cells is not None:
            d["joint_cells"] = [dict(c, cell=c["cell"] if c["cell"] >= 0 else "layer") for c in self.joint_cells]
            d["counts_along_path"] = self.counts_along_path
            d["through_two_solution_cell"] = self.through_two_solution_cell
        d["depth"] = self.depth
        d["raw_waypoints"] = self.raw_waypoints
        d["pieces_per_segment"] = [int(s.pieces.shape[0]) for s in self.segments]
        return d

    def certificate(self) -> dict:
        """What an independent checker needs to re-prove the motion (floats as exact hex strings).

        For each segment: the enclosures of its end points and its pieces [t0, t1];
        the claim is that on every piece the segment stays where det A has the sign
        ``sign`` and the legs within [rho_min, rho_max] (module docstring).
        """
        hx = lambda v: float(v).hex()  # noqa: E731
        return {
            "claim": "non-singular motion within the joint limits",
            "rho_exact": [f"{v.numerator}/{v.denominator}" for v in self.rho],
            "from": self.i_from,
            "to": self.i_to,
            "aspect": self.aspect,
            "det_sign": self.sign,
            "segments": [
                {
                    "start": [[hx(a), hx(b)] for a, b in s.start],
                    "end": [[hx(a), hx(b)] for a, b in s.end],
                    "pieces": [[hx(a), hx(b)] for a, b in s.pieces],
                    "certified": bool(s.certified),
                }
                for s in self.segments
            ],
        }

    def summary(self) -> str:
        """A few human-readable lines."""
        lines = [
            f"trajectory from solution {self.i_from} to {self.i_to} in {self.aspect}: "
            f"{len(self.waypoints)} waypoints ({self.raw_waypoints} before smoothing), "
            f"{'CERTIFIED' if self.certified else 'NOT certified: ' + self.reason}",
        ]
        if self.basic_regions is not None:
            lines.append("basic regions: " + " -> ".join(str(r) if r >= 0 else "layer" for r in self.basic_regions))
        if self.joint_cells is not None:
            lines.append("joint cells (count): " + " -> ".join(
                f"{c['cell']} ({c['count']})" if c["cell"] >= 0 else "layer" for c in self.joint_cells))
            lines.append(f"through a 2-solution cell: {'yes' if self.through_two_solution_cell else 'no'}")
        lines.append("waypoints (x, y, phi unwrapped):")
        lines += [f"  {x: .6f} {y: .6f} {p: .6f}" for x, y, p in self.waypoints]
        return "\n".join(lines)


# --------------------------------------------------------------------------------------
# Input
# --------------------------------------------------------------------------------------
def _joint_vector(geometry: Geometry, rho) -> tuple[Fraction, Fraction, Fraction]:
    from .dkp import parse_joint_vector

    vals = list(rho)
    if all(isinstance(v, (Fraction, int)) and not isinstance(v, bool) for v in vals) and len(vals) == 3:
        out = tuple(Fraction(v) for v in vals)
        for i, v in enumerate(out):
            if not geometry.rho_min[i] <= v <= geometry.rho_max[i]:
                raise InputError(f"rho_{i + 1}: {v} is outside the joint limits "
                                 f"[{float(geometry.rho_min[i])}, {float(geometry.rho_max[i])}]")
        return out  # type: ignore[return-value]
    return parse_joint_vector(geometry, [str(v) for v in vals])


def check_request(geometry: Geometry, rho, i_from: int, i_to: int) -> None:
    """Raise (one-line :class:`IntervalkinError`) when no path can be asked for; cheap (one solve)."""
    _endpoints(geometry, rho, i_from, i_to)


def _endpoints(geometry: Geometry, rho, i_from: int, i_to: int):
    """The certified solutions numbered i_from, i_to; raises when the request cannot be met."""
    from .dkp import solve

    q = _joint_vector(geometry, rho)
    res = solve(geometry, q)
    n = len(res.solutions)
    for name, i in (("--from", i_from), ("--to", i_to)):
        if isinstance(i, bool) or not isinstance(i, (int, np.integer)) or not 1 <= i <= n:
            raise InputError(f"{name}: expected a solution number in 1..{n} for rho = "
                             f"{[float(v) for v in q]}, got {i!r}")
    if i_from == i_to:
        raise InputError(f"--from and --to both name solution {i_from}: nothing to move")
    if not res.complete:
        raise InputError(f"rho = {[float(v) for v in q]}: the direct kinematics could not be certified "
                         f"({res.completeness_reason}), so solution numbers are not well defined")
    sa, sb = res.solutions[i_from - 1], res.solutions[i_to - 1]
    for i, s in ((i_from, sa), (i_to, sb)):
        if s.status != "unique" or s.det_sign == 0:
            raise InputError(f"solution {i}: its enclosure or its det A sign could not be certified")
    if sa.det_sign != sb.det_sign:
        sym = lambda s: "+" if s > 0 else "-"  # noqa: E731
        raise NoPathError(
            f"no non-singular path: solutions {i_from} and {i_to} are in different aspects "
            f"(det A signs {sym(sa.det_sign)}, {sym(sb.det_sign)})"
        )
    return q, res, sa, sb


# --------------------------------------------------------------------------------------
# Shortest path in the box graph
# --------------------------------------------------------------------------------------
def _metric_length(geometry: Geometry) -> float:
    """L: root-mean-square distance of the three platform points from B1."""
    return math.sqrt(sum(float(geometry.platform_radius_sq(i)) for i in range(3)) / 3.0)


def _wrap(d: np.ndarray) -> np.ndarray:
    """d modulo 2 pi into [-pi, pi)."""
    return np.mod(d + math.pi, _TWO_PI) - math.pi


def _dist(a: np.ndarray, b: np.ndarray, L: float) -> np.ndarray:
    dphi = _wrap(b[..., 2] - a[..., 2])
    return np.sqrt((b[..., 0] - a[..., 0]) ** 2 + (b[..., 1] - a[..., 1]) ** 2 + (L * dphi) ** 2)


def _point_box_distance(p: np.ndarray, lo: np.ndarray, hi: np.ndarray, L: float) -> np.ndarray:
    dx = np.maximum(np.maximum(lo[:, 0] - p[0], p[0] - hi[:, 0]), 0.0)
    dy = np.maximum(np.maximum(lo[:, 1] - p[1], p[1] - hi[:, 1]), 0.0)
    best = np.full(lo.shape[0], np.inf)
    for shift in (-_TWO_PI, 0.0, _TWO_PI):
        ph = p[2] + shift
        best = np.minimum(best, np.maximum(np.maximum(lo[:, 2] - ph, ph - hi[:, 2]), 0.0))
    return np.sqrt(dx * dx + dy * dy + (L * best) ** 2)


def _shortest_box_path(paving: Paving, edges: np.ndarray, name: str, start: np.ndarray, goal: np.ndarray,
                       L: float) -> np.ndarray | None:
    """Indices of the boxes of a shortest path (A*), or None when start and goal are not connected."""
    inside = paving.labels[name] == Label.INSIDE
    nodes = np.flatnonzero(inside)
    if nodes.size == 0:
        return None
    lo, hi = paving.lo[nodes], paving.hi[nodes]
    centre = 0.5 * (lo + hi)
    s = int(np.argmin(_point_box_distance(start, lo, hi, L)))
    t = int(np.argmin(_point_box_distance(goal, lo, hi, L)))
    local = np.full(len(paving), -1, dtype=np.int64)
    local[nodes] = np.arange(nodes.size)
    e = edges[:, inside[edges[0]] & inside[edges[1]]]
    u = np.concatenate([local[e[0]], local[e[1]]])
    v = np.concatenate([local[e[1]], local[e[0]]])
    w = _dist(centre[u], centre[v], L)
    order = np.argsort(u, kind="stable")
    u, v, w = u[order], v[order], w[order]
    indptr = np.concatenate([[0], np.cumsum(np.bincount(u, minlength=nodes.size))]).tolist()
    nbr, wt = v.tolist(), w.tolist()
    h = _dist(centre, centre[t], L).tolist()  # consistent heuristic: the same metric
    dist = {s: 0.0}
    prev = {s: -1}
    heap = [(h[s], 0.0, s)]
    closed = set()
    while heap:
        _, g, a = heapq.heappop(heap)
        if a in closed:
            continue
        if a == t:
            break
        closed.add(a)
        for k in range(indptr[a], indptr[a + 1]):
            b = nbr[k]
            nd = g + wt[k]
            if nd < dist.get(b, math.inf):
                dist[b] = nd
                prev[b] = a
                heapq.heappush(heap, (nd + h[b], nd, b))
    if t not in prev:
        return None
    path = [t]
    while prev[path[-1]] >= 0:
        path.append(prev[path[-1]])
    return nodes[np.array(path[::-1], dtype=np.int64)]


def _crossing_waypoints(paving: Paving, path: np.ndarray, start_phi: float) -> tuple[np.ndarray, np.ndarray]:
    """Centres of the shared face pieces along a box path, phi unwrapped; also each box's phi offset."""
    lo, hi = paving.lo[path], paving.hi[path]
    offs = np.zeros(len(path))
    c0 = 0.5 * (lo[0, 2] + hi[0, 2])
    offs[0] = _TWO_PI * round((start_phi - c0) / _TWO_PI)
    points = []
    for k in range(len(path) - 1):
        a_lo, a_hi, b_lo, b_hi = lo[k], hi[k], lo[k + 1], hi[k + 1]
        shift = 0.0
        if a_hi[2] == PI_HI and b_lo[2] == -PI_HI and not (b_lo[2] <= a_hi[2] and a_lo[2] <= b_hi[2]):
            shift = _TWO_PI  # across the seam upward
        elif b_hi[2] == PI_HI and a_lo[2] == -PI_HI and not (b_lo[2] <= a_hi[2] and a_lo[2] <= b_hi[2]):
            shift = -_TWO_PI
        offs[k + 1] = offs[k] + shift
        b_lo_u = b_lo.copy()
        b_hi_u = b_hi.copy()
        b_lo_u[2] += offs[k + 1] - offs[k]
        b_hi_u[2] += offs[k + 1] - offs[k]
        # in a's frame: the shared piece is the intersection of the two closed boxes
        p_lo = np.maximum(a_lo, b_lo_u)
        p_hi = np.minimum(a_hi, b_hi_u)
        p = 0.5 * (p_lo + p_hi)
        p[2] += offs[k]
        points.append(p)
    return np.array(points).reshape(-1, 3), offs


def _goal_turns(goal_phi: float, last_centre_phi: float) -> int:
    return int(round((last_centre_phi - goal_phi) / _TWO_PI))


def _shift_phi(box: np.ndarray, turns: int) -> np.ndarray:
    """The enclosure box with phi + 2 pi turns, rounded outward."""
    if turns == 0:
        return box.copy()
    two_pi = Interval(np.float64(2.0 * PI_LO), np.float64(2.0 * PI_HI))
    s = Interval(np.float64(box[2, 0]), np.float64(box[2, 1])) + two_pi * float(turns)
    out = box.copy()
    out[2] = [float(s.lo), float(s.hi)]
    return out


# --------------------------------------------------------------------------------------
# Smoothing
# --------------------------------------------------------------------------------------
def _smooth(geometry: Geometry, ends: list[np.ndarray], sign: int, quick: int,
            leaves: "_LeafIndex", name: str) -> list[int]:
    """Indices of the waypoints kept: from each kept one, jump to the farthest acceptable one.

    A shortcut is acceptable when points sampled along it (steps below half the
    finest leaf width) all lie in boxes certified INSIDE the aspect, so the path
    keeps to the certified part of the paving (some clearance from det A = 0,
    readable region sequences), AND the segment is certified (the proof).  The
    farthest is searched by doubling the jump then bisecting, assuming (not
    requiring) monotonicity; a failed guess only costs length.
    """
    paving = leaves.paving
    inside = paving.labels[name] == Label.INSIDE
    step = (paving.domain[:, 1] - paving.domain[:, 0]) / (1 << paving.depth) / 2
    m = len(ends)
    mids = [0.5 * (e[:, 0] + e[:, 1]) for e in ends]
    lo_lim = np.array([float(v) for v in geometry.rho_min])
    hi_lim = np.array([float(v) for v in geometry.rho_max])

    def ok(i: int, j: int) -> bool:
        # a float look first (a heuristic filter only: it never certifies anything)
        n = int(np.ceil(np.max(np.abs(mids[j] - mids[i]) / step))) + 2
        t = np.linspace(0.0, 1.0, n)[:, None]
        pts = mids[i] + t * (mids[j] - mids[i])
        leaf = leaves.lookup(pts)
        if np.any(leaf < 0) or not np.all(inside[leaf]):
            return False
        if np.any(sign * approx_det_a(geometry, pts) <= 0):
            return False
        r = approx_inverse_kinematics(geometry, pts)
        if np.any(r < lo_lim) or np.any(r > hi_lim):
            return False
        return certify_segment(geometry, ends[i], ends[j], sign, max_bisections=quick, max_pieces=4096).certified

    kept = [0]
    i = 0
    while i < m - 1:
        if ok(i, m - 1):
            kept.append(m - 1)
            break
        good, step = i + 1, 1
        bad = m - 1
        while good + step < m - 1:
            if ok(i, good + step):
                good += step
                step *= 2
            else:
                bad = good + step
                break
        while bad - good > 1:
            mid = (good + bad) // 2
            if ok(i, mid):
                good = mid
            else:
                bad = mid
        kept.append(good)
        i = good
    return kept


# --------------------------------------------------------------------------------------
# Regions and joint cells along the path
# --------------------------------------------------------------------------------------
class _LeafIndex:
    """Finds the leaf of a paving that holds each point (sorted integer keys per level)."""

    def __init__(self, paving: Paving):
        self.paving = paving
        d = paving.depth
        self.nb = d + 1
        self.levels = []
        for L in range(d + 1):
            sel = np.flatnonzero(paving.level == L)
            if sel.size == 0:
                continue
            ijk = paving.ijk[sel]
            keys = (ijk[:, 0] << (2 * self.nb)) | (ijk[:, 1] << self.nb) | ijk[:, 2]
            order = np.argsort(keys)
            self.levels.append((L, keys[order], sel[order]))

    def lookup(self, points: np.ndarray) -> np.ndarray:
        """Leaf index of each point (x, y, phi; phi any real, wrapped here), -1 outside the domain."""
        p = self.paving
        d = p.depth
        n = 1 << d
        pts = np.array(points, dtype=np.float64, copy=True).reshape(-1, 3)
        pts[:, 2] = _wrap(pts[:, 2])
        width = p.domain[:, 1] - p.domain[:, 0]
        f = np.floor((pts - p.domain[:, 0]) / (width / n)).astype(np.int64)
        ok = np.all((f >= 0) & (f < n), axis=1)
        f = np.clip(f, 0, n - 1)
        out = np.full(pts.shape[0], -1, dtype=np.int64)
        for L, ks, idx in self.levels:
            g = f >> (d - L)
            q = (g[:, 0] << (2 * self.nb)) | (g[:, 1] << self.nb) | g[:, 2]
            pos = np.minimum(np.searchsorted(ks, q), ks.size - 1)
            hit = (ks[pos] == q) & ok & (out < 0)
            out[hit] = idx[pos[hit]]
        return out


def _samples(waypoints: np.ndarray, step: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points along each segment with every coordinate step below ``step``; segment index of each."""
    pts, seg = [], []
    for k in range(len(waypoints) - 1):
        a, b = waypoints[k], waypoints[k + 1]
        n = int(np.ceil(np.max(np.abs(b - a) / step))) + 1
        t = np.linspace(0.0, 1.0, max(n, 2) + 1)
        if k < len(waypoints) - 2:
            t = t[:-1]
        pts.append(a + t[:, None] * (b - a))
        seg.append(np.full(t.size, k))
    return np.concatenate(pts), np.concatenate(seg)


def _dedupe(seq) -> list:
    out: list = []
    for s in seq:
        if not out or out[-1] != s:
            out.append(s)
    return out


def _collapse(seq) -> list:
    """Merge repeats, and a layer stretch (-1) between two visits of the same id into that id.

    >>> _collapse([-1, 3, 3, -1, 3, -1, 0, -1, 0, 4])
    [-1, 3, -1, 0, 4]
    """
    out = _dedupe(seq)
    changed = True
    while changed:
        changed = False
        for k in range(1, len(out) - 1):
            if out[k] == -1 and out[k - 1] == out[k + 1]:
                out = _dedupe(out[:k] + out[k + 1:])
                changed = True
                break
    return out


def _cells_along(geometry: Geometry, joint: "JointPaving", seg: SegmentCertificate, max_level: int = 14):
    """(t0, cell) pairs along one segment, each piece's image certified inside that cell (-1: layer)."""
    step = min(float(s) for s in joint.step)
    t0, t1 = seg.pieces[:, 0].copy(), seg.pieces[:, 1].copy()
    level = np.zeros(t0.size, dtype=np.int64)
    out_t, out_c = [], []
    while t0.size:
        boxes = _piece_boxes(seg.start, seg.end, t0, t1)
        r = rho_interval(geometry, boxes)
        lo = np.stack([np.asarray(v.lo) for v in r], axis=1)
        hi = np.stack([np.asarray(v.hi) for v in r], axis=1)
        cell = joint.cell_of_boxes(lo, hi)
        wide = np.max(hi - lo, axis=1) > step / 8
        again = (cell < 0) & wide & (level < max_level)
        keep = ~again
        out_t.append(t0[keep])
        out_c.append(cell[keep])
        t0, t1, level = t0[again], t1[again], level[again]
        tm = 0.5 * t0 + 0.5 * t1
        t0, t1 = np.concatenate([t0, tm]), np.concatenate([tm, t1])
        level = np.concatenate([level, level]) + 1
    t = np.concatenate(out_t)
    c = np.concatenate(out_c)
    order = np.argsort(t, kind="stable")
    return t[order], c[order]


# --------------------------------------------------------------------------------------
# The trajectory
# --------------------------------------------------------------------------------------
def trajectory(
    geometry: Geometry,
    rho: Sequence,
    i_from: int,
    i_to: int,
    depth: int = 8,
    analysis: "RegionAnalysis | None" = None,
    joint: "JointPaving | None" = None,
    smooth: bool = True,
    paving: Paving | None = None,
) -> Trajectory:
    """A certified non-singular motion between solutions ``i_from`` and ``i_to`` of ``rho``.

    Parameters
    ----------
    geometry : the manipulator.
    rho : three leg lengths (decimal strings, read exactly, or Fractions).
    i_from, i_to : solution numbers, 1-based in increasing phi, as ``intervalkin dkp`` lists them.
    depth : octree depth of the workspace paving (ignored when ``analysis`` is
        given: its paving is used, so the regions crossed refer to it).
    analysis : optional region analysis: reports the basic regions crossed.
    joint : optional joint paving: reports the joint cells crossed and their counts.
    smooth : drop waypoints whose removal keeps the path certified.
    paving : optional workspace paving with aspect labels (``pave_workspace``),
        reused instead of paving again (ignored when ``analysis`` is given).

    Returns
    -------
    Trajectory
        ``certified`` True is a proof that the motion (the straight segments
        between the waypoints, from the exact start solution to the exact goal)
        keeps det A of one sign and every leg within its limits.

    Raises
    ------
    NoPathError
        The solutions are in different aspects (no non-singular path exists), or
        no path was found through the certified boxes at this depth (that is not
        a proof that none exists).
    InputError
        Bad joint vector or solution numbers, or uncertifiable direct kinematics.
    """
    from .predicates import pave_workspace

    times: dict[str, float] = {}
    t_start = time.perf_counter()
    q, res, sa, sb = _endpoints(geometry, rho, i_from, i_to)
    sign = int(sa.det_sign)
    aspect = "WA1" if sign > 0 else "WA2"
    times["dkp"] = time.perf_counter() - t_start

    t = time.perf_counter()
    if analysis is not None:
        paving, edges = analysis.paving, analysis.edges
    else:
        if paving is None:
            paving = pave_workspace(geometry, depth)
        edges = shares_face(paving.level, paving.ijk, paving.depth)
    times["paving"] = time.perf_counter() - t

    t = time.perf_counter()
    L = _metric_length(geometry)
    start_pt, goal_pt = sa.midpoint, sb.midpoint
    path = _shortest_box_path(paving, edges, aspect, start_pt, goal_pt, L)
    if path is None:
        raise NoPathError(
            f"no path found from solution {i_from} to {i_to} through boxes certified in {aspect} at depth "
            f"{paving.depth} (not a proof that none exists: the boxes may be joined through the undecided "
            "layer; try a larger depth)"
        )
    crossings, offs = _crossing_waypoints(paving, path, float(start_pt[2]))
    last = path[-1]
    last_centre = 0.5 * (paving.lo[last, 2] + paving.hi[last, 2]) + offs[-1]
    turns = _goal_turns(float(goal_pt[2]), float(last_centre))
    goal_box = _shift_phi(np.asarray(sb.box, dtype=np.float64), turns)
    start_box = np.asarray(sa.box, dtype=np.float64)
    goal_mid = 0.5 * (goal_box[:, 0] + goal_box[:, 1])
    raw = np.vstack([start_pt[None, :], crossings, goal_mid[None, :]])
    ends = [start_box] + [np.stack([p, p], axis=1) for p in crossings] + [goal_box]
    times["path"] = time.perf_counter() - t

    t = time.perf_counter()
    leaves = _LeafIndex(paving)
    kept = _smooth(geometry, ends, sign, 20, leaves, aspect) if smooth else list(range(len(ends)))
    times["smoothing"] = time.perf_counter() - t

    t = time.perf_counter()
    segments = tuple(certify_segment(geometry, ends[a], ends[b], sign) for a, b in zip(kept[:-1], kept[1:]))
    certified = all(s.certified for s in segments)
    reason = "" if certified else "; ".join(
        f"segment {k + 1}: {s.reason}" for k, s in enumerate(segments) if not s.certified)
    waypoints = raw[kept]
    times["certificate"] = time.perf_counter() - t

    t = time.perf_counter()
    leaf = (paving.domain[:, 1] - paving.domain[:, 0]) / (1 << paving.depth)
    samples, sample_seg = _samples(waypoints, leaf / 2)
    sample_rho = approx_inverse_kinematics(geometry, samples)
    basic_regions = sample_region = None
    if analysis is not None:
        idx = leaves.lookup(samples)
        sample_region = np.where(idx >= 0, analysis.region[np.maximum(idx, 0)], -1).astype(np.int64)
        basic_regions = tuple(int(r) for r in _collapse(sample_region.tolist()))
    joint_cells = sample_count = None
    if joint is not None:
        seq = []
        for s in segments:
            _, cells = _cells_along(geometry, joint, s)
            seq.extend(int(c) for c in cells)
        joint_cells = tuple(_cell_info(joint, c) for c in _collapse(seq))
        pt = np.stack([samples, samples], axis=-1)
        r = rho_interval(geometry, pt)
        lo = np.stack([np.asarray(v.lo) for v in r], axis=1)
        hi = np.stack([np.asarray(v.hi) for v in r], axis=1)
        sc = joint.cell_of_boxes(lo, hi)
        counts = np.array([c.count for c in joint.cells] + [-1], dtype=np.int64)
        sample_count = counts[np.where(sc >= 0, sc, len(joint.cells))]
    times["image"] = time.perf_counter() - t
    times["total"] = time.perf_counter() - t_start

    return Trajectory(
        rho=q, i_from=int(i_from), i_to=int(i_to), aspect=aspect, sign=sign, waypoints=waypoints,
        phi_turns=turns, segments=segments, certified=certified, reason=reason, box_path=path,
        raw_waypoints=len(raw), depth=int(paving.depth), samples=samples, sample_rho=sample_rho,
        sample_segment=sample_seg, basic_regions=basic_regions, sample_region=sample_region,
        joint_cells=joint_cells, sample_count=sample_count, solutions=tuple(res.solutions), seconds=times,
    )


def _cell_info(joint: "JointPaving", c: int) -> dict:
    if c < 0:
        return {"cell": -1, "count": -1, "n_wa1": -1, "n_wa2": -1}
    cell = joint.cells[c]
    return {"cell": int(c), "count": int(cell.count), "n_wa1": int(cell.n_wa1), "n_wa2": int(cell.n_wa2)}


# --------------------------------------------------------------------------------------
# Output: JSON and figures (atomic)
# --------------------------------------------------------------------------------------
def _plt():
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    return plt


def _save_png(fig, path: Path) -> Path:
    import io

    from .export import atomic_write_bytes

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    return atomic_write_bytes(path, buf.getvalue())


def _platform(geometry: Geometry, pose: np.ndarray):
    """Base points (3, 2) and platform points (3, 2) of a float pose (for drawing)."""
    base = np.array([[float(c) for c in a] for a in geometry.base])
    x, y, phi = pose
    c, s = math.cos(phi), math.sin(phi)
    pts = []
    for i in range(3):
        px, py = (float(v) for v in geometry.platform_point(i))
        pts.append((x + c * px - s * py, y + s * px + c * py))
    return base, np.array(pts)


def _segments_3d(samples: np.ndarray):
    """Split a path at the phi seam: list of (k, 3) arrays with wrapped phi."""
    w = samples.copy()
    w[:, 2] = _wrap(w[:, 2])
    jumps = np.flatnonzero(np.abs(np.diff(w[:, 2])) > math.pi) + 1
    return np.split(w, jumps)


def render_trajectory(traj: Trajectory, geometry: Geometry, out: str | Path, paving: Paving | None = None,
                      joint: "JointPaving | None" = None, frames: int = 48) -> list[Path]:
    """Write the figures of a trajectory into folder ``out`` (atomically); returns the paths.

    * ``trajectory_workspace_3d.png``: the path in (x, y, phi), phi wrapped, over
      the singular layer of the paving (grey, subsampled) with the solutions numbered;
    * ``trajectory_workspace_xy.png``: its projection on the (x, y) plane;
    * ``trajectory_joint.png``: its image g(path) in joint space over the marked
      layer of the joint paving, coloured by the certified count of the cell, and
      the count along the path;
    * ``trajectory_animation.gif`` (Pillow) or ``trajectory_frames/frame_NNN.png``:
      the platform and legs moving.
    """
    plt = _plt()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    rng = np.random.default_rng(0)
    sols = np.array([s.midpoint for s in traj.solutions]) if traj.solutions else np.zeros((0, 3))
    colour = "#1f77b4" if traj.sign > 0 else "#d62728"
    layer = None
    if paving is not None:
        sel = np.flatnonzero((paving.labels["W"] != Label.OUTSIDE) & (paving.labels["det_positive"] == Label.BOUNDARY))
        if sel.size > 6000:
            sel = np.sort(rng.choice(sel, 6000, replace=False))
        layer = 0.5 * (paving.lo[sel] + paving.hi[sel])
    title = (f"rho = ({', '.join(f'{float(v):g}' for v in traj.rho)}): solution {traj.i_from} -> {traj.i_to} "
             f"in {traj.aspect}, {'certified' if traj.certified else 'NOT certified'}")

    # 3-D workspace
    fig = plt.figure(figsize=(7.5, 6.5))
    ax = fig.add_subplot(projection="3d")
    if layer is not None:
        ax.scatter(layer[:, 0], layer[:, 1], layer[:, 2], s=2, c="0.6", alpha=0.3, label="det A = 0 (undecided layer)")
    for k, part in enumerate(_segments_3d(traj.samples)):
        ax.plot(part[:, 0], part[:, 1], part[:, 2], color=colour, lw=2.5, label="path" if k == 0 else None)
    for i, s in enumerate(sols, 1):
        ax.scatter([s[0]], [s[1]], [s[2]], color="k", s=18)
        ax.text(s[0], s[1], s[2], f" {i}", fontsize=9)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_zlabel("phi (rad)")
    ax.set_title(title, fontsize=9)
    ax.legend(loc="upper left", fontsize=8)
    written.append(_save_png(fig, out / "trajectory_workspace_3d.png"))
    plt.close(fig)

    # x-y projection
    fig, ax = plt.subplots(figsize=(7, 6.5))
    if layer is not None:
        ax.scatter(layer[:, 0], layer[:, 1], s=1, c="0.8", alpha=0.3, label="det A = 0 (undecided layer)")
    ax.plot(traj.samples[:, 0], traj.samples[:, 1], color=colour, lw=2, label="path")
    ax.plot(traj.waypoints[:, 0], traj.waypoints[:, 1], "o", color=colour, ms=3, label="waypoints")
    for i, s in enumerate(sols, 1):
        ax.plot(s[0], s[1], "k*", ms=8)
        ax.annotate(str(i), (s[0], s[1]), textcoords="offset points", xytext=(4, 4))
    ax.set_aspect("equal")
    ax.set_xlabel("x (B1)")
    ax.set_ylabel("y (B1)")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=8)
    written.append(_save_png(fig, out / "trajectory_workspace_xy.png"))
    plt.close(fig)

    # joint space
    fig = plt.figure(figsize=(12, 5.5))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    if joint is not None:
        idx = np.argwhere(joint.marked)
        if idx.shape[0] > 8000:
            idx = idx[rng.choice(idx.shape[0], 8000, replace=False)]
        r0 = np.array([float(v) for v in joint.rho_min])
        h = np.array([float(v) for v in joint.step])
        vox = r0 + (idx + 0.5) * h
        ax.scatter(vox[:, 0], vox[:, 1], vox[:, 2], s=2, c="0.6", alpha=0.2, label="enclosure of g(S)")
    counts = traj.sample_count if traj.sample_count is not None else np.full(len(traj.samples), -1)
    cmap = {-1: "0.4", 2: "#2ca02c", 4: "#ff7f0e", 6: "#9467bd", 0: "k"}
    r = traj.sample_rho
    for c in sorted(set(counts.tolist())):
        m = counts == c
        ax.scatter(r[m, 0], r[m, 1], r[m, 2], s=4, color=cmap.get(c, "c"),
                   label=f"{c} solutions" if c >= 0 else "layer (may meet g(S))")
    ax.scatter(*[[float(v)] for v in traj.rho], color="k", s=40, marker="*", label="rho (start = end)")
    ax.set_xlabel("rho1")
    ax.set_ylabel("rho2")
    ax.set_zlabel("rho3")
    ax.legend(fontsize=7, loc="upper left")
    ax.set_title("image g(path): a closed loop in joint space", fontsize=9)
    ax2 = fig.add_subplot(1, 2, 2)
    s_along = np.concatenate([[0.0], np.cumsum(_dist(traj.samples[:-1], traj.samples[1:], _metric_length(geometry)))])
    ax2.step(s_along, np.where(counts >= 0, counts, np.nan), where="post", color="k")
    ax2.scatter(s_along[counts < 0], np.full(np.count_nonzero(counts < 0), 0.5), s=3, color="0.5",
                label="image may meet g(S)")
    ax2.set_yticks([0, 2, 4, 6])
    ax2.set_xlabel("length along the path")
    ax2.set_ylabel("certified number of solutions of g(X)")
    ax2.set_title("solution count along the path (joint cells)", fontsize=9)
    ax2.legend(fontsize=8)
    written.append(_save_png(fig, out / "trajectory_joint.png"))
    plt.close(fig)

    written += _render_animation(traj, geometry, out, frames)
    return written


def _render_animation(traj: Trajectory, geometry: Geometry, out: Path, frames: int) -> list[Path]:
    plt = _plt()
    s = traj.samples
    L = _metric_length(geometry)
    arc = np.concatenate([[0.0], np.cumsum(_dist(s[:-1], s[1:], L))])
    targets = np.linspace(0.0, arc[-1], frames)
    poses = np.stack([np.interp(targets, arc, s[:, j]) for j in range(3)], axis=1)
    allpts = np.vstack([_platform(geometry, p)[1] for p in poses] + [_platform(geometry, poses[0])[0]])
    pad = 3.0
    xl = (allpts[:, 0].min() - pad, allpts[:, 0].max() + pad)
    yl = (allpts[:, 1].min() - pad, allpts[:, 1].max() + pad)

    fig, ax = plt.subplots(figsize=(6, 6))

    def draw(k):
        ax.clear()
        base, plat = _platform(geometry, poses[k])
        for i in range(3):
            ax.plot([base[i, 0], plat[i, 0]], [base[i, 1], plat[i, 1]], color="0.3", lw=2)
        tri = np.vstack([plat, plat[:1]])
        ax.fill(tri[:, 0], tri[:, 1], color="#1f77b4" if traj.sign > 0 else "#d62728", alpha=0.5)
        ax.plot(tri[:, 0], tri[:, 1], color="k", lw=1)
        ax.plot(base[:, 0], base[:, 1], "ks", ms=6)
        ax.plot(s[:, 0], s[:, 1], color="0.7", lw=1)
        ax.set_xlim(*xl)
        ax.set_ylim(*yl)
        ax.set_aspect("equal")
        ax.set_title(f"solution {traj.i_from} -> {traj.i_to} ({traj.aspect}), frame {k + 1}/{len(poses)}", fontsize=9)

    written: list[Path] = []
    try:
        import PIL  # noqa: F401

        have_pillow = True
    except ImportError:  # pragma: no cover - Pillow ships with matplotlib in practice
        have_pillow = False
    if have_pillow:
        from matplotlib.animation import FuncAnimation, PillowWriter

        anim = FuncAnimation(fig, draw, frames=len(poses))
        final = out / "trajectory_animation.gif"
        fd, tmp = tempfile.mkstemp(prefix=".trajectory_animation.", suffix=".gif", dir=out)
        os.close(fd)
        try:
            anim.save(tmp, writer=PillowWriter(fps=12), dpi=80)
            os.chmod(tmp, 0o644)
            os.replace(tmp, final)
        except BaseException:
            if os.path.exists(tmp):
                os.unlink(tmp)
            raise
        written.append(final)
    else:
        folder = out / "trajectory_frames"
        folder.mkdir(exist_ok=True)
        for k in range(len(poses)):
            draw(k)
            written.append(_save_png(fig, folder / f"frame_{k:03d}.png"))
    plt.close(fig)
    return written


def write_trajectory(traj: Trajectory, geometry: Geometry, out: str | Path, paving: Paving | None = None,
                     joint: "JointPaving | None" = None) -> list[Path]:
    """``trajectory.json`` (the --json object plus the certificate) and the figures, atomically."""
    from .export import write_json

    out = Path(out)
    doc = traj.to_json()
    doc["certificate"] = traj.certificate()
    doc["seconds"] = traj.seconds
    paths = [write_json(out / "trajectory.json", doc)]
    paths += render_trajectory(traj, geometry, out, paving=paving, joint=joint)
    return paths
