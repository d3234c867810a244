"""A pose's basic region by local refinement: a certified segment from the pose into a labelled box.

When the paving leaves a pose's basic region undecided (its box is not
certified off the characteristic surfaces S_c, typically because its image
meets the undecided layer of joint space), the region can still be proved
by looking around the pose instead of deepening the whole paving.

The argument.  A basic region of an aspect is a connected component of WA minus
S_c, and S_c is the set of poses of WA whose joint vector lies on g(S).  Let P
be a point of a paving box labelled with basic region r, and consider the
segment X + t (P - X), t in [0, 1], from the pose X.  Cut [0, 1] into pieces;
for each piece, the box hull of the segment's points (outward rounded) has an
interval image R under g (:func:`~intervalkin.kinematics.enclosures.rho_interval`).
If every R lies within the joint limits and is *clear*
(:mod:`intervalkin.solve.simple_roots`: for every q in R every root of the
reduced equation is simple, so no pose with a joint vector in R is singular and
R misses g(S)), then every point of the segment lies in W with its joint
vector off g(S): the segment stays in WA (det A cannot change sign without a
singular point, which would map into g(S)) and off S_c.  X and P are then in
one component, and X lies in basic region r, which was certified for the
whole box holding P.  Pieces that fail are bisected, within a budget; the
nearest labelled boxes of the pose's aspect are tried in turn.

The same argument works in joint space, which suits a pose whose basic region
is thin (near a cusp of g(S), as Table 1's solutions are): a straight segment
from q = g(X) to g(P) is proved inside the joint limits and clear, and the
solution X is followed along it by certified continuation
(:mod:`intervalkin.solve.continuation`, parameter Krawczyk steps).  The path
of X stays off S_c (its joint vector is on the clear segment) and ends at a
solution X' of g(P); when the final enclosure of X' lies inside the box of P,
X and X' (and P) are in one basic region.  The joint path may also be a
polyline that enters a joint cell of the analysis and runs through the centres
of its voxels (:mod:`intervalkin.space.joint_route`): the legs inside the cell
are clear because every voxel of a cell is certified off the enclosure of g(S)
by the joint paving; the legs into and out of the cell are proved as above.
:func:`path_to_region` tries the routes through a cell, then straight joint
segments, then straight workspace segments.

Both ends may be enclosures (an angle reduced modulo 2 pi is irrational): the
piece boxes then hold every segment between a point of one end and a point of
the other, the true one among them.  The phi axis is periodic, so the target
may be reached through phi = +-pi: its angle is then shifted by a multiple of
2 pi, enclosed with the float bounds of pi.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from intervalkin.core.exact import fraction_bounds
from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import PI_HI, PI_LO, Interval
from intervalkin.kinematics.enclosures import rho_interval
from intervalkin.kinematics.formulas import approx_inverse_kinematics
from intervalkin.solve.continuation import certify_start, compare_mod_2pi, new_tracks, shift_phi_boxes, track
from intervalkin.solve.joint_box import clear_boxes
from intervalkin.solve.simple_roots import initial_pieces, open_pieces
from intervalkin.space.joint_route import JointGrid, cell_tree, voxel_route
from intervalkin.space.path_search import metric_length, path_distance

__all__ = ['PathResult', 'Budget', 'TARGETS', 'MAX_PIECES', 'path_to_region', 'segment_is_clear', 'joint_segment_is_clear', 'follow', 'landing_box', 'followed_into']

#: Labelled boxes tried, nearest first.
TARGETS = 8
#: Pieces examined per segment before giving up on it.
MAX_PIECES = 4096
#: Voxels of certified cells tried as the entry of a route through a cell (nearest first).
ENTRIES = 4
#: Pieces examined per joint segment (a joint segment that fails usually meets g(S): give up sooner).
JOINT_PIECES = 256
#: Boxes left by the simple-roots test that are handed to the slower joint_box test.
FALLBACK_BOXES = 4
#: ... and only while the pieces are at least this fraction of their segment.
FALLBACK_WIDTH = 2.0**-6
#: Pieces one query may examine in all its attempts.
QUERY_PIECES = 1500
#: Narrowest piece of [0, 1] before a segment is given up (it meets, or nearly meets, S_c).
MIN_PIECE = 2.0**-12


@dataclass(frozen=True)
class PathResult:
    """The basic region reached by a certified segment (None when none was proved), and why."""

    region: int | None
    domain: int | None
    why: str
    target: int | None = None
    pieces: int = 0


def _end_interval(bounds) -> Interval:
    """The float enclosure (3,) of a pose given by exact bounds (lo, hi) per coordinate."""
    return Interval.from_bounds([fraction_bounds(Fraction(a))[0] for a, _ in bounds],
                                [fraction_bounds(Fraction(b))[1] for _, b in bounds])


def _box(iv: Interval) -> np.ndarray:
    """The box (1, 3, 2) of an enclosure (3,)."""
    return np.stack([iv.lo, iv.hi], axis=-1)[None]


def _limits(geometry: Geometry) -> tuple[np.ndarray, np.ndarray]:
    """Floats lo_i >= rho_min_i and hi_i <= rho_max_i: a rho enclosure within [lo, hi] is within the limits."""
    return (np.array([fraction_bounds(v)[1] for v in geometry.rho_min]),
            np.array([fraction_bounds(v)[0] for v in geometry.rho_max]))


def _pieces_clear(geometry: Geometry, boxes: np.ndarray, fallback: bool = True) -> np.ndarray:
    """(m,) True where a workspace box (m, 3, 2) maps into the joint limits and onto a clear joint box."""
    r = rho_interval(geometry, boxes)
    return _joint_pieces_clear(geometry, np.stack([r.lo, r.hi], axis=-1), fallback)


def _joint_pieces_clear(geometry: Geometry, boxes: np.ndarray, fallback: bool = True) -> np.ndarray:
    """(m,) True where a joint box (m, 3, 2) lies within the joint limits and is proved clear of g(S).

    Two sound tests, either one enough: every root of the reduced equation simple
    (:mod:`intervalkin.solve.simple_roots`, fast), then, for the few boxes it
    leaves (at most FALLBACK_BOXES, and only with ``fallback``: it is slower), no
    singular pose on the circle of leg 1 (:mod:`intervalkin.solve.joint_box`,
    which has no blind spot where two solutions share an orientation).
    """
    lo, hi = _limits(geometry)
    ok = np.all((boxes[:, :, 0] >= lo) & (boxes[:, :, 1] <= hi), axis=1)
    idx = np.flatnonzero(ok)
    if idx.size:
        owner, _, _ = open_pieces(geometry, boxes[idx], *initial_pieces(len(idx)))
        left = idx[np.bincount(owner, minlength=len(idx)) > 0]
        ok[left] = False
        if fallback and 0 < left.size <= FALLBACK_BOXES:
            ok[left] = clear_boxes(geometry, boxes[left])
    return ok


class Budget:
    """Pieces a whole query may still examine (the search is bounded by work, not time: answers are reproducible)."""

    def __init__(self, pieces: int | None = None):
        self.left = QUERY_PIECES if pieces is None else pieces

    def take(self, n: int) -> bool:
        """Spend n pieces; False when fewer are left (the budget is then spent: the search stops)."""
        if n > self.left:
            self.left = 0
            return False
        self.left -= n
        return True


def _bisect_until(test, start: Interval, end: Interval, max_pieces: int, budget: Budget | None = None) -> int:
    """Cut [0, 1] until ``test`` accepts the box hull of every piece of start + t (end - start); pieces used, 0 if not."""
    t0 = np.linspace(0.0, 1.0, 17)[:-1]
    t1 = np.append(t0[1:], 1.0)
    used = 0
    delta = end - start
    while t0.size:
        used += t0.size
        if used > max_pieces or np.any(t1 - t0 < MIN_PIECE) or (budget is not None and not budget.take(t0.size)):
            return 0
        t = Interval.from_bounds(t0, t1)
        pts = Interval(start.lo[None, :], start.hi[None, :]) + Interval(t.lo[:, None], t.hi[:, None]) * \
            Interval(delta.lo[None, :], delta.hi[None, :])
        # the slow second test only on pieces still wide: a piece left narrow meets g(S) more often than not
        ok = test(np.stack([pts.lo, pts.hi], axis=-1), bool(np.min(t1 - t0) >= FALLBACK_WIDTH))
        a, b = t0[~ok], t1[~ok]
        mid = 0.5 * (a + b)
        t0, t1 = np.concatenate([a, mid]), np.concatenate([mid, b])
    return used


def joint_segment_is_clear(geometry: Geometry, qa: Interval, qb: Interval, max_pieces: int = MAX_PIECES,
                           budget: Budget | None = None) -> int:
    """Prove the joint segment from ``qa`` to ``qb`` (enclosures (3,)) within the limits and off g(S); pieces used."""
    return _bisect_until(lambda b, f: _joint_pieces_clear(geometry, b, f), qa, qb, max_pieces, budget)


def _row(iv: Interval) -> Interval:
    return Interval(iv.lo[None, :], iv.hi[None, :])


def _key(iv: Interval) -> tuple:
    return tuple(iv.lo) + tuple(iv.hi)


def follow(geometry: Geometry, x: Interval, waypoints: list[Interval], cache: dict | None = None):
    """Follow the solution x of ``waypoints[0]`` along the polyline of joint vectors; its end enclosure, or None.

    Each waypoint is an enclosure (3,).  The start box proved by Krawczyk must
    contain x (then x is the one solution there); each leg is tracked from the
    box the previous one ended in.  Returns (z_lo, z_hi), arrays (1, 3) holding
    the followed solution at the last waypoint (phi unwrapped along the way),
    or None when a step could not be certified.  ``cache`` keeps the state
    after each prefix of legs, for routes that share their first legs.  The
    legs' clearance is the caller's to prove: tracking alone does not keep the
    path off S_c.
    """
    cache = {} if cache is None else cache
    prefix: tuple = (_key(x), _key(waypoints[0]))
    state = cache.get(prefix)
    if state is None:
        ok, zl, zh, pt = certify_start(geometry, _row(waypoints[0]), x.mid()[None, :])
        state = (zl, zh, pt) if ok[0] and np.all(zl[0] <= x.lo) and np.all(x.hi <= zh[0]) else False
        cache[prefix] = state
    for a, b in zip(waypoints, waypoints[1:]):
        if state is False:
            return None
        prefix = prefix + (_key(b),)
        hit = cache.get(prefix)
        if hit is None:
            zl, zh, pt = state
            tr = track(geometry, new_tracks(_row(a), _row(b), pt, zl, zh))
            hit = cache[prefix] = (tr.z_lo, tr.z_hi, tr.p) if tr.status[0] == 1 else False
        state = hit
    return None if state is False else state[:2]


def landing_box(paving, sign: int, z_lo: np.ndarray, z_hi: np.ndarray) -> int | None:
    """A box labelled with a basic region of the aspect ``sign`` holding the whole enclosure z (modulo 2 pi), or None."""
    ok = (paving.region >= 0) & (paving.det_sign == sign) & (paving.in_workspace == 1)
    for turns in (-1, 0, 1):
        lo, hi = shift_phi_boxes(z_lo, z_hi, np.array([turns]))
        hit = np.flatnonzero(ok & np.all((paving.lo <= lo[0]) & (hi[0] <= paving.hi), axis=1))
        if hit.size:
            return int(hit[0])
    return None


def followed_into(geometry: Geometry, x: Interval, qa: Interval, qb: Interval, box_lo, box_hi) -> bool:
    """Follow x along the straight joint segment qa -> qb; True when it ends inside [box_lo, box_hi] (mod 2 pi)."""
    end = follow(geometry, x, [qa, qb])
    if end is None:
        return False
    inside, _ = compare_mod_2pi(np.asarray(box_lo, float)[None, :], np.asarray(box_hi, float)[None, :], *end)
    return bool(inside[0])


def segment_is_clear(geometry: Geometry, start: Interval, end: Interval, max_pieces: int = MAX_PIECES,
                     budget: Budget | None = None) -> int:
    """Prove the workspace segment from ``start`` to ``end`` (enclosures (3,)) inside W and off S_c.

    Returns the number of pieces used (> 0) when proved, 0 when not proved
    within ``max_pieces`` pieces or down to pieces of width MIN_PIECE.
    """
    return _bisect_until(lambda b, f: _pieces_clear(geometry, b, f), start, end, max_pieces, budget)


def _targets(order: np.ndarray, region: np.ndarray, n: int, per_region: int) -> list[int]:
    """The first ``n`` of ``order``, at most ``per_region`` per basic region (every sheet nearby gets a try)."""
    taken: dict[int, int] = {}
    out = []
    for i in order:
        r = int(region[i])
        if taken.get(r, 0) < per_region:
            taken[r] = taken.get(r, 0) + 1
            out.append(int(i))
            if len(out) == n:
                break
    return out


def _end_point(here: np.ndarray, b_lo: np.ndarray, b_hi: np.ndarray) -> Interval:
    """An enclosure (3,) of a point of the box [b_lo, b_hi] near ``here``, its angle moved by 2 pi k toward ``here``."""
    # the turn k that brings the box's angle nearest the pose's, and the point of the box nearest the pose
    k = int(np.round((here[2] - 0.5 * (b_lo[2] + b_hi[2])) / (2 * np.pi)))
    assert abs(k) <= 1, "both angles lie in [-pi, pi]"  # so 2 k PI_LO and 2 k PI_HI are exact floats
    inner_lo, inner_hi = b_lo + 0.25 * (b_hi - b_lo), b_hi - 0.25 * (b_hi - b_lo)
    p = np.minimum(np.maximum(here - np.array([0.0, 0.0, 2 * np.pi * k]), inner_lo), inner_hi)
    p = np.minimum(np.maximum(p, b_lo), b_hi)  # a float point of the closed box
    turn = (min(2 * k * PI_LO, 2 * k * PI_HI), max(2 * k * PI_LO, 2 * k * PI_HI))
    return Interval.from_bounds(p, p) + Interval(np.array([0.0, 0.0, turn[0]]), np.array([0.0, 0.0, turn[1]]))


def _follow_route(geometry: Geometry, start: Interval, waypoints: list[Interval], paving, sign: int,
                  memo: dict, budget: Budget, in_cell: int = 0) -> tuple[int, int | None]:
    """Prove the legs of a joint polyline clear, follow the pose along it, and find the labelled box it lands in.

    The legs numbered 1 .. ``in_cell`` run between centres of voxels of one joint
    cell (a route of :func:`~intervalkin.space.joint_route.voxel_route`): each
    lies in the union of the closed voxels it crosses, every one certified off
    the enclosure of g(S) by the joint paving, so they need no further proof.
    ``memo`` keeps the legs proved and the tracks followed, shared between routes.
    Returns (pieces of the clearance proofs, index of the box landed in), or (0, None) when
    a leg is not proved or the pose lands in no labelled box.
    """
    proved, tracked = memo.setdefault("legs", {}), memo.setdefault("tracks", {})
    free = memo.get("free", set())
    pieces = 0
    for k, (a, b) in enumerate(zip(waypoints, waypoints[1:])):
        if 1 <= k <= in_cell or (_key(a), _key(b)) in free:
            continue
        key = (_key(a), _key(b))
        if key not in proved:
            proved[key] = joint_segment_is_clear(geometry, a, b, JOINT_PIECES, budget)
        if not proved[key]:
            return 0, None
        pieces += proved[key]
    end = follow(geometry, start, waypoints, tracked)
    box = None if end is None else landing_box(paving, sign, *end)
    return (pieces, box) if box is not None else (0, None)


def _cell_routes(geometry: Geometry, qa: Interval, grid: JointGrid, memo: dict, budget: Budget):
    """(entry voxel, tree) for a voxel of a certified cell joined to qa: qa's own voxel when it is one
    (the leg to its centre stays in it), else the nearest one joined by a proved segment; or None."""
    own = grid.certified_voxel_holding(qa.lo, qa.hi)
    if own is not None:
        memo.setdefault("free", set()).add((_key(qa), _key(Interval.point(grid.centres(own[None, :])[0]))))
        return own, cell_tree(grid, own)
    for e in grid.nearest_voxels(qa.mid(), ENTRIES):
        c = grid.centres(e[None, :])[0]
        leg = (_key(qa), _key(Interval.point(c)))
        legs = memo.setdefault("legs", {})
        if leg not in legs:
            legs[leg] = joint_segment_is_clear(geometry, qa, Interval.point(c), JOINT_PIECES, budget)
        if legs[leg]:
            return e, cell_tree(grid, e)
    return None


def path_to_region(geometry: Geometry, bounds, sign: int, paving, grid: JointGrid | None = None,
                   targets: int = TARGETS) -> PathResult:
    """The basic region of a pose proved by a certified path into a labelled box of its aspect (see the module).

    Parameters
    ----------
    bounds : exact bounds (lo, hi) of the pose's x, y and phi (phi in (-pi, pi]).
    sign : the pose's certified sign of det A (1: WA1, -1: WA2).
    paving : the labelled boxes (attributes ``lo``, ``hi``, ``in_workspace``, ``det_sign``,
        ``region``, ``uniqueness_domain``, as :class:`~intervalkin.space.pose_label.LabelledBoxes`).
    grid : the joint cells, a guide for joint routes through a cell (optional).
    targets : boxes tried per route, those whose image is nearest g(pose) first (at most two per region).

    Routes, in turn: through the voxels of a joint cell (with ``grid``), a straight joint
    segment, a straight workspace segment.  Every leg is proved; a route only guides.
    """
    aspect = "WA1" if sign > 0 else "WA2"
    ok = (paving.region >= 0) & (paving.det_sign == sign) & (paving.in_workspace == 1)
    if not np.any(ok):
        return PathResult(None, None, f"no box of the paving is labelled with a basic region of {aspect}")
    start = _end_interval(bounds)
    here = start.mid()
    cand = np.flatnonzero(ok)
    centres = 0.5 * (paving.lo[cand] + paving.hi[cand])
    qa = rho_interval(geometry, _box(start))[0]
    gq = approx_inverse_kinematics(geometry, centres)
    near_q = np.argsort(np.linalg.norm(gq - qa.mid(), axis=1), kind="stable")
    near_x = np.argsort(path_distance(here[None, :], centres, metric_length(geometry)), kind="stable")
    region = paving.region[cand]
    memo: dict = {}
    budget = Budget()
    entry = None if grid is None else _cell_routes(geometry, qa, grid, memo, budget)
    plans = []
    if entry is not None:
        vox = grid.voxel_of(gq)
        flat = np.where(vox[:, 0] >= 0, np.ravel_multi_index(tuple(np.maximum(vox, 0).T), grid.cell.shape), 0)
        reach = (vox[:, 0] >= 0) & (entry[1][flat] >= 0)
        plans.append(("cells", _targets(near_q[reach[near_q]], region, targets, 2)))
    plans += [("joint", _targets(near_q, region, targets // 2, 1)), ("workspace", _targets(near_x, region, targets // 2, 1))]
    for route, order in plans:
        for j in order:
            i = int(cand[j])
            end = _end_point(here, paving.lo[i], paving.hi[i])
            qb = rho_interval(geometry, _box(end))[0]
            if route == "workspace":
                pieces = segment_is_clear(geometry, start, end, budget=budget)
                box = i if pieces else None
                what = "a workspace segment from the pose into"
            else:
                corners = None if route == "joint" else voxel_route(grid, entry[1], grid.voxel_of(qb.mid()[None, :])[0])
                if route == "cells" and corners is None:
                    continue  # g(P) is not in the cell after all (the guide used the box centre)
                via = [] if corners is None else [Interval.point(c) for c in corners]
                last = None if corners is None else grid.certified_voxel_holding(qb.lo, qb.hi)
                if last is not None and np.array_equal(grid.centres(last[None, :])[0], corners[-1]):
                    memo.setdefault("free", set()).add((_key(via[-1]), _key(qb)))  # the last leg stays in its voxel
                pieces, box = _follow_route(geometry, start, [qa, *via, qb], paving, sign, memo, budget,
                                            max(len(via) - 1, 0))
                what = (f"a joint path of {len(via) + 1} straight legs" + (" through the voxels of a joint cell"
                                                                              if via else "")
                        + ", followed by certified continuation from the pose into")
            if box is not None:
                rid, did = int(paving.region[box]), int(paving.uniqueness_domain[box])
                why = (f"{what} paving box {box} (basic region {rid}) is proved within the joint limits with its joint "
                       f"image clear of g(S) ({pieces} pieces proved, the legs inside certified voxels need none): "
                       f"the pose lies in basic region {rid}")
                return PathResult(rid, did if did >= 0 else None, why, box, pieces)
            if budget.left <= 0:
                break
    spent = "" if budget.left > 0 else f", within the search budget of {QUERY_PIECES} segment pieces"
    return PathResult(None, None, f"no certified path was found from the pose to the labelled boxes of {aspect} tried "
                                  f"(those nearest in joint space and in the workspace{spent}): the pose may lie on or "
                                  "very near a characteristic surface, where no basic region holds it")
