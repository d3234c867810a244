"""Joint space paved directly: adaptive boxes certified off g(S), and their cells.

The joint box [rho_min, rho_max]^3 is bisected level by level; a box is kept when
it is *clear* (:func:`intervalkin.solve.simple_roots.clear_boxes`: every root of the
reduced equation simple for every joint vector of the box, so the box lies off
g(S) and the solution count and aspect split are constant on it), and split
otherwise, down to ``depth``.  Unlike the enclosure of g(S) by images of workspace
boxes (:mod:`intervalkin.space.joint_space`), the resolution follows the singular
surface itself.

Cells are the face-connected components of the clear boxes (no axis wraps).  A
union of face-adjacent closed boxes is connected and lies off g(S), so one
certified solve at an exact rational point of any of its boxes gives the count
and split of the whole cell (proofs/lemma-simple-roots-constant-count.md,
proofs/lemma-constant-count-off-gS.md).

What is NOT yet claimed: two cells are not proved to be different components of
the joint box minus g(S) (they may join through the undecided boxes), and the
undecided boxes may hide small cells.  Counting cells exactly is the subject of
the certified local models (DESIGN.md section 8).

Known limit of the predicate: where two solutions share one orientation phi*
(phi* a zero of D, so the 2x2 position system is singular there, and N(phi*) = 0),
f has a double root at phi* although nothing is singular.  For the paper's
manipulator D vanishes at phi* = 0.0339 and 0.8834, and each condition
N(phi*; r) = 0 is a plane in r = rho^2 that crosses the joint box: boxes across
these planes stay undecided and split cells that are one true cell.  They need a
second elimination (or joining by continuation) before cell counts mean anything.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Callable

import numpy as np

from intervalkin.core.exact import fraction_bounds
from intervalkin.core.geometry import Geometry
from intervalkin.paving.adjacency import component_labels, shares_face
from intervalkin.paving.budget import check_depth
from intervalkin.paving.labels import Label
from intervalkin.paving.tree import Paving, pave_multi
from intervalkin.solve.dkp import solve
from intervalkin.solve.simple_roots import clear_boxes

__all__ = ["JointSpaceCell", "JointSpacePaving", "pave_joint_space", "joint_domain"]


@dataclass(frozen=True)
class JointSpaceCell:
    """A face-connected set of clear joint boxes, with its certified count.

    ``count``, ``n_wa1``, ``n_wa2``: from one complete certified solve at
    ``witness`` (exact, the centre of one box of the cell) in which the sign of
    det A is proved for every solution; -1 if that could not be done (never
    expected off g(S)).  ``volume`` is the sum of
    the box volumes (a float measure, not a certified bound).
    """

    id: int
    boxes: int
    volume: float
    count: int
    n_wa1: int
    n_wa2: int
    witness: tuple[Fraction, Fraction, Fraction]

    def to_json(self) -> dict:
        return {"id": self.id, "boxes": self.boxes, "volume": self.volume, "count": self.count,
                "n_wa1": self.n_wa1, "n_wa2": self.n_wa2, "witness": [str(v) for v in self.witness]}


@dataclass(frozen=True, eq=False)
class JointSpacePaving:
    """The adaptive paving of the joint box and its cells.

    Attributes
    ----------
    paving : the boxes (rho_1, rho_2, rho_3) with label ``clear`` (INSIDE: proved
        off g(S); BOUNDARY: undecided at the deepest level or not yet split).
    cell : (n,) int32, the cell of each clear box, -1 for undecided boxes.
    cells : one :class:`JointSpaceCell` per cell, largest first.
    """

    paving: Paving
    cell: np.ndarray
    cells: tuple[JointSpaceCell, ...]

    def undecided_volume(self) -> float:
        return float(self.paving.volume()[self.cell < 0].sum())

    def certified_share(self) -> float:
        v = self.paving.volume()
        return float(v[self.cell >= 0].sum() / v.sum())

    def columns(self) -> dict[str, np.ndarray]:
        """npz columns: lo, hi, level, cell id, count, n_wa1, n_wa2 (-1 where undecided)."""
        count = np.full(len(self.cell), -1, dtype=np.int32)
        wa1, wa2 = count.copy(), count.copy()
        for c in self.cells:
            m = self.cell == c.id
            count[m], wa1[m], wa2[m] = c.count, c.n_wa1, c.n_wa2
        return {"lo": self.paving.lo, "hi": self.paving.hi, "level": self.paving.level.astype(np.int32),
                "cell": self.cell.astype(np.int32), "count": count, "n_wa1": wa1, "n_wa2": wa2}


def joint_domain(geometry: Geometry) -> np.ndarray:
    """The joint box, rounded outward to floats: (3, 2) [rho_min_i, rho_max_i]."""
    return np.array([[fraction_bounds(lo)[0], fraction_bounds(hi)[1]]
                     for lo, hi in zip(geometry.rho_min, geometry.rho_max)], dtype=np.float64)


def _exact_centre(lo: np.ndarray, hi: np.ndarray) -> tuple[Fraction, Fraction, Fraction]:
    c = [(Fraction(float(a)) + Fraction(float(b))) / 2 for a, b in zip(lo, hi)]
    return c[0], c[1], c[2]


def pave_joint_space(geometry: Geometry, depth: int, progress: Callable[[dict], None] | None = None) -> JointSpacePaving:
    """Pave the joint box to ``depth`` with the clear-box predicate and find its cells.

    Cost: the undecided boxes lie along the 2-D surface g(S), so their number
    grows like 4**depth; each box costs one clear-box test (a few hundred
    microseconds), and each cell one certified solve.
    """
    check_depth(depth)
    domain = joint_domain(geometry)

    def clear(boxes: np.ndarray) -> np.ndarray:
        lab = np.full(len(boxes), Label.BOUNDARY, dtype=np.uint8)
        lab[clear_boxes(geometry, boxes)] = Label.INSIDE
        return lab

    paving = pave_multi(domain, [("clear", clear)], depth, progress=progress)
    ok = paving.labels["clear"] == Label.INSIDE
    edges = shares_face(paving.level, paving.ijk, paving.depth, periodic=(False, False, False))
    cell = component_labels(len(paving), edges, ok)
    vol = paving.volume()
    cells = []
    for cid in range(int(cell.max()) + 1 if ok.any() else 0):
        members = np.flatnonzero(cell == cid)
        best = members[np.argmin(paving.level[members])]  # the largest box: its centre is far from g(S)
        witness = _exact_centre(paving.lo[best], paving.hi[best])
        res = solve(geometry, witness)
        if res.complete and all(s.aspect in ("WA1", "WA2") for s in res.solutions):
            n1 = sum(1 for s in res.solutions if s.aspect == "WA1")
            count, n_wa1, n_wa2 = res.count, n1, res.count - n1
        else:
            count = n_wa1 = n_wa2 = -1
        cells.append(JointSpaceCell(cid, len(members), float(vol[members].sum()), count, n_wa1, n_wa2, witness))
    return JointSpacePaving(paving, cell.astype(np.int32), tuple(cells))
