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

* the basic regions crossed (when a :class:`~intervalkin.space.basic_region.RegionAnalysis`
  is given): region ids of the paving leaves met by points sampled along the
  path at steps below half the finest leaf width, consecutive repeats merged,
  -1 ("layer") where the leaf carries no region (the enclosure of S_c or an
  undecided sheet).  Sampled, so a region touched only between two samples
  could be missed;
* the joint-space image (when a :class:`~intervalkin.space.joint_space.JointPaving` is
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

import math
import time
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Sequence

import numpy as np

from intervalkin.core.errors import InputError, IntervalkinError
from intervalkin.core.geometry import Geometry
from intervalkin.kinematics.enclosures import rho_interval
from intervalkin.kinematics.formulas import approx_inverse_kinematics
from intervalkin.paving.adjacency import shares_face
from intervalkin.paving.predicates import pave_workspace
from intervalkin.paving.tree import Paving
from intervalkin.solve.dkp import parse_joint_vector, solve
from intervalkin.space.basic_region import RegionAnalysis
from intervalkin.space.joint_space import JointPaving
from intervalkin.space.path_search import (
    _TWO_PI,
    _crossing_waypoints,
    _dedupe,
    _goal_turns,
    _LeafIndex,
    _metric_length,
    _samples,
    _shift_phi,
    _shortest_box_path,
    _smooth,
)
from intervalkin.space.segment import SegmentCertificate, _piece_boxes, certify_segment

__all__ = ['NoPathError', 'Trajectory', 'check_request', 'trajectory']


class NoPathError(IntervalkinError):
    """The request cannot be met: no non-singular path (different aspects), or none found."""


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
