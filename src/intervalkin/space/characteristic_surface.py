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

from typing import Callable

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.paving.labels import Label
from intervalkin.paving.predicates import (
    aspect_labels,
    det_sign_predicate,
    workspace_predicate,
)
from intervalkin.paving.tree import Paving, pave_multi, workspace_paving_domain
from intervalkin.space.joint_space import JointPaving
from intervalkin.space.singular_surface import singular_image

__all__ = ['off_characteristic_predicate', 'pave_regions']


def off_characteristic_predicate(geometry: Geometry, joint: JointPaving) -> Callable[[np.ndarray], np.ndarray]:
    """Tri-state label "certified off the characteristic surfaces".

    INSIDE where the interval image g(b) meets no marked voxel (so g(b) misses g(S));
    never OUTSIDE (no box is proved to lie wholly on S_c); BOUNDARY otherwise.
    """

    def predicate(boxes: np.ndarray) -> np.ndarray:
        lo, hi = singular_image(geometry, boxes)
        meets = joint.meets_marked(lo, hi)
        return np.where(meets, Label.BOUNDARY, Label.INSIDE).astype(np.uint8)

    return predicate


def pave_regions(geometry: Geometry, joint: JointPaving, depth: int, progress=None) -> Paving:
    """Pave W, det A, the aspects and "off S_c" in one pass (labels W, det_positive, WA1, WA2, off_Sc).

    A box is split while W is undecided, while it is in W with an undecided det A
    sign, or while it is inside an aspect but not certified off S_c.
    """
    def split(labels):
        w, d, c = labels["W"], labels["det_positive"], labels["off_Sc"]
        in_aspect = (w == Label.INSIDE) & (d != Label.BOUNDARY)
        return (w == Label.BOUNDARY) | ((w == Label.INSIDE) & (d == Label.BOUNDARY)) | (in_aspect & (c == Label.BOUNDARY))

    p = pave_multi(
        workspace_paving_domain(geometry),
        [
            ("W", workspace_predicate(geometry)),
            ("det_positive", det_sign_predicate(geometry)),
            ("off_Sc", off_characteristic_predicate(geometry, joint)),
        ],
        depth,
        split=split,
        relevant={
            "det_positive": lambda labels: labels["W"] != Label.OUTSIDE,
            "off_Sc": lambda labels: (labels["W"] == Label.INSIDE) & (labels["det_positive"] != Label.BOUNDARY),
        },
        progress=progress,
    )
    p.labels["WA1"], p.labels["WA2"] = aspect_labels(p.labels["W"], p.labels["det_positive"])
    return p
