"""Window models in the joint paving: certified counts at the points of leaves that have no other model.

A leaf of the joint paving that is neither clear (no cell) nor a fold box lies near a cusp
edge of g(S) or where two of its sheets cross.  :func:`joint_windows` gives such leaves
window models (:mod:`intervalkin.solve.window_model`, proofs/lemma-window-model.md): the
orientations where roots of the reduced equation may merge fall into windows holding at
most two or three of them, and the count and aspect split at any point of the leaf follow
from certified signs at that point.

What this adds, and what it does not: a point of a window-modelled leaf gets a certified
signature (``JointSpacePaving.signature_of``).  The leaf is not cut into proved connected
pieces, so it stays open for the counts of cells (``JointSpacePaving.open_places`` lists it,
and reports its volume apart from the leaves with no model of any kind).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.workers import Workers
from intervalkin.solve.window_fold import CLEAR, FOLD, WindowFolds, window_folds, why_not_pieced
from intervalkin.solve.window_count import window_signature
from intervalkin.solve.window_model import WindowModels, window_models
from intervalkin.space.joint_leaves import leaves_to_paving, refine_leaves, timed_step

__all__ = ["JointWindows", "joint_windows", "window_refinement", "WINDOW_LEVELS"]

#: Times a leaf whose window model fails is split and its children modelled again.
WINDOW_LEVELS = 2


@dataclass(frozen=True, eq=False)
class JointWindows:
    """The window models of a joint paving's leaves.

    Attributes
    ----------
    leaf : (k,) int64, sorted: the leaves that were given a window model to try (not clear, no fold model).
    models : the models, row j for leaf ``leaf[j]`` (``models.ok[j]``: modelled).
    seconds : the time spent building them.
    folds : which models prove the leaf off g(S) (window-clear) or cut by one monotone sheet
        into two connected pieces (window folds; :mod:`intervalkin.solve.window_fold`).
    split : leaves whose model failed and that were split, their children modelled in their place
        (:func:`window_refinement`).
    """

    leaf: np.ndarray
    models: WindowModels
    seconds: float
    folds: WindowFolds | None = None
    split: int = 0

    def without(self, drop: np.ndarray, renumber: np.ndarray) -> "JointWindows":
        """These rows less those marked ``drop`` (k,), their leaves renumbered by ``renumber`` (old -> new)."""
        rows = np.flatnonzero(~drop)
        folds = None if self.folds is None else self.folds.take(rows, self.models.window_renumber(rows))
        return JointWindows(renumber[self.leaf[rows]], self.models.take(rows), self.seconds, folds, self.split)

    def concat(self, other: "JointWindows") -> "JointWindows":
        """These rows followed by ``other``'s (whose leaves must all come after these)."""
        folds = None
        if self.folds is not None and other.folds is not None:
            folds = self.folds.concat(other.folds, len(self.models.degree))
        return JointWindows(np.concatenate([self.leaf, other.leaf]), self.models.concat(other.models),
                            self.seconds + other.seconds, folds, self.split + other.split)

    def pieced_mask(self, n: int) -> np.ndarray:
        """(n,) bool over the paving's leaves: the window-clear leaves and the window folds."""
        out = np.zeros(n, dtype=bool)
        if self.folds is not None:
            out[self.leaf[np.isin(self.folds.kind, (CLEAR, FOLD))]] = True
        return out

    def modelled_mask(self, n: int) -> np.ndarray:
        """(n,) bool over the paving's leaves: the leaves with a window model."""
        out = np.zeros(n, dtype=bool)
        out[self.leaf[self.models.ok]] = True
        return out

    def why_not_pieced(self, n: int) -> np.ndarray:
        """(n,) int8 over the paving's leaves: why a window-modelled leaf's pieces are not proved connected, an index
        into :data:`~intervalkin.solve.window_fold.WHY_NOT`; -1 for the other leaves."""
        out = np.full(n, -1, dtype=np.int8)
        if self.folds is not None:
            out[self.leaf] = why_not_pieced(self.models, self.folds)
        return out

    def signature_at(self, geometry: Geometry, leaf: np.ndarray, points: np.ndarray) -> np.ndarray:
        """(m, 3) certified (count, n_wa1, n_wa2) at points (m, 3) lying in the leaves ``leaf`` (m,);
        -1 where the leaf has no window model or the point's signs do not decide."""
        leaf = np.asarray(leaf, dtype=np.int64)
        out = np.full((len(leaf), 3), -1, dtype=np.int64)
        if len(self.leaf) == 0:
            return out
        row = np.minimum(np.searchsorted(self.leaf, leaf), len(self.leaf) - 1)
        has = np.flatnonzero(self.leaf[row] == leaf)
        if has.size:
            out[has] = window_signature(geometry, self.models, row[has], np.asarray(points, dtype=np.float64)[has])
        return out

    def stats(self, volume: np.ndarray) -> dict:
        """Figures: leaves tried and modelled, their volumes, windows by degree, seconds."""
        ok = self.models.ok
        return {"leaves_tried": int(len(self.leaf)), "leaves_modelled": int(ok.sum()),
                "volume_tried": float(volume[self.leaf].sum()), "volume_modelled": float(volume[self.leaf[ok]].sum()),
                "pair_windows": int(np.count_nonzero(self.models.degree == 2)),
                "triple_windows": int(np.count_nonzero(self.models.degree == 3)), "seconds": self.seconds,
                "leaves_split": self.split,
                **({} if self.folds is None else {
                    "window_clear": int(np.count_nonzero(self.folds.kind == CLEAR)),
                    "window_folds": int(np.count_nonzero(self.folds.kind == FOLD)),
                    "volume_pieced": float(volume[self.leaf[np.isin(self.folds.kind, (CLEAR, FOLD))]].sum())})}


def joint_windows(geometry: Geometry, lo: np.ndarray, hi: np.ndarray, no_model: np.ndarray,
                  workers: Workers | None = None) -> JointWindows:
    """Window models of the leaves ``no_model`` (n,) bool of a paving with leaf bounds lo, hi (n, 3);
    in parts on the workers (each box is modelled on its own)."""
    t0 = time.perf_counter()
    leaf = np.flatnonzero(no_model).astype(np.int64)
    boxes = np.stack([lo[leaf], hi[leaf]], axis=-1)
    workers = Workers(1) if workers is None else workers
    parts = workers.run(_modelled, [(geometry, boxes[a:b]) for a, b in workers.parts(len(boxes))])
    models, folds = parts[0]
    for m, f in parts[1:]:
        folds = folds.concat(f, len(models.degree))
        models = models.concat(m)
    return JointWindows(leaf, models, time.perf_counter() - t0, folds)


def window_refinement(geometry: Geometry, domain: np.ndarray, leaves, stats: list, store, progress, fine: int,
                      workers: Workers, levels: int = WINDOW_LEVELS):
    """Window models of the undecided leaves without a fold model, a leaf whose model fails split in eight
    (up to ``levels`` times): its children are tested, given local models and window models in its place.

    Near a cusp edge meeting another sheet of g(S) one leaf may hold more roots in play than a window
    bounds; its halves are smaller and are modelled.  Returns (leaves, paving, windows, finest level, made):
    ``made`` (n,) bool marks the leaves this step created, which must not start a cell (a clear child is an
    island inside the undecided layer, as those of the local refinement are).
    """
    paving = leaves_to_paving(domain, leaves, stats)
    found = joint_windows(geometry, paving.lo, paving.hi, store.unresolved(leaves), workers)
    made = np.zeros(len(paving), dtype=bool)
    for _ in range(levels):
        failed = np.zeros(len(paving), dtype=bool)
        failed[found.leaf[~found.models.ok]] = True
        if not failed.any():
            break
        # refine_leaves keeps the other leaves in their order and appends the children
        renumber, kept = np.cumsum(~failed) - 1, int(np.count_nonzero(~failed))
        leaves = timed_step(progress, stats, store, "window refinement", fine + 1,
                            lambda: store.settle(refine_leaves(geometry, domain, leaves, failed, workers)), leaves, failed)
        fine = max(fine, int(leaves[0].max()))
        paving = leaves_to_paving(domain, leaves, stats)
        children = np.zeros(len(paving), dtype=bool)
        children[kept:] = True
        made = np.r_[made[~failed], children[kept:]]
        more = joint_windows(geometry, paving.lo, paving.hi, children & store.unresolved(leaves), workers)
        found = found.without(failed[found.leaf], renumber).concat(replace(more, split=int(failed.sum())))
    return leaves, paving, found, fine, made


def _modelled(geometry: Geometry, boxes: np.ndarray) -> tuple[WindowModels, WindowFolds]:
    models = window_models(geometry, boxes)
    return models, window_folds(geometry, models)
