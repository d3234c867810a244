"""The number of aspects, bounded from both sides: each sign's part of W minus {det A = 0}, its components counted.

For a sign s let S_s = {X in W : s det A(X) > 0} (WA1 for s = +1, WA2 for s = -1).
The aspects are the connected components of S_+ and of S_-, so

    number of aspects = c(S_+) + c(S_-),   c = number of connected components.

:func:`prove_aspects` builds, for each sign, a COVER of the paving domain by octree
boxes (integer coordinates, as in :mod:`intervalkin.paving.tree`), each box one of

* OUT: certified free of S_s (one constraint certified violated on the box, or a
  nonnegative combination of the constraints certified negative);
* SINK: certified inside S_s; the sinks form face-connected GROUPS (few: one per
  component of S_s when the proof closes);
* RET(e): the retraction condition of :mod:`intervalkin.space.aspect_retraction`
  holds along e, and every box across an exit face of e is OUT, a SINK, or a RET
  box of lower rank (the ranks make the chains acyclic);
* LEFT: none of these could be proved (reported: location and volume).

Upper bound (proofs/lemma-aspect-retraction.md): with no LEFT box, every point of
S_s is joined inside S_s to a group of sinks, each of which is connected: S_s has at
most as many components as there are groups.  An IN box that is not a sink needs no
condition of its own (every direction retracts it), so small fragments of IN boxes
are joined to the sinks through their exit faces.

Lower bound (same lemma, "Separations"): the closed boxes that are not OUT hold all
of S_s; the components of their union (boxes meeting at a face, an edge or a corner,
phi wrapping) are disjoint closed PIECES, so each piece holding a sink holds its own
components of S_s.  When every group of sinks lies in its own piece, the count of
each sign is exact, whatever it is (the second design, examples/second_design_0246.toml,
has two components of each sign: 4 aspects).

How the cover is built: boxes are split top-down while neither OUT, IN nor
retractable (up to ``start_depth``); then ranks are computed by a fixed point over
the face adjacency (a worklist: each rank looks only at the boxes beside those
resolved at the rank before); clusters of unresolved boxes get one shared direction
(corners of S_s), again while a pass resolves an eighth of what is left.  What one group of sinks cannot
reach is resolved with more groups (the largest unreached fragment of IN boxes first,
up to MAX_GROUPS); where two groups share a piece, the boxes the first group could not
reach are refined while that joins groups, then the boxes where the groups' regions
meet and those a float screen finds free of S_s (a cut by OUT boxes is found there;
the screen only chooses what to split).  Refinement goes up to ``max_depth``.  Only
these boxes are refined, so the cover stays small (about 20 000 boxes per sign for the
paper's manipulator, where the depth-8 paving has millions): the independent checker
re-proves every box of it in arb.  Cost on the paper's manipulator: about 1 s per sign.
"""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.status import Count
from intervalkin.paving.adjacency import component_labels
from intervalkin.paving.tree import box_bounds, split_boxes, workspace_paving_domain
from intervalkin.space.aspect_cover_graph import (LEFT, OUT, RET, SINK, between_groups, face_pairs, resolve_cover,
                                                  separations)
from intervalkin.space.aspect_retraction import (DIRECTIONS, approx_free_of_aspect, classify_boxes, exit_faces,
                                                shared_directions)

__all__ = ["OUT", "SINK", "RET", "LEFT", "AspectCover", "AspectTopology", "face_pairs", "resolve_cover",
           "separations", "cover_aspect", "prove_aspects"]

#: Refinement rounds of the unresolved boxes (each one splits them once).
MAX_ROUNDS = 12
#: No refinement round that would take a cover past this many boxes (what is unresolved then is reported).
MAX_BOXES = 200_000
#: Passes of shared directions per round: a cluster's direction is averaged over all its boxes; once part of
#: it is resolved, the rest (often one corner of S) gets a direction of its own.
SHARE_PASSES = 4
#: Share again only when the last pass resolved at least this fraction of the boxes left.
SHARE_GAIN = 0.125
#: Most groups of sinks a cover may use when one group cannot be reached from everywhere.
MAX_GROUPS = 8


@dataclass(frozen=True, eq=False)
class AspectCover:
    """A cover of the paving domain for one sign of det A (module docstring).

    ``level`` (n,), ``ijk`` (n, 3): the boxes; ``kind`` (n,): OUT, SINK, RET or LEFT;
    ``direction`` (n, 3) int: e = (a, b, c / PHI_DIVISOR) of RET boxes (0 elsewhere);
    ``weights`` (n, 7) int: on OUT boxes proved by a combination sum_j w_j f_j < 0 of the seven
    constraints, its weights (0 elsewhere; None: no such box);
    ``rank`` (n,): 0 for OUT and SINK, the step at which a RET box was resolved, -1 for LEFT.
    ``fragments``: face-connected components of IN boxes (before the joins by retraction).
    ``groups``: face-connected groups of sinks (each is connected; every point reaches one).
    ``separated``: components of the union of the closed non-OUT boxes (boxes meeting at a face, an
    edge or a corner; phi wraps) that hold a sink: S_s has at least that many components.
    ``connected``: no LEFT box and one group of sinks: S_s is proved nonempty and connected.
    ``empty``: every box is OUT: S_s is proved empty.
    """

    sign: int
    domain: np.ndarray
    level: np.ndarray
    ijk: np.ndarray
    kind: np.ndarray
    direction: np.ndarray
    rank: np.ndarray
    fragments: int
    groups: int
    separated: int
    seconds: float
    weights: np.ndarray | None = None

    @property
    def closed(self) -> bool:
        """No LEFT box: every point of S_s reaches a group of sinks, so S_s has at most ``groups`` components."""
        return not np.any(self.kind == LEFT)

    @property
    def components_at_most(self) -> int | None:
        """The proved upper bound on the number of components of S_s (None: the cover is open)."""
        return self.groups if self.closed else None

    @property
    def components_at_least(self) -> int:
        """The proved lower bound on the number of components of S_s: the sinks lie in S_s, and the OUT boxes,
        free of it, split the rest of the domain into ``separated`` pieces that each hold a sink."""
        return self.separated

    @property
    def exact(self) -> bool:
        """The number of components of S_s is proved: the cover is closed and each group of sinks is cut off
        from the others by OUT boxes."""
        return self.closed and self.separated == self.groups

    @property
    def connected(self) -> bool:
        return self.closed and self.groups == 1

    @property
    def empty(self) -> bool:
        return bool(np.all(self.kind == OUT))

    def boxes(self, mask: np.ndarray | None = None) -> np.ndarray:
        """Float boxes (m, 3, 2) of the selected cover boxes (all when ``mask`` is None)."""
        sel = slice(None) if mask is None else mask
        lo, hi = box_bounds(self.domain, self.level[sel], self.ijk[sel])
        return np.stack([lo, hi], axis=-1)

    def leftovers(self) -> list[dict]:
        """The LEFT boxes: where the proof did not close (box bounds and volume)."""
        b = self.boxes(self.kind == LEFT)
        return [{"box": bb.tolist(), "volume": float(np.prod(bb[:, 1] - bb[:, 0]))} for bb in b]

    def to_json(self) -> dict:
        kinds = {name: int(np.count_nonzero(self.kind == v)) for name, v in
                 (("out", OUT), ("sink", SINK), ("retract", RET), ("left", LEFT))}
        kinds["out_by_combination"] = 0 if self.weights is None else int(np.count_nonzero(np.any(self.weights > 0, 1)))
        return {"sign": self.sign, "boxes": int(len(self.level)), "kinds": kinds, "inside_fragments": self.fragments,
                "sink_groups": self.groups, "components_at_most": self.components_at_most,
                "components_at_least": self.components_at_least, "connected": self.connected, "empty": self.empty,
                "deepest_level": int(self.level.max()),
                "longest_chain": int(self.rank.max()), "seconds": round(self.seconds, 3),
                "leftovers": self.leftovers()[:20]}


@dataclass(frozen=True, eq=False)
class AspectTopology:
    """Both covers and the upper bound they prove on the number of aspects (None: not proved)."""

    covers: tuple[AspectCover, ...]

    @property
    def upper(self) -> int | None:
        """Sum over the signs of the proved bound on their components; None when a cover is open."""
        bounds = [c.components_at_most for c in self.covers]
        return None if any(b is None for b in bounds) else sum(bounds)

    @property
    def seconds(self) -> float:
        return sum(c.seconds for c in self.covers)

    def lower(self, found: Count) -> int:
        """The lower bound of ``found`` (distinct signs) raised by the separations of the closed covers.

        Per sign of det A, the larger of 1 when ``found`` witnesses the sign and the ``separated`` pieces of its
        closed cover (each holds a sink, so each lies in its own component), summed over the signs: the checker's
        bound (``checker.claims.count_bound``), which the count must never fall below.  ``found`` says how many
        signs it witnesses, not which: with one, the smaller of the two assignments is taken.  A cover's sinks
        prove its sign's part of W nonempty even where ``found`` has no certified box of it (a shallow paving).
        """
        sep = {c.sign: (c.separated if c.closed else 0) for c in self.covers}
        a, b = sep.get(1, 0), sep.get(-1, 0)
        if found.lower >= 2:
            bound = max(1, a) + max(1, b)
        elif found.lower == 1:
            bound = min(max(1, a) + b, a + max(1, b))
        else:
            bound = a + b
        return max(bound, found.lower)

    def count(self, found: Count) -> Count:
        """The aspect count ``found`` (its lower bound from opposite signs) with the covers' bounds added.

        ``found`` is raised to the proved lower bound when the separations prove more aspects than
        the library's components of certified boxes of each sign found.
        """
        upper, lower = self.upper, self.lower(found)
        n = max(found.found, lower)
        per_sign = ", ".join(f"{'WA1' if c.sign > 0 else 'WA2'} {c.components_at_least}.."
                             f"{c.components_at_most if c.closed else '?'}" for c in self.covers)
        if upper is None or upper < n:
            left = sum(len(c.leftovers()) for c in self.covers)
            return Count(n, lower, None, False, found.why + f"; components per sign {per_sign}; the covers of the two "
                         f"signs leave {left} boxes undecided (listed under \"covers\"), so no upper bound is proved")
        groups = " + ".join(str(c.groups) for c in self.covers)
        proofs = []
        if found.lower:
            proofs.append("opposite certified signs of det A" if found.lower >= 2 else "a certified sign of det A")
        if lower > found.lower:
            proofs.append("the sinks of the closed covers, with OUT boxes cutting a sign's part of W into pieces that "
                          "each hold a sink")
        return Count(n, lower, upper, upper == lower,
                     f"at least {lower}: " + ", and ".join(proofs or ["nothing certified"])
                     + f"; at most {upper} = {groups}: for each sign, a cover of the domain by boxes free of it, "
                     "inside it (face-connected groups of sinks) or retracting onto the sinks along certified "
                     "monotone directions proves that its part of W has at most one component per group "
                     f"(components per sign: {per_sign}; proofs/lemma-aspect-retraction.md)")

    def to_json(self) -> dict:
        return {"upper_bound": self.upper, "covers": {("WA1" if c.sign > 0 else "WA2"): c.to_json()
                                                      for c in self.covers}}


def _classified(geometry, domain, level, ijk, sign):
    """Labels of boxes given by integer coordinates, with room for a third per-box direction (shared)."""
    lo, hi = box_bounds(domain, level, ijk)
    c = classify_boxes(geometry, np.stack([lo, hi], axis=-1), sign)
    n = len(level)
    ok = np.concatenate([c.ok, np.zeros((n, 1), dtype=bool)], axis=1)
    custom = np.concatenate([c.custom, np.zeros((n, 1, 3), dtype=np.int64)], axis=1)
    return [c.out, c.inside, ok, custom, np.prod(hi - lo, axis=1), c.weights]


def _share_directions(geometry, domain, level, ijk, kind, edges, sign, ok, custom) -> None:
    """Give each face-connected cluster of LEFT boxes one shared direction where it is certified (in place)."""
    left = kind == LEFT
    if not np.any(left):
        return
    rows = np.flatnonzero(left)
    comp = component_labels(len(level), edges, left)[rows]
    lo, hi = box_bounds(domain, level[rows], ijk[rows])
    e, good = shared_directions(geometry, np.stack([lo, hi], axis=-1), sign, comp)
    custom[rows[good], 2] = e[comp[good]]
    ok[rows[good], -1] = True


def _resolve_shared(geometry, domain, level, ijk, depth, sign, out, inside, ok, custom, vol, max_groups):
    """:func:`resolve_cover`, then shared directions for the clusters left, again while that helps (in place)."""
    adjacency = face_pairs(level, ijk, depth)
    res = resolve_cover(level, ijk, depth, out, inside, ok, exit_faces(custom), vol, max_groups, adjacency)
    for _ in range(SHARE_PASSES):
        left = int(np.count_nonzero(res[0] == LEFT))
        if left == 0:
            break
        _share_directions(geometry, domain, level, ijk, res[0], res[4], sign, ok, custom)
        res = resolve_cover(level, ijk, depth, out, inside, ok, exit_faces(custom), vol, max_groups, adjacency)
        if np.count_nonzero(res[0] == LEFT) > (1 - SHARE_GAIN) * left:  # again only while a pass pays
            break
    return res


def cover_aspect(geometry: Geometry, sign: int, start_depth: int = 9, max_depth: int = 12) -> AspectCover:
    """The cover of S_sign (module docstring): split top-down to ``start_depth``, then refine the unresolved.

    Each round resolves the cover; clusters of unresolved boxes are given a shared direction and
    the cover is resolved again; what is still unresolved is split (up to ``max_depth``).
    """
    t0 = time.perf_counter()
    domain = workspace_paving_domain(geometry)
    level = np.zeros(1, dtype=np.int64)
    ijk = np.zeros((1, 3), dtype=np.int64)
    parts = []
    for lev in range(start_depth + 1):  # top-down: split what is neither OUT, IN nor retractable
        lab = _classified(geometry, domain, level, ijk, sign)
        out, inside, ok = lab[:3]
        cut = ~out & ~inside & ~np.any(ok, axis=1) & (lev < start_depth)
        parts.append([level[~cut], ijk[~cut]] + [a[~cut] for a in lab])
        if not np.any(cut):
            break
        level, ijk = split_boxes(level[cut], ijk[cut])
    level, ijk, out, inside, ok, custom, vol, weights = (np.concatenate(p) for p in zip(*parts))
    unjoined_before = 1 << 30  # groups of sinks sharing a piece with another group, at the round before
    for rnd in range(MAX_ROUNDS + 1):
        depth = max(int(level.max()), 1)
        args = (geometry, domain, level, ijk, depth, sign, out, inside, ok, custom, vol)
        kind, rank, choice, fragments, edges, groups = one = _resolve_shared(*args, 1)
        crowded = np.zeros(len(level), dtype=bool)
        if np.any(kind == LEFT) and np.any(inside & (kind == LEFT)):
            # more groups of sinks where one group does not reach everything; a group cut off from the others by
            # OUT boxes is another component (no refinement can join it); where two groups share a piece of the
            # non-OUT boxes, the boxes one group could not reach are refined, in the hope of a join
            kind, rank, choice, fragments, edges, groups = _resolve_shared(*args, MAX_GROUPS)
        separated = groups  # one group: in one piece (and none: S is empty or the cover open)
        if groups > 1:
            piece, group, separated, touching = separations(level, ijk, depth, out, kind == SINK, edges)
            holding = np.unique(piece[group >= 0])
            per_piece = np.array([len(np.unique(group[(piece == p) & (group >= 0)])) for p in holding])
            many = holding[per_piece > 1]
            if many.size:
                unjoined = int(per_piece[per_piece > 1].sum())
                if unjoined < unjoined_before:  # refine what one group cannot reach, while that joins groups
                    crowded = (one[0] == LEFT) & np.isin(piece, many)
                else:  # else refine where the groups' regions meet and where S seems absent: a join or a cut
                    crowded = between_groups(kind, piece, group, touching, many) & ~inside
                    maybe = np.flatnonzero(np.isin(piece, many) & ~inside & (kind != SINK))
                    lo, hi = box_bounds(domain, level[maybe], ijk[maybe])
                    crowded[maybe] |= approx_free_of_aspect(geometry, np.stack([lo, hi], axis=-1), sign)
                unjoined_before = unjoined
        cut = ((kind == LEFT) | crowded) & (level < max_depth)
        if rnd == MAX_ROUNDS or not np.any(cut) or len(level) + 7 * int(cut.sum()) > MAX_BOXES:
            break
        cl, cijk = split_boxes(level[cut], ijk[cut])
        lab = _classified(geometry, domain, cl, cijk, sign)
        keep = ~cut
        level, ijk = np.concatenate([level[keep], cl]), np.concatenate([ijk[keep], cijk])
        out, inside, ok, custom, vol, weights = (np.concatenate([a[keep], b]) for a, b in
                                                 zip((out, inside, ok, custom, vol, weights), lab))
    direction = np.zeros((len(level), 3), dtype=np.int64)
    rows = np.flatnonzero(kind == RET)
    j = choice[rows]
    m = len(DIRECTIONS)
    direction[rows] = np.where((j < m)[:, None], DIRECTIONS[np.minimum(j, m - 1)], custom[rows, np.clip(j - m, 0, 2)])
    return AspectCover(sign, domain, level.astype(np.int64), ijk, kind, direction, rank, fragments, groups,
                       separated, time.perf_counter() - t0, weights)


def prove_aspects(geometry: Geometry, start_depth: int = 9, max_depth: int = 12) -> AspectTopology:
    """Covers of WA1 (det A > 0) and WA2 (det A < 0); :attr:`AspectTopology.upper` is the proved bound.

    The covers depend on nothing but the arguments, whatever the depth of the analysis that asks, so a process
    proves them once per geometry (about 5 s on the paper's manipulator; the last four geometries are kept) and
    hands the same result to later analyses.  Its arrays are read-only, so no caller can change what the others
    read; ``seconds`` stays the time the proof took."""
    return _proved_aspects(geometry, start_depth, max_depth)


@functools.lru_cache(maxsize=4)  # keyed by the frozen (hashable) Geometry and the depths
def _proved_aspects(geometry: Geometry, start_depth: int, max_depth: int) -> AspectTopology:
    topology = AspectTopology(tuple(cover_aspect(geometry, s, start_depth, max_depth) for s in (1, -1)))
    for cover in topology.covers:
        for a in (cover.domain, cover.level, cover.ijk, cover.kind, cover.direction, cover.rank, cover.weights):
            if isinstance(a, np.ndarray):
                a.setflags(write=False)
    return topology
