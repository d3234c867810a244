"""Joint space paved directly: adaptive boxes proved off g(S), and the cells they form.

The joint box [rho_min, rho_max]^3 is bisected level by level; a box is kept when
it is *clear* (:mod:`intervalkin.solve.joint_box`: no singular pose has its joint
vector in the box, so the box lies off g(S) and the solution count and aspect split
are constant on it) and split otherwise, down to ``depth``.  A box hands the cells
of the torus (theta, phi) that its test left live to its children, so each level
re-tests only what the level above could not settle.  Unlike the enclosure of g(S)
by images of workspace boxes (:mod:`intervalkin.space.joint_space`), the resolution
follows the singular surface itself.

Cells (:mod:`intervalkin.space.joint_cells`) are the face-connected components of
the clear boxes (no axis wraps).  A union of face-adjacent closed boxes is
connected and lies off g(S), so one certified solve at an exact rational point of
any of its boxes gives the count and split of the whole cell
(proofs/lemma-clear-joint-box.md, proofs/lemma-constant-count-off-gS.md).

Local models (:mod:`intervalkin.space.joint_models`, on by default): each undecided
leaf is proved clear by Krawczyk exclusion, or cut by one proved fold sheet into two
pieces that join the cells, or left unresolved; unresolved leaves are split
``model_levels`` more times.  Components made only by that local refinement, touching
no face of the joint box, are *fragments*: listed, not counted as cells.

Joins: an undecided box that touches two cells with the same count and split may
be a wall of the paving, not of g(S).  Such boxes are refined past the finest level
of the local refinement (up to ``join_levels`` more levels, only there); clear
sub-boxes that touch both cells join them, by the same face-adjacency argument.

Pieces joined to no cell still get a certified signature when the other piece of
their box has one: the side of the sheet on which the two extra solutions live is
proved at one sheet point (:mod:`intervalkin.solve.fold_side`), and a piece can be
proved empty.  A fold box counts as certified volume when each piece is known or empty.

Window models (:mod:`intervalkin.space.joint_windows`, with ``windows=True``): the undecided leaves left
without a fold model get a certified count at each of their points, proved at the point
(proofs/lemma-window-model.md).  Those whose model shows no sheet (window-clear) or one sheet along
which the model's minimum is monotone (window folds, proofs/lemma-window-fold.md) are cut into proved
pieces that join the piece graph (:mod:`intervalkin.space.joint_window_pieces`); the others stay open.

What is NOT claimed: two cells are not proved to be different components of the
joint box minus g(S) (they may still join through undecided boxes), and undecided
boxes may hide small cells.  Counting cells exactly needs a model for every
undecided box (cusps and crossings of g(S) have none yet; DESIGN.md section 8).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from intervalkin.core.errors import InputError
from intervalkin.core.exact import fraction_bounds
from intervalkin.core.geometry import Geometry
from intervalkin.core.workers import Workers, default_workers, one_blas_thread
from intervalkin.paving.budget import check_depth
from intervalkin.paving.tree import Paving
from intervalkin.solve.fold_side import placed_side
from intervalkin.space.joint_leaves import adaptive_leaves, leaves_to_paving, refine_leaves, timed_step
from intervalkin.space.joint_cells import CellSolver, JointSpaceCell, joining_paths
from intervalkin.space.joint_models import ModelStore
from intervalkin.space.joint_pieces import FoldPieces, PieceSignatures, piece_signatures
from intervalkin.space.joint_retraction import JointRetraction
from intervalkin.space.joint_places import WHY_OPEN, open_leaves, open_places, place_labels, why_counts
from intervalkin.space.joint_window_pieces import (check_window_cells, signatures_from_windows, window_cell_of,
                                                   window_columns, window_pieces)
from intervalkin.space.joint_windows import JointWindows, window_refinement
from intervalkin.space.joint_zones import RefinementZone

__all__ = ["JointSpaceCell", "JointSpacePaving", "pave_joint_space", "joint_domain", "DEFAULT_JOINT_DEPTH", "JOIN_LEVELS", "MODEL_LEVELS"]

#: Uniform levels of the joint paving by default (leaf width: the joint range / 64).
DEFAULT_JOINT_DEPTH = 6
#: Further levels, only in the walls between cells of equal count.
JOIN_LEVELS = 2
#: Further levels in the undecided boxes that touch a face of the joint box (where thin cells hug the limits).
FACE_LEVELS = 1
#: Further levels in the undecided boxes that local models could not settle (with ``fold``).
MODEL_LEVELS = 2


@dataclass(frozen=True, eq=False)
class JointSpacePaving:
    """The adaptive paving of the joint box and its cells.

    Attributes
    ----------
    paving : the boxes (rho_1, rho_2, rho_3) with label ``clear`` (INSIDE: proved
        off g(S); BOUNDARY: undecided at the deepest level or not yet split).
    cell : (n,) int32, the cell of each clear box, -1 for undecided boxes.
    cells : one :class:`JointSpaceCell` per cell, largest first.
    pieces, piece_cell : the fold boxes' pieces and the cell of each piece (-1: joined to none).
    fold_stats : figures of the local models (fold boxes, boxes proved clear by exclusion, ...).
    voided : (n,) bool, clear leaves proved clear by Krawczyk exclusion rather than by the torus search.
    fragments : components of certified boxes made only by the local refinement inside the
        undecided layer and touching no face of the joint box (islands near cusps and crossings
        of g(S)); each has a certified count and lies in some component of the joint box minus
        g(S), but it is not joined to one, so it is listed apart and not counted as a cell.  Their
        ids follow the cells' ids.
    piece_signatures : the certified signature of each fold piece, from its cell or inferred from
        the other piece of its box (:func:`intervalkin.space.joint_pieces.piece_signatures`).
    windows : window models of the undecided leaves without a fold model (near cusps and crossings
        of g(S); :mod:`intervalkin.space.joint_windows`): a certified signature at each of their points;
        the window-clear leaves and window folds among them are also cut into proved pieces.
    window_cell : (2 k,) the cell of each window piece (piece s of window row j at 2 j + s), -1 where none.
    retraction : the nodes of the leaves and their retraction ranks towards the cells, the local step of an
        upper bound (set by :func:`~intervalkin.space.joint_topology.pave_joint_topology`).
    """

    paving: Paving
    cell: np.ndarray
    cells: tuple[JointSpaceCell, ...]
    pieces: FoldPieces | None = None
    piece_cell: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int32))
    fold_stats: dict = field(default_factory=dict)
    voided: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))
    fragments: tuple[JointSpaceCell, ...] = ()
    piece_signatures: PieceSignatures | None = None
    windows: JointWindows | None = None
    window_cell: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int32))
    #: the open layer's retraction into the cells (:mod:`intervalkin.space.joint_retraction`), when computed
    retraction: JointRetraction | None = None

    def counted_fold_mask(self) -> np.ndarray:
        """(n,) bool: the leaves that are fold boxes each of whose pieces has a certified signature or is empty."""
        out = np.zeros(len(self.cell), dtype=bool)
        if self.pieces is not None and len(self.pieces) and self.piece_signatures is not None:
            out[self.pieces.box] = self.piece_signatures.counted()
        return out

    def open_places(self) -> dict:
        """What the paving leaves open (the ``undecided`` block of the counts it backs): the volume of undecided
        leaves, the certified share, the fragments, the fold pieces joined to no cell, and the places
        (face-connected groups of open leaves, :mod:`intervalkin.space.joint_places`), the largest listed."""
        fs = self.fold_stats
        open_leaf, no_model, windowed, reason = open_leaves(self)
        p = self.paving
        n, largest = open_places(p.level, p.ijk, p.lo, p.hi, open_leaf, no_model, p.domain, reason)
        return {"joint_volume": self.undecided_volume(), "joint_certified_share": self.certified_share(),
                "fragments": [{"count": c.count, "volume": c.volume, "witness": [str(v) for v in c.witness]}
                              for c in self.fragments],
                "unjoined_fold_pieces": {"groups": int(fs.get("unjoined_piece_groups", 0)),
                                         "volume": float(fs.get("unjoined_piece_volume", 0.0))},
                "places": {"count": n, "volume_without_model": float(p.volume()[no_model].sum()),
                           "volume_window_model": float(p.volume()[windowed].sum()),
                           "volume_window_pieces": float(p.volume()[self.pieced_mask()].sum()),
                           "why": WHY_OPEN,
                           "by_reason": {name: {"leaves": k, "volume": v} for name, k, v in
                                         why_counts(reason[open_leaf], p.volume()[open_leaf])},
                           "largest": [q.to_json() for q in largest]},
                **({} if self.retraction is None else {"retraction": self.retraction.to_json(p.volume())})}

    def pieced_mask(self) -> np.ndarray:
        """(n,) bool: window-clear leaves and window folds (their pieces' signatures are fixed by their models)."""
        if self.windows is None:
            return np.zeros(len(self.cell), dtype=bool)
        return self.windows.pieced_mask(len(self.cell))

    def undecided_volume(self) -> float:
        """Volume of the leaves that are neither clear, nor fold boxes with both pieces counted, nor window-pieced."""
        return float(self.paving.volume()[(self.cell < 0) & ~self.counted_fold_mask() & ~self.pieced_mask()].sum())

    def certified_share(self) -> float:
        """Share of the joint box whose count is certified: clear boxes, fold boxes (both pieces counted),
        window-clear leaves and window folds."""
        v = self.paving.volume()
        return float(v[(self.cell >= 0) | self.counted_fold_mask() | self.pieced_mask()].sum() / v.sum())

    def cell_of(self, rho: np.ndarray, geometry: Geometry | None = None) -> np.ndarray:
        """Cell id (m,) of each joint box or point rho (m, 3, 2) or (m, 3): the cell of the leaf that
        contains it entirely, -1 when that leaf is undecided or no single leaf contains it.

        With ``geometry``, a point in a fold box is placed in one of its two pieces by the
        side test (:func:`intervalkin.solve.fold_side.placed_side`) and gets that piece's cell.
        """
        q = np.asarray(rho, dtype=np.float64)
        boxes = np.stack([q, q], axis=-1) if q.ndim == 2 else q
        leaf = self.paving.locate_boxes(boxes)
        out = np.where(leaf >= 0, self.cell[np.maximum(leaf, 0)], -1)
        if geometry is None or q.ndim != 2:
            return out
        if self.pieces is None or not len(self.pieces):
            return self._window_cells(out, leaf, q, geometry)
        row = np.full(len(self.cell), -1, dtype=np.int64)
        row[self.pieces.box] = np.arange(len(self.pieces))
        t = np.where(leaf >= 0, row[np.maximum(leaf, 0)], -1)
        at = np.flatnonzero((out < 0) & (t >= 0))
        if at.size:
            side = placed_side(geometry, self.pieces.models, t[at], q[at])
            pc = self.piece_cell.reshape(-1, 2)[t[at], (side > 0).astype(np.int64)]
            out[at] = np.where(side != 0, pc, -1)
        return self._window_cells(out, leaf, q, geometry)

    def _window_cells(self, out: np.ndarray, leaf: np.ndarray, q: np.ndarray, geometry: Geometry) -> np.ndarray:
        at = np.flatnonzero((out < 0) & (leaf >= 0))
        if self.windows is not None and len(self.window_cell) and at.size:
            out[at] = window_cell_of(geometry, self.windows, self.window_cell, leaf[at], q[at])
        return out

    def signature_of(self, rho: np.ndarray, geometry: Geometry) -> np.ndarray:
        """(m, 3) certified (count, n_wa1, n_wa2) at joint vectors rho (m, 3), -1 where not known.

        A vector in a clear leaf takes its cell's signature; one in a fold box is placed in a
        piece by the side test and takes that piece's signature (from its cell, or inferred); one in
        a window-modelled leaf gets the signature its window model proves at it.
        """
        q = np.asarray(rho, dtype=np.float64)
        every = self.cells + self.fragments
        table = np.full((len(every) + 1, 3), -1, dtype=np.int64)  # row -1: no cell
        for c in every:
            table[c.id] = c.signature
        out = table[self.cell_of(q, geometry)]
        leaf = self.paving.locate_boxes(np.stack([q, q], axis=-1))
        if self.windows is not None:
            at = np.flatnonzero((out[:, 0] < 0) & (leaf >= 0))
            out[at] = self.windows.signature_at(geometry, leaf[at], q[at])
        if self.pieces is None or not len(self.pieces) or self.piece_signatures is None:
            return out
        row = np.full(len(self.cell), -1, dtype=np.int64)
        row[self.pieces.box] = np.arange(len(self.pieces))
        t = np.where(leaf >= 0, row[np.maximum(leaf, 0)], -1)
        at = np.flatnonzero((out[:, 0] < 0) & (t >= 0))
        if at.size:
            side = placed_side(geometry, self.pieces.models, t[at], q[at])
            sig = self.piece_signatures.signature[t[at], (side > 0).astype(np.int64)]
            out[at] = np.where((side != 0)[:, None], sig, -1)
        return out

    def columns(self) -> dict[str, np.ndarray]:
        """npz columns: lo, hi, level, cell id, count, n_wa1, n_wa2 (-1 where undecided); and for fold
        boxes: fold_axis (the axis k of the sheet, -1 elsewhere), cell_below and cell_above (the cells of
        the pieces q_k < h and q_k > h, -1 elsewhere or unknown), count_below and count_above (their
        certified counts, inferred where the piece has no cell; -1 where unknown); window-clear leaves
        and window folds likewise (:func:`intervalkin.space.joint_window_pieces.window_columns`); for the open
        leaves, open_reason (an index into :data:`~intervalkin.space.joint_places.REASONS`) and open_place (the
        place's id, by decreasing volume, as ``summary.json`` lists places); -1 for the other leaves."""
        count = np.full(len(self.cell), -1, dtype=np.int32)
        wa1, wa2 = count.copy(), count.copy()
        for c in self.cells + self.fragments:
            m = self.cell == c.id
            count[m], wa1[m], wa2[m] = c.count, c.n_wa1, c.n_wa2
        axis, below, above = count.copy(), count.copy(), count.copy()
        n_below, n_above = count.copy(), count.copy()
        if self.pieces is not None and len(self.pieces):
            pc = self.piece_cell.reshape(-1, 2)
            axis[self.pieces.box] = self.pieces.models.axis
            below[self.pieces.box], above[self.pieces.box] = pc[:, 0], pc[:, 1]
            if self.piece_signatures is not None:
                n_below[self.pieces.box] = self.piece_signatures.signature[:, 0, 0]
                n_above[self.pieces.box] = self.piece_signatures.signature[:, 1, 0]
        open_leaf, _, _, reason = open_leaves(self)
        p = self.paving
        cols = {"lo": p.lo, "hi": p.hi, "level": p.level.astype(np.int32),
                "cell": self.cell.astype(np.int32), "count": count, "n_wa1": wa1, "n_wa2": wa2,
                "fold_axis": axis, "cell_below": below, "cell_above": above,
                "count_below": n_below, "count_above": n_above, "open_reason": reason,
                "open_place": place_labels(p.level, p.ijk, p.lo, p.hi, open_leaf)[1]}
        return cols if self.windows is None else window_columns(cols, self.windows, self.window_cell)


def joint_domain(geometry: Geometry) -> np.ndarray:
    """The joint box, rounded outward to floats: (3, 2) [rho_min_i, rho_max_i]."""
    return np.array([[fraction_bounds(lo)[0], fraction_bounds(hi)[1]]
                     for lo, hi in zip(geometry.rho_min, geometry.rho_max)], dtype=np.float64)


def pave_joint_space(geometry: Geometry, depth: int = DEFAULT_JOINT_DEPTH, join_levels: int = JOIN_LEVELS,
                     progress: Callable[[dict], None] | None = None, fold: bool = True,
                     face_levels: int = FACE_LEVELS, model_levels: int = MODEL_LEVELS,
                     windows: bool = False, workers: int | None = None,
                     zone: RefinementZone | None = None) -> JointSpacePaving:
    """Pave the joint box to ``depth`` with the clear-box test, join cells across walls, and count them.

    Parameters
    ----------
    depth : levels of uniform refinement of the undecided boxes (leaf width: the joint
        range / 2**depth); 1..11, memory checked before any work.
    join_levels : further levels (past the finest level of the local refinement), only in
        undecided boxes that separate two cells of equal count and split (0: no joins).
    fold : give the undecided leaves local models (:mod:`intervalkin.solve.local_model`):
        leaves proved free of singular poses by Krawczyk exclusion become clear, leaves cut
        by one proved fold sheet get two pieces that join the cells and count as certified
        volume.  On the paper's manipulator at depth 6: 97 % of the joint box certified with
        one model level, 99.3 % with two (76 % without models).
    face_levels : further levels in the undecided leaves that touch a face of the joint box.
    model_levels : with ``fold``, further levels in the leaves left without a model (split,
        re-tested, modelled again), the last step of the local refinement.
    windows : with ``fold``, give the leaves left without a model window models
        (:mod:`intervalkin.space.joint_windows`): certified counts at their points, and proved
        pieces for the window-clear leaves and window folds among them.  On the paper's manipulator
        at the default depth: all of them once the 13 whose model fails are split (window_refinement);
        off by default here, on in ``analyze``/``paper`` at full depth.
    workers : processes (default: two on a machine with two cores or more, see
        :func:`intervalkin.core.workers.default_workers`); large steps are cut into parts
        computed at once, and the paving is the same bit for bit whatever the number.
    zone : undecided leaves inside its boxes are split ``zone.levels`` more times after the face levels
        (:mod:`intervalkin.space.joint_zones`: where the separations found two cells joined).

    Cost: the undecided boxes lie along the 2-D surface g(S), so their number grows
    like 4**depth; each cell costs one certified solve.
    """
    check_depth(depth)
    for name, v in (("join_levels", join_levels), ("face_levels", face_levels), ("model_levels", model_levels)):
        if isinstance(v, bool) or not isinstance(v, int) or not 0 <= v <= 8:
            raise InputError(f"{name}: expected an integer in 0..8, got {v!r}")
    if zone is not None and zone.depth != depth:
        raise InputError(f"zone: its boxes are of level {zone.depth}, the paving's uniform level is {depth}")
    count = default_workers() if workers is None else workers
    if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= 64:
        raise InputError(f"workers: expected an integer in 1..64, got {workers!r}")
    with Workers(count) as pool, one_blas_thread():
        if depth >= DEFAULT_JOINT_DEPTH:  # large enough to use them: started while this process is small
            pool.start()
        return _pave(geometry, depth, join_levels, progress, fold, face_levels, model_levels, windows, pool, zone)


def _pave(geometry: Geometry, depth: int, join_levels: int, progress, fold: bool, face_levels: int,
          model_levels: int, windows: bool, pool: Workers, zone=None) -> JointSpacePaving:
    domain = joint_domain(geometry)
    found_leaves, stats = adaptive_leaves(geometry, domain, depth, progress, pool)
    leaves = found_leaves.merge()
    store = ModelStore(geometry, pool) if fold else None
    settle = (lambda lv: store.settle(lv)) if store is not None else (lambda lv: lv)
    leaves = timed_step(progress, stats, store, "local models", depth, lambda: settle(leaves), leaves)
    for extra in range(model_levels if store is not None else 0):
        wall = store.unresolved(leaves) & (leaves[0] >= depth + extra)
        if not np.any(wall):
            break
        leaves = timed_step(progress, stats, store, "local refinement", depth + extra + 1,
                        lambda: settle(refine_leaves(geometry, domain, leaves, wall, pool)), leaves, wall)
    for extra in range(face_levels):
        # thin cells hug the faces rho_i = rho_min / rho_max: refine the undecided leaves that touch one
        level, lo, hi, clear = leaves[0], leaves[2], leaves[3], leaves[4]
        touch = ((lo <= domain[:, 0]) | (hi >= domain[:, 1])).any(axis=1)
        wall = ~clear & touch & (level >= depth + extra)
        if not np.any(wall):
            break
        leaves = timed_step(progress, stats, store, "faces", depth + extra + 1,
                        lambda: settle(refine_leaves(geometry, domain, leaves, wall, pool)), leaves, wall)
    for _ in range(zone.levels if zone is not None else 0):  # where the separations asked for finer leaves
        wall = ~leaves[4] & zone.holds(leaves[0], leaves[1])
        if not np.any(wall):
            break
        leaves = timed_step(progress, stats, store, "zone", int(leaves[0][wall].max()) + 1,
                            lambda: settle(refine_leaves(geometry, domain, leaves, wall, pool)), leaves, wall)
    fine = top = int(leaves[0].max())
    cells = CellSolver(geometry)

    def anchor(lv):  # boxes of the uniform paving and of the face refinement may start a cell
        touch = ((lv[2] <= domain[:, 0]) | (lv[3] >= domain[:, 1])).any(axis=1)
        return (lv[0] <= depth) | touch

    for extra in range(join_levels + 1):
        paving = leaves_to_paving(domain, leaves, stats)
        cell, found, _, _ = cells.label(paving, fine, anchor=anchor(leaves))
        if extra == join_levels:
            break
        # walls as fine as the local refinement made them may still be split join_levels times
        wall = joining_paths(cells.edges, cell, found) & (paving.level < top + join_levels)
        if not np.any(wall):
            break
        leaves = timed_step(progress, stats, store, "joins", depth + extra + 1,
                        lambda: settle(refine_leaves(geometry, domain, leaves, wall, pool)), leaves, wall)
        fine = max(fine, int(leaves[0].max()))
    pieces, piece_cell, fold_stats, signatures = None, np.zeros(0, dtype=np.int32), {}, None
    found_windows, window_cell = None, np.zeros(0, dtype=np.int32)
    if store is not None:
        t0 = time.perf_counter()
        paving = leaves_to_paving(domain, leaves, stats)
        wins = None
        if windows:
            leaves, paving, found_windows, fine, made = window_refinement(geometry, domain, leaves, stats, store,
                                                                           progress, fine, pool)
            if progress is not None:
                progress({"stage": "window models", "level": fine, "depth": fine, "boxes": len(found_windows.leaf),
                          "split": 0, "cells": 0})

            def wins(e, fp):
                return window_pieces(geometry, paving.lo, paving.hi, leaves[4], e, fp, found_windows, pool)
        starts = anchor(leaves) & ~made if windows else anchor(leaves)
        labelled = cells.label(paving, fine, lambda e: store.pieces(leaves, e), starts, wins)
        cell, found, pieces, piece_cell = labelled
        window_cell = cells.window_cell
        unjoined = cells.unjoined
        signatures = None
        every = {c.id: c.signature for c in found}
        if found_windows is not None:
            check_window_cells(window_cell, found_windows, every)
        if pieces is not None:
            from_cells = np.array([every.get(int(c), (-1, -1, -1)) for c in piece_cell], dtype=np.int64)
            if found_windows is not None and cells.window_pieces is not None:
                near = signatures_from_windows(cells.window_pieces, found_windows, len(paving), len(pieces))
                both = (from_cells[:, 0] >= 0) & (near[:, 0] >= 0)
                if np.any(both & (from_cells != near).any(axis=1)):
                    raise AssertionError("a fold piece's cell and its window neighbour disagree (unsound)")
                from_cells = np.where(from_cells[:, :1] >= 0, from_cells, near)
            signatures = piece_signatures(geometry, paving.lo, paving.hi, pieces, from_cells.reshape(-1, 3), pool)
        fold_stats = {"fold_boxes": 0 if pieces is None else len(pieces), "seconds": time.perf_counter() - t0,
                      "void_boxes": int(store.void_keys.size), "void_volume": store.void_volume,
                      "unjoined_piece_groups": unjoined[0], "unjoined_piece_volume": unjoined[1],
                      "inferred_piece_signatures": 0 if signatures is None else signatures.inferred,
                      "empty_pieces": 0 if signatures is None else int(np.count_nonzero(signatures.empty))}
        if found_windows is not None:
            fold_stats["windows"] = found_windows.stats(paving.volume())
        if progress is not None:
            progress({"stage": "fold pieces", "level": fine, "depth": fine,
                      "boxes": fold_stats["fold_boxes"], "split": 0, "cells": len(found)})
    voided = store.voided(paving.level, paving.ijk) if store is not None else np.zeros(len(cell), dtype=bool)
    return JointSpacePaving(paving, cell, tuple(c for c in found if not c.fragment), pieces, piece_cell,
                            fold_stats, voided, tuple(c for c in found if c.fragment), signatures, found_windows,
                            window_cell)
