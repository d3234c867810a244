"""The nodes of the joint retraction: which sets cover each leaf's part of a signature, and their ways out.

:func:`~intervalkin.space.joint_retraction.retract_joint_paving` ranks them; this module builds them, one
source at a time (clear leaves, fold pieces, window pieces, patterns of pair windows, cusp sides, cusp sides beside
pair windows, signature-only leaves).  Each node carries its OPTIONS, (k, 6) masks of the faces a straight segment (or a lifted path) from any
of its points reaches while keeping the node's signature, with the direction it moves along; what makes an option
certified is stated at each builder and proved in proofs/lemma-joint-retraction.md.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.workers import Workers
from intervalkin.solve.cusp_flow import flow_ways, inflection_flows
from intervalkin.solve.fold_model import height_slopes
from intervalkin.solve.window_cusp import (cusp_adds, cusp_direction_signs, cusp_retractions, cusp_retractions_where,
                                          cusp_windows, lifted_pair_signs)
from intervalkin.solve.window_fold import (CLEAR, FOLD, PAIR, STEADY, base_signature, pair_direction_signs,
                                          pair_windows, window_kinds)
from intervalkin.solve.window_model import DET_SIGN
from intervalkin.solve.window_patterns import curved_keeps, pattern_keeps, patterns
from intervalkin.solve.window_plane import split_at_zeros_of_d
from intervalkin.solve.window_union import joined_windows
from intervalkin.space.retraction_ranks import LEFT, RET, SINK

__all__ = ["Nodes", "MAX_ROOTS", "MAX_PAIR_WINDOWS", "PAIR_HALVINGS", "DIRECTIONS", "MAX_OPTIONS", "EACH_FACE",
           "clear_nodes", "fold_nodes", "window_nodes"]

#: f is a trigonometric polynomial of degree 3 (not identically 0): no joint vector has more solutions, so a
#: node (a pattern, a cusp side, a window fold's piece) that would hold more is empty and is dropped.
MAX_ROOTS = 6
#: Window-modelled leaves with more live pair windows than this get signature-only nodes (2**k patterns each; a pattern
#: of more than MAX_ROOTS roots is empty and dropped; 3 -> 6 left 431 fewer leaves open on the paper's paving).
MAX_PAIR_WINDOWS = 6
#: Halvings of the pair windows' critical pieces before their direction signs are read.  More come out free of
#: roots or with a proved direction, at a cost that grows with the joined sub-windows' many pieces: on the paper's
#: paving 40 005 leaves stay open at 1 (21 s), 37 304 at 2 (41 s).  The retraction runs in the paper run's
#: joint process, which the run waits for, so the cheaper setting is kept.
PAIR_HALVINGS = 1
EACH_FACE = np.eye(6, dtype=bool)
#: Directions e (in rho) tried for the patterns of pair windows: integer vectors with entries in -2..2, not
#: multiples of one another, fewest nonzero entries first (a straight retraction along e leaves through one face
#: per nonzero entry, all of which must be resolved).
DIRECTIONS = np.array(sorted((e for e in itertools.product(range(-2, 3), repeat=3)
                              if any(e) and math.gcd(*e) == 1), key=lambda e: (sum(map(bool, e)), e)), dtype=np.int64)
#: Directions kept per node (the first that hold, fewest faces first).
MAX_OPTIONS = 8



def _faces_of_axis(rising: np.ndarray, towards: np.ndarray) -> np.ndarray:
    """(m, 6) bool: for each axis l with rising[:, l] != 0, the face on the side of sign towards * rising."""
    out = np.zeros((len(rising), 6), dtype=bool)
    for ax in range(3):
        d = rising[:, ax].astype(np.int64) * towards
        out[:, 2 * ax] = d < 0
        out[:, 2 * ax + 1] = d > 0
    return out


class Nodes:
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


def clear_nodes(jp, nodes: Nodes) -> None:
    every = jp.cells + jp.fragments
    sig = np.array([c.signature for c in every] or np.zeros((0, 3)), dtype=np.int64).reshape(-1, 3)
    leaf = np.flatnonzero(jp.cell >= 0)
    c = jp.cell[leaf].astype(np.int64)
    s = sig[c]
    cell = np.where(c < len(jp.cells), c, -1)
    nodes.add(leaf, s, _kind(cell, s), 0, cell, EACH_FACE)


def fold_nodes(jp, geometry: Geometry, nodes: Nodes) -> None:
    """The two pieces of each fold box.  The piece below (rho_k < h) leaves through its -e_k face, the piece
    above through its +e_k face; and where the slope dh/dr_l of the sheet is proved over the box
    (:func:`~intervalkin.solve.fold_model.height_slopes`) also sideways: the piece below along the direction in which h rises, the piece above
    along the one in which it falls (rho_k stays fixed, so it stays on its side of the graph)."""
    pieces, sigs = jp.pieces, jp.piece_signatures
    if pieces is None or not len(pieces) or sigs is None:
        return
    axis = pieces.models.axis.astype(np.int64)
    slope = height_slopes(geometry, pieces.models)
    for side in (0, 1):  # below: towards -e_k; above: towards +e_k
        keep = sigs.empty != (-1 if side == 0 else 1)
        s = sigs.signature[keep, side]
        cell = _cell_of_piece(jp.piece_cell[2 * np.flatnonzero(keep) + side], len(jp.cells))
        faces = _faces_of_axis(slope[keep], np.int64(1 - 2 * side))
        faces[np.arange(faces.shape[0]), 2 * axis[keep] + side] = True
        nodes.add(pieces.box[keep], s, _kind(cell, s), 1, cell, _single_faces(faces))


def window_nodes(jp, geometry: Geometry, nodes: Nodes, workers: Workers | None = None) -> np.ndarray:
    """Nodes of the window-modelled leaves; returns the rows left without nodes (their leaves are LEFT).
    ``workers`` share the direction signs of the pair windows (most of the time)."""
    win = jp.windows
    if win is None or win.folds is None:
        return np.zeros(0, dtype=np.int64)
    models, folds, counted = win.models, win.folds, len(jp.cells)
    for code, sides in ((CLEAR, (0,)), (FOLD, (0, 1))):
        rows = np.flatnonzero(folds.kind == code)
        for side in sides:
            s = folds.signature[rows, side]
            cell = _cell_of_piece(jp.window_cell[2 * rows + side], counted)
            options = (EACH_FACE if code == CLEAR
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
    nodes.add(win.leaf[fixed], base[fixed], RET, 2, -1, EACH_FACE, plane=(split, fixed))
    rows = np.flatnonzero(open_rows & only_pairs & (n_pair >= 1))
    # one cusp window, pair windows and windows of fixed count besides it: a node per pattern and cusp side
    cusp = cusp_windows(models)
    with_cusp = np.flatnonzero(open_rows & (n_pair >= 1) & (np.bincount(box, weights=cusp, minlength=n) == 1)
                               & (np.bincount(box, weights=~pair & ~constant & ~cusp, minlength=n) == 0))
    cusp_rows = np.zeros(0, dtype=np.int64)
    if rows.size or with_cusp.size:
        # each window's signs come from its own box: the pattern rows' are those they would have alone
        signs, free = pair_direction_signs(geometry, models, np.union1d(rows, with_cusp), DIRECTIONS,
                                           halvings=PAIR_HALVINGS, at_roots=True, workers=workers)
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
            for real in patterns(k):
                keeps = pattern_keeps(signs[wins], real)
                at = _within_rolle(split, constant, wins, real)
                nodes.add(win.leaf[rk[at]], base[rk[at]] + int(real.sum()) * PAIR, RET, 3, -1,
                          *_direction_options(keeps[at]), plane=(split, rk[at]))
        cusp_rows = _cusp_pattern_nodes(geometry, models, split, with_cusp, live, signs, nodes, win.leaf, workers)
    # one cusp window, the others of fixed count: a node for each side (one root, three roots), lifted paths (not
    # where a plane cuts the leaf: they may cross it)
    crows = _cusp_nodes(geometry, models, open_rows & (split.plane == 0), nodes, win.leaf, workers)
    done = np.isin(folds.kind, (CLEAR, FOLD))
    done[rows] = True
    done[fixed] = True
    done[crows] = True
    done[cusp_rows] = True
    # runs of sub-windows whose Rolle bound is 4 with end signs that differ hold one or three roots: cusp windows too
    done[_cusp_nodes(geometry, joined_windows(win.models, max_degree=4), open_rows & ~done, nodes, win.leaf,
                     workers)] = True
    done |= _signature_nodes(models, open_rows & ~done, nodes, win.leaf)
    # the rows left have a window decided only at points (a run of sub-windows whose Rolle bound exceeds 3): the
    # same runs joined up to degree 6 give them signatures too
    done |= _signature_nodes(joined_windows(win.models, max_degree=MAX_ROOTS), open_rows & ~done, nodes, win.leaf)
    return np.flatnonzero(~done)


def _cusp_nodes(geometry: Geometry, models, rows: np.ndarray, nodes: Nodes, leaf_of_row: np.ndarray,
                workers: Workers | None = None) -> np.ndarray:
    """The nodes of the rows (n,) bool with one cusp window and all their other windows of fixed count (one root
    each): each side (one root, three roots) with its lifted paths, and the straight directions along which only
    pairs die (the one-root side) or are born (the three-root side) at the window's double roots; returns the
    rows given nodes.  ``workers`` share the straight directions' signs."""
    cusp = cusp_windows(models)
    box, n = models.window_box, len(models.ok)
    constant = window_kinds(models)[3]
    n_cusp = np.bincount(box, weights=cusp, minlength=n)
    others = np.bincount(box, weights=~cusp & ~constant, minlength=n) == 0
    crows = np.flatnonzero(rows & (n_cusp == 1) & others)
    if crows.size:
        base = base_signature(models)
        lifted = cusp_retractions(geometry, models, crows)
        flows = inflection_flows(geometry, models, crows)
        signs = cusp_direction_signs(geometry, models, crows, DIRECTIONS, workers)[lifted.window]
        for side, keeps in ((0, 1), (1, -1)):
            straight, direction = _direction_options((signs == keeps) | (signs == STEADY))
            options = np.concatenate([lifted.faces[:, side], flows[:, side], straight], axis=1)
            curved = lifted.faces.shape[2] + flows.shape[2]
            # lifted paths and inflection flows have no direction: they are not segments
            directions = np.concatenate([np.zeros((crows.size, curved, 3)), direction], axis=1)
            nodes.add(leaf_of_row[crows], base[crows] + lifted.adds[:, side], RET, 4, -1, options, directions)
    return crows


def _cusp_pattern_nodes(geometry: Geometry, models, split, rows: np.ndarray, live: np.ndarray, pair_signs: np.ndarray,
                        nodes: Nodes, leaf_of_row: np.ndarray, workers: Workers | None = None) -> np.ndarray:
    """The nodes of the rows (m,) with one cusp window, pair windows and windows of fixed count: one per pattern of
    the live pair windows (``live``, their signs ``pair_signs``) and side of the cusp window (one root, three roots);
    returns the rows given nodes (those with at most MAX_PAIR_WINDOWS live pair windows).

    Each window's roots stay in its own arc of phi, so a straight segment keeps such a node when it keeps every
    window's part: each pair window its pattern (as for the pattern nodes), the cusp window its side (the straight
    ways of :func:`~intervalkin.solve.window_cusp.cusp_direction_signs`: +1 keeps the one-root side, -1 the
    three-root side, STEADY both), the windows of fixed count their one root whatever the segment.  A lifted path of
    the cusp window (:func:`~intervalkin.solve.window_cusp.cusp_retractions`) keeps the node when it also keeps each
    pair window's pattern: r moves with velocity d (u - q v), and s D_u f - q s D_v f is signed on the window's
    critical pieces for every q of the way (:func:`~intervalkin.solve.window_cusp.lifted_pair_signs`); a side
    proved empty keeps its (empty) node along any face.  The inflection flow of the cusp window
    (:func:`~intervalkin.solve.cusp_flow.flow_ways`) has the same form, r' = |V_i| d (u - q v), so it keeps the node
    on the same terms (lemma "Cusp patterns: the inflection flow").  Curved ways are not used where a plane cuts
    the leaf: they may cross it."""
    box, n = models.window_box, len(models.ok)
    n_live = np.bincount(box, weights=live, minlength=n)
    rows = rows[n_live[rows] <= MAX_PAIR_WINDOWS]
    if not rows.size:
        return rows
    base = base_signature(models)
    constant = window_kinds(models)[3]
    cusp = np.flatnonzero(cusp_windows(models) & np.isin(box, rows))  # one per row, in row order
    side_signs = cusp_direction_signs(geometry, models, rows, DIRECTIONS, workers)[cusp]
    adds = cusp_adds(models, cusp)
    # only leaves no plane cuts can use lifted ways (Nodes.add keeps segments alone on the others)
    lifted = cusp_retractions_where(geometry, models, rows, cusp, split.plane[rows] == 0)
    ways = lifted.faces.shape[2]
    # the ways of both sides at once, side-major: (rows, 2 ways, 3) and (rows, 2 ways)
    way_signs = lifted_pair_signs(geometry, models, rows, np.concatenate([lifted.drive_u] * 2, axis=1),
                                  np.concatenate([lifted.follow_v] * 2, axis=1), lifted.follow_lo.reshape(rows.size, -1),
                                  lifted.follow_hi.reshape(rows.size, -1), PAIR_HALVINGS)
    uncut = split.plane[rows] == 0
    flows = flow_ways(geometry, models, rows)  # both sides share u, v and q; only the drive's sign differs
    go = flows.drive.any(axis=(1, 2)) & uncut
    flow_signs = lifted_pair_signs(geometry, models, rows[go], flows.drive_u[go], flows.follow_v[go],
                                   flows.follow_lo[go], flows.follow_hi[go], PAIR_HALVINGS)
    for k in range(MAX_PAIR_WINDOWS + 1):  # k = 0: every pair window free of roots, the cusp window alone
        pick = np.flatnonzero(n_live[rows] == k)
        if not pick.size:
            continue
        rk = rows[pick]
        wins = np.flatnonzero(live & np.isin(box, rk)).reshape(rk.size, k)
        for real in patterns(k):
            keeps = pattern_keeps(pair_signs[wins], real)
            at = _within_rolle(split, constant, wins, real)
            for side, want in ((0, 1), (1, -1)):
                both = keeps & ((side_signs[pick] == want) | (side_signs[pick] == STEADY))
                straight, direction = _direction_options(both[at])
                steady = (pair_signs[wins[at]][:, :, :1] == STEADY)
                faces = [w.faces[pick[at], side] & uncut[pick[at], None, None] for w in (lifted, flows)]
                curved = [curved_keeps(w.drive[pick[at], side], s[wins[at]], f, steady, real) for w, s, f
                          in zip((lifted, flows), (way_signs[:, side * ways:(side + 1) * ways], flow_signs), faces)]
                options = np.concatenate([straight] + curved, axis=1)
                directions = np.concatenate([direction, np.zeros((len(options), sum(c.shape[1] for c in curved), 3))], axis=1)
                nodes.add(leaf_of_row[rk[at]], base[rk[at]] + int(real.sum()) * PAIR + adds[pick[at], side], RET, 7,
                          -1, options, directions, plane=(split, rk[at]))
    return rows


def _signature_nodes(models, rows: np.ndarray, nodes: Nodes, leaf_of_row: np.ndarray) -> np.ndarray:
    """Rows (n,) bool whose windows are all firm but fit no node above (two cusp windows, more live pair windows
    than MAX_PAIR_WINDOWS, a union of degree 4 to 6): one node per signature they allow, with no way
    out; returns the rows given nodes.  A firm window of degree d holds at most d roots (Rolle); they alternate
    in the sign of f', and D has one sign on it, so their det A signs alternate too.  Ends that differ: an odd
    number, the first and the last crossing as the ends say (one root of the aspect of the crossing rule, and
    pairs); equal ends: pairs of one root of each aspect.  So the signatures are off + the crossing roots
    + j PAIR, j = 0..sum of (d - odd) // 2 over the windows.  Never ranked, but a neighbour of another signature
    need not wait for them, as it must for a LEFT leaf."""
    firm, even, _, _ = window_kinds(models)
    box, n = models.window_box, len(models.ok)
    rows = np.flatnonzero(rows & (np.bincount(box, weights=~firm, minlength=n) == 0))
    if not rows.size:
        return np.zeros(n, dtype=bool)
    ends = models.end_signs.astype(np.int64)
    odd = firm & ~even
    det_pos = odd & ((DET_SIGN * models.d_sign.astype(np.int64) * np.where(ends[:, 0] < 0, 1, -1)) > 0)
    root = np.stack([np.bincount(box, weights=w, minlength=n) for w in (odd, det_pos, odd & ~det_pos)],
                    axis=1).astype(np.int64)
    pairs = np.where(firm, (models.degree.astype(np.int64) - odd) // 2, 0)
    extra = np.bincount(box, weights=pairs, minlength=n).astype(np.int64)
    fixed = models.off.astype(np.int64) + root
    for j in range(int(extra[rows].max()) + 1):
        at = rows[(extra[rows] >= j) & (fixed[rows, 0] + 2 * j <= MAX_ROOTS)]
        nodes.add(leaf_of_row[at], fixed[at] + j * PAIR, RET, 5, -1, np.zeros((1, 6), dtype=bool))
    out = np.zeros(n, dtype=bool)
    out[rows] = True
    return out


def _within_rolle(split, constant: np.ndarray, wins: np.ndarray, real: np.ndarray) -> np.ndarray:
    """(k,) bool over rows of live pair windows ``wins`` (k, c): the pattern ``real`` (c,) puts at most the whole
    window's degree in the two halves of each cut window (a half's twin: a live pair window, or one root)."""
    twin = split.twin[wins]
    twin_real = (twin[:, :, None] == wins[:, None, :]).astype(np.int64) @ real
    twin_fixed = np.where(twin >= 0, constant[np.maximum(twin, 0)], False)
    roots = 2 * real[None, :] + 2 * twin_real + twin_fixed
    return ((twin < 0) | (roots <= split.window_degree[wins])).all(axis=1)
