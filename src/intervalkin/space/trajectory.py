"""Certified non-singular trajectories between assembly modes of one aspect: :func:`trajectory`.

The paper (section 3.2, Table 1) observes that solutions 2, 3 and 6 of the joint
vector rho = (14.98, 15.38, 12.0) lie in one aspect WA1, so the platform can move
from one to another without meeting a type-2 singularity; section 5.2 and
Figure 13 add that such a motion must pass through an intermediate basic region,
whose image is a joint-space domain with only two solutions.  :func:`trajectory`
builds such a motion and PROVES it non-singular:

1. The two solutions are the certified direct-kinematic boxes of
   :func:`~intervalkin.solve.dkp.solve` (numbered from 1 in increasing phi, as
   ``intervalkin dkp`` prints them).  Opposite certified signs of det A put them
   in different aspects: then no non-singular path exists and
   :class:`~intervalkin.core.errors.NoPathError` says so.
2. A path through the boxes of a workspace paving certified inside the aspect
   proposes the waypoints, smoothed (:mod:`intervalkin.space.path_search`).
3. Each straight segment between consecutive waypoints is certified
   (:mod:`intervalkin.space.segment`); the paving plays no part in the proof.

The result, a :class:`~intervalkin.space.trajectory_result.Trajectory`, also
reports, with what each claim rests on:

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

import time
from typing import Sequence

import numpy as np

from intervalkin.core.errors import InputError, NoPathError
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
    LeafIndex,
    crossing_waypoints,
    goal_turns,
    metric_length,
    sample_path,
    shift_phi,
    shortest_box_path,
    smooth_waypoints,
)
from intervalkin.space.segment import SegmentCertificate, certify_segment, piece_boxes
from intervalkin.space.trajectory_result import Trajectory

__all__ = ['NoPathError', 'Trajectory', 'check_request', 'trajectory']


# --------------------------------------------------------------------------------------
# The request
# --------------------------------------------------------------------------------------
def check_request(geometry: Geometry, rho, i_from: int, i_to: int) -> None:
    """Raise (one-line :class:`IntervalkinError`) when no path can be asked for; cheap (one solve)."""
    _endpoints(geometry, rho, i_from, i_to)


def _endpoints(geometry: Geometry, rho, i_from: int, i_to: int):
    """The certified solutions numbered i_from, i_to; raises when the request cannot be met."""
    q = parse_joint_vector(geometry, list(rho))
    res = solve(geometry, q)
    n = len(res.solutions)
    for name, i in (("i_from", i_from), ("i_to", i_to)):
        if isinstance(i, bool) or not isinstance(i, (int, np.integer)) or not 1 <= i <= n:
            raise InputError(f"{name}: expected a solution number in 1..{n} for rho = "
                             f"{[float(v) for v in q]}, got {i!r}")
    if i_from == i_to:
        raise InputError(f"i_from and i_to both name solution {i_from}: nothing to move")
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
# What the path crosses
# --------------------------------------------------------------------------------------
def _merge_repeats(seq) -> list:
    """The sequence with runs of equal consecutive items written once."""
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
    out = _merge_repeats(seq)
    changed = True
    while changed:
        changed = False
        for k in range(1, len(out) - 1):
            if out[k] == -1 and out[k - 1] == out[k + 1]:
                out = _merge_repeats(out[:k] + out[k + 1:])
                changed = True
                break
    return out


def _image_cells(geometry: Geometry, joint: JointPaving, boxes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The cell holding the interval image g(b) of each workspace box (-1: it may meet g(S)), and g's widths."""
    r = rho_interval(geometry, boxes)
    return joint.cell_of_boxes(r.lo, r.hi), np.max(r.hi - r.lo, axis=1)


def _cells_along(geometry: Geometry, joint: JointPaving, seg: SegmentCertificate, max_level: int = 14):
    """(t0, cell) pairs along one segment, each piece's image certified inside that cell (-1: layer)."""
    step = min(float(s) for s in joint.step)
    t0, t1 = seg.pieces[:, 0].copy(), seg.pieces[:, 1].copy()
    level = np.zeros(t0.size, dtype=np.int64)
    out_t, out_c = [], []
    while t0.size:
        cell, width = _image_cells(geometry, joint, piece_boxes(seg.start, seg.end, t0, t1))
        wide = width > step / 8
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
    analysis: RegionAnalysis | None = None,
    joint: JointPaving | None = None,
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
    L = metric_length(geometry)
    start_pt, goal_pt = sa.midpoint, sb.midpoint
    path = shortest_box_path(paving, edges, aspect, start_pt, goal_pt, L)
    if path is None:
        raise NoPathError(
            f"no path found from solution {i_from} to {i_to} through boxes certified in {aspect} at depth "
            f"{paving.depth} (not a proof that none exists: the boxes may be joined through the undecided "
            "layer; try a larger depth)"
        )
    crossings, offs = crossing_waypoints(paving, path, float(start_pt[2]))
    last = path[-1]
    last_centre = 0.5 * (paving.lo[last, 2] + paving.hi[last, 2]) + offs[-1]
    turns = goal_turns(float(goal_pt[2]), float(last_centre))
    goal_box = shift_phi(np.asarray(sb.box, dtype=np.float64), turns)
    start_box = np.asarray(sa.box, dtype=np.float64)
    goal_mid = 0.5 * (goal_box[:, 0] + goal_box[:, 1])
    raw = np.vstack([start_pt[None, :], crossings, goal_mid[None, :]])
    ends = [start_box] + [np.stack([p, p], axis=1) for p in crossings] + [goal_box]
    times["path"] = time.perf_counter() - t

    t = time.perf_counter()
    leaves = LeafIndex(paving)
    kept = smooth_waypoints(geometry, ends, sign, 20, leaves, aspect) if smooth else list(range(len(ends)))
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
    samples, sample_seg = sample_path(waypoints, leaf / 2)
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
        sc, _ = _image_cells(geometry, joint, np.stack([samples, samples], axis=-1))
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


def _cell_info(joint: JointPaving, c: int) -> dict:
    if c < 0:
        return {"cell": -1, "count": -1, "n_wa1": -1, "n_wa2": -1}
    cell = joint.cells[c]
    return {"cell": int(c), "count": int(cell.count), "n_wa1": int(cell.n_wa1), "n_wa2": int(cell.n_wa2)}
