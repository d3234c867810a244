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
from dataclasses import dataclass

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.workers import Workers
from intervalkin.solve.window_fold import CLEAR, FOLD, WindowFolds, window_folds
from intervalkin.solve.window_count import window_signature
from intervalkin.solve.window_model import WindowModels, window_models

__all__ = ["JointWindows", "joint_windows"]


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
    """

    leaf: np.ndarray
    models: WindowModels
    seconds: float
    folds: WindowFolds | None = None

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


def _modelled(geometry: Geometry, boxes: np.ndarray) -> tuple[WindowModels, WindowFolds]:
    models = window_models(geometry, boxes)
    return models, window_folds(geometry, models)
