"""Certified continuation of direct-kinematic solutions along joint-space paths.

Used by :mod:`intervalkin.space.basic_region` to tell which sheet above a joint cell a piece
of certified boxes lies in (proofs/lemma-sheet-continuation.md).

Parameter Krawczyk test
-----------------------
Along a segment q(t) = q_a + t (q_b - q_a) of joint space (q_a, q_b exact, t a
float) the system is F(X, t)_i = |B_i(X) - A_i|^2 - rho_i(t)^2.  For a box X,
a parameter interval T = [t0, t1], a point m of X, a float matrix Y (inverse of
the float Jacobian at m) and an interval matrix J(X) enclosing dF/dX over X
(independent of t),

    K(X, T) = m - Y F(m, tm) - (T - tm) Y dF/dt(m, T) + (I - Y J(X)) (X - m)

encloses m - Y F(m, t) + (I - Y J(X)) (X - m) for every t in T (mean value in t,
dF_i/dt = -2 rho_i(t) (q_b - q_a)_i).  If K(X, T) lies in the interior of X,
then for EVERY t in T the box X holds exactly one solution x(t), every Jacobian
on X is non-singular (so det A keeps one sign on X) and t -> x(t) is continuous
(proofs/lemma-krawczyk-uniqueness.md applied at each t; closed graph in a
compact box).  Every zero of F(., t1) in X also lies in

    K1 = p - Y F(p, t1) + (I - Y J(X)) (X - p)     (any point p of X),

so K1 n X is a box that holds the solution at t1 (no interior test needed).
All of it is evaluated with :class:`intervalkin.core.interval.Interval` (outward
rounding), vectorized over many tracks at once.

Tracking
--------
A track carries a box Z known to hold the followed solution at q(t).  A step
[t, t1] predicts the solution at t1 in float (tangent + Newton), builds X around
both ends and around Z, and accepts the step when K(X, [t, t1]) is inside X:
the followed solution is then the unique one in X for all of [t, t1], and
Z := K1 n X at t1.  The step doubles on success and halves on failure, with a
floor below which the track gives up (never a guess).

Voxel paths
-----------
Paths run inside one joint cell: between centres of face-adjacent voxels of the
cell (the segment lies in the union of the two closed voxels), in straight runs
along a breadth-first tree of the cell rooted at the cell's witness voxel.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from intervalkin.core.exact import fraction_bounds
from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import Interval
from intervalkin.kinematics.constants import _k
from intervalkin.kinematics.formulas import _approx_f_and_jacobian
from intervalkin.solve.continuation import (
    Tracks,
    certify_start,
    compare_mod_2pi,
    new_tracks,
    step_tracks,
)
from intervalkin.solve.dkp import solve


# --------------------------------------------------------------------------------------
# Voxel tree of one joint cell
# --------------------------------------------------------------------------------------
def voxel_tree(in_cell: np.ndarray, root: tuple[int, int, int]):
    """Breadth-first tree of the True voxels of a 3-D grid, from ``root``.

    Returns (parent, direction) as flat arrays over the grid (-1 outside the
    tree).  ``direction`` d in 0..5 says the voxel is its parent moved one step
    along axis d // 2, in the + sense when d is even.  Among the parents at the
    previous distance, one reached along the parent's own direction is preferred,
    so that the tree paths run in long straight runs.
    """
    shape = in_cell.shape
    free = in_cell.ravel()
    n = free.size
    strides = np.array([shape[1] * shape[2], shape[2], 1], dtype=np.int64)
    parent = np.full(n, -1, dtype=np.int64)
    direction = np.full(n, -1, dtype=np.int8)
    seen = np.zeros(n, dtype=bool)
    r = int(np.dot(root, strides))
    if not free[r]:
        raise ValueError("root voxel is not in the cell")
    seen[r] = True
    front = np.array([r], dtype=np.int64)
    while front.size:
        coords = np.stack(np.unravel_index(front, shape), axis=1)
        cand_v, cand_u, cand_d, cand_pref = [], [], [], []
        for d in range(6):
            axis, sgn = d // 2, (1 if d % 2 == 0 else -1)
            c = coords[:, axis] + sgn
            okc = (c >= 0) & (c < shape[axis])
            u = front[okc]
            v = u + sgn * strides[axis]
            keep = free[v] & ~seen[v]
            u, v = u[keep], v[keep]
            cand_v.append(v)
            cand_u.append(u)
            cand_d.append(np.full(v.size, d, dtype=np.int8))
            cand_pref.append((direction[u] != d).astype(np.int8))  # 0 = same direction as the parent link
        v = np.concatenate(cand_v)
        if v.size == 0:
            break
        u = np.concatenate(cand_u)
        dd = np.concatenate(cand_d)
        pref = np.concatenate(cand_pref)
        order = np.lexsort((dd, pref, v))
        v, u, dd = v[order], u[order], dd[order]
        first = np.ones(v.size, dtype=bool)
        first[1:] = v[1:] != v[:-1]
        v, u, dd = v[first], u[first], dd[first]
        parent[v] = u
        direction[v] = dd
        seen[v] = True
        front = v
    return parent, direction


def straight_edges(parent: np.ndarray, direction: np.ndarray, root: int, targets, max_run: int = 1 << 30):
    """Edges (top, bottom, length) of the tree spanned by root and targets, cut into straight runs.

    Each edge joins two voxels of one straight run of the tree, at most
    ``max_run`` voxels apart; every voxel in between is a tree voxel, so the
    segment between their centres lies in the union of the closed voxels of
    the run.  Edges are listed top-down: an edge's top is the root or the
    bottom of an earlier edge.
    """
    children: dict[int, list[int]] = {}
    in_union = {root}
    for t in targets:
        v = int(t)
        while v not in in_union:
            in_union.add(v)
            u = int(parent[v])
            if u < 0:
                raise ValueError("target voxel not in the tree")
            children.setdefault(u, []).append(v)
            v = u
    target_set = {int(t) for t in targets}
    edges: list[tuple[int, int, int]] = []
    stack = [(root, c) for c in children.get(root, [])]
    while stack:
        top, v = stack.pop()
        run = 1
        while run < max_run:  # walk down the straight run while the node is not a stop
            ch = children.get(v, [])
            if v in target_set or len(ch) != 1 or direction[ch[0]] != direction[v]:
                break
            v = ch[0]
            run += 1
        edges.append((top, v, run))
        stack.extend((v, c) for c in children.get(v, []))
    return edges


def voxel_centres(joint, flat: np.ndarray) -> Interval:
    """Enclosures (m, 3) of the exact centres rho_min + (k + 1/2) step of voxels (flat C order)."""
    idx = np.stack(np.unravel_index(np.asarray(flat, dtype=np.int64), (joint.n,) * 3), axis=1).astype(np.float64)
    r0 = [fraction_bounds(v) for v in joint.rho_min]
    h = [fraction_bounds(v) for v in joint.step]
    R0 = Interval(np.array([b[0] for b in r0]), np.array([b[1] for b in r0]))
    H = Interval(np.array([b[0] for b in h]), np.array([b[1] for b in h]))
    return R0 + H * (idx + 0.5)


# --------------------------------------------------------------------------------------
# Sheets above one joint cell
# --------------------------------------------------------------------------------------
def _take(tr: Tracks, idx: np.ndarray) -> Tracks:
    return Tracks(tr.qa[idx], tr.qb[idx], tr.t[idx], tr.h[idx], tr.p[idx], tr.z_lo[idx], tr.z_hi[idx],
                  tr.x_lo[idx], tr.x_hi[idx], tr.status[idx], tr.steps[idx])


def _concat(parts: list[Tracks]) -> Tracks:
    def iv(name):
        return Interval(np.concatenate([getattr(p, name).lo for p in parts]),
                        np.concatenate([getattr(p, name).hi for p in parts]))

    def cat(name):
        return np.concatenate([getattr(p, name) for p in parts])

    return Tracks(iv("qa"), iv("qb"), cat("t"), cat("h"), cat("p"), cat("z_lo"), cat("z_hi"), cat("x_lo"), cat("x_hi"),
                  cat("status"), cat("steps"))


def _voxel_of_points(joint, q: np.ndarray) -> np.ndarray:
    """Voxel index (m, 3) of float joint vectors q (m, 3), checked exactly; -1 rows when outside."""
    from fractions import Fraction

    r0 = np.array([float(v) for v in joint.rho_min])
    h = np.array([float(v) for v in joint.step])
    k = np.floor((q - r0) / h).astype(np.int64)
    out = np.full(q.shape, -1, dtype=np.int64)
    for i in range(len(q)):
        row = []
        for j in range(3):
            v = Fraction(float(q[i, j]))
            kk = int(k[i, j])
            for cand in (kk, kk - 1, kk + 1):  # the float floor may be one off; the exact test decides
                if 0 <= cand < joint.n and joint.rho_min[j] + cand * joint.step[j] <= v <= joint.rho_min[j] + (cand + 1) * joint.step[j]:
                    row.append(cand)
                    break
            else:
                row = None
                break
        if row is not None:
            out[i] = row
    return out


@dataclass
class SheetReport:
    """What :func:`identify_sheets` did for one cell (counts, for the consistency report)."""

    starts: int = 0
    start_failed: int = 0
    edges: int = 0
    atlas_failed: int = 0
    piece_tracks_failed: int = 0
    undecided: int = 0
    steps: int = 0
    hubs: int = 0
    hubs_named: int = 0


def identify_sheets(geometry: Geometry, joint, cid: int, root_q, references: dict, start_boxes: np.ndarray,
                    start_aspect: list, hub_spacing: int | None = None) -> tuple[np.ndarray, SheetReport]:
    """Sheet of each start box, by certified continuation inside joint cell ``cid``.

    Parameters
    ----------
    root_q : exact joint vector (Fractions), the centre of a voxel of the cell.
    references : aspect -> list of k boxes (3, 2), the certified solutions of
        root_q in that aspect; sheet s of the aspect is the sheet holding
        solution s (proofs/lemma-theorem1-distinctness.md (d)).
    start_boxes : ndarray (m, 3, 2), one box of each piece to identify (a box
        certified inside the aspect and off S_c, mapping into the cell).
    start_aspect : the aspect of each start box.
    hub_spacing : voxels of tree path between hubs (default 2**(depth - 2)).

    Returns (sheet (m,) int32, -1 where undecided; report).

    Method (proofs/lemma-sheet-continuation.md).  A breadth-first tree of the
    cell's voxels from root_q's voxel spans the start voxels; it is cut into
    straight runs.  Some run ends are *hubs*: the root, and every node at least
    ``hub_spacing`` voxels below the previous hub whose voxel centre has a
    complete certified solve.  From every hub, its own solutions are tracked
    (parameter Krawczyk) down the runs to the next hubs, all at once; a track
    arriving at a hub matches one of the hub's solutions (the hub's box lies in
    the track's final Krawczyk box), which carries the sheet names from hub to
    hub, top-down.  Each start box gets a certified solution of q_R = g(centre)
    inside it, tracked to the centre of q_R's voxel, where it matches one of the
    tracked solutions there (or is apart from all sheets but one).
    """
    rep = SheetReport(starts=len(start_boxes))
    m = len(start_boxes)
    sheet = np.full(m, -1, dtype=np.int32)
    if m == 0:
        return sheet, rep
    n = joint.n
    if hub_spacing is None:
        hub_spacing = max(4, 1 << max(joint.depth - 2, 0))
    sign_of = {"WA1": 1, "WA2": -1}
    labels = [(a, s_) for a in sorted(references) for s_ in range(len(references[a]))]
    root_idx = tuple(int((root_q[i] - joint.rho_min[i]) / joint.step[i] - Fraction(1, 2)) for i in range(3))
    if not all(joint.rho_min[i] + (root_idx[i] + Fraction(1, 2)) * joint.step[i] == root_q[i] for i in range(3)):
        rep.start_failed = m  # the reference must be a voxel centre: nothing is decided
        return sheet, rep
    root = int((root_idx[0] * n + root_idx[1]) * n + root_idx[2])

    # 1. a certified solution inside each start box, and its voxel
    lo_b, hi_b = start_boxes[:, :, 0], start_boxes[:, :, 1]
    x_r = 0.5 * (lo_b + hi_b)
    q_r = np.sqrt(_approx_f_and_jacobian(_k(geometry), x_r)[0])
    ok, zl, zh, p = certify_start(geometry, Interval.point(q_r), x_r)
    ok &= np.all((lo_b <= zl) & (zh <= hi_b), axis=1)
    vox = _voxel_of_points(joint, q_r)
    ok &= np.all(vox >= 0, axis=1)
    flat = np.where(ok, (vox[:, 0] * n + vox[:, 1]) * n + vox[:, 2], 0)
    ok &= joint.cell.ravel()[flat] == cid
    rep.start_failed = int((~ok).sum())
    use = np.flatnonzero(ok)
    if use.size == 0:
        return sheet, rep

    # 2. the tree, its straight runs and the hubs (each with its own certified solutions)
    parent, direction = voxel_tree(joint.cell == cid, root_idx)
    edges = straight_edges(parent, direction, root, np.unique(flat[use]), max_run=hub_spacing)
    rep.edges = len(edges)
    below: dict[int, list[int]] = {}
    for e, (top, _, _) in enumerate(edges):
        below.setdefault(top, []).append(e)
    hub_boxes: dict[int, list] = {root: [np.asarray(references[a][s_], dtype=np.float64) for a, s_ in labels]}
    hub_parent: dict[int, int] = {}
    since = {root: 0}
    owner = {root: root}  # the hub whose tracks reach each node
    for top, bot, run in edges:
        d = since[top] + run
        owner[bot] = owner[top]
        since[bot] = d
        if d >= hub_spacing:
            q = _voxel_centre_exact(joint, bot)
            boxes = _hub_solutions(geometry, q, references, sign_of)
            if boxes is not None:
                hub_parent[bot] = owner[top]
                hub_boxes[bot] = boxes
                owner[bot] = bot
                since[bot] = 0
    rep.hubs = len(hub_boxes)

    # 3. one pool of tracks: pieces to their voxel centres, hubs down to the next hubs
    atlas: dict[tuple[int, int, int], tuple] = {}  # (node, hub, label) -> (z_lo, z_hi) at the node
    arrivals: dict[tuple[int, int, int], tuple] = {}  # (hub reached, hub, label) -> final Krawczyk box
    for h, boxes in hub_boxes.items():
        for li, b in enumerate(boxes):
            atlas[(h, h, li)] = (b[:, 0].copy(), b[:, 1].copy())
    centre_cache: dict[int, tuple[np.ndarray, np.ndarray]] = {}

    def centres(vs):
        missing = [v for v in set(vs) if v not in centre_cache]
        if missing:
            c = voxel_centres(joint, np.array(missing))
            for i, v in enumerate(missing):
                centre_cache[v] = (c.lo[i], c.hi[i])
        return Interval(np.array([centre_cache[v][0] for v in vs]).reshape(-1, 3),
                        np.array([centre_cache[v][1] for v in vs]).reshape(-1, 3))

    def edge_tracks(items):
        """Tracks for (edge, hub, label) whose top node holds that atlas entry."""
        tops = [edges[e][0] for e, _, _ in items]
        z = [atlas[(t, h, li)] for t, (_, h, li) in zip(tops, items)]
        zl_ = np.array([a for a, _ in z])
        zh_ = np.array([b for _, b in z])
        return new_tracks(centres(tops), centres([edges[e][1] for e, _, _ in items]), 0.5 * (zl_ + zh_), zl_, zh_)

    meta = [("piece", int(i), -1, -1) for i in use]
    pool = [new_tracks(Interval.point(q_r[use]), centres(flat[use].tolist()), p[use], zl[use], zh[use])]
    first = [(e, h, li) for h in hub_boxes for e in below.get(h, []) for li in range(len(labels))]
    if first:
        pool.append(edge_tracks(first))
        meta += [("edge", e, h, li) for e, h, li in first]
    active = _concat(pool)
    final: dict[int, tuple[np.ndarray, np.ndarray]] = {}
    while meta:
        step_tracks(geometry, active, np.flatnonzero(active.status == 0))
        done = np.flatnonzero(active.status != 0)
        if done.size == 0:
            continue
        spawn = []
        for i in done:
            kind, a_, h, li = meta[i]
            rep.steps += int(active.steps[i])
            if active.status[i] != 1:
                if kind == "piece":
                    rep.piece_tracks_failed += 1
                else:
                    rep.atlas_failed += 1
                continue
            if kind == "piece":
                final[a_] = (active.x_lo[i].copy(), active.x_hi[i].copy())
                continue
            bot = edges[a_][1]
            if bot in hub_boxes:
                arrivals[(bot, h, li)] = (active.x_lo[i].copy(), active.x_hi[i].copy())
            else:
                atlas[(bot, h, li)] = (active.z_lo[i].copy(), active.z_hi[i].copy())
                spawn += [(e, h, li) for e in below.get(bot, [])]
        keep = np.flatnonzero(active.status == 0)
        parts = [_take(active, keep)]
        meta = [meta[i] for i in keep]
        if spawn:
            parts.append(edge_tracks(spawn))
            meta += [("edge", e, h, li) for e, h, li in spawn]
        active = _concat(parts)

    # 4. sheet names at the hubs, top-down: name[h][li] = sheet of the hub's solution li.
    # A hub's solution li is matched to the track (from the hub above) whose final box holds it.
    pairs = [(hub, li, lj) for hub, up in hub_parent.items() for li, (a, _) in enumerate(labels)
             for lj, (b, _) in enumerate(labels) if a == b and (hub, up, lj) in arrivals]
    holds = _holds([arrivals[(hub, hub_parent[hub], lj)] for hub, _, lj in pairs],
                   [(hub_boxes[hub][li][:, 0], hub_boxes[hub][li][:, 1]) for hub, li, _ in pairs])[0]
    matched: dict[tuple[int, int], list[int]] = {}
    for (hub, li, lj), yes in zip(pairs, holds):
        if yes:
            matched.setdefault((hub, li), []).append(lj)
    name: dict[int, list[int]] = {root: [s_ for _, s_ in labels]}
    for _, bot, _ in edges:
        if bot not in hub_parent or hub_parent[bot] not in name:
            continue
        up = name[hub_parent[bot]]
        got = []
        for li in range(len(labels)):
            cand = {up[lj] for lj in matched.get((bot, li), []) if up[lj] >= 0}
            got.append(cand.pop() if len(cand) == 1 else -1)
        name[bot] = _complete_names(got, labels)
    rep.hubs_named = sum(1 for h in hub_boxes if h in name and all(v >= 0 for v in name[h]))

    # 5. each piece: its final box at its voxel centre against the tracked solutions there
    pairs = []
    for i in use:
        v = int(flat[i])
        h = owner.get(v, -1)
        if i not in final or h not in name:
            continue
        pairs += [(int(i), name[h][li], atlas[(v, h, li)]) for li, (aa, _) in enumerate(labels)
                  if aa == start_aspect[i] and (v, h, li) in atlas and name[h][li] >= 0]
    inside, apart = _holds([final[i] for i, _, _ in pairs], [z for _, _, z in pairs])
    verdict: dict[int, tuple[set, set]] = {int(i): (set(), set()) for i in use}
    for (i, nm, _), ins, ap in zip(pairs, inside, apart):
        if ins:
            verdict[i][0].add(nm)
        elif ap:
            verdict[i][1].add(nm)
    for i in use:
        ins, ap = verdict[int(i)]
        # the piece's final box holds exactly one of the k solutions at the voxel centre, one per sheet
        rest = set(range(len(references[start_aspect[i]]))) - ap
        if len(ins) == 1:
            sheet[i] = ins.pop()
        elif not ins and len(rest) == 1 and i in final:
            sheet[i] = rest.pop()
        else:
            rep.undecided += 1
    return sheet, rep


def _holds(xs: list, zs: list):
    """compare_mod_2pi over lists of (lo, hi) pairs: (z inside x, z apart from x) arrays."""
    if not xs:
        return np.zeros(0, dtype=bool), np.zeros(0, dtype=bool)
    return compare_mod_2pi(np.array([x[0] for x in xs]), np.array([x[1] for x in xs]),
                           np.array([z[0] for z in zs]), np.array([z[1] for z in zs]))


def _voxel_centre_exact(joint, flat: int) -> tuple:
    idx = np.unravel_index(flat, (joint.n,) * 3)
    return tuple(joint.rho_min[i] + (int(idx[i]) + Fraction(1, 2)) * joint.step[i] for i in range(3))


def _hub_solutions(geometry: Geometry, q, references: dict, sign_of: dict):
    """The certified solutions of q, in the order of the labels, or None when q cannot be a hub."""

    res = solve(geometry, q)
    if not res.complete or any(s.status != "unique" for s in res.solutions):
        return None
    out = []
    for a in sorted(references):
        boxes = [np.asarray(s.box, dtype=np.float64) for s in res.solutions if s.det_sign == sign_of[a]]
        if len(boxes) != len(references[a]):
            return None
        out += boxes
    return out


def _complete_names(got: list[int], labels) -> list[int]:
    """Fill in the last unnamed solution of an aspect when the other k - 1 have distinct names."""
    out = list(got)
    for a in {aa for aa, _ in labels}:
        idx = [li for li, (aa, _) in enumerate(labels) if aa == a]
        k = len(idx)
        named = [out[li] for li in idx if out[li] >= 0]
        if len(set(named)) != len(named):  # a contradiction: name nothing of this aspect
            for li in idx:
                out[li] = -1
            continue
        unnamed = [li for li in idx if out[li] < 0]
        if len(unnamed) == 1:
            out[unnamed[0]] = (set(range(k)) - set(named)).pop()
    return out
