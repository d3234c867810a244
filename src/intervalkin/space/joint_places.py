"""The places a joint paving leaves open: where a hidden cell or a missing join could still be.

An *open leaf* is a leaf of the joint paving whose points do not all have a certified
signature: an undecided leaf without a local model, or a fold box one of whose pieces
has no known signature.  The open leaves fall into face-connected groups, the *places*;
each is reported with its bounding box, volume, number of leaves, the share of them
that have no model, and whether it touches a face of the joint box.  A place is where
an upper bound on the number of cells fails today: a cell could hide inside it, or two
cells could meet through it (issue 14).  Nothing here is a certified claim; it is the
exact list of what the certified labels do not cover.

Why a leaf has no model: the parametric Krawczyk test of its singular four-bar system
(:mod:`intervalkin.solve.fold_model`) failed for every axis.  Near a cusp edge of g(S) the
kernel of A becomes tangent to S and that system's Jacobian is singular for every axis;
where two sheets of g(S) cross, the live torus cells form two groups that are both
non-empty; both need models with more than one sheet (DESIGN.md section 8).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

from intervalkin.paving.adjacency import shares_face
from intervalkin.solve.window_fold import WHY_NOT

__all__ = ["OpenPlace", "open_leaves", "open_places", "place_labels", "leaf_reasons", "why_counts", "PLACES_LISTED", "WHY_OPEN", "REASONS"]

#: Why a leaf is open, as the ``places`` block of ``summary.json`` says it.
WHY_OPEN = ("no model of any kind (volume_without_model, without_model): the Krawczyk test of "
            "the singular four-bar system failed for every axis (near cusp edges and "
            "crossings of g(S)) and the window model failed too; or a window model "
            "(volume_window_model: a certified count at each point, but the leaf's pieces "
            "are not proved connected: a cusp window, several pair windows, or a slope "
            "sign not certified); or a fold box with a piece of unknown count; "
            "window-clear leaves and window folds (volume_window_pieces) are not open")
#: Why one open leaf is open, as each place's ``why`` counts them: no model of any kind; a window model whose
#: pieces are not proved connected, for the reason :data:`~intervalkin.solve.window_fold.WHY_NOT` gives; a fold
#: box one of whose pieces has no known count; anything else (none on the pavings measured).
REASONS = ("no_model", *WHY_NOT, "fold_piece_count", "other")
#: The largest places listed one by one (the totals cover all of them).
PLACES_LISTED = 40


@dataclass(frozen=True)
class OpenPlace:
    """A face-connected group of open leaves: bounding box (3, 2) lists, volume, leaves, how many lack a model,
    whether it touches a face of the joint box, its leaves and volume by reason, and its id (the ``open_place``
    column of ``pavings/joint.npz``)."""

    lo: tuple[float, float, float]
    hi: tuple[float, float, float]
    volume: float
    leaves: int
    without_model: int
    on_face: bool
    why: tuple[tuple[str, int, float], ...] = ()
    place: int = -1

    def to_json(self) -> dict:
        return {"place": self.place, "lo": list(self.lo), "hi": list(self.hi), "volume": self.volume,
                "leaves": self.leaves, "without_model": self.without_model, "on_face": self.on_face,
                "why": {name: {"leaves": k, "volume": v} for name, k, v in self.why}}


def why_counts(reason: np.ndarray, volume: np.ndarray) -> tuple[tuple[str, int, float], ...]:
    """(name, leaves, volume) per :data:`REASONS` entry present among leaves with codes ``reason``."""
    k = np.bincount(reason, minlength=len(REASONS))
    v = np.bincount(reason, weights=volume, minlength=len(REASONS))
    return tuple((REASONS[i], int(k[i]), float(v[i])) for i in np.flatnonzero(k).tolist())


def leaf_reasons(open_leaf: np.ndarray, no_model: np.ndarray, window_why: np.ndarray | None,
                 fold_box: np.ndarray) -> np.ndarray:
    """(n,) int8 per leaf: why an open leaf is open, an index into :data:`REASONS` (-1 for the other leaves).
    ``window_why``: the window models' reasons (:meth:`~intervalkin.space.joint_windows.JointWindows.why_not_pieced`,
    -1 where none), ``fold_box``: the fold boxes of the local models."""
    reason = np.full(open_leaf.shape, REASONS.index("other"), dtype=np.int8)
    reason[no_model] = REASONS.index("no_model")
    if window_why is not None:
        reason[window_why >= 0] = 1 + window_why[window_why >= 0]
    reason[fold_box] = REASONS.index("fold_piece_count")
    return np.where(open_leaf, reason, -1).astype(np.int8)


def open_leaves(jp) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """For a :class:`~intervalkin.space.joint_paving.JointSpacePaving`: (n,) masks of its open leaves, of those
    without a model of any kind and of the open window-modelled ones; and why each open leaf is open
    (:func:`leaf_reasons`)."""
    n = len(jp.cell)
    open_leaf = (jp.cell < 0) & ~jp.counted_fold_mask() & ~jp.pieced_mask()
    fold = np.zeros(n, dtype=bool)
    if jp.pieces is not None and len(jp.pieces):
        fold[jp.pieces.box] = True
    windowed = jp.windows.modelled_mask(n) if jp.windows is not None else np.zeros(n, dtype=bool)
    no_model = (jp.cell < 0) & ~fold & ~windowed
    why = jp.windows.why_not_pieced(n) if jp.windows is not None else None
    # a window-modelled leaf is open for the counts all the same: a point model proves no pieces
    return open_leaf, no_model, windowed & ~jp.pieced_mask(), leaf_reasons(open_leaf, no_model, why, fold)


def place_labels(level: np.ndarray, ijk: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                 open_leaf: np.ndarray) -> tuple[int, np.ndarray]:
    """(number of places, (n,) int32 place of each open leaf, -1 for the others).  Place 0 has the largest
    volume, then 1, and so on (ties by first leaf); the ``largest`` list of :func:`open_places` follows that order."""
    out = np.full(len(open_leaf), -1, dtype=np.int32)
    idx = np.flatnonzero(open_leaf)
    if idx.size == 0:
        return 0, out
    depth = int(np.asarray(level)[idx].max())
    e = shares_face(level[idx], ijk[idx], depth, periodic=(False, False, False))
    g = csr_matrix((np.ones(e.shape[1]), (e[0], e[1])), shape=(idx.size, idx.size))
    n, lab = connected_components(g, directed=False)
    total = np.bincount(lab, weights=np.prod(hi[idx] - lo[idx], axis=1), minlength=n)
    rank = np.empty(n, dtype=np.int32)
    rank[np.argsort(-total, kind="stable")] = np.arange(n, dtype=np.int32)
    out[idx] = rank[lab]
    return int(n), out


def open_places(level: np.ndarray, ijk: np.ndarray, lo: np.ndarray, hi: np.ndarray, open_leaf: np.ndarray,
                no_model: np.ndarray, domain: np.ndarray, reason: np.ndarray | None = None
                ) -> tuple[int, list[OpenPlace]]:
    """(number of places, the largest :data:`PLACES_LISTED` of them by volume).

    open_leaf (n,) bool: the open leaves; no_model (n,) bool: those without a local model; reason (n,) int: why
    each open leaf is open, an index into :data:`REASONS` (each place then counts its leaves and volume by reason).
    """
    idx = np.flatnonzero(open_leaf)
    if idx.size == 0:
        return 0, []
    n, place = place_labels(level, ijk, lo, hi, open_leaf)
    lab = place[idx]
    vol = np.prod(hi[idx] - lo[idx], axis=1)
    total = np.bincount(lab, weights=vol, minlength=n)
    top = np.arange(min(n, PLACES_LISTED))  # place ids run by decreasing volume
    out = []
    touch = ((lo[idx] <= domain[:, 0]) | (hi[idx] >= domain[:, 1])).any(axis=1)
    for c in top:
        m = lab == c
        why = () if reason is None else why_counts(np.asarray(reason)[idx][m], vol[m])
        out.append(OpenPlace(tuple(float(v) for v in lo[idx][m].min(axis=0)),
                             tuple(float(v) for v in hi[idx][m].max(axis=0)),
                             float(total[c]), int(m.sum()), int(np.count_nonzero(no_model[idx][m])),
                             bool(touch[m].any()), why, int(c)))
    return int(n), out
