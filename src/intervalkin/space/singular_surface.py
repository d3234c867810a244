"""Joint space: an outer enclosure of g(S) and the cells of constant solution count.

Mathematics (DESIGN.md section 5; proofs/lemma-constant-count-off-gS.md).  The
inverse kinematics g is proper (|B1 - A1| = rho_1 bounds the pose) and a local
diffeomorphism off the type-2 surface S, so on every connected set of joint
space that does not meet g(S) the number of real direct-kinematic solutions,
and the number in each aspect, is constant.  Hence:

1. Outer enclosure of g(S) inside the joint box: the union of the interval
   images g(b) of the workspace boxes b that may hold a singular point of W
   (det A undecided and not certainly outside W).  Every singular X with g(X) in
   the joint box is in W, so lies in such a box.
2. A uniform grid of N = 2**depth voxels per axis over prod_i [rho_min_i,
   rho_max_i] (voxel edges at the exact rationals rho_min_i + k h_i).  A voxel is
   *marked* when it may meet one of the boxes of step 1 (a conservative overlap
   test with a margin that absorbs the float rounding of the index computation);
   an unmarked voxel is certified off g(S).  Marking uses a 3-D difference array
   (one ``np.add.at`` per corner) and prefix sums; the prefix sums also answer
   "does this joint-space box meet a marked voxel" in O(1) per box.
3. Cells: face-connected components of the unmarked voxels.  A cell is
   connected and off g(S), so ONE certified direct-kinematics solve at one exact
   point of it certifies its count and aspect split for every point of every
   voxel of the cell (closed voxels included).

What is NOT certified: two cells with the same count may be parts of one true
component of (joint box minus g(S)) joined through the marked layer; cells with
different counts are certainly different.  Cells whose solve could not be
completed (or that were not solved because of the solve budget) keep count -1.
"""

from __future__ import annotations

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.kinematics.quadratic import rho_sq_tight
from intervalkin.paving.labels import Label
from intervalkin.paving.predicates import pave_workspace

__all__ = ['singular_image', 'solution_count']


def singular_image(geometry: Geometry, boxes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Interval images g(b) of workspace boxes (m, 3, 2): (lo, hi) each (m, 3) in rho. Certified."""

    r = [v.sqrt() for v in rho_sq_tight(geometry, np.asarray(boxes, dtype=np.float64))]
    lo = np.stack([np.asarray(ri.lo) for ri in r], axis=1)
    hi = np.stack([np.asarray(ri.hi) for ri in r], axis=1)
    return lo, hi




def pave_singular_layer(geometry: Geometry, depth: int, progress=None) -> np.ndarray:
    """Workspace boxes (m, 3, 2) at ``depth`` covering every singular point of W.

    A paving that splits only the boxes that may hold a singular point of W
    (det A sign undecided and not certainly outside W): the layer is a surface,
    so its size grows about 4x per level, not 8x.  Every other box is certified
    free of singular points of W.
    """

    def split(labels):
        return (labels["W"] != Label.OUTSIDE) & (labels["det_positive"] == Label.BOUNDARY)

    p = pave_workspace(geometry, depth, progress=progress, split=split)
    sel = split(p.labels)
    return p.boxes[sel]
