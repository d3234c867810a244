"""The graph side of an aspect cover: face adjacency, the fixed point of retraction ranks, separations.

The boxes of a cover (:mod:`intervalkin.space.aspect_topology`) are OUT, SINK, RET(e) or
LEFT.  This module holds what works on the tiling alone, given each box's certified
facts: the directed face pairs (phi wraps), the fixed point that ranks the retraction
boxes towards the sinks (:func:`resolve_cover`), and the separations: pieces of the
union of the non-OUT boxes, each holding its own components of the set
(proofs/lemma-aspect-retraction.md, "Separations").
"""

from __future__ import annotations

import numpy as np

from intervalkin.paving.adjacency import component_labels, directed_face_pairs as face_pairs, grow_labels, touching_pairs
from intervalkin.space.aspect_retraction import DIRECTIONS, exit_faces

__all__ = ["OUT", "SINK", "RET", "LEFT", "face_pairs", "resolve_cover", "separations", "between_groups"]

#: Kinds of the boxes of a cover.
OUT, SINK, RET, LEFT = 0, 1, 2, 3


def resolve_cover(level, ijk, depth, out, inside, ok, custom_faces, volume, max_groups: int = 1, adjacency=None):
    """Sinks, ranks and chosen candidates of the boxes of one cover (numpy fixed point).

    The sinks are the face-connected component of IN boxes of largest volume; other IN boxes
    take any fixed direction.  When the fixed point stalls with IN boxes unresolved and fewer than
    ``max_groups`` sink groups, the largest unresolved fragment of IN boxes becomes one more group
    (each group is connected; the set is then proved to have at most that many components).
    Returns (kind, rank, choice, fragments, edges, groups); ``choice`` indexes the candidate
    directions (-1: none), LEFT boxes are those no rank reached, ``edges`` the face adjacency.
    ``adjacency``: :func:`face_pairs` of the boxes when already computed.
    """
    n = len(level)
    pairs, border, edges = face_pairs(level, ijk, depth) if adjacency is None else adjacency
    comp = component_labels(n, edges, inside)
    fragments = int(comp.max()) + 1 if np.any(inside) else 0
    frag_vol = np.bincount(comp[inside], weights=volume[inside], minlength=fragments)
    sink = np.zeros(n, dtype=bool)
    groups = 0
    ok = ok.copy()
    ok[inside, :len(DIRECTIONS)] = True  # the fixed directions only (a per-box one may be 0)
    fixed_faces = exit_faces(DIRECTIONS).astype(np.uint8).T  # (6, m)
    resolved = out.copy()
    rank = np.where(resolved, 0, -1)
    choice = np.full(n, -1, dtype=np.int64)
    # opened[a, f]: neighbours across face f of a not resolved yet (a worklist: only boxes next to the
    # boxes resolved at the last step can change)
    opened = np.zeros((n, 6), dtype=np.int64)
    nb = ~resolved[pairs[1]]
    np.add.at(opened, (pairs[0][nb], pairs[2][nb]), 1)
    new = np.zeros(0, dtype=np.int64)
    step = 0
    while True:
        if new.size == 0:  # stalled (or starting): one more sink group, if allowed and any IN box is left
            left_in = inside & ~resolved
            if groups >= max_groups or not np.any(left_in):
                break
            vols = np.where(np.bincount(comp[left_in], minlength=fragments) > 0, frag_vol, -1.0)
            new = np.flatnonzero(comp == int(np.argmax(vols)))
            sink[new] = True
            rank[new] = 0
            groups += 1
        else:
            step += 1
            rank[new] = step
        resolved[new] = True
        now = np.zeros(n, dtype=bool)
        now[new] = True
        sel = now[pairs[1]]
        np.subtract.at(opened, (pairs[0][sel], pairs[2][sel]), 1)
        touched = np.flatnonzero(~resolved) if groups == 1 and step == 0 else np.unique(pairs[0][sel])
        frontier = touched[~resolved[touched]]
        bad = border[frontier] | (opened[frontier] > 0)
        blocked = np.concatenate([(bad.astype(np.uint8) @ fixed_faces) > 0,
                                  np.any(custom_faces[frontier] & bad[:, None, :], axis=-1)], axis=1)
        good = ok[frontier] & ~blocked
        hit = np.any(good, axis=1)
        new = frontier[hit]
        choice[new] = np.argmax(good[hit], axis=1)
    kind = np.full(n, LEFT, dtype=np.uint8)
    kind[out] = OUT
    kind[sink] = SINK
    kind[(rank > 0)] = RET
    return kind, rank, choice, fragments, edges, groups


def separations(level: np.ndarray, ijk: np.ndarray, depth: int, out: np.ndarray, sink: np.ndarray,
                edges: np.ndarray) -> tuple[np.ndarray, np.ndarray, int, np.ndarray]:
    """Where OUT boxes cut the sinks apart: (piece (n,), group (n,), separated, touching (2, m)).

    ``piece``: component of the union of the closed non-OUT boxes (boxes that meet at a face, an
    edge or a corner, :func:`~intervalkin.paving.adjacency.touching_pairs`; phi wraps), -1 on OUT
    boxes; ``group``: face-connected group of sinks (``edges``: face adjacency), -1 elsewhere;
    ``separated``: number of pieces holding a sink; ``touching``: the pairs of non-OUT boxes that meet.
    The pieces are closed, pairwise disjoint and cover S (the OUT boxes hold none of it): a piece
    holding a sink holds its own components of S, so S has at least ``separated`` components
    (proofs/lemma-aspect-retraction.md, "Separations").
    """
    touching = touching_pairs(level, ijk, depth, ~out)
    piece = component_labels(len(level), touching, ~out)
    group = component_labels(len(level), edges, sink)
    return piece, group, len(np.unique(piece[sink])), touching


def between_groups(kind: np.ndarray, piece: np.ndarray, group: np.ndarray, touching: np.ndarray,
                    pieces: np.ndarray) -> np.ndarray:
    """Boxes (not sinks) where the regions nearest to two groups of sinks meet, inside the given pieces.

    Each non-OUT box of the pieces takes the group nearest to it in the touching graph; the boxes
    touching a box of another group are where a join (refined IN boxes) or a cut (refined OUT
    boxes) between the groups must be found.
    """
    inc = np.isin(piece, pieces)
    near = grow_labels(len(kind), touching, np.where(inc, group, -1), inc)
    a, b = touching
    meet = (near[a] >= 0) & (near[b] >= 0) & (near[a] != near[b])
    out = np.zeros(len(kind), dtype=bool)
    out[a[meet]] = True
    out[b[meet]] = True
    return out & (kind != SINK)
