"""Uniqueness domains: the fewest unions of basic regions on which the direct kinematics is unique.

Theorem 2 of the paper: a union of basic regions of one aspect whose basic
components are pairwise disjoint, connected through the characteristic surfaces
between them, is a domain on which every joint vector has at most one
solution.  Here the regions of each aspect are partitioned into the fewest
groups that are connected in the region adjacency graph and hold at most one
region above each joint cell (regions above one cell have coincident basic
components).

What is certified: the lower bound.  The certified solutions of one joint
vector in one aspect lie in pairwise different uniqueness domains, so there are
at least as many domains of an aspect as the largest number of regions of that
aspect above one cell; a partition reaching that number is minimal.

What is not: the adjacency of regions across the characteristic surfaces.  The
boxes of an aspect that carry no region (the enclosure of S_c, and pieces whose
sheet is undecided) are shared out to the nearest region by growth through
face adjacency, and two regions whose shares touch are called adjacent: a
heuristic, said so in the counts.
"""

from __future__ import annotations

import time

import networkx as nx
import numpy as np

from intervalkin.paving.adjacency import grow_labels
from intervalkin.paving.labels import Label
from intervalkin.paving.tree import Paving
from intervalkin.space.aspect import ASPECTS

__all__ = ['region_adjacency', 'uniqueness_domains']


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
