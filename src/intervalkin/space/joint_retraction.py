"""Retraction of the joint paving's open layer into its cells: the local step of an upper bound on the cells.

Fix a signature sigma = (count, n_wa1, n_wa2) and let U be the set of joint vectors of the joint box
whose direct kinematics has signature sigma.  The cells of the paving
(:mod:`intervalkin.space.joint_cells`) with signature sigma are connected subsets of U.  Each leaf's
part of U is covered by NODES, sets on which the signature is known at every point:

* a clear leaf: one node, its closed box;
* a fold box (:mod:`intervalkin.solve.fold_model`): the piece below the graph rho_k = h and the one above;
* a window-clear leaf or a window fold (:mod:`intervalkin.solve.window_fold`): its one or two pieces;
* a window-modelled leaf whose windows are pair windows (end signs and sign of D proved over the box:
  0 or 2 roots) besides windows of fixed count: one node per PATTERN, which pair windows hold their two roots;
* a leaf whose D-open window holds a zero phi_D of D (:mod:`intervalkin.solve.window_plane`): the same, with that
  window replaced by its two halves, once on each SIDE of the plane of double roots s(phi_D; rho^2) = 0 (a null
  set, in no node), each side's nodes retracting only along directions that keep it.
* any other leaf whose windows are all firm: one node per signature they allow, with no way out (it tells a
  neighbour of another signature that it need not wait, which a LEFT leaf cannot).

A node is a SINK when it lies in a counted cell (a clear leaf of it, or a piece joined to it).  A node
RETRACTS through face f of its leaf, of outward normal d e_l, when moving along d e_l keeps every point
of the node in it up to the face:

* a node of a clear leaf: through every face (the signature is the same on the whole box);
* the fold piece below: through the -e_k face; the piece above: through the +e_k face;
* a pattern node: along a direction e of :data:`DIRECTIONS`, through the faces on the sides of e's nonzero
  entries, when for each pair window i the sign of s D_e f at the roots of f on the window's critical pieces
  (:func:`~intervalkin.solve.window_fold.pair_direction_signs` with ``at_roots``) is +1 where the window is
  empty (u_i = min s f > 0 cannot reach 0) and -1 where it holds two roots (u_i < 0 cannot reach 0), or the
  window is STEADY (no root on any critical piece: u_i keeps its sign on the whole box); the other roots are the
  same on the whole box.

RANKS (a fixed point): a node is resolved at rank r >= 1 when, for some face f it retracts through that is not
on the border of the joint box, every leaf across f is modelled (no LEFT node of unknown signature) and
each of its nodes with the same signature is a sink or resolved at a rank below r (but for those on the other
side of the node's own plane, :mod:`intervalkin.space.retraction_ranks`).

Upper bound (proofs/lemma-joint-retraction.md): a point of U in a resolved node moves inside U to a face
point, which lies in a node of signature sigma of a leaf across that face, of lower rank; so every point of
U is joined inside U to a cell of signature sigma.  When every node is a sink or resolved, U has at most as
many components as the paving has counted cells of signature sigma, and the number of basic regions is at
most the sum of the cells' counts.  Certified: the nodes' sets come from the proved models (their
signatures are those the paving proved); the slopes are outward-rounded enclosures.  Leaves near a cusp
edge of g(S) (a window of one or three roots) but for one cusp window among windows of fixed count, windows
decided only at points that no plane explains, and leaves with no model are LEFT: they block every node that
would retract into them, so with any of them in the way no upper bound is claimed.
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.solve.window_cusp import cusp_retractions, cusp_windows
from intervalkin.solve.window_fold import (CLEAR, FOLD, PAIR, STEADY, base_signature, pair_direction_signs,
                                          pair_windows, window_kinds)
from intervalkin.solve.window_model import DET_SIGN
from intervalkin.solve.window_plane import split_at_zeros_of_d
from intervalkin.solve.window_union import joined_windows
from intervalkin.space.retraction_ranks import LEFT, RET, SINK, retraction_ranks

__all__ = ["SINK", "RET", "LEFT", "SOURCES", "MAX_ROOTS", "MAX_PAIR_WINDOWS", "JointRetraction", "retract_joint_paving"]

#: What a node is: a clear leaf, a fold piece, a window piece (window-clear leaf or window fold), a pattern of
#: pair windows, a side of a cusp window (one root or three), or a LEFT leaf with no model of its pieces (its
#: signature unknown).
SOURCES = ("clear", "fold_piece", "window_piece", "pair_pattern", "cusp_side", "signature_only", "no_piece_model")
#: f is a trigonometric polynomial of degree 3 (not identically 0): no joint vector has more solutions, so a
#: node (a pattern, a cusp side, a window fold's piece) that would hold more is empty and is dropped.
MAX_ROOTS = 6
#: Window-modelled leaves with more pair windows than this that may hold roots are LEFT (2**k patterns each).
MAX_PAIR_WINDOWS = 3
#: Halvings of the pair windows' critical pieces before their direction signs are read.  More come out free of
#: roots or with a proved direction, at a cost that grows with the joined sub-windows' many pieces: on the paper's
#: paving 40 005 leaves stay open at 1 (21 s), 37 304 at 2 (41 s).  The retraction runs in the paper run's
#: joint process, which the run waits for, so the cheaper setting is kept.
PAIR_HALVINGS = 1
_EACH_FACE = np.eye(6, dtype=bool)
#: Directions e (in rho) tried for the patterns of pair windows: integer vectors with entries in -2..2, not
#: multiples of one another, fewest nonzero entries first (a straight retraction along e leaves through one face
#: per nonzero entry, all of which must be resolved).
DIRECTIONS = np.array(sorted((e for e in itertools.product(range(-2, 3), repeat=3)
                              if any(e) and math.gcd(*e) == 1), key=lambda e: (sum(map(bool, e)), e)), dtype=np.int64)
#: Directions kept per node (the first that hold, fewest faces first).
MAX_OPTIONS = 8


@dataclass(frozen=True, eq=False)
class JointRetraction:
    """The nodes of a joint paving's leaves and their retraction ranks.

    leaf : (v,) int64, sorted: the leaf of each node.
    signature : (v, 3) int64, (count, n_wa1, n_wa2) at every point of the node; -1 for a LEFT node of
        unknown signature (it may hold points of any signature).
    kind : (v,) int8, SINK, RET or LEFT.
    source : (v,) int8, an index into :data:`SOURCES`.
    cell : (v,) int32, the counted cell of a sink, -1 for the others.
    option_node, option_faces : (o,) and (o, 6) bool, the ways RET nodes retract: every point of the node
        reaches one of the option's faces (face 2l: the -e_l side, 2l + 1: +e_l) along a path inside the node.
    rank : (v,) int32, 0 for sinks, r >= 1 for resolved RET nodes, -1 for the others.
    option_direction : (o, 3) float, the direction e in rho of a straight option (the segment from each point
        along e), zeros for a lifted path (:mod:`intervalkin.solve.window_cusp`).
    exit : (v,) int64, the option that ranked the node (an index into the option arrays), -1 elsewhere.
    side : (v,) int8, 0, or +-(k + 1) for a node of a leaf cut by the k-th plane of double roots
        (:mod:`intervalkin.solve.window_plane`): the node is the part of its pattern on the side s > 0 or s < 0.
    seconds : the time taken.
    """

    leaf: np.ndarray
    signature: np.ndarray
    kind: np.ndarray
    source: np.ndarray
    cell: np.ndarray
    option_node: np.ndarray
    option_faces: np.ndarray
    option_direction: np.ndarray
    rank: np.ndarray
    exit: np.ndarray
    side: np.ndarray
    seconds: float

    @property
    def unresolved(self) -> np.ndarray:
        """(v,) bool: the nodes that are neither sinks nor resolved (LEFT nodes included)."""
        return self.rank < 0

    def closed(self) -> bool:
        """Every node is a sink or resolved: every point off g(S) is joined to a counted cell of its signature."""
        return not self.unresolved.any()

    def leaves_left(self, n: int) -> np.ndarray:
        """(n,) bool over the paving's leaves: those holding an unresolved node."""
        out = np.zeros(n, dtype=bool)
        out[self.leaf[self.unresolved]] = True
        return out

    def to_json(self, volume: np.ndarray) -> dict:
        """Figures of the retraction for summary.json; ``volume`` (n,) the paving's leaf volumes."""
        left = self.unresolved
        by_source = {}
        for code, name in enumerate(SOURCES):
            at = self.source == code
            if at.any():
                leaves = np.unique(self.leaf[at & left])
                by_source[name] = {"nodes": int(at.sum()), "unresolved": int((at & left).sum()),
                                   "leaves_unresolved": int(leaves.size),
                                   "volume_unresolved": float(volume[leaves].sum())}
        leaves = np.unique(self.leaf[left])
        sided = self.side != 0
        plane_sides = {"nodes": int(sided.sum()), "unresolved": int((sided & left).sum()),
                       "leaves": int(np.unique(self.leaf[sided]).size),
                       "leaves_unresolved": int(np.unique(self.leaf[sided & left]).size)}
        return {"closed": self.closed(), "nodes": int(self.leaf.size), "sinks": int((self.kind == SINK).sum()),
                "resolved": int(((self.kind == RET) & ~left).sum()), "unresolved": int(left.sum()),
                "leaves_unresolved": int(leaves.size), "volume_unresolved": float(volume[leaves].sum()),
                "largest_rank": int(self.rank.max(initial=0)), "by_source": by_source, "plane_sides": plane_sides,
                "seconds": round(self.seconds, 2)}


def _faces_of_axis(rising: np.ndarray, towards: np.ndarray) -> np.ndarray:
    """(m, 6) bool: for each axis l with rising[:, l] != 0, the face on the side of sign towards * rising."""
    out = np.zeros((len(rising), 6), dtype=bool)
    for ax in range(3):
        d = rising[:, ax].astype(np.int64) * towards
        out[:, 2 * ax] = d < 0
        out[:, 2 * ax + 1] = d > 0
    return out


class _Nodes:
    """The node table, filled source by source; each node with its options, (k, 6) face masks."""

    def __init__(self):
        self.parts: list[tuple] = []

    def add(self, leaf, signature, kind, source, cell, options, directions=None, plane=None):
        """``plane``: (PlaneSplit, rows) when the nodes are those of window rows, some of them cut by a plane of
        double roots: those are added once per side, keeping only the straight options that keep the side."""
        leaf = np.asarray(leaf, dtype=np.int64)
        m = leaf.size
        kind = np.broadcast_to(np.asarray(kind, dtype=np.int8), (m,))
        cell = np.broadcast_to(np.asarray(cell, dtype=np.int32), (m,))
        options = np.asarray(options, dtype=bool)
        options = np.broadcast_to(options, (m,) + options.shape[-2:])
        if directions is None:  # one face: the straight segment along its outward normal; several: a lifted path
            one = options.sum(axis=2) == 1
            face = np.argmax(options, axis=2)
            directions = np.where(one[..., None], np.eye(3)[face // 2] * (2 * (face % 2) - 1)[..., None], 0.0)
        directions = np.broadcast_to(np.asarray(directions, dtype=np.float64), options.shape[:2] + (3,))
        signature = np.asarray(signature, dtype=np.int64).reshape(m, 3)
        side = np.zeros(m, dtype=np.int8)
        if plane is not None:
            split, rows = plane
            cut = split.plane[rows] != 0
            if cut.any():
                at = np.flatnonzero(cut)
                keep = [np.flatnonzero(~cut)] + [at, at]
                rising = split.rising[rows[at]].astype(np.int64)[:, None, :]
                masks = [options[~cut]]
                for towards in (1, -1):  # along e, s(phi_D; rho^2) never falls (rises) when every moving rho_l does
                    e = np.sign(directions[at]).astype(np.int64)
                    keeps = ((e == 0) | (e * rising * towards > 0)).all(axis=2) & (e != 0).any(axis=2)
                    masks.append(options[at] & keeps[..., None])
                order = np.concatenate(keep)
                side = np.concatenate([np.zeros(int((~cut).sum()), np.int8)]
                                      + [towards * split.plane[rows[at]] for towards in (1, -1)]).astype(np.int8)
                leaf, signature, kind, cell = leaf[order], signature[order], kind[order], cell[order]
                options, directions = np.concatenate(masks), directions[order]
        possible = signature[:, 0] <= MAX_ROOTS  # a node of more solutions than f has roots is empty
        self.parts.append((leaf[possible], signature[possible], kind[possible],
                           np.full(int(possible.sum()), source, dtype=np.int8), cell[possible], options[possible],
                           directions[possible], side[possible]))

    def table(self):
        """(leaf, signature, kind, source, cell, side) sorted by leaf, and the options (node, (o, 6) mask) of RET
        nodes."""
        cols = [np.concatenate([p[i] for p in self.parts]) for i in (0, 1, 2, 3, 4, 7)]
        order = np.argsort(cols[0], kind="stable")
        new = np.empty_like(order)
        new[order] = np.arange(order.size)
        opt_node, opt_mask, opt_dir, base = [], [], [], 0
        for part in self.parts:
            options = part[5]
            m = len(part[0])
            node, k = np.nonzero(options.any(axis=2) & (part[2] == RET)[:, None])
            opt_node.append(new[base + node])
            opt_mask.append(options[node, k])
            opt_dir.append(part[6][node, k])
            base += m
        return ([c[order] for c in cols], np.concatenate(opt_node), np.concatenate(opt_mask).reshape(-1, 6),
                np.concatenate(opt_dir).reshape(-1, 3))


def _direction_options(keeps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(m, MAX_OPTIONS, 6) options and (m, MAX_OPTIONS, 3) their directions from (m, c) bool, the directions of
    :data:`DIRECTIONS` that keep each node: the first MAX_OPTIONS, each with a face per nonzero entry, on its side."""
    faces = np.zeros((len(DIRECTIONS), 6), dtype=bool)
    for ax in range(3):
        faces[:, 2 * ax] = DIRECTIONS[:, ax] < 0
        faces[:, 2 * ax + 1] = DIRECTIONS[:, ax] > 0
    rank = np.where(keeps, np.arange(keeps.shape[1])[None, :], keeps.shape[1])
    first = np.sort(rank, axis=1)[:, :MAX_OPTIONS]
    out = np.zeros((len(keeps), first.shape[1], 6), dtype=bool)
    direction = np.zeros((len(keeps), first.shape[1], 3))
    held = first < keeps.shape[1]
    out[held] = faces[first[held]]
    direction[held] = DIRECTIONS[first[held]]
    return out, direction


def _single_faces(faces: np.ndarray) -> np.ndarray:
    """(m, 6, 6) options, one per face allowed in ``faces`` (m, 6): each its own face alone."""
    return np.asarray(faces, dtype=bool)[:, :, None] & np.eye(6, dtype=bool)[None]


def _cell_of_piece(piece_cell: np.ndarray, counted: int) -> np.ndarray:
    return np.where((piece_cell >= 0) & (piece_cell < counted), piece_cell, -1)


def _kind(cell: np.ndarray, signature: np.ndarray) -> np.ndarray:
    """SINK where joined to a counted cell, RET where the signature is known, LEFT elsewhere."""
    return np.where(cell >= 0, SINK, np.where(signature[:, 0] >= 0, RET, LEFT)).astype(np.int8)


def _clear_nodes(jp, nodes: _Nodes) -> None:
    every = jp.cells + jp.fragments
    sig = np.array([c.signature for c in every] or np.zeros((0, 3)), dtype=np.int64).reshape(-1, 3)
    leaf = np.flatnonzero(jp.cell >= 0)
    c = jp.cell[leaf].astype(np.int64)
    s = sig[c]
    cell = np.where(c < len(jp.cells), c, -1)
    nodes.add(leaf, s, _kind(cell, s), 0, cell, _EACH_FACE)


def _fold_nodes(jp, nodes: _Nodes) -> None:
    pieces, sigs = jp.pieces, jp.piece_signatures
    if pieces is None or not len(pieces) or sigs is None:
        return
    axis = pieces.models.axis.astype(np.int64)
    for side in (0, 1):  # below: towards -e_k; above: towards +e_k
        keep = sigs.empty != (-1 if side == 0 else 1)
        s = sigs.signature[keep, side]
        cell = _cell_of_piece(jp.piece_cell[2 * np.flatnonzero(keep) + side], len(jp.cells))
        faces = np.zeros((int(keep.sum()), 6), dtype=bool)
        faces[np.arange(faces.shape[0]), 2 * axis[keep] + side] = True
        nodes.add(pieces.box[keep], s, _kind(cell, s), 1, cell, faces[:, None, :])


def _window_nodes(jp, geometry: Geometry, nodes: _Nodes) -> np.ndarray:
    """Nodes of the window-modelled leaves; returns the rows left without nodes (their leaves are LEFT)."""
    win = jp.windows
    if win is None or win.folds is None:
        return np.zeros(0, dtype=np.int64)
    models, folds, counted = win.models, win.folds, len(jp.cells)
    for code, sides in ((CLEAR, (0,)), (FOLD, (0, 1))):
        rows = np.flatnonzero(folds.kind == code)
        for side in sides:
            s = folds.signature[rows, side]
            cell = _cell_of_piece(jp.window_cell[2 * rows + side], counted)
            options = (_EACH_FACE if code == CLEAR
                       else _single_faces(_faces_of_axis(folds.rising[rows], np.int64(1 - 2 * side))))
            nodes.add(win.leaf[rows], s, _kind(cell, s), 2, cell, options)
    # the other modelled rows, their runs of sub-windows joined (solve.window_union) and their D-open window cut
    # at the zero of D (solve.window_plane, nodes then on each side of the plane): windows of fixed count only,
    # one node for the whole leaf; pair windows besides them, a node per pattern
    split = split_at_zeros_of_d(geometry, joined_windows(models))
    models = split.models
    pair = pair_windows(models)
    box = models.window_box
    n = len(models.ok)
    constant = window_kinds(models)[3]
    only_pairs = np.bincount(box, weights=~pair & ~constant, minlength=n) == 0
    n_pair = np.bincount(box, weights=pair, minlength=n)
    open_rows = models.ok & ~np.isin(folds.kind, (CLEAR, FOLD))
    fixed = np.flatnonzero(open_rows & only_pairs & (n_pair == 0))
    base = base_signature(models)
    nodes.add(win.leaf[fixed], base[fixed], RET, 2, -1, _EACH_FACE, plane=(split, fixed))
    rows = np.flatnonzero(open_rows & only_pairs & (n_pair >= 1))
    if rows.size:
        signs, free = pair_direction_signs(geometry, models, rows, DIRECTIONS, halvings=PAIR_HALVINGS, at_roots=True)
        # a free window (no critical piece: u > 0 on the whole box) never holds roots and keeps every direction,
        # so only the others make patterns
        live = pair & ~free
        n_live = np.bincount(box, weights=live, minlength=n)
        rows = rows[n_live[rows] <= MAX_PAIR_WINDOWS]
        for k in range(0, MAX_PAIR_WINDOWS + 1):
            rk = rows[n_live[rows] == k]
            if not rk.size:
                continue
            wins = np.flatnonzero(live & np.isin(box, rk)).reshape(rk.size, k)  # windows are sorted by box
            for pattern in range(1 << k):
                real = np.array([(pattern >> i) & 1 for i in range(k)], dtype=np.int64)
                # u_i must not fall where window i is empty, not rise where it holds its two roots
                keeps = ((signs[wins] * (1 - 2 * real)[None, :, None] == 1) | (signs[wins] == STEADY)).all(axis=1)
                at = _within_rolle(split, constant, wins, real)
                nodes.add(win.leaf[rk[at]], base[rk[at]] + int(real.sum()) * PAIR, RET, 3, -1,
                          *_direction_options(keeps[at]), plane=(split, rk[at]))
    # one cusp window, the others of fixed count: a node for each side (one root, three roots), lifted paths
    cusp = cusp_windows(models)
    n_cusp = np.bincount(box, weights=cusp, minlength=n)
    others = np.bincount(box, weights=~cusp & ~constant, minlength=n) == 0
    crows = np.flatnonzero(open_rows & (n_cusp == 1) & others & (split.plane == 0))  # lifted paths may cross a plane
    if crows.size:
        lifted = cusp_retractions(geometry, models, crows)
        for side in (0, 1):
            nodes.add(win.leaf[crows], base[crows] + lifted.adds[:, side], RET, 4, -1, lifted.faces[:, side],
                      np.zeros(lifted.faces.shape[2:3] + (3,)))  # lifted paths, not segments
    done = np.isin(folds.kind, (CLEAR, FOLD))
    done[rows] = True
    done[fixed] = True
    done[crows] = True
    _signature_nodes(models, open_rows & ~done, base, nodes, win.leaf)
    done[open_rows & (np.bincount(box, weights=~window_kinds(models)[0], minlength=n) == 0)] = True
    return np.flatnonzero(~done)


def _signature_nodes(models, rows: np.ndarray, base: np.ndarray, nodes: _Nodes, leaf_of_row: np.ndarray) -> None:
    """Rows (n,) bool whose windows are all firm but fit no node above (a cusp window beside pair windows, more
    pair windows than MAX_PAIR_WINDOWS): one node per signature they allow, with no way out.  Each cusp window adds
    its one root (aspect by the crossing rule) and maybe a pair, each pair window maybe a pair; so the signatures
    are base + cusp roots + j PAIR, j = 0..(pair + cusp windows).  Never ranked, but a neighbour of another
    signature need not wait for them, as it must for a LEFT leaf."""
    firm, even, cusp, _ = window_kinds(models)
    box, n = models.window_box, len(models.ok)
    rows = np.flatnonzero(rows & (np.bincount(box, weights=~firm, minlength=n) == 0))
    if not rows.size:
        return
    ends = models.end_signs.astype(np.int64)
    det_pos = cusp & ((DET_SIGN * models.d_sign.astype(np.int64) * np.where(ends[:, 0] < 0, 1, -1)) > 0)
    root = np.stack([np.bincount(box, weights=w, minlength=n) for w in (cusp, det_pos, cusp & ~det_pos)],
                    axis=1).astype(np.int64)
    extra = np.bincount(box, weights=even | cusp, minlength=n).astype(np.int64)
    for j in range(int(extra[rows].max()) + 1):
        at = rows[extra[rows] >= j]
        nodes.add(leaf_of_row[at], base[at] + root[at] + j * PAIR, RET, 5, -1, np.zeros((1, 6), dtype=bool))


def _within_rolle(split, constant: np.ndarray, wins: np.ndarray, real: np.ndarray) -> np.ndarray:
    """(k,) bool over rows of live pair windows ``wins`` (k, c): the pattern ``real`` (c,) puts at most the whole
    window's degree in the two halves of each cut window (a half's twin: a live pair window, or one root)."""
    twin = split.twin[wins]
    twin_real = (twin[:, :, None] == wins[:, None, :]).astype(np.int64) @ real
    twin_fixed = np.where(twin >= 0, constant[np.maximum(twin, 0)], False)
    roots = 2 * real[None, :] + 2 * twin_real + twin_fixed
    return ((twin < 0) | (roots <= split.window_degree[wins])).all(axis=1)


def retract_joint_paving(jp, geometry: Geometry) -> JointRetraction:
    """The nodes of the leaves of ``jp`` (a :class:`~intervalkin.space.joint_paving.JointSpacePaving`) and
    their retraction ranks (module docstring)."""
    t0 = time.perf_counter()
    n = len(jp.cell)
    nodes = _Nodes()
    _clear_nodes(jp, nodes)
    _fold_nodes(jp, nodes)
    left_rows = _window_nodes(jp, geometry, nodes)
    covered = np.zeros(n, dtype=bool)
    for part in nodes.parts:
        covered[part[0]] = True
    if jp.windows is not None:
        covered[jp.windows.leaf[left_rows]] = False  # a window row without nodes: its leaf is LEFT
    left = np.flatnonzero(~covered)
    nodes.add(left, -np.ones((left.size, 3)), LEFT, len(SOURCES) - 1, -1, np.zeros((1, 6), dtype=bool))
    (leaf, sig, kind, source, cell, side), opt_node, opt_mask, opt_dir = nodes.table()
    rank, exit_ = retraction_ranks(jp.paving, leaf, sig, kind, opt_node, opt_mask, side)
    return JointRetraction(leaf, sig, kind, source, cell, opt_node, opt_mask, opt_dir, rank, exit_, side,
                           time.perf_counter() - t0)

