"""Sheets above a joint cell: which certified solution each piece of a workspace paving continues.

Above a joint cell C (certified off g(S)), the poses of one aspect with g(X) in C
form k sheets, each mapped one-to-one onto C by g: every q of C has one solution
on each sheet (proofs/lemma-theorem1-distinctness.md (d)).  Basic regions are
built from the pieces of the paving certified off S_c; two pieces above C lie
in the same basic region exactly when they lie on the same sheet.  Sheet s of an
aspect is named by the s-th certified solution of a reference joint vector
root_q of the cell.

:func:`identify_sheets` names the sheet of a piece by certified continuation
(proofs/lemma-sheet-continuation.md): a certified solution inside the piece is
followed (parameter Krawczyk, :mod:`intervalkin.solve.continuation`) along
straight joint-space segments inside C (:mod:`intervalkin.space.voxel_paths`)
to a voxel centre, where it is matched against the reference solutions carried
there along the same kind of paths.  Each step of a track is proved (one
solution in the track's box for the whole parameter range), so a match is a
proof that the piece and the reference solution lie on one sheet.  A piece
whose track fails, or whose match is ambiguous, stays undecided (-1): it is
never named by a guess.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import Interval
from intervalkin.kinematics.formulas import approx_inverse_kinematics
from intervalkin.solve.continuation import (
    Tracks,
    certify_start,
    compare_mod_2pi,
    new_tracks,
    step_tracks,
)
from intervalkin.solve.dkp import solve
from intervalkin.space.voxel_paths import (
    straight_edges,
    voxel_centres,
    voxel_of_points,
    voxel_tree,
)

__all__ = ['SheetReport', 'identify_sheets']


def _take_tracks(tr: Tracks, idx: np.ndarray) -> Tracks:
    """The tracks ``idx`` of a batch, as a new batch."""
    return Tracks(tr.qa[idx], tr.qb[idx], tr.t[idx], tr.h[idx], tr.p[idx], tr.z_lo[idx], tr.z_hi[idx],
                  tr.x_lo[idx], tr.x_hi[idx], tr.status[idx], tr.steps[idx])


def _concat_tracks(parts: list[Tracks]) -> Tracks:
    """One batch holding the tracks of ``parts`` in order."""

    def iv(name):
        return Interval(np.concatenate([getattr(p, name).lo for p in parts]),
                        np.concatenate([getattr(p, name).hi for p in parts]))

    def cat(name):
        return np.concatenate([getattr(p, name) for p in parts])

    return Tracks(iv("qa"), iv("qb"), cat("t"), cat("h"), cat("p"), cat("z_lo"), cat("z_hi"), cat("x_lo"), cat("x_hi"),
                  cat("status"), cat("steps"))


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
    if joint.voxel_centre(root_idx) != tuple(root_q):
        rep.start_failed = m  # the reference must be a voxel centre: nothing is decided
        return sheet, rep
    root = int((root_idx[0] * n + root_idx[1]) * n + root_idx[2])

    # 1. a certified solution inside each start box, and its voxel
    lo_b, hi_b = start_boxes[:, :, 0], start_boxes[:, :, 1]
    x_r = 0.5 * (lo_b + hi_b)
    q_r = approx_inverse_kinematics(geometry, x_r)
    ok, zl, zh, p = certify_start(geometry, Interval.point(q_r), x_r)
    ok &= np.all((lo_b <= zl) & (zh <= hi_b), axis=1)
    vox = voxel_of_points(joint, q_r)
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
            q = joint.voxel_centre(np.unravel_index(bot, (n,) * 3))
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
    active = _concat_tracks(pool)
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
        parts = [_take_tracks(active, keep)]
        meta = [meta[i] for i in keep]
        if spawn:
            parts.append(edge_tracks(spawn))
            meta += [("edge", e, h, li) for e, h, li in spawn]
        active = _concat_tracks(parts)

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
