"""The certified labels of one exact pose, read from the boxes that hold it.

A pose X = (x, y, phi) is read exactly (decimal text or Fractions; phi in
radians, in the paving's range [-pi, pi]: it is not reduced modulo 2 pi, which
cannot be done exactly).  The boxes of a paving that contain it are found by an
exact test: a float filter that cannot lose a box (each coordinate is enclosed
by floats lo <= v <= hi from the rounding layer, and the box bounds are compared
with those), then a comparison of the box bounds, read as exact
binary fractions, with the exact pose.  A box is closed, so a pose on a shared
face lies in every box around it, and each of them is consulted.

What is certified: a label of a box holds at every point of the closed box,
so a certified label of any box holding the pose is a label of the pose.  The
uniqueness domain is the group of the partition found that holds the pose's
basic region: the region is certified, the partition is found, not proved.

Both the in-memory analysis and the ``workspace.npz`` of an earlier run are
read through :func:`label_from_boxes`, one function for both.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Sequence

import numpy as np

from intervalkin.core.errors import InputError
from intervalkin.core.exact import fraction_bounds
from intervalkin.core.status import Status

__all__ = ["PoseLabel", "read_pose", "boxes_holding", "label_from_boxes"]

Pose = tuple[Fraction, Fraction, Fraction]


@dataclass(frozen=True)
class PoseLabel:
    """Certified aspect, basic region and uniqueness domain of one pose.

    Attributes
    ----------
    pose : the exact pose (x, y, phi).
    boxes : number of paving boxes holding the pose (0: the pose is outside the paved domain).
    in_workspace : True / False when certified inside / outside W, None when undecided.
    aspect : ``"WA1"`` (det A > 0) or ``"WA2"`` (det A < 0) when certified, else None.
    basic_region : id of the certified basic region, else None.
    uniqueness_domain : the group of the partition found holding that region, else None.
    status : CERTIFIED when everything asked is decided (a basic region, or outside W),
        UNDECIDED otherwise (a value that is not None is still certified).
    why : what decided the answer, or what is missing.
    """

    pose: Pose
    boxes: int
    in_workspace: bool | None
    aspect: str | None
    basic_region: int | None
    uniqueness_domain: int | None
    status: Status
    why: str


def read_pose(values: Sequence) -> Pose:
    """Three exact numbers (x, y, phi) from decimal text, ints, Decimals or Fractions.

    Floats are read through their shortest decimal text (0.1 is 1/10).  Raises
    :class:`InputError` naming the pose when a value is not a finite number.
    """
    text = " ".join(map(str, values)) if isinstance(values, (list, tuple)) else repr(values)
    if not isinstance(values, (list, tuple)) or len(values) != 3:
        raise InputError(f"pose: expected three numbers x, y, phi, got {text}")
    try:
        pose = tuple(Fraction(str(v).strip()) for v in values)
        for v in pose:
            float(v)  # a value too large for a float cannot be in any box
    except (ValueError, ZeroDivisionError, OverflowError):
        raise InputError(f"pose: expected three finite numbers x, y, phi, got {text}") from None
    return pose  # type: ignore[return-value]


def boxes_holding(lo: np.ndarray, hi: np.ndarray, pose: Pose) -> np.ndarray:
    """Indices of the closed boxes [lo, hi] (arrays (n, 3)) that contain the exact pose.

    The float filter keeps every box that meets the float enclosure
    [below, above] of each coordinate (:func:`~intervalkin.core.exact.fraction_bounds`);
    the kept few are then tested exactly.
    """
    below, above = np.array([fraction_bounds(v) for v in pose]).T
    candidates = np.flatnonzero(np.all((lo <= above) & (below <= hi), axis=1))
    hits = [int(i) for i in candidates
            if all(Fraction(float(lo[i, j])) <= pose[j] <= Fraction(float(hi[i, j])) for j in range(3))]
    return np.array(hits, dtype=np.int64)


def label_from_boxes(pose: Pose, in_workspace: np.ndarray, det_sign: np.ndarray, region: np.ndarray,
                     domain: np.ndarray) -> PoseLabel:
    """The label of a pose from the columns of the boxes holding it (arrays (k,)).

    ``in_workspace`` and ``det_sign`` are signed labels (1 certified inside W / det A > 0,
    -1 certified outside / det A < 0, 0 undecided); ``region`` and ``domain`` are ids, -1 for none.
    """
    inside_w = bool(np.any(in_workspace > 0))
    outside_w = bool(np.any(in_workspace < 0))
    signs = set(det_sign[in_workspace > 0].tolist()) - {0}
    regions = set(region[region >= 0].tolist())
    domains = set(domain[domain >= 0].tolist())
    # closed certified boxes around one point cannot disagree (that would be an unsound label)
    assert not (inside_w and outside_w) and len(signs) <= 1 and len(regions) <= 1 and len(domains) <= 1, \
        f"contradictory certified labels around the pose {pose}"
    boxes = int(in_workspace.size)
    if outside_w:
        return PoseLabel(pose, boxes, False, None, None, None, Status.CERTIFIED,
                         "a box holding the pose is certified outside the workspace W")
    aspect = ({1: "WA1", -1: "WA2"}[signs.pop()]) if signs else None
    rid = regions.pop() if regions else None
    did = domains.pop() if domains else None
    if rid is not None:
        why = (f"a box holding the pose is certified in {aspect}, off the characteristic surfaces, "
               f"in basic region {rid}")
        return PoseLabel(pose, boxes, True, aspect, rid, did, Status.CERTIFIED, why)
    if boxes == 0:
        why = ("no box holds the pose: it is outside the paved domain (x, y farther than rho_max from A1 are "
               "outside W; phi is looked up in [-pi, pi] only)")
    elif aspect is not None:
        why = (f"certified in {aspect}, but the boxes holding the pose may meet a characteristic surface, or "
               "their sheet is not identified at this depth")
    else:
        why = "the boxes holding the pose are on the undecided layer of W or of det A = 0 at this depth"
    return PoseLabel(pose, boxes, True if inside_w else None, aspect, None, None, Status.UNDECIDED, why)
