"""The leaves of the adaptive joint paving: bisection fronts, their tests, and refinement.

The joint box is bisected level by level (:func:`adaptive_leaves`); every box is tested
by the clear-box search (:func:`intervalkin.solve.joint_box.live_cells`), which also
narrows the live torus cells that a box hands to its 8 children, so each level re-tests
only what its parent could not settle.  :func:`refine_leaves` splits chosen leaves once
more (local refinement, faces, joins).  Leaves travel as the tuple (level, ijk, lo, hi,
clear, owner, cells): owner/cells are the live torus cells of the undecided leaves,
sorted by owner.  Certified: a leaf is ``clear`` only when the search proved it off g(S).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.workers import Workers, owned_rows
from intervalkin.paving.labels import Label
from intervalkin.paving.tree import Paving, box_bounds, split_boxes
from intervalkin.solve.joint_box import initial_cells, live_cells

__all__ = ["adaptive_leaves", "refine_leaves", "leaves_to_paving", "Leaves", "timed_step"]

#: (level, ijk, lo, hi, clear, owner, cells)
Leaves = tuple[np.ndarray, ...]
#: Leaves split together by :func:`refine_leaves` (their children, 8 per leaf, are tested together).
_BATCH = 16384


@dataclass
class _Front:
    """Boxes waiting for their test, with the torus cells their parent left live (owner = row)."""

    level: np.ndarray
    ijk: np.ndarray
    owner: np.ndarray
    cells: np.ndarray


def _children(front: _Front, cut: np.ndarray) -> _Front:
    """The 8 children of the cut boxes of a tested front; each inherits its parent's live cells."""
    rank = np.cumsum(cut) - 1
    sel = np.flatnonzero(cut[front.owner])
    c = rank[front.owner[sel]]
    # child 8 c + t of parent c gets the parent's run of cells, in order: runs of children follow each other
    count = np.bincount(c, minlength=int(np.count_nonzero(cut)))
    start = np.cumsum(count) - count
    at = 8 * start[c] + (np.arange(sel.size) - start[c])
    owner = np.empty(8 * sel.size, dtype=np.int64)
    cells = np.empty((8 * sel.size, front.cells.shape[1]))
    parent_cells = front.cells[sel]
    for t in range(8):  # written in place: no (8 m, 4) temporaries besides the result
        owner[at] = 8 * c + t
        cells[at] = parent_cells
        at += count[c]
    level, ijk = split_boxes(front.level[cut], front.ijk[cut])
    return _Front(level, ijk, owner, cells)


def _test(geometry: Geometry, domain: np.ndarray, front: _Front,
          workers: Workers | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray, _Front]:
    """Test a front: (lo, hi, clear mask, the front with its cells updated); in parts on the workers."""
    lo, hi = box_bounds(domain, front.level, front.ijk)
    boxes = np.stack([lo, hi], axis=-1)
    workers = Workers(1) if workers is None else workers
    parts = workers.parts(len(boxes))
    calls = [(geometry, boxes[a:b], front.owner[ra:rb] - a, front.cells[ra:rb])
             for (a, b), (ra, rb) in zip(parts, owned_rows(front.owner, parts))]
    found = workers.run(live_cells, calls)
    owner = np.concatenate([o + a for (o, _), (a, _) in zip(found, parts)])
    cells = np.concatenate([c for _, c in found])
    clear = np.bincount(owner, minlength=len(front.level)) == 0
    return lo, hi, clear, _Front(front.level, front.ijk, owner, cells)


@dataclass
class _Leaves:
    """The leaves found so far; the undecided ones keep their live cells for later refinement."""

    parts: list = field(default_factory=list)

    def add(self, front: _Front, lo, hi, clear, keep) -> None:
        idx = np.flatnonzero(keep)
        pos = np.full(len(keep), -1)
        pos[idx] = np.arange(idx.size)
        sel = keep[front.owner]
        self.parts.append((front.level[keep], front.ijk[keep], lo[keep], hi[keep], clear[keep],
                           pos[front.owner[sel]], front.cells[sel]))

    def merge(self) -> tuple[np.ndarray, ...]:
        offs = np.cumsum([0] + [len(p[0]) for p in self.parts])
        cols = [np.concatenate([p[i] for p in self.parts]) for i in range(5)]
        owner = np.concatenate([p[5] + o for p, o in zip(self.parts, offs)])
        cells = np.concatenate([p[6] for p in self.parts])
        return (*cols, owner, cells)


def adaptive_leaves(geometry: Geometry, domain: np.ndarray, depth: int, progress: Callable[[dict], None] | None,
                    workers: Workers | None = None) -> tuple[_Leaves, list[dict]]:
    """Bisect the joint box, keeping clear boxes and splitting the others, down to ``depth``."""
    owner, cells = initial_cells(1)
    front = _Front(np.zeros(1, dtype=np.int64), np.zeros((1, 3), dtype=np.int64), owner, cells)
    leaves = _Leaves()
    stats: list[dict] = []
    dom_vol = float(np.prod(domain[:, 1] - domain[:, 0]))
    for lev in range(depth + 1):
        t0 = time.perf_counter()
        lo, hi, clear, front = _test(geometry, domain, front, workers)
        cut = ~clear if lev < depth else np.zeros(len(clear), dtype=bool)
        leaves.add(front, lo, hi, clear, ~cut)
        stats.append({"stage": "joint paving", "level": lev, "depth": depth, "boxes": int(len(clear)),
                      "split": int(np.count_nonzero(cut)), "live_cells": int(front.owner.size),
                      "seconds": time.perf_counter() - t0,
                      "undecided_volume": {"clear": dom_vol * 8.0 ** (-lev) * int(np.count_nonzero(~clear))}})
        if progress is not None:
            progress(stats[-1])
        if not np.any(cut):
            break
        front = _children(front, cut)
    return leaves, stats


def leaves_to_paving(domain: np.ndarray, leaves: tuple[np.ndarray, ...], stats: list[dict]) -> Paving:
    level, ijk, lo, hi, clear = leaves[:5]
    lab = np.where(clear, Label.INSIDE, Label.BOUNDARY).astype(np.uint8)
    return Paving(domain=domain, depth=int(level.max()), level=level.astype(np.int8), ijk=ijk, lo=lo, hi=hi,
                  labels={"clear": lab}, stats=stats)


def refine_leaves(geometry: Geometry, domain: np.ndarray, leaves: tuple[np.ndarray, ...], wall: np.ndarray,
                  workers: Workers | None = None):
    """Split the wall leaves once and test their children (inheriting the walls' live cells)."""
    level, ijk, lo, hi, clear, owner, cells = leaves
    sel = wall[owner]
    rank = np.cumsum(wall) - 1
    parents = _Front(level[wall], ijk[wall], rank[owner[sel]], cells[sel])
    out = _Leaves()
    keep = ~wall
    pos = np.full(len(keep), -1)
    pos[keep] = np.arange(np.count_nonzero(keep))
    out.parts.append((level[keep], ijk[keep], lo[keep], hi[keep], clear[keep], pos[owner[~sel]], cells[~sel]))
    # the children inherit their parents' cells eightfold: made and tested a batch of parents at a time, so
    # only one batch's inherited cells are in memory (each box's test is its own: the same leaves, in order)
    n = len(parents.level)
    batches = [(a, min(a + _BATCH, n)) for a in range(0, n, _BATCH)]
    for (a, b), (ra, rb) in zip(batches, owned_rows(parents.owner, batches)):
        batch = _Front(parents.level[a:b], parents.ijk[a:b], parents.owner[ra:rb] - a, parents.cells[ra:rb])
        front = _children(batch, np.ones(b - a, dtype=bool))
        clo, chi, cclear, front = _test(geometry, domain, front, workers)
        out.add(front, clo, chi, cclear, np.ones(len(cclear), dtype=bool))
    return out.merge()


def timed_step(progress, stats: list, store, stage: str, level: int, step: Callable, leaves, wall=None):
    """Run one refinement step; record (and report) the boxes it split and the volume left undecided.

    ``undecided_volume``: "clear" is the volume of the leaves not proved clear, "model" the
    part of it without a fold model either (what further local refinement would split).
    """
    t0 = time.perf_counter()
    out = step()
    vol = np.prod(out[3] - out[2], axis=1)
    open_ = ~out[4]
    unresolved = store.unresolved(out) if store is not None else open_
    st = {"stage": stage, "level": level, "depth": level, "seconds": time.perf_counter() - t0,
          "boxes": int(len(out[0])), "split": 0 if wall is None else int(np.count_nonzero(wall)),
          "undecided": int(np.count_nonzero(open_)),
          "undecided_volume": {"clear": float(vol[open_].sum()), "model": float(vol[unresolved].sum())}}
    stats.append(st)
    if progress is not None:
        progress(st)
    return out
