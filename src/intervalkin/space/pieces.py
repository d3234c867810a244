"""Pieces of certified boxes, and the sheet of its joint cell that each piece lies on.

A *piece* is a face-connected set (phi seam included) of workspace boxes
certified inside one aspect and off its characteristic surface.  It is
connected and avoids S_c, so it lies in ONE basic region; its image lies in
ONE joint cell (checked here: every box of a piece maps into unmarked voxels
of the same cell, and adjacent boxes share a face).

Above a cell C with k solutions of an aspect there are exactly k basic regions
of that aspect, its *sheets* (Theorem 1 and Proposition 1 of the paper;
proofs/lemma-theorem1-distinctness.md (d)).  The k certified solutions of the
cell's witness joint vector name the sheets 0..k-1; a piece holding one of them
is on that sheet, and any other piece is placed by certified continuation
inside the cell (:func:`intervalkin.space.sheets.identify_sheets`,
proofs/lemma-sheet-continuation.md).  A piece whose track cannot be certified
keeps sheet -1: it is never guessed.

The same solves give the distinctness witnesses of DESIGN.md section 6: the
certified solutions of one joint vector in one aspect that land in different
pieces prove those pieces to lie in different basic regions (Theorem 1: g is
injective on a basic region).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.paving.adjacency import component_labels
from intervalkin.paving.labels import Label
from intervalkin.paving.tree import Paving
from intervalkin.solve.dkp import solve
from intervalkin.space.aspect import ASPECTS
from intervalkin.space.joint_space import JointPaving
from intervalkin.space.sheets import identify_sheets
from intervalkin.space.singular_surface import singular_image

__all__ = ['Witness', 'certified_pieces', 'assign_sheets']


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


def certified_pieces(paving: Paving, edges: np.ndarray, joint: JointPaving, geometry: Geometry):
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


def assign_sheets(geometry: Geometry, paving: Paving, piece: np.ndarray, piece_aspect: list[str],
                  piece_cell: np.ndarray, joint: JointPaving, tries: int = 12, seed: int = 0):
    """Sheet of each piece (-1 undecided) by certified continuation, and the witnesses.

    Above a cell C with k = n_a(C) solutions of aspect a there are exactly k sheets
    (proofs/lemma-theorem1-distinctness.md (d)).  k = 1: every piece is in the one
    sheet.  Otherwise the certified solutions of the cell's witness q0 (a voxel
    centre) name the sheets 0..k-1 in the solver's order; a piece holding one of
    them is in that sheet; every other piece is identified by continuation
    (:func:`~intervalkin.space.sheets.identify_sheets`): a certified solution inside one of
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
        boxes = paving.box(start_box[todo])
        got, _ = identify_sheets(geometry, joint, cid, q0, references, boxes, [piece_aspect[p] for p in todo])
        sheet[todo] = np.where(got >= 0, got, sheet[todo])
    return sheet, tuple(witnesses)
