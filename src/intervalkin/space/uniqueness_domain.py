"""Characteristic surfaces, basic regions, basic components and uniqueness domains.

The paper's sections 4 and 5 (Definitions 2-4, Proposition 1, Theorems 1-2),
rebuilt on certified pavings.

* Characteristic surface S_c(WA) = {X in WA : g(X) in g(S)} (the joint-limit part
  of the aspect's boundary maps onto the boundary of the joint box).  A box of an
  aspect is *certified off S_c* when its interval image g(b) meets no marked
  voxel of the joint-space enclosure of g(S) (:mod:`intervalkin.space.joint_space`); the
  boxes of the aspect that are not so certified form an outer enclosure of S_c.
* Basic regions (Definition 3): connected components of WA minus S_c.  Here:
  face-connected components (phi seam included) of the boxes certified inside an
  aspect and off S_c.  Each is connected (union of adjacent closed boxes) and
  lies in ONE true basic region (it is connected and avoids S_c).
* Basic component (Definition 4): g of a basic region.  Every box of a region
  maps into unmarked voxels of one joint cell (its index range is a block of
  unmarked voxels); adjacent boxes share a face, so a whole region maps into
  one cell, which the code checks.
* Sheets: above a cell C with k solutions of an aspect there are exactly k
  sheets (the basic regions over C); the k solutions of the cell's witness name
  them, and the sheet of each piece is found by certified continuation inside C
  (:mod:`intervalkin.solve.continuation`, proofs/lemma-sheet-continuation.md).
* Distinctness (DESIGN.md section 6): two regions are certified different when
  (a) their aspects differ (opposite certified det A signs); (b) their cells have
  different certified counts (different basic components); or (c) a joint
  vector q has two certified solutions of the same aspect, one in a box of each
  region: by Theorem 1, g is injective on a basic region, so the two regions lie
  in different basic regions.  The certified lower bound on the number of basic
  regions is the size of a largest set of pairwise certified-distinct regions.
* Proposition 1 check: above each cell C and for each aspect, the number of
  regions found should equal the certified number of solutions of that aspect
  in C; every mismatch is reported (a region split by the undecided layer, or
  one not resolved at this depth).
* Uniqueness domains (Theorem 2): each aspect's regions are partitioned into the
  fewest groups that are connected in the region adjacency graph and hold at
  most one region above each cell.  The number is minimal because the regions
  above one cell must all be in different groups: it cannot be smaller than the
  largest number of solutions of one aspect over the cells.

What is not certified, and said so in the results: that two cells of equal
count are different true cells (so regions above them may be parts of one true
basic region), hence the found number of regions is exact only when the
consistency checks pass AND the lower bound equals it; and the adjacency of
regions across the undecided layer (a heuristic: the layer is split between
the regions by nearest-region growth).
"""

from __future__ import annotations

import time

import numpy as np

from intervalkin.paving.adjacency import grow_labels
from intervalkin.paving.labels import Label
from intervalkin.paving.tree import Paving
from intervalkin.space.aspect import ASPECTS

__all__ = ['region_adjacency', 'uniqueness_domains']


# --------------------------------------------------------------------------------------
# Region adjacency across the characteristic surfaces, uniqueness domains
# --------------------------------------------------------------------------------------
def region_adjacency(paving: Paving, edges: np.ndarray, region: np.ndarray) -> set[tuple[int, int]]:
    """Pairs of basic regions of one aspect adjacent across its characteristic surface.

    The boxes of each aspect that carry no region (the enclosure of S_c and the
    pieces whose sheet is undecided) are shared out to the nearest region by
    growth through face adjacency; two regions are adjacent when their shares
    touch.  A heuristic, not a certified adjacency.
    """
    n = len(paving)
    adj: set[tuple[int, int]] = set()
    for name in ASPECTS:
        in_aspect = paving.labels[name] == Label.INSIDE
        seeds = np.where(in_aspect & (region >= 0), region, -1).astype(np.int64)
        inner = edges[:, in_aspect[edges[0]] & in_aspect[edges[1]]]
        lab = grow_labels(n, inner, seeds, in_aspect & (region < 0))
        u, v = inner
        m = (lab[u] >= 0) & (lab[v] >= 0) & (lab[u] != lab[v]) & in_aspect[u] & in_aspect[v]
        for a, b in set(zip(lab[u[m]].tolist(), lab[v[m]].tolist())):
            adj.add((min(a, b), max(a, b)))
    return adj


def uniqueness_domains(regions, adjacency: set[tuple[int, int]], time_limit: float = 20.0):
    """Fewest connected groups per aspect, with at most one region above each cell.

    Returns (groups, lower_bound): groups as tuples of region ids; lower_bound is
    the sum over the aspects of the largest number of regions above one cell
    (those must all be in different groups).  Backtracking from that bound
    upward; the first feasible number of groups is the minimum for this graph.
    """
    import networkx as nx

    g = nx.Graph()
    g.add_nodes_from(r.id for r in regions)
    g.add_edges_from(adjacency)
    by_id = {r.id: r for r in regions}
    groups_all: list[tuple[int, ...]] = []
    bound_total = 0
    deadline = time.perf_counter() + time_limit
    for name in ASPECTS:
        ids = [r.id for r in regions if r.aspect == name]
        if not ids:
            continue
        per_cell: dict[int, list[int]] = {}
        for i in ids:
            per_cell.setdefault(by_id[i].cell, []).append(i)
        bound = max(len(v) for v in per_cell.values())
        bound_total += bound
        for k in range(bound, len(ids) + 1):
            sol = _partition(ids, k, g, by_id, per_cell, deadline)
            if sol is not None:
                groups_all.extend(tuple(sorted(s)) for s in sol)
                break
        else:  # pragma: no cover - every region alone is always feasible
            groups_all.extend((i,) for i in ids)
    return tuple(groups_all), bound_total


def _partition(ids, k, g, by_id, per_cell, deadline):
    """k connected groups, one region per cell per group, covering ids; None if not found."""
    seed_cell = max(per_cell, key=lambda c: len(per_cell[c]))
    seeds = per_cell[seed_cell]
    groups = [{s} for s in seeds] + [set() for _ in range(k - len(seeds))]
    cells = [{by_id[s].cell} for s in seeds] + [set() for _ in range(k - len(seeds))]
    rest = [i for i in ids if i not in seeds]

    def search(unassigned):
        if time.perf_counter() > deadline:
            return False
        if not unassigned:
            return all(groups)
        best, best_opts = None, None
        for r in unassigned:  # the most constrained region first
            opts = [gi for gi in range(k)
                    if by_id[r].cell not in cells[gi]
                    and (not groups[gi] or any(nb in groups[gi] for nb in g.neighbors(r)))]
            if best_opts is None or len(opts) < len(best_opts):
                best, best_opts = r, opts
            if not opts:
                break
        for gi in best_opts:
            if not groups[gi] and any(not grp for grp in groups[:gi]):
                continue  # empty groups are interchangeable
            groups[gi].add(best)
            cells[gi].add(by_id[best].cell)
            if search([r for r in unassigned if r != best]):
                return True
            groups[gi].discard(best)
            cells[gi].discard(by_id[best].cell)
        return False

    return [set(s) for s in groups] if search(rest) else None
