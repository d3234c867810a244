"""Basic regions and basic components: the paper's section 4 on certified pavings.

Definitions (Wenger & Chablat 1997, Definitions 3 and 4): a *basic region* of
an aspect WA is a connected component of WA minus its characteristic surface
S_c; its image under the inverse kinematics g is a *basic component*, a cell of
joint space minus g(S).  Theorem 1: g maps a basic region one to one onto its
basic component; Proposition 1: two basic components are either coincident or
disjoint.  Above a joint cell C with k solutions of an aspect there are
therefore exactly k basic regions of that aspect, the sheets of C.

Here a basic region is named by (cell, aspect, sheet), one per sheet of every
joint cell that carries certified workspace boxes
(:mod:`intervalkin.space.pieces` finds the pieces of certified boxes and the
sheet of each).  A box's ``region`` label is certified: the box lies inside the
aspect, off S_c, on that sheet.

Counts (DESIGN.md sections 6 and 8): two regions are certified different when
their aspects differ (opposite det A signs), when their cells have different
certified counts or aspect splits (different basic components), or when one
joint vector has a certified solution in each (Theorem 1).  The lower bound is
the size of a set of regions pairwise different by these witnesses: the
sheets of one cell per distinct aspect split (n_wa1, n_wa2), the rule the
independent checker applies.  No upper bound is proved: two cells of equal
split may be one true cell joined through the undecided layer of joint space.

Proposition 1 is checked: above each counted cell and for each aspect, the
number of sheets that hold certified boxes is compared with the certified
number of solutions; a mismatch (a sheet with no certified box at this depth)
is reported in ``consistency``, never hidden.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.status import Count
from intervalkin.paving.adjacency import shares_face
from intervalkin.paving.labels import signed_labels
from intervalkin.paving.tree import Paving
from intervalkin.space.aspect import ASPECTS, aspect_components
from intervalkin.space.characteristic_surface import pave_regions
from intervalkin.space.joint_route import JointGrid
from intervalkin.space.joint_space import JointPaving
from intervalkin.space.pieces import Witness, assign_sheets, certified_pieces
from intervalkin.space.pose_label import LabelledBoxes, PoseLabel, label_pose_in
from intervalkin.space.uniqueness_domain import region_adjacency, uniqueness_domains

__all__ = ['BasicRegion', 'RegionCounts', 'RegionAnalysis', 'analyse_regions', 'label_pose']


@dataclass(frozen=True)
class BasicRegion:
    """A basic region: one sheet of g^{-1}(C) in one aspect above a joint cell C.

    ``n_boxes`` / ``volume`` are those of the certified boxes assigned to it
    (possibly 0 when all its boxes are still in the undecided layer).
    ``pieces`` is the number of face-connected pieces of boxes assigned to it.
    """

    id: int
    aspect: str
    cell: int
    sheet: int
    cell_count: int
    n_boxes: int
    volume: float
    pieces: int

    def to_json(self) -> dict:
        return {"id": self.id, "aspect": self.aspect, "cell": self.cell, "sheet": self.sheet,
                "cell_count": self.cell_count, "boxes": self.n_boxes, "volume": self.volume, "pieces": self.pieces}


@dataclass(frozen=True)
class RegionCounts:
    """The counts of one analysis, each with its certified bounds, and the facts summary.json adds to them.

    ``aspects_per_sign``: number of components of certified boxes of each det A sign;
    ``consistent``: Proposition 1 seen in full (every sheet of every counted cell holds certified boxes);
    ``domains_minimal``: the partition found has as many domains as the certified lower bound;
    ``unplaced_regions``: regions with no certified box at this depth (in no domain).
    """

    aspects: Count
    basic_regions: Count
    uniqueness_domains: Count
    aspects_per_sign: Mapping[str, int]
    consistent: bool
    domains_minimal: bool
    unplaced_regions: tuple[int, ...]

    def to_json(self) -> dict:
        """The three count blocks of summary.json ("count", "exact", "lower_bound", "why" and their extras)."""
        return {
            "aspects": {**self.aspects.to_json(), "components_per_sign": dict(self.aspects_per_sign)},
            "basic_regions": {**self.basic_regions.to_json(), "consistent_with_proposition_1": self.consistent},
            "uniqueness_domains": {**self.uniqueness_domains.to_json(), "minimal": self.domains_minimal,
                                   "unplaced_regions": list(self.unplaced_regions)},
        }


@dataclass(frozen=True, eq=False)
class RegionAnalysis:
    """Everything sections 4-5 of the paper define, on one paving.

    Per box (arrays of shape (n,), -1 for none): ``aspect`` (aspect component),
    ``piece`` (face-connected piece of certified boxes off S_c), ``region`` (basic
    region id, -1 where the sheet is undecided), ``domain`` (uniqueness domain).
    """

    paving: Paving
    edges: np.ndarray
    aspect: np.ndarray
    piece: np.ndarray
    piece_cell: np.ndarray
    region: np.ndarray
    domain: np.ndarray
    regions: tuple[BasicRegion, ...]
    witnesses: tuple[Witness, ...]
    lower_bound: int
    consistency: tuple[dict, ...]
    unrealized_cells: tuple[int, ...]
    domains: tuple[tuple[int, ...], ...]
    domains_lower_bound: int
    aspect_info: tuple[dict, ...]
    seconds: float

    @property
    def consistent(self) -> bool:
        """Every sheet above every realized cell holds certified boxes (Proposition 1 seen in full)."""
        return all(c["sheets_with_boxes"] == c["expected"] for c in self.consistency)

    @property
    def unplaced_regions(self) -> tuple[int, ...]:
        """Regions with no certified box at this depth (left out of the uniqueness domains)."""
        return tuple(r.id for r in self.regions if r.n_boxes == 0)

    def counts(self) -> RegionCounts:
        """The numbers of aspects, basic regions and uniqueness domains, with their certified bounds."""
        per_sign = {a: sum(1 for i in self.aspect_info if i["aspect"] == a) for a in ASPECTS}
        n_aspects = sum(1 for a in ASPECTS if per_sign[a] > 0)
        aspects = Count(
            n_aspects, n_aspects, None, False,
            "opposite certified signs of det A witness two different aspects (the lower bound); "
            "each sign's INSIDE boxes form the components listed; a piece of an aspect lying wholly "
            "in the undecided layer cannot be excluded, so no upper bound is proved")
        n_regions, lower = len(self.regions), self.lower_bound
        regions = Count(
            max(n_regions, lower), lower, None, False,
            f"the {n_regions} regions found are the sheets above the {len({r.cell for r in self.regions})} joint "
            "cells that carry certified boxes (each cell's certified solve gives its number of sheets per "
            f"aspect); at least {lower} basic regions are pairwise certified distinct (opposite aspects, the "
            "sheets of cells of different certified aspect splits, distinct solutions of one joint vector)"
            + (", more than the regions found at this depth, so the bound is reported" if n_regions < lower else "")
            + "; two cells of equal split are not proved to be different true cells, so the count is not proved "
            "exact")
        n_domains, bound = len(self.domains), self.domains_lower_bound
        placed = ("reaches this bound" if n_domains == bound else "exceeds it" if n_domains > bound else
                  f"has only {n_domains} groups, for the regions placed at this depth, so the bound is reported")
        domains = Count(
            max(n_domains, bound), bound, None, False,
            f"at least {bound}: the certified solutions of one joint vector lie in different uniqueness domains "
            "(largest number of solutions of each aspect in one joint cell, summed over the aspects); the partition "
            f"found {placed}; it relies on region adjacency across the undecided layer, which is heuristic"
            + (f"; regions {list(self.unplaced_regions)} have no certified box at this depth and are not "
               "placed in any domain" if self.unplaced_regions else ""))
        return RegionCounts(aspects, regions, domains, per_sign, self.consistent, n_domains == bound,
                            self.unplaced_regions)


# --------------------------------------------------------------------------------------
# The whole analysis
# --------------------------------------------------------------------------------------
def analyse_regions(geometry: Geometry, joint: JointPaving, depth: int, progress=None) -> RegionAnalysis:
    """Basic regions, basic components, their witnesses, Proposition 1 and uniqueness domains.

    Parameters
    ----------
    joint : the joint-space cells with the enclosure of g(S) (:func:`~intervalkin.space.joint_space.joint_paving`).
    depth : octree depth of the workspace paving.

    An empty aspect gives no region.  Cost: one paving with four predicates, a
    few certified solves per (cell, aspect), and a small exact search on the
    region graph.
    """

    t0 = time.perf_counter()
    paving = pave_regions(geometry, joint, depth, progress=progress)
    edges = shares_face(paving.level, paving.ijk, paving.depth)
    aspect, aspect_info = aspect_components(paving, edges)
    piece, piece_aspect, piece_cell = certified_pieces(paving, edges, joint, geometry)
    sheet, witnesses = assign_sheets(geometry, paving, piece, piece_aspect, piece_cell, joint)

    vol = paving.volume()
    realized = sorted({int(c) for c in piece_cell if joint.cells[int(c)].count > 0})
    regions: list[BasicRegion] = []
    rid_of: dict[tuple[int, str, int], int] = {}
    for name in ASPECTS:
        for cid in sorted(realized, key=lambda c: -joint.cells[c].n_voxels):
            cell = joint.cells[cid]
            k = cell.n_wa1 if name == "WA1" else cell.n_wa2
            for s in range(k):
                rid_of[(cid, name, s)] = len(regions)
                regions.append(BasicRegion(len(regions), name, cid, s, cell.count, 0, 0.0, 0))
    piece_region = np.array(
        [rid_of.get((int(c), a, int(s)), -1) if s >= 0 else -1 for c, a, s in zip(piece_cell, piece_aspect, sheet)],
        dtype=np.int32,
    )
    region = np.where(piece >= 0, piece_region[np.maximum(piece, 0)] if len(piece_region) else -1, -1).astype(np.int32)
    nb = np.bincount(region[region >= 0], minlength=len(regions))
    vb = np.bincount(region[region >= 0], weights=vol[region >= 0], minlength=len(regions))
    npieces = np.bincount(piece_region[piece_region >= 0], minlength=len(regions))
    regions = [BasicRegion(r.id, r.aspect, r.cell, r.sheet, r.cell_count, int(nb[r.id]), float(vb[r.id]),
                           int(npieces[r.id])) for r in regions]

    # certified lower bounds, from every cell with a certified count (whether or not the paving holds
    # certified boxes above it at this depth: its sheets exist all the same)
    solved = [c for c in joint.cells if c.count >= 0]
    # the sheets of one cell per distinct aspect split (n_wa1, n_wa2) are pairwise distinct: cells of different
    # splits lie in different basic components; the rule the checker applies (checker.claims.count_bound)
    lower = sum(n1 + n2 for n1, n2 in {(c.n_wa1, c.n_wa2) for c in solved})
    # the solutions of one joint vector in one aspect lie in different uniqueness domains
    bound = sum(max((c.n_wa1 if name == "WA1" else c.n_wa2 for c in solved), default=0) for name in ASPECTS)

    consistency = []
    for cid in realized:
        cell = joint.cells[cid]
        for name in ASPECTS:
            k = cell.n_wa1 if name == "WA1" else cell.n_wa2
            pids = [p for p in range(len(piece_cell)) if piece_cell[p] == cid and piece_aspect[p] == name]
            with_boxes = len({int(sheet[p]) for p in pids if sheet[p] >= 0})
            consistency.append({"cell": cid, "aspect": name, "expected": k, "sheets_with_boxes": with_boxes,
                                "pieces": len(pids), "unassigned_pieces": sum(1 for p in pids if sheet[p] < 0)})
    unrealized = tuple(c.id for c in joint.cells if c.count > 0 and c.id not in realized)

    adjacency = region_adjacency(paving, edges, region)
    # regions without certified boxes at this depth cannot be placed (no adjacency is known)
    groups, _ = uniqueness_domains([r for r in regions if r.n_boxes > 0], adjacency)
    lookup = np.full(len(regions) + 1, -1, dtype=np.int32)
    for gi, grp in enumerate(groups):
        lookup[list(grp)] = gi
    domain = np.where(region >= 0, lookup[np.maximum(region, 0)], -1).astype(np.int32)
    return RegionAnalysis(paving, edges, aspect, piece, piece_cell, region, domain, tuple(regions), witnesses,
                          lower, tuple(consistency), unrealized, groups, bound, tuple(aspect_info),
                          time.perf_counter() - t0)


def label_pose(analysis: RegionAnalysis, pose: Sequence, geometry: Geometry | None = None,
               joint: JointPaving | None = None, refine: bool = True) -> PoseLabel:
    """Certified aspect, basic region and uniqueness domain of an exact pose (x, y, phi).

    The pose is read exactly (decimal text, ints or Fractions; phi in radians,
    reduced modulo 2 pi); every box of the paving that holds it is consulted,
    and with ``geometry`` the pose itself and a certified path to a labelled box
    (guided by the cells of ``joint``; skipped when ``refine`` is False) decide
    what the boxes leave open (:mod:`intervalkin.space.pose_label`).
    """
    p = analysis.paving
    boxes = LabelledBoxes(p.lo, p.hi, p.domain, signed_labels(p.labels["W"]), signed_labels(p.labels["det_positive"]),
                          analysis.region, analysis.domain)
    return label_pose_in(boxes, pose, geometry, None if joint is None else JointGrid.of_paving(joint), refine)
