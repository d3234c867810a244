"""The tiling side of an aspect cover, re-checked: boxes tile the domain, neighbours across faces, groups, pieces.

Boxes are integer keys (level, i, j, k) of the cover's octree over its domain (phi wraps,
x and y do not).  Standard library only: the checker's arithmetic is elsewhere
(:mod:`intervalkin.checker.aspects`).
"""

from __future__ import annotations

from intervalkin.checker.parse import Refused

__all__ = ["check_tiling", "across", "sink_groups", "separate_pieces", "AROUND"]


def check_tiling(keys: set, deepest: int) -> None:
    total = 0
    for key in keys:
        lev = key[0]
        for up in range(1, lev + 1):
            if (lev - up,) + tuple(c >> up for c in key[1:]) in keys:
                raise Refused(f"box {list(key)} lies inside another box of the cover")
        total += 8 ** (deepest - lev)
    if total != 8 ** deepest:
        raise Refused("the boxes do not tile the domain (their volumes do not add up to it)")


def across(keys: set, key, face: int, deepest: int):
    """The boxes of the cover across ``face`` of box ``key`` (None: the x or y border of the domain)."""
    lev, ax, step = key[0], face // 2, 1 if face % 2 else -1
    c = list(key[1:])
    c[ax] += step
    if ax < 2 and not 0 <= c[ax] < (1 << lev):
        return None
    c[ax] %= 1 << lev
    for up in range(lev + 1):
        k = (lev - up,) + tuple(v >> up for v in c)
        if k in keys:
            return [k]
    found, stack = [], [(lev, c)]
    near = 0 if step > 0 else 1  # the children of the neighbour that touch the face
    while stack:
        lv, cc = stack.pop()
        for o1 in (0, 1):
            for o2 in (0, 1):
                off = [o1, o2]
                off.insert(ax, near)
                k = (lv + 1,) + tuple(2 * v + o for v, o in zip(cc, off))
                if k in keys:
                    found.append(k)
                elif lv + 1 < deepest:
                    stack.append((lv + 1, list(k[1:])))
                else:
                    raise Refused(f"no box of the cover across face {face} of box {list(key)}")
    return found


class _Groups:
    """Union-find over box keys (path halving)."""

    def __init__(self, keys):
        self.parent = {k: k for k in keys}

    def __contains__(self, k) -> bool:
        return k in self.parent

    def root(self, k):
        parent = self.parent
        while parent[k] != k:
            parent[k] = parent[parent[k]]
            k = parent[k]
        return k

    def join(self, a, b) -> None:
        self.parent[self.root(a)] = self.root(b)

    def count(self, keys) -> int:
        """The number of groups the given keys fall in."""
        return len({self.root(k) for k in keys})


def sink_groups(keys: set, sinks: list, deepest: int) -> int:
    """The number of face-connected groups of sink boxes (union-find; phi wraps)."""
    groups = _Groups(sinks)
    for k in sinks:
        for face in (1, 3, 5):
            for nb in across(keys, k, face, deepest) or []:
                if nb in groups:
                    groups.join(nb, k)
    return groups.count(sinks)


AROUND = [(a, b, c) for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1) if (a, b, c) != (0, 0, 0)]


def separate_pieces(keys: set, keep: set, sinks: list) -> int:
    """The number of pieces (contact components of the boxes ``keep``, the non-OUT ones; phi wraps) holding a sink.

    Two closed boxes of a tiling meet exactly when, for one of the 26 offsets d, the cell of the
    finer one's level beside it along d lies in the coarser one: each box looks along every d for
    the box holding that cell at its own level or above (the finer boxes beside it find it in turn).
    """
    groups = _Groups(keep)
    for key in keep:
        lev, n = key[0], 1 << key[0]
        for d in AROUND:
            c = [key[1] + d[0], key[2] + d[1], (key[3] + d[2]) % n]
            if not (0 <= c[0] < n and 0 <= c[1] < n):
                continue
            for up in range(lev + 1):
                k = (lev - up, c[0] >> up, c[1] >> up, c[2] >> up)
                if k in keys:
                    if k in groups and k != key:
                        groups.join(k, key)
                    break
    return groups.count(sinks)
