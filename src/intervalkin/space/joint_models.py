"""The local models of the undecided leaves of a joint paving, computed once per leaf.

A joint paving re-labels its leaves several times (refinement of unresolved boxes,
faces, joins); each undecided leaf gets its model once (:func:`intervalkin.solve.local_model.local_models`):

* void: the Krawczyk exclusion proved that no singular pose has its joint vector in the
  leaf, so the leaf is clear and becomes a clear leaf of the paving;
* fold: one sheet of g(S) cuts the leaf into two connected pieces
  (:mod:`intervalkin.solve.fold_model`);
* unresolved: neither; such leaves are split further when the caller asks for it.

Leaves travel as the tuple (level, ijk, lo, hi, clear, owner, cells) of
:mod:`intervalkin.space.joint_paving`: owner/cells are the live torus cells of the
undecided leaves, sorted by owner.
"""

from __future__ import annotations

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.workers import Workers, owned_rows
from intervalkin.solve.fold_model import FoldModels
from intervalkin.solve.local_model import local_models
from intervalkin.space.joint_pieces import FoldPieces, fold_pieces

__all__ = ["ModelStore", "leaf_keys"]

Leaves = tuple[np.ndarray, ...]


def leaf_keys(level: np.ndarray, ijk: np.ndarray) -> np.ndarray:
    """One int64 key per leaf (level and integer position; positions below 2**16 per axis)."""
    ijk = np.asarray(ijk, dtype=np.int64)
    return (np.asarray(level, dtype=np.int64) << 48) | (ijk[:, 0] << 32) | (ijk[:, 1] << 16) | ijk[:, 2]


class ModelStore:
    """Local models of undecided leaves, keyed by leaf; void leaves are turned clear."""

    def __init__(self, geometry: Geometry, workers: Workers | None = None):
        self.geometry = geometry
        self.workers = Workers(1) if workers is None else workers
        self.keys = np.zeros(0, dtype=np.int64)
        self.models: FoldModels | None = None
        #: keys of the leaves proved clear by exclusion so far, and their volume
        self.void_keys = np.zeros(0, dtype=np.int64)
        self.void_volume = 0.0

    def settle(self, leaves: Leaves) -> Leaves:
        """Model every new undecided leaf; return the leaves with the void ones made clear (their cells dropped)."""
        level, ijk, lo, hi, clear, owner, cells = leaves
        und = np.flatnonzero(~clear)
        keys = leaf_keys(level[und], ijk[und])
        new = ~np.isin(keys, self.keys)
        if not new.any():
            return leaves
        fresh = und[new]
        pos = np.full(len(level), -1)
        pos[fresh] = np.arange(fresh.size)
        sel = pos[owner] >= 0
        boxes = np.stack([lo[fresh], hi[fresh]], axis=-1)
        m = self._local_models(boxes, pos[owner[sel]], cells[sel])
        self.models = m if self.models is None else self.models.concat(m)
        self.keys = np.concatenate([self.keys, keys[new]])
        gone = fresh[m.void]
        if gone.size == 0:
            return leaves
        self.void_keys = np.concatenate([self.void_keys, leaf_keys(level[gone], ijk[gone])])
        self.void_volume += float(np.prod(hi[gone] - lo[gone], axis=1).sum())
        clear = clear.copy()
        clear[gone] = True
        keep = ~np.isin(owner, gone)
        return level, ijk, lo, hi, clear, owner[keep], cells[keep]

    def _local_models(self, boxes: np.ndarray, owner: np.ndarray, cells: np.ndarray) -> FoldModels:
        """:func:`local_models` of the boxes, in contiguous parts on the workers (each box is modelled on its own)."""
        parts = self.workers.parts(len(boxes))
        calls = [(self.geometry, boxes[a:b], owner[ra:rb] - a, cells[ra:rb])
                 for (a, b), (ra, rb) in zip(parts, owned_rows(owner, parts))]
        out = self.workers.run(local_models, calls)
        models = out[0]
        for m in out[1:]:
            models = models.concat(m)
        return models

    def voided(self, level: np.ndarray, ijk: np.ndarray) -> np.ndarray:
        """(n,) bool: which of these leaves were proved clear by exclusion."""
        return np.isin(leaf_keys(level, ijk), self.void_keys)

    def rows(self, leaves: Leaves) -> np.ndarray:
        """(n,) the store row of each undecided leaf with a fold model, -1 elsewhere (leaves must be settled)."""
        level, ijk, clear = leaves[0], leaves[1], leaves[4]
        row = np.full(len(level), -1, dtype=np.int64)
        und = np.flatnonzero(~clear)
        if und.size == 0 or self.models is None:
            return row
        keys = leaf_keys(level[und], ijk[und])
        order = np.argsort(self.keys, kind="stable")
        at = np.searchsorted(self.keys[order], keys)
        at = order[np.minimum(at, order.size - 1)]
        found = self.keys[at] == keys
        row[und] = np.where(found & self.models.ok[at], at, -1)
        return row

    def unresolved(self, leaves: Leaves) -> np.ndarray:
        """(n,) bool: undecided leaves without a fold model."""
        return ~leaves[4] & (self.rows(leaves) < 0)

    def pieces(self, leaves: Leaves, face_edges: np.ndarray) -> FoldPieces | None:
        """The fold pieces of the settled leaves and their edges to the leaves around them."""
        row = self.rows(leaves)
        box = np.flatnonzero(row >= 0)
        if box.size == 0:
            return None
        level, ijk, lo, hi, clear = leaves[:5]
        return fold_pieces(self.geometry, lo, hi, clear, face_edges, box, self.models.take(row[box]), self.workers)
