"""Local models of undecided joint boxes: clusters of live torus cells, each excluded or modelled.

The clear-box search (:mod:`intervalkin.solve.joint_box`) leaves, for a joint box R it
cannot clear, live cells of the torus (theta, phi) whose pose boxes hold every singular
pose X with g(X) in R.  Those cells often fall into several groups far apart on the
torus: one per sheet of g(S) near R, plus groups holding no singular pose at all that
the bisection budget did not discard.  One hull around all of them is a poor start for
a Krawczyk proof, so the cells are grouped (:func:`cluster_cells`) and each group's hull
gets its own proof (:func:`intervalkin.solve.fold_model.fold_models`):

* a group whose Krawczyk images have an empty intersection holds no singular pose;
* when every group is empty, R is clear (proved off g(S) by exclusion);
* when every group but one is empty and that one has a fold model, the model holds for
  R: all singular poses with joint vector in R lie in that group's pose box, which is
  all the model's argument needs (proofs/lemma-fold-joint-box.md).

Any grouping is sound (each hull holds the singular poses of its cells); the grouping by
contact on the torus only makes the hulls small.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import PI_LO, Interval
from intervalkin.solve.fold_model import FoldModels, fold_models, pose_hulls

__all__ = ["cluster_cells", "local_models", "MAX_GROUPED"]

#: Boxes with more live cells than this keep them in one group (the pairwise contact test is quadratic).
MAX_GROUPED = 96
#: Pairs of cells tested together.
_PAIRS = 1 << 16


def _touch(a: list[np.ndarray], b: list[np.ndarray]) -> np.ndarray:
    """Cells a and b, as columns [theta_lo, theta_hi, phi_lo, phi_hi] of (m,), share a point of the torus (closed cells)."""
    def axis(lo, hi):
        meet = (a[lo] <= b[hi]) & (b[lo] <= a[hi])
        # the cells tile [-pi, pi]: one ending at the upper seam touches one starting at the lower
        seam = ((a[hi] >= PI_LO) & (b[lo] <= -PI_LO)) | ((b[hi] >= PI_LO) & (a[lo] <= -PI_LO))
        return meet | seam
    return axis(0, 1) & axis(2, 3)


def cluster_cells(owner: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """(m,) group id of each live cell (ids 0..g-1, increasing with the owner; groups never span two owners).

    owner (m,) sorted; cells (m, 4).  Two cells of one owner are in one group when a chain
    of touching cells joins them; owners with more than :data:`MAX_GROUPED` cells form one group.
    """
    owner = np.asarray(owner, dtype=np.int64)
    m = owner.size
    if m == 0:
        return np.zeros(0, dtype=np.int64)
    starts = np.flatnonzero(np.r_[True, owner[1:] != owner[:-1]])
    counts = np.diff(np.r_[starts, m])
    rows, cols = [], []
    column = [np.ascontiguousarray(cells[:, c]) for c in range(4)]
    for n in np.unique(counts[(counts > 1) & (counts <= MAX_GROUPED)]):
        a, b = np.triu_indices(int(n), 1)
        every = starts[counts == n]
        per = max(1, _PAIRS // a.size)
        for s in range(0, every.size, per):  # cache-sized pieces of pairs
            first = every[s:s + per]
            ia = (first[:, None] + a[None, :]).ravel()
            ib = (first[:, None] + b[None, :]).ravel()
            hit = _touch([c[ia] for c in column], [c[ib] for c in column])
            rows.append(ia[hit])
            cols.append(ib[hit])
    big = np.flatnonzero(counts > MAX_GROUPED)
    for s in big:  # one chain through the box's cells: a single group
        rows.append(np.arange(starts[s], starts[s] + counts[s] - 1))
        cols.append(np.arange(starts[s] + 1, starts[s] + counts[s]))
    r = np.concatenate(rows) if rows else np.zeros(0, dtype=np.int64)
    c = np.concatenate(cols) if cols else np.zeros(0, dtype=np.int64)
    graph = csr_matrix((np.ones(r.size), (r, c)), shape=(m, m))
    _, lab = connected_components(graph, directed=False)
    # renumber by first cell, so ids increase with the owner
    first_at = np.full(lab.max() + 1, m)
    np.minimum.at(first_at, lab, np.arange(m))
    rank = np.argsort(np.argsort(first_at, kind="stable"), kind="stable")
    return rank[lab]


def local_models(geometry: Geometry, joint_boxes: np.ndarray, owner: np.ndarray,
                 cells: np.ndarray) -> FoldModels:
    """One :class:`FoldModels` row per joint box (n, 3, 2): ``void`` (clear by exclusion), a fold model, or neither.

    owner, cells : the live torus cells of the boxes (owner sorted).  A box with no live
    cell is not judged here (``void`` False, no model): the clear-box test has settled it.
    """
    n = len(joint_boxes)
    owner = np.asarray(owner, dtype=np.int64)
    group = cluster_cells(owner, cells)
    ng = int(group.max()) + 1 if group.size else 0
    group_box = np.zeros(ng, dtype=np.int64)
    group_box[group] = owner
    boxes = joint_boxes[group_box]
    order = np.argsort(group, kind="stable")  # pose_hulls takes the cells of one group as one run
    models = fold_models(geometry, boxes, pose_hulls(geometry, boxes, group[order], cells[order]))
    void = models.void
    open_groups = np.bincount(group_box, weights=~void, minlength=n)
    has_cells = np.bincount(owner, minlength=n) > 0
    box_void = has_cells & (open_groups == 0)
    # the one group left open, where there is exactly one
    pick = np.full(n, -1, dtype=np.int64)
    lone = np.flatnonzero(~void)
    pick[group_box[lone]] = lone
    single = has_cells & (open_groups == 1)
    rows = np.where(single, pick, 0)
    out = models.take(rows) if ng else _empty(n)
    ok = single & out.ok
    return FoldModels(ok, np.where(ok, out.axis, -1).astype(np.int8), out.pose, out.height, out.inv,
                      out.contraction, box_void)


def _empty(n: int) -> FoldModels:
    nan = np.full((n, 3, 2), np.nan)
    m33 = Interval(np.full((n, 3, 3), np.nan), np.full((n, 3, 3), np.nan))
    return FoldModels(np.zeros(n, dtype=bool), np.full(n, -1, dtype=np.int8), nan,
                      Interval(np.full(n, np.nan), np.full(n, np.nan)), np.full((n, 3, 3), np.nan), m33,
                      np.zeros(n, dtype=bool))
