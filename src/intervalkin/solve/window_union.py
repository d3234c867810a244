"""Sub-windows joined back into one window, with a degree bound by Rolle across the runs.

A window of :mod:`intervalkin.solve.window_model` whose 2nd and 3rd phi-derivatives of f have no one
sign over it is cut into runs (sub-windows, :func:`intervalkin.solve.window_split.sub_windows`) R_1..R_m,
f^(d_i) of one strict sign over R^2 x R_i.  The signs of f at the inner cuts are proved only at points,
which is enough to count roots at a point, not to say how the roots move across the box.  The union
U = R_1 + ... + R_m is itself a window with a bound on its roots:

    with j = min_i d_i,   #roots of f(.; r) in U  <=  j + sum_i (d_i - j)        (multiplicity counted)

for every r in R^2.  Proof: k roots in U give f^(j) at least k - j roots in U (Rolle, j times); on R_i,
f^(d_i) != 0 leaves f^(j) at most d_i - j roots (Rolle again, d_i >= j); summing over the runs bounds the
roots of f^(j) in U by sum_i (d_i - j).  So (3, 1) and (2, 3) runs bound U by 3, (2, 1) and (2, 2) by 2.
The end signs of U are those of its first and last run, certified over the box; with the sign of D the
same on every run, U is a firm window of that degree (proofs/lemma-window-model.md, the window's count
and the det A signs of its roots read as for any window whose roots are bounded by Rolle).

:func:`joined_windows` returns the models with every such union in place of its runs (degree the bound
above, when it is at most 3, or a larger ``max_degree``); the other windows are unchanged.  The retraction
of the open layer (:mod:`intervalkin.space.joint_retraction`) reads its pair and cusp windows from it (and
unions up to degree 4 and 6 where those leave a leaf without nodes); the certified counts at points keep the
runs (their inner cut signs decide more points).
"""

from __future__ import annotations

import numpy as np

from intervalkin.solve.window_model import WindowModels

__all__ = ["MAX_JOINED_DEGREE", "joined_degree", "joined_windows"]

#: Unions whose bound exceeds this keep their runs (the pair and cusp models need 2 or 3).
MAX_JOINED_DEGREE = 3


def joined_degree(degrees: np.ndarray, group: np.ndarray, groups: int) -> np.ndarray:
    """(groups,) the Rolle bound j + sum_i (d_i - j), j = min_i d_i, of each group of runs (module docstring)."""
    low = np.full(groups, np.iinfo(np.int64).max)
    np.minimum.at(low, group, degrees.astype(np.int64))
    total = np.bincount(group, weights=degrees, minlength=groups).astype(np.int64)
    size = np.bincount(group, minlength=groups)
    return low + total - size * low


def joined_windows(models: WindowModels, max_degree: int = MAX_JOINED_DEGREE) -> WindowModels:
    """The models with each run of sub-windows (linked by inner cuts, end sign 0) joined into one window when its
    degree bound is at most ``max_degree``, its outer end signs are certified and D has one sign on every run;
    the windows stay sorted by box, the pieces in circle order.  The bound holds whatever its size; the pair and
    cusp models read windows of degree 2 or 3 (the default), the signature-only nodes of the retraction take
    unions up to 6 (no joint vector has more roots)."""
    w = len(models.degree)
    if w == 0:
        return models
    box, ends = models.window_box, models.end_signs
    linked = np.r_[False, (ends[1:, 0] == 0) & (ends[:-1, 1] == 0) & (box[1:] == box[:-1])]
    group = np.cumsum(~linked) - 1
    groups = int(group[-1]) + 1
    first = np.flatnonzero(~linked)
    last = np.r_[first[1:] - 1, w - 1]
    size = last - first + 1
    degree = joined_degree(models.degree, group, groups)
    d_lo, d_hi = np.full(groups, 2), np.full(groups, -2)
    np.minimum.at(d_lo, group, models.d_sign.astype(np.int64))
    np.maximum.at(d_hi, group, models.d_sign.astype(np.int64))
    outer = np.stack([ends[first, 0], ends[last, 1]], axis=1)
    join = (size > 1) & (degree <= max_degree) & (d_lo == d_hi) & (d_lo != 0) & (outer != 0).all(axis=1)
    # a joined group becomes one window, every other window stays itself
    keep = ~join[group] | ~linked  # the first window of a joined group carries the union
    new_id = np.cumsum(keep) - 1
    rows = np.flatnonzero(keep)
    g = group[rows]
    joined = join[g]
    new_degree = np.where(joined, degree[g], models.degree[rows]).astype(np.int8)
    new_ends = np.where(joined[:, None], outer[g], ends[rows]).astype(np.int8)
    return WindowModels(models.boxes, models.ok, models.off, box[rows], new_degree, new_ends,
                        models.d_sign[rows], new_id[models.piece_window], models.piece_lo, models.piece_hi,
                        models.root_box, models.root_lo, models.root_hi)
