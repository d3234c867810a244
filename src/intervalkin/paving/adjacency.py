"""Face adjacency of the boxes of a paving, and connected components of labelled boxes.

Face adjacency (``shares_face``): two boxes are adjacent when they share a 2-D
piece of a face (a common edge or corner is not enough).  In an x-phi section
(faces are drawn as edges)::

      phi = +pi  +---------+----+----+      ^ phi
                 |         | b  | c  |      |
                 |    a    +----+----+      +--> x
                 |         | d  | e  |
                 +----+----+----+----+      a-b, a-d, a-f, a-g: share a face piece
                 | f  | g  |         |      d-h, e-h, g-h, j-h: share a face piece
                 +----+----+    h    |      a-h, d-g: a corner only, NOT adjacent
                 | i  | j  |         |
      phi = -pi  +----+----+---------+
                 seam: phi = +pi is phi = -pi, so the top faces of a, b, c touch
                 the bottom faces of i, j, h: a-i, a-j, b-h, c-h are adjacent too.

All adjacency pairs are computed in bulk from the integer coordinates: along an
axis, a "+" face and a "-" face on the same plane overlap in 2-D exactly when one
dyadic square contains the other, so each box looks up the box across each of its
sides by the Z-order code of one finest cell (one sorted search per side).
"""

from __future__ import annotations

import numpy as np

__all__ = ['shares_face', 'shares_face_bruteforce', 'directed_face_pairs', 'touching_pairs', 'touching_pairs_bruteforce', 'adjacency_graph', 'component_labels', 'connected_components']


# --------------------------------------------------------------------------------------
# Adjacency
# --------------------------------------------------------------------------------------
def shares_face(level: np.ndarray, ijk: np.ndarray, depth: int, periodic=(False, False, True)) -> np.ndarray:
    """Face-adjacent pairs of a paving, as a (2, m) int64 array with row 0 < row 1, sorted by (row 0, row 1).

    Parameters
    ----------
    level : (n,) ints, ijk : (n, 3) ints, integer coordinates of boxes that tile
        (part of) the domain without overlapping; max(level) <= depth <= 21.
    periodic : which axes wrap (default: phi, so phi = +pi touches phi = -pi).

    Two boxes are adjacent when they share a 2-D piece of a face.  How: faces of dyadic boxes on one
    plane share a 2-D piece exactly when one contains the other, so of two adjacent boxes the finer one
    (either, at equal levels) has the other across its face, holding the finest cell next to its own lowest
    corner.  Each box looks up, on each of its six sides, the box holding that finest cell (a sorted search
    of Z-order codes, :func:`_morton`; a gap of a partial tiling holds none) and keeps it when it is not
    finer; at equal levels only the "+" side keeps it, so that a pair is found once.  Cost: six sorted
    searches per box.
    """
    level = np.asarray(level, dtype=np.int64)
    ijk = np.asarray(ijk, dtype=np.int64)
    n = level.shape[0]
    if n == 0:
        return np.zeros((2, 0), dtype=np.int64)
    if depth > _MORTON_BITS:
        raise ValueError(f"shares_face: depth must be at most {_MORTON_BITS}, got {depth}")
    nfine = np.int64(1) << depth
    shift = depth - level
    corner = ijk << shift[:, None]
    holder = _cell_holders(level, ijk, depth)
    pairs = []
    for ax in range(3):
        for side in (-1, 1):
            cell = corner.copy()
            cell[:, ax] = corner[:, ax] - 1 if side < 0 else (ijk[:, ax] + 1) << shift
            if periodic[ax]:
                cell[:, ax] %= nfine
                at = np.arange(n)
            else:
                at = np.flatnonzero((cell[:, ax] >= 0) & (cell[:, ax] < nfine))
            found = holder(cell[at])
            other = level[np.maximum(found, 0)]
            not_finer = (other < level[at]) if side < 0 else (other <= level[at])
            keep = (found >= 0) & not_finer
            pairs.append(np.stack([at[keep], found[keep]]))
    p = np.concatenate(pairs, axis=1)
    p = p[:, p[0] != p[1]]
    p = np.sort(p, axis=0)
    if p.size == 0:
        return np.zeros((2, 0), dtype=np.int64)
    # a pair may still come twice (a box reaching round a periodic axis both ways): one sorted key each
    keys = np.sort(p[0] * np.int64(n) + p[1])
    keys = keys[np.concatenate(([True], keys[1:] != keys[:-1]))]
    return np.stack([keys // n, keys % n])


def shares_face_bruteforce(level, ijk, depth: int, periodic=(False, False, True)) -> np.ndarray:
    """Reference O(n^2) version of :func:`shares_face` (for tests, small n only)."""
    level = np.asarray(level, dtype=np.int64)
    ijk = np.asarray(ijk, dtype=np.int64)
    shift = (depth - level)[:, None]
    lo = ijk << shift
    hi = (ijk + 1) << shift
    nfine = 1 << depth
    out = []
    n = len(level)
    for a in range(n):
        for b in range(a + 1, n):
            for ax in range(3):
                others = [o for o in range(3) if o != ax]
                overlap = all(min(hi[a, o], hi[b, o]) - max(lo[a, o], lo[b, o]) > 0 for o in others)
                if not overlap:
                    continue
                touch = hi[a, ax] == lo[b, ax] or hi[b, ax] == lo[a, ax]
                if periodic[ax]:
                    touch = touch or (hi[a, ax] == nfine and lo[b, ax] == 0) or (hi[b, ax] == nfine and lo[a, ax] == 0)
                if touch:
                    out.append((a, b))
                    break
    return np.array(out, dtype=np.int64).reshape(-1, 2).T


#: Bits per coordinate of a Z-order code (3 x 21 bits fit an int64).
_MORTON_BITS = 21
#: Shifts and masks spreading 21 bits to every third bit of 63.
_SPREAD = ((32, 0x1F00000000FFFF), (16, 0x1F0000FF0000FF), (8, 0x100F00F00F00F00F), (4, 0x10C30C30C30C30C3),
           (2, 0x1249249249249249))


def _spread(v: np.ndarray) -> np.ndarray:
    x = v & 0x1FFFFF
    for s, m in _SPREAD:
        x = (x | (x << s)) & m
    return x


def _morton(ijk: np.ndarray, bits: int) -> np.ndarray:
    """Z-order codes of integer cells (n, 3) with coordinates below 2**bits (bits <= 21): bit b of axis a
    goes to bit 3 b + a."""
    ijk = np.asarray(ijk, dtype=np.int64)
    return _spread(ijk[:, 0]) | (_spread(ijk[:, 1]) << 1) | (_spread(ijk[:, 2]) << 2)


def _cell_holders(level: np.ndarray, ijk: np.ndarray, depth: int):
    """For boxes (level, ijk) tiling part of the domain: a function mapping finest cells (m, 3) to the box holding
    each (-1 where none, a gap).  The boxes sorted by the Z-order code of their lowest finest cell hold the codes
    [start, start + 8^(depth - level)), disjoint ranges: the holder of a code is the last box starting at or
    before it, when the code lies in its range."""
    shift = depth - level
    start = _morton(ijk << shift[:, None], depth)
    order = np.argsort(start, kind="stable")
    starts = start[order]
    ends = starts + (np.int64(1) << (3 * shift[order]))

    def holder(cells: np.ndarray) -> np.ndarray:
        code = _morton(cells, depth)
        pos = np.maximum(np.searchsorted(starts, code, side="right") - 1, 0)
        return np.where((starts[pos] <= code) & (code < ends[pos]), order[pos], -1)

    return holder


#: The 26 offsets to the cells around a cell (faces, edges and corners).
_AROUND = np.array([(a, b, c) for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1) if (a, b, c) != (0, 0, 0)],
                   dtype=np.int64)


def touching_pairs(level: np.ndarray, ijk: np.ndarray, depth: int, mask: np.ndarray | None = None,
                   periodic=(False, False, True)) -> np.ndarray:
    """Pairs of boxes of a tiling whose CLOSED boxes meet (a face, an edge or a corner), (2, m), row 0 < row 1.

    Unlike :func:`shares_face`, a common edge or corner is enough: the components of this graph
    are the connected components of the union of the closed boxes.  ``mask`` (n,) keeps the pairs
    of selected boxes only (default: all).  The boxes must tile the whole domain (every fine cell
    lies in exactly one box).

    How: if closed boxes f and C meet and C is not finer than f, C contains the cell f + d of f's
    level for one of the 26 offsets d (per axis: the intervals overlap, d = 0, or touch, d = +-1),
    hence the fine cell of f + d nearest to f; so each box looks up, for each offset, the box
    holding that fine cell (one sorted search of Z-order codes; every box found does meet f: it
    holds a fine cell touching f; :func:`_cell_holders`).  Cost: 26 sorted searches per selected box.  depth <= 20.
    """
    level = np.asarray(level, dtype=np.int64)
    ijk = np.asarray(ijk, dtype=np.int64)
    n = level.shape[0]
    mask = np.ones(n, dtype=bool) if mask is None else np.asarray(mask, dtype=bool)
    if depth > 20:
        raise ValueError(f"touching_pairs: depth must be at most 20, got {depth}")
    if n == 0 or not np.any(mask):
        return np.zeros((2, 0), dtype=np.int64)
    shift = depth - level
    holder = _cell_holders(level, ijk, depth)
    sel = np.flatnonzero(mask)
    nfine = np.int64(1) << depth
    rows = []
    for d in _AROUND:
        own = np.int64(1) << level[sel]
        c = ijk[sel] + d
        keep = np.ones(sel.size, dtype=bool)
        for ax in range(3):
            if periodic[ax]:
                c[:, ax] %= own
            else:
                keep &= (c[:, ax] >= 0) & (c[:, ax] < own)
        s = shift[sel][:, None]
        fine = (c << s) + np.where(d < 0, (np.int64(1) << s) - 1, 0)  # the fine cell of c nearest to the box
        fine = np.clip(fine, 0, nfine - 1)
        found = holder(fine)
        keep &= (found >= 0) & mask[found] & (found != sel)
        rows.append(np.stack([sel[keep], found[keep]]))
    p = np.sort(np.concatenate(rows, axis=1), axis=0)
    if p.size == 0:
        return np.zeros((2, 0), dtype=np.int64)
    keys = np.unique(p[0] * np.int64(n) + p[1])
    return np.stack([keys // n, keys % n])


def touching_pairs_bruteforce(level, ijk, depth: int, periodic=(False, False, True)) -> np.ndarray:
    """Reference O(n^2) version of :func:`touching_pairs` (for tests, small n only)."""
    level = np.asarray(level, dtype=np.int64)
    ijk = np.asarray(ijk, dtype=np.int64)
    shift = (depth - level)[:, None]
    lo, hi = ijk << shift, (ijk + 1) << shift
    nfine = 1 << depth
    out = []
    for a in range(len(level)):
        for b in range(a + 1, len(level)):
            meet = True
            for ax in range(3):
                m = min(hi[a, ax], hi[b, ax]) >= max(lo[a, ax], lo[b, ax])
                if periodic[ax]:
                    m = m or (hi[a, ax] == nfine and lo[b, ax] == 0) or (hi[b, ax] == nfine and lo[a, ax] == 0)
                meet = meet and m
            if meet:
                out.append((a, b))
    return np.array(out, dtype=np.int64).reshape(-1, 2).T


def adjacency_graph(n: int, edges: np.ndarray, nodes: np.ndarray | None = None):
    """A networkx Graph on box indices ``nodes`` (default all n) with the given (2, m) edges.

    Edges with an endpoint outside ``nodes`` are dropped.
    """
    import networkx as nx

    g = nx.Graph()
    if nodes is None:
        nodes = np.arange(n)
    nodes = np.asarray(nodes)
    g.add_nodes_from(nodes.tolist())
    keep = np.zeros(n, dtype=bool)
    keep[nodes] = True
    e = edges[:, keep[edges[0]] & keep[edges[1]]]
    g.add_edges_from(zip(e[0].tolist(), e[1].tolist()))
    return g


def component_labels(n: int, edges: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """Connected components of the boxes selected by ``mask`` under ``edges``, in bulk.

    Returns (n,) int32: component id 0..c-1 for selected boxes (numbered by their
    smallest box index, ids ordered by decreasing size), -1 elsewhere.  Union by
    minimum label with pointer jumping (numpy, no Python loop per box).
    """
    mask = np.asarray(mask, dtype=bool)
    e = edges[:, mask[edges[0]] & mask[edges[1]]]
    parent = np.arange(n, dtype=np.int64)
    u, v = e[0], e[1]
    while True:
        pu, pv = parent[u], parent[v]
        diff = pu != pv
        if not np.any(diff):
            break
        hi_ = np.maximum(pu[diff], pv[diff])
        lo_ = np.minimum(pu[diff], pv[diff])
        np.minimum.at(parent, hi_, lo_)
        while True:  # pointer jumping until every node points at a root
            pp = parent[parent]
            if np.array_equal(pp, parent):
                break
            parent = pp
    out = np.full(n, -1, dtype=np.int32)
    roots = parent[mask]
    if roots.size == 0:
        return out
    uniq, inv, counts = np.unique(roots, return_inverse=True, return_counts=True)
    order = np.argsort(-counts, kind="stable")
    rank = np.empty_like(order)
    rank[order] = np.arange(order.size)
    out[mask] = rank[inv].astype(np.int32)
    return out


def grow_labels(n: int, edges: np.ndarray, seeds: np.ndarray, layer: np.ndarray, max_steps: int = 100_000) -> np.ndarray:
    """Multi-source growth of integer labels into the ``layer`` nodes (nearest seed by graph distance).

    ``seeds`` (n,) holds a label >= 0 on seed nodes and -1 elsewhere; each step
    gives every unlabelled layer node adjacent to a labelled node the smallest
    neighbouring label.  Returns the grown labels (layer nodes out of reach
    stay -1).  Cost: one pass over the edges that touch the layer per step.
    """
    lab = np.asarray(seeds, dtype=np.int64).copy()
    layer = np.asarray(layer, dtype=bool)
    edges = edges[:, layer[edges[0]] | layer[edges[1]]]  # edges between seeds never change a label
    u, v = edges
    big = np.iinfo(np.int64).max
    for _ in range(max_steps):
        a = (lab[u] >= 0) & (lab[v] < 0) & layer[v]
        b = (lab[v] >= 0) & (lab[u] < 0) & layer[u]
        if not (np.any(a) or np.any(b)):
            break
        new = np.full(n, big, dtype=np.int64)
        np.minimum.at(new, v[a], lab[u[a]])
        np.minimum.at(new, u[b], lab[v[b]])
        upd = new != big
        lab[upd] = new[upd]
    return lab


def connected_components(n: int, edges: np.ndarray, mask: np.ndarray) -> list[frozenset]:
    """Components (frozensets of box indices) of the selected boxes, via networkx."""
    import networkx as nx

    g = adjacency_graph(n, edges, np.flatnonzero(mask))
    return [frozenset(c) for c in nx.connected_components(g)]


def directed_face_pairs(level: np.ndarray, ijk: np.ndarray, depth: int, periodic=(False, False, True),
                        source: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Directed face adjacency of a tiling: (pairs (3, m): box, neighbour, face), on_border (n, 6), edges.

    Row (a, b, f): b lies across face f of a (face 2k: the -axis-k side, 2k + 1: the + side).
    ``on_border[a, f]``: face f of a lies on the border of the domain along an axis that does not
    wrap (no neighbour there).  ``edges`` is :func:`shares_face` of the boxes.  With ``source`` (n,)
    bool, only the rows whose box a is marked are returned.
    """
    level = np.asarray(level, dtype=np.int64)
    edges = shares_face(level, ijk, depth, periodic=periodic)
    shift = (depth - level)[:, None]
    lo, hi = ijk << shift, (ijk + 1) << shift
    nfine = np.int64(1) << depth
    a, b = edges
    if source is not None:
        near = source[a] | source[b]
        a, b = a[near], b[near]
    rows = []
    for ax in range(3):
        others = [o for o in range(3) if o != ax]
        overlap = np.all(np.minimum(hi[a][:, others], hi[b][:, others]) > np.maximum(lo[a][:, others],
                                                                                     lo[b][:, others]), axis=1)
        wrap = nfine if periodic[ax] else np.int64(1) << 62
        for p, q in ((a, b), (b, a)):
            m = overlap & ((hi[p, ax] % wrap) == (lo[q, ax] % wrap))  # q across the + face of p
            rows.append(np.stack([p[m], q[m], np.full(int(m.sum()), 2 * ax + 1)]))
            rows.append(np.stack([q[m], p[m], np.full(int(m.sum()), 2 * ax)]))
    pairs = np.concatenate(rows, axis=1)
    if source is not None:
        pairs = pairs[:, source[pairs[0]]]
    border = np.zeros((len(level), 6), dtype=bool)
    for ax in range(3):
        if not periodic[ax]:
            border[:, 2 * ax] = lo[:, ax] == 0
            border[:, 2 * ax + 1] = hi[:, ax] == nfine
    return pairs, border, edges
