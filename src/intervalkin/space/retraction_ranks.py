"""The ranks of the joint retraction's nodes: a fixed point over their options (proofs/lemma-joint-retraction.md).

A node is resolved at rank r >= 1 when one of its options (a set of faces its points reach) has, across every
face, no leaf that waits: no LEFT node, and no node of the same signature that is neither a sink nor resolved
at a rank below r.  Sinks have rank 0.  Two copies of a node on opposite sides of a plane of double roots
(:mod:`intervalkin.solve.window_plane`) never wait for one another: a path that keeps its side reaches only
points of that side.
"""

from __future__ import annotations

import numpy as np

from intervalkin.core.rows import ramp
from intervalkin.paving.adjacency import directed_face_pairs

__all__ = ["SINK", "RET", "LEFT", "retraction_ranks"]

#: Kinds of nodes: in a counted cell, of known signature (to be ranked), of unknown signature (blocks).
SINK, RET, LEFT = 0, 1, 2


def retraction_ranks(paving, leaf, sig, kind, opt_node, opt_mask,
                     side: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The fixed point of the ranks (module docstring), a worklist over the options: an option of node N is ready
    when, across every face of its mask, no leaf waits (a LEFT node, or a node of N's signature not yet ranked).
    ``side`` (v,) int8: 0, or +-(k + 1) for a node on the side s > 0 or s < 0 of the k-th plane of double roots;
    nodes of opposite sides of one plane do not wait for one another.
    Returns (rank, the option that ranked each node or -1)."""
    v = leaf.size
    n = len(paving.level)
    source = np.zeros(n, dtype=bool)
    source[leaf[opt_node]] = True
    pairs, border, _ = directed_face_pairs(paving.level, paving.ijk, paving.depth, periodic=(False, False, False),
                                           source=source)
    start = np.searchsorted(leaf, np.arange(n + 1))
    index = np.flatnonzero(~(opt_mask & border[leaf[opt_node]]).any(axis=1))  # a face on the border: nothing proved
    opt_node, opt_mask = opt_node[index], opt_mask[index]
    option, face = np.nonzero(opt_mask)
    # leaf pairs across each face, looked up by (leaf, face)
    key = pairs[0] * 6 + pairs[2]
    order = np.argsort(key, kind="stable")
    key, across = key[order], pairs[1][order]
    want = leaf[opt_node[option]] * 6 + face
    e_lo, e_hi = np.searchsorted(key, want), np.searchsorted(key, want, side="right")
    entry = np.repeat(option, e_hi - e_lo)
    nb = across[np.repeat(e_lo, e_hi - e_lo) + ramp(e_hi - e_lo)]
    # the nodes of each neighbour leaf the option waits for: same signature, or of unknown signature
    q = np.repeat(start[nb], start[nb + 1] - start[nb]) + ramp(start[nb + 1] - start[nb])
    entry = np.repeat(entry, start[nb + 1] - start[nb])
    wait = ((sig[q, 0] < 0) | (sig[q] == sig[opt_node[entry]]).all(axis=1)) & (kind[q] != SINK)
    if side is not None:
        wait &= (side[q] == 0) | (side[q] != -side[opt_node[entry]])
    entry, q = entry[wait], q[wait]
    pending = np.bincount(entry, minlength=opt_node.size)
    by_q = np.argsort(q, kind="stable")
    q_sorted, entry_by_q = q[by_q], entry[by_q]
    rank = np.where(kind == SINK, 0, -1).astype(np.int32)
    exit_ = np.full(v, -1, dtype=np.int64)
    ready = np.flatnonzero(pending == 0)
    r = 0
    while ready.size:
        r += 1
        ready = ready[rank[opt_node[ready]] < 0]
        fresh, first = np.unique(opt_node[ready], return_index=True)
        if not fresh.size:
            break
        rank[fresh] = r
        exit_[fresh] = index[ready[first]]
        lo = np.searchsorted(q_sorted, fresh)
        hi = np.searchsorted(q_sorted, fresh, side="right")
        hit = entry_by_q[np.repeat(lo, hi - lo) + ramp(hi - lo)]
        np.subtract.at(pending, hit, 1)
        hit = np.unique(hit)
        ready = hit[(pending[hit] == 0) & (rank[opt_node[hit]] < 0)]
    return rank, exit_

