"""Characteristic surfaces, basic regions, basic components and uniqueness domains.

The paper's sections 4 and 5 (Definitions 2-4, Proposition 1, Theorems 1-2),
rebuilt on certified pavings.

* Characteristic surface S_c(WA) = {X in WA : g(X) in g(S)} (the joint-limit part
  of the aspect's boundary maps onto the boundary of the joint box).  A box of an
  aspect is *certified off S_c* when its interval image g(b) meets no marked
  voxel of the joint-space enclosure of g(S) (:mod:`intervalkin.space.joint_space`); the
  boxes of the aspect that are not so certified form an outer enclosure of S_c.
* Basic regions (Definition 3): connected components of WA minus S_c.  Here:
  face-connected components (phi seam included) of the boxes certified inside an
  aspect and off S_c.  Each is connected (union of adjacent closed boxes) and
  lies in ONE true basic region (it is connected and avoids S_c).
* Basic component (Definition 4): g of a basic region.  Every box of a region
  maps into unmarked voxels of one joint cell (its index range is a block of
  unmarked voxels); adjacent boxes share a face, so a whole region maps into
  one cell, which the code checks.
* Sheets: above a cell C with k solutions of an aspect there are exactly k
  sheets (the basic regions over C); the k solutions of the cell's witness name
  them, and the sheet of each piece is found by certified continuation inside C
  (:mod:`intervalkin.solve.continuation`, proofs/lemma-sheet-continuation.md).
* Distinctness (DESIGN.md section 6): two regions are certified different when
  (a) their aspects differ (opposite certified det A signs); (b) their cells have
  different certified counts (different basic components); or (c) a joint
  vector q has two certified solutions of the same aspect, one in a box of each
  region: by Theorem 1, g is injective on a basic region, so the two regions lie
  in different basic regions.  The certified lower bound on the number of basic
  regions is the size of a largest set of pairwise certified-distinct regions.
* Proposition 1 check: above each cell C and for each aspect, the number of
  regions found should equal the certified number of solutions of that aspect
  in C; every mismatch is reported (a region split by the undecided layer, or
  one not resolved at this depth).
* Uniqueness domains (Theorem 2): each aspect's regions are partitioned into the
  fewest groups that are connected in the region adjacency graph and hold at
  most one region above each cell.  The number is minimal because the regions
  above one cell must all be in different groups: it cannot be smaller than the
  largest number of solutions of one aspect over the cells.

What is not certified, and said so in the results: that two cells of equal
count are different true cells (so regions above them may be parts of one true
basic region), hence the found number of regions is exact only when the
consistency checks pass AND the lower bound equals it; and the adjacency of
regions across the undecided layer (a heuristic: the layer is split between
the regions by nearest-region growth).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from fractions import Fraction
from typing import Sequence

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.paving.adjacency import component_labels, shares_face
from intervalkin.paving.labels import Label
from intervalkin.paving.tree import Paving
from intervalkin.solve.dkp import solve
from intervalkin.space.aspect import ASPECTS, aspect_components
from intervalkin.space.characteristic_surface import pave_regions
from intervalkin.space.joint_space import JointPaving
from intervalkin.space.sheets import identify_sheets
from intervalkin.space.singular_surface import singular_image
from intervalkin.space.uniqueness_domain import region_adjacency, uniqueness_domains

__all__ = ['BasicRegion', 'Witness', 'RegionAnalysis', 'analyse_regions', 'label_pose']



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
class Witness:
    """A joint vector with certified solutions of one aspect, each inside a box of a piece.

    ``pieces[k]`` is the piece whose box contains ``boxes[k]``; the solutions are
    distinct, so by Theorem 1 the pieces lie in pairwise different basic regions.
    """

    rho: tuple[Fraction, Fraction, Fraction]
    cell: int
    aspect: str
    pieces: tuple[int, ...]
    boxes: tuple[tuple[tuple[float, float], ...], ...]

    def to_json(self) -> dict:
        return {
            "rho": [f"{v.numerator}/{v.denominator}" for v in self.rho],
            "cell": self.cell,
            "aspect": self.aspect,
            "pieces": list(self.pieces),
            "solution_boxes": [[list(iv) for iv in b] for b in self.boxes],
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

    def counts(self) -> dict:
        """The counts with their certification status (the summary.json schema)."""
        per_sign = {a: sum(1 for i in self.aspect_info if i["aspect"] == a) for a in ASPECTS}
        n_aspects = sum(1 for a in ASPECTS if per_sign[a] > 0)
        n_regions = len(self.regions)
        return {
            "aspects": {
                "count": n_aspects,
                "exact": False,
                "lower_bound": n_aspects,
                "components_per_sign": per_sign,
                "why": "opposite certified signs of det A witness two different aspects (the lower bound); "
                       "each sign's INSIDE boxes form the components listed; a piece of an aspect lying wholly "
                       "in the undecided layer cannot be excluded, so no upper bound is proved",
            },
            "basic_regions": {
                "count": n_regions,
                "exact": False,
                "lower_bound": self.lower_bound,
                "consistent_with_proposition_1": self.consistent,
                "why": (
                    f"the {n_regions} regions are the sheets above the {len({r.cell for r in self.regions})} joint "
                    "cells that carry certified boxes (each cell's certified solve gives its number of sheets per "
                    f"aspect); {self.lower_bound} of them are pairwise certified distinct (opposite aspects, cells of "
                    "different certified counts, distinct solutions of one joint vector); two cells of equal count "
                    "are not proved to be different true cells, so the count is not proved exact"
                ),
            },
            "uniqueness_domains": {
                "count": len(self.domains),
                "exact": False,
                "lower_bound": self.domains_lower_bound,
                "minimal": len(self.domains) == self.domains_lower_bound,
                "why": (
                    f"at least {self.domains_lower_bound}: the certified solutions of one joint vector lie in "
                    "different uniqueness domains (largest number of solutions of each aspect in one cell, summed "
                    "over the aspects); the partition found "
                    + ("reaches this bound" if len(self.domains) == self.domains_lower_bound else "exceeds it")
                    + "; it relies on region adjacency across the undecided layer, which is heuristic"
                    + (f"; regions {list(self.unplaced_regions)} have no certified box at this depth and are not "
                       "placed in any domain" if self.unplaced_regions else "")
                ),
                "unplaced_regions": list(self.unplaced_regions),
            },
        }


# --------------------------------------------------------------------------------------
# Pieces of certified boxes, and the sheet each belongs to
# --------------------------------------------------------------------------------------
def _pieces(paving: Paving, edges: np.ndarray, joint: JointPaving, geometry: Geometry):
    """Face-connected pieces of boxes inside an aspect and off S_c, with their cell.

    Returns piece (n,) int32, piece_aspect list, piece_cell (p,) int32.  Asserts
    that each piece maps into exactly one cell (see the module docstring).
    """
    n = len(paving)
    piece = np.full(n, -1, dtype=np.int32)
    box_cell = np.full(n, -1, dtype=np.int32)
    aspects: list[str] = []
    cells: list[int] = []
    base = 0
    for name in ASPECTS:
        mask = (paving.labels[name] == Label.INSIDE) & (paving.labels["off_Sc"] == Label.INSIDE)
        comp = component_labels(n, edges, mask)
        idx = np.flatnonzero(mask)
        if idx.size:
            lo, hi = singular_image(geometry, paving.boxes[idx])
            box_cell[idx] = joint.cell_of_boxes(lo, hi)
        m = comp >= 0
        ncomp = int(comp.max()) + 1 if np.any(m) else 0
        if ncomp:
            lo_cell = np.full(ncomp, np.iinfo(np.int32).max, dtype=np.int64)
            hi_cell = np.full(ncomp, -2, dtype=np.int64)
            np.minimum.at(lo_cell, comp[m], box_cell[m])
            np.maximum.at(hi_cell, comp[m], box_cell[m])
            assert np.all(lo_cell == hi_cell) and np.all(lo_cell >= 0), "a piece must map into exactly one cell"
            cells.extend(lo_cell.tolist())
            aspects.extend([name] * ncomp)
        piece[m] = comp[m] + base
        base += ncomp
    return piece, aspects, np.array(cells, dtype=np.int32)


def _point_in_cell(joint: JointPaving, rng, cid: int) -> tuple[Fraction, Fraction, Fraction]:
    vox = np.argwhere(joint.cell == cid)
    v = vox[rng.integers(len(vox))]
    return tuple(joint.rho_min[i] + (Fraction(int(v[i])) + Fraction(1, 2)) * joint.step[i] for i in range(3))


class _Locator:
    """Finds the piece whose box holds a certified solution box (vectorized per query)."""

    def __init__(self, paving: Paving, piece: np.ndarray):
        self.paving, self.piece = paving, piece

    def piece_of(self, box: np.ndarray) -> int:
        i = int(self.paving.locate_boxes(box[None])[0])
        return int(self.piece[i]) if i >= 0 else -1


def _solve_located(geometry, q, sign, locator):
    """Certified solutions of q with det sign ``sign``: list of (piece or -1, box)."""

    res = solve(geometry, q)
    if not res.complete or any(s.status != "unique" for s in res.solutions):
        return None
    return [(locator.piece_of(np.asarray(s.box)), np.asarray(s.box)) for s in res.solutions if s.det_sign == sign]


def _assign_sheets(geometry, paving, piece, piece_aspect, piece_cell, joint, tries: int = 12, seed: int = 0):
    """Sheet of each piece (-1 undecided) by certified continuation, and the witnesses.

    Above a cell C with k = n_a(C) solutions of aspect a there are exactly k sheets
    (proofs/lemma-theorem1-distinctness.md (d)).  k = 1: every piece is in the one
    sheet.  Otherwise the certified solutions of the cell's witness q0 (a voxel
    centre) name the sheets 0..k-1 in the solver's order; a piece holding one of
    them is in that sheet; every other piece is identified by continuation
    (:func:`continuation.identify_sheets`): a certified solution inside one of
    its boxes is tracked, with parameter Krawczyk steps, along a path of cell
    voxels to where the k reference solutions of q0 have been tracked, and its
    box there holds exactly one of them (proofs/lemma-sheet-continuation.md).
    A piece whose track cannot be certified keeps -1; it is never guessed.

    The witnesses (distinct pieces holding the solutions of one joint vector)
    come from the joint vector of the cell, among the witness and ``tries``
    random voxel centres, whose solutions land in the most pieces.
    """

    rng = np.random.default_rng(seed)
    locator = _Locator(paving, piece)
    sheet = np.full(len(piece_cell), -1, dtype=np.int32)
    witnesses: list[Witness] = []
    sign_of = {"WA1": 1, "WA2": -1}
    groups: dict[tuple[int, str], list[int]] = {}
    for pid, (a, c) in enumerate(zip(piece_aspect, piece_cell)):
        groups.setdefault((int(c), a), []).append(pid)
    vol = paving.volume()
    piece_vol = np.bincount(piece[piece >= 0], weights=vol[piece >= 0], minlength=len(piece_cell))
    pending: dict[int, list[str]] = {}
    for (cid, a), pids in sorted(groups.items()):
        cell = joint.cells[cid]
        k = cell.n_wa1 if a == "WA1" else cell.n_wa2
        if k <= 0:
            continue
        if k == 1:
            sheet[pids] = 0
            continue
        if cell.witness is not None:
            pending.setdefault(cid, []).append(a)
        # witnesses of distinctness: the joint vector whose solutions land in the most pieces
        best = None
        candidates = ([cell.witness] if cell.witness else []) + [_point_in_cell(joint, rng, cid) for _ in range(tries)]
        for q in candidates:
            loc = _solve_located(geometry, q, sign_of[a], locator)
            if loc is None:
                continue
            landed = [p for p, _ in loc if p >= 0]
            if best is None or len(set(landed)) > len(set(best[1])):
                best = (q, landed, loc)
            if len(set(landed)) == k:
                break
        if best is None:
            continue
        q0, landed, loc = best
        if len(landed) >= 2 and len(set(landed)) == len(landed):
            witnesses.append(Witness(tuple(q0), cid, a, tuple(landed),
                                     tuple(tuple((float(x), float(y)) for x, y in b) for p, b in loc if p >= 0)))
    # the largest box of each piece starts its track
    has = np.flatnonzero(piece >= 0)
    order = has[np.lexsort((-vol[has], piece[has]))]
    first = np.ones(order.size, dtype=bool)
    first[1:] = piece[order[1:]] != piece[order[:-1]]
    start_box = np.full(len(piece_cell), -1, dtype=np.int64)
    start_box[piece[order[first]]] = order[first]
    for cid, aspects in sorted(pending.items()):
        q0 = joint.cells[cid].witness
        res = solve(geometry, q0)
        if not res.complete or any(s.status != "unique" for s in res.solutions):
            continue
        references = {a: [np.asarray(s.box) for s in res.solutions if s.det_sign == sign_of[a]] for a in aspects}
        todo = []
        for a in aspects:
            for s_idx, b in enumerate(references[a]):
                p = locator.piece_of(b)  # the piece holding solution s of q0 is in sheet s
                if p >= 0 and piece_aspect[p] == a and int(piece_cell[p]) == cid:
                    sheet[p] = s_idx
            todo += [p for p in groups[(cid, a)] if sheet[p] < 0]
        todo.sort(key=lambda t: -piece_vol[t])
        if not todo:
            continue
        boxes = paving.boxes[start_box[todo]]
        got, _ = identify_sheets(geometry, joint, cid, q0, references, boxes, [piece_aspect[p] for p in todo])
        sheet[todo] = np.where(got >= 0, got, sheet[todo])
    return sheet, tuple(witnesses)


# --------------------------------------------------------------------------------------
# The whole analysis
# --------------------------------------------------------------------------------------
def analyse_regions(geometry: Geometry, joint: JointPaving, depth: int, progress=None) -> RegionAnalysis:
    """Basic regions, basic components, their witnesses, Proposition 1 and uniqueness domains.

    Parameters
    ----------
    joint : the joint-space cells with the enclosure of g(S) (:func:`joint.joint_paving`).
    depth : octree depth of the workspace paving.

    An empty aspect gives no region.  Cost: one paving with four predicates, a
    few certified solves per (cell, aspect), and a small exact search on the
    region graph.
    """

    t0 = time.perf_counter()
    paving = pave_regions(geometry, joint, depth, progress=progress)
    edges = shares_face(paving.level, paving.ijk, paving.depth)
    aspect, aspect_info = aspect_components(paving, edges)
    piece, piece_aspect, piece_cell = _pieces(paving, edges, joint, geometry)
    sheet, witnesses = _assign_sheets(geometry, paving, piece, piece_aspect, piece_cell, joint)

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

    # certified lower bound: per aspect, one cell per distinct count, its sheets are pairwise distinct
    lower = 0
    for name in ASPECTS:
        best: dict[int, int] = {}
        for cid in realized:
            cell = joint.cells[cid]
            k = cell.n_wa1 if name == "WA1" else cell.n_wa2
            best[cell.count] = max(best.get(cell.count, 0), k)
        lower += sum(best.values())

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
    bound = sum(max((r.sheet + 1 for r in regions if r.aspect == name), default=0) for name in ASPECTS)
    lookup = np.full(len(regions) + 1, -1, dtype=np.int32)
    for gi, grp in enumerate(groups):
        lookup[list(grp)] = gi
    domain = np.where(region >= 0, lookup[np.maximum(region, 0)], -1).astype(np.int32)
    return RegionAnalysis(paving, edges, aspect, piece, piece_cell, region, domain, tuple(regions), witnesses,
                          lower, tuple(consistency), unrealized, groups, bound, tuple(aspect_info),
                          time.perf_counter() - t0)


def label_pose(analysis: RegionAnalysis, pose: Sequence) -> dict:
    """Certified aspect, basic region and uniqueness domain of an exact pose, or "undecided".

    The pose (x, y, phi) is read exactly (decimal strings or Fractions); phi is
    taken modulo 2 pi into the paving's range only when it is already inside it.
    Every box of the paving that contains the pose is consulted; a label is
    reported when one of them is certified.
    """
    p = analysis.paving
    x = [Fraction(str(v)) for v in pose]
    xf = np.array([float(v) for v in x])
    # float filter with a margin, then the exact test on the few candidates
    near = np.all((p.lo <= xf + 1e-9) & (xf - 1e-9 <= p.hi), axis=1)
    cand = np.flatnonzero(near)
    keep = [i for i in cand if all(Fraction(float(p.lo[i, j])) <= x[j] <= Fraction(float(p.hi[i, j])) for j in range(3))]
    inside = np.zeros(len(p), dtype=bool)
    inside[keep] = True
    idx = np.flatnonzero(inside)
    out = {"pose": [str(v) for v in pose], "boxes": int(idx.size), "aspect": "undecided",
           "basic_region": "undecided", "uniqueness_domain": "undecided", "in_workspace": "undecided"}
    for i in idx:
        w = p.labels["W"][i]
        if w == Label.OUTSIDE:
            out["in_workspace"] = "no"
        elif w == Label.INSIDE:
            out["in_workspace"] = "yes"
        for name in ASPECTS:
            if p.labels[name][i] == Label.INSIDE:
                out["aspect"] = name
        if analysis.region[i] >= 0:
            out["basic_region"] = int(analysis.region[i])
        if analysis.domain[i] >= 0:
            out["uniqueness_domain"] = int(analysis.domain[i])
    if out["in_workspace"] == "no":
        out["aspect"] = out["basic_region"] = out["uniqueness_domain"] = "none (outside W)"
    return out
