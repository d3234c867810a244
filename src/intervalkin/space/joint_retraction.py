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
* a leaf with one cusp window beside pair windows (and windows of fixed count): one node per pattern and side of
  the cusp window, retracting along the straight directions that keep both (source ``cusp_pattern``).
* any other leaf whose windows are all firm: one node per signature they allow, with no way out (it tells a
  neighbour of another signature that it need not wait, which a LEFT leaf cannot).

A node is a SINK when it lies in a counted cell (a clear leaf of it, or a piece joined to it).  A node
RETRACTS through face f of its leaf, of outward normal d e_l, when moving along d e_l keeps every point
of the node in it up to the face:

* a node of a clear leaf: through every face (the signature is the same on the whole box);
* the fold piece below: through the -e_k face; the piece above: through the +e_k face; and sideways through
  the e_l face on the side where the sheet's height h rises (below) or falls (above), when dh/dr_l is proved;
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

import time
from dataclasses import dataclass

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.workers import Workers
from intervalkin.space.retraction_nodes import MAX_PAIR_WINDOWS, MAX_ROOTS, Nodes, clear_nodes, fold_nodes, window_nodes
from intervalkin.space.retraction_ranks import LEFT, RET, SINK, retraction_ranks

__all__ = ["SINK", "RET", "LEFT", "SOURCES", "MAX_ROOTS", "MAX_PAIR_WINDOWS", "JointRetraction", "retract_joint_paving"]

#: What a node is, in order: a clear leaf, a fold piece, a window piece (window-clear leaf or window fold), a pattern
#: of pair windows, a side of a cusp window (one root or three), a signature of a leaf whose windows fit no other
#: node, a LEFT leaf with no model of its pieces (its signature unknown), a side of a cusp window beside pair windows
#: (added last, so the earlier indices keep their meaning).  The builders of :mod:`intervalkin.space.retraction_nodes`
#: pass their index.
SOURCES = ("clear", "fold_piece", "window_piece", "pair_pattern", "cusp_side", "signature_only", "no_piece_model",
           "cusp_pattern")


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


def retract_joint_paving(jp, geometry: Geometry, workers: Workers | None = None) -> JointRetraction:
    """The nodes of the leaves of ``jp`` (a :class:`~intervalkin.space.joint_paving.JointSpacePaving`) and
    their retraction ranks (module docstring); ``workers``: processes sharing the window nodes' direction signs."""
    t0 = time.perf_counter()
    n = len(jp.cell)
    nodes = Nodes()
    clear_nodes(jp, nodes)
    fold_nodes(jp, geometry, nodes)
    left_rows = window_nodes(jp, geometry, nodes, workers)
    covered = np.zeros(n, dtype=bool)
    for part in nodes.parts:
        covered[part[0]] = True
    if jp.windows is not None:
        covered[jp.windows.leaf[left_rows]] = False  # a window row without nodes: its leaf is LEFT
    left = np.flatnonzero(~covered)
    nodes.add(left, -np.ones((left.size, 3)), LEFT, SOURCES.index("no_piece_model"), -1, np.zeros((1, 6), dtype=bool))
    (leaf, sig, kind, source, cell, side), opt_node, opt_mask, opt_dir = nodes.table()
    rank, exit_ = retraction_ranks(jp.paving, leaf, sig, kind, opt_node, opt_mask, side)
    return JointRetraction(leaf, sig, kind, source, cell, opt_node, opt_mask, opt_dir, rank, exit_, side,
                           time.perf_counter() - t0)

