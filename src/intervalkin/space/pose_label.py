"""The certified labels of one exact pose: from the boxes that hold it, from the pose itself, and nearby.

A pose X = (x, y, phi) is read exactly (decimal text or Fractions; phi in
radians, any value).  phi is reduced modulo 2 pi into (-pi, pi]: when it
already lies there it stays exact, otherwise the reduced angle phi - 2 pi k is
irrational and is carried as exact rational bounds around it, computed in arb
(:func:`pose_enclosure`).  A pose whose (x, y) lies outside the paved domain is
refused (:class:`~intervalkin.core.errors.InputError`): the domain holds the
whole workspace, and a lookup there would say nothing.

Three sources of certified labels, merged by :func:`label_pose_in`:

* **the boxes holding the pose.**  A float filter that cannot lose a box, then
  an exact comparison of the box bounds (binary fractions) with the pose's
  enclosure; only boxes that contain the whole enclosure are consulted (they
  certainly hold the pose).  A box is closed, so a pose on a shared face lies
  in every box around it, and each is consulted.  A certified label of any of
  them holds at the pose.
* **the pose itself.**  A pose is a point: rho_i^2 and det A at the point are
  evaluated in arb (:func:`point_labels`), which proves W membership and the
  sign of det A wherever the point is not on the boundary of W or on the
  singular surface, whatever the paving's depth.
* **a path to a labelled box** (:mod:`intervalkin.space.pose_path`), when the
  boxes leave the basic region undecided: a segment from the pose into a box of
  a basic region, proved inside W with its joint image clear of g(S), puts the
  pose in that region.

The uniqueness domain is the group of the partition found that holds the
pose's basic region: the region is certified, the partition is found, not proved.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Sequence

import numpy as np
from flint import arb, ctx, fmpq

from intervalkin.core.errors import InputError
from intervalkin.core.exact import exact_text, fraction_bounds
from intervalkin.core.geometry import Geometry
from intervalkin.core.status import Status
from intervalkin.kinematics.formulas import det_a_arb, rho_sq_arb
from intervalkin.space.joint_route import JointGrid
from intervalkin.space.pose_path import path_to_region

__all__ = ["PoseLabel", "LabelledBoxes", "read_pose", "pose_enclosure", "boxes_containing", "boxes_holding",
           "point_labels", "label_from_boxes", "check_pose_domain", "label_pose_in"]

Pose = tuple[Fraction, Fraction, Fraction]
#: An exact enclosure of a pose: (lo, hi) rational bounds per coordinate (lo == hi when exact).
PoseBounds = tuple[tuple[Fraction, Fraction], tuple[Fraction, Fraction], tuple[Fraction, Fraction]]

#: arb precisions (bits) tried, in turn, for the reduced angle and for the point labels.
PRECISIONS = (128, 256, 512, 1024, 2048)


@dataclass(frozen=True)
class PoseLabel:
    """Certified aspect, basic region and uniqueness domain of one pose.

    Attributes
    ----------
    pose : the exact pose (x, y, phi) as given.
    boxes : number of paving boxes certainly holding the pose.
    in_workspace : True / False when certified inside / outside W, None when undecided.
    aspect : ``"WA1"`` (det A > 0) or ``"WA2"`` (det A < 0) when certified, else None.
    basic_region : id of the certified basic region, else None.
    uniqueness_domain : the group of the partition found holding that region, else None.
    status : CERTIFIED when everything asked is decided (a basic region, or outside W),
        UNDECIDED otherwise (a value that is not None is still certified).
    why : what decided the answer, or what is missing.
    phi_reduced : exact bounds (lo, hi) of phi reduced into (-pi, pi] when phi was
        outside that range (the reduced angle is irrational), else None.
    """

    pose: Pose
    boxes: int
    in_workspace: bool | None
    aspect: str | None
    basic_region: int | None
    uniqueness_domain: int | None
    status: Status
    why: str
    phi_reduced: tuple[Fraction, Fraction] | None = None


@dataclass(frozen=True)
class LabelledBoxes:
    """The columns of a paving that a pose lookup reads (in memory, or from ``workspace.npz``).

    ``lo``, ``hi`` (n, 3) box bounds; ``domain`` (3, 2) the paved box; ``in_workspace``
    and ``det_sign`` (n,) signed labels (1 certified inside W / det A > 0, -1 certified
    outside / det A < 0, 0 undecided); ``region`` and ``uniqueness_domain`` (n,) ids, -1 for none.
    """

    lo: np.ndarray
    hi: np.ndarray
    domain: np.ndarray
    in_workspace: np.ndarray
    det_sign: np.ndarray
    region: np.ndarray
    uniqueness_domain: np.ndarray


def read_pose(values: Sequence) -> Pose:
    """Three exact numbers (x, y, phi) from decimal text, ints, Decimals or Fractions.

    Floats are read through their shortest decimal text (0.1 is 1/10).  Raises
    :class:`InputError` naming the pose when a value is not a finite number
    within the float range (no paving box lies beyond it).
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


def _arb(q: Fraction) -> arb:
    return arb(fmpq(q.numerator, q.denominator))


def _fraction(x: arb) -> Fraction:
    """The exact value of an exact arb (an end point of a ball)."""
    m, e = x.man_exp()
    return Fraction(int(m)) * (Fraction(2) ** int(e))


def _ends(x: arb) -> tuple[Fraction, Fraction]:
    return _fraction(x.lower()), _fraction(x.upper())


def pose_enclosure(pose: Pose, prec: int = PRECISIONS[0]) -> PoseBounds:
    """Exact bounds of the pose with phi reduced modulo 2 pi into (-pi, pi].

    phi - 2 pi k lies in (-pi, pi] for k = ceil((phi - pi) / (2 pi)), a quotient
    that is never an integer (pi is irrational, phi rational); k is found in arb
    at ``prec`` bits plus the size of phi, more when the ball still meets an
    integer.  k = 0 leaves phi exact; otherwise the bounds are the end points of
    the arb ball of phi - 2 pi k (about 2**-prec wide).
    """
    x, y, phi = pose
    bits = prec + max(0, abs(phi).numerator.bit_length() - abs(phi).denominator.bit_length())
    while True:
        with ctx.workprec(bits):
            pi = arb.pi()
            lo, hi = _ends((_arb(phi) - pi) / (2 * pi))
            k = math.floor(lo) + 1
            if math.floor(hi) + 1 != k:  # the ball meets an integer: not separated yet
                bits *= 2
                continue
            if k == 0:
                return (x, x), (y, y), (phi, phi)
            return (x, x), (y, y), _ends(_arb(phi) - 2 * k * pi)


def boxes_containing(lo: np.ndarray, hi: np.ndarray, bounds: PoseBounds) -> tuple[np.ndarray, np.ndarray]:
    """(containing, meeting): indices of the closed boxes [lo, hi] (arrays (n, 3)) that contain the whole
    enclosure ``bounds``, and of those that meet it.

    The float filter keeps every box that meets the float hull of the enclosure
    (:func:`~intervalkin.core.exact.fraction_bounds`); the kept few are then
    compared exactly.
    """
    below = np.array([fraction_bounds(a)[0] for a, _ in bounds])
    above = np.array([fraction_bounds(b)[1] for _, b in bounds])
    candidates = np.flatnonzero(np.all((lo <= above) & (below <= hi), axis=1))
    contain, meet = [], []
    for i in candidates:
        box = [(Fraction(float(lo[i, j])), Fraction(float(hi[i, j]))) for j in range(3)]
        if all(b_lo <= a and b <= b_hi for (a, b), (b_lo, b_hi) in zip(bounds, box)):
            contain.append(int(i))
        if all(b_lo <= b and a <= b_hi for (a, b), (b_lo, b_hi) in zip(bounds, box)):
            meet.append(int(i))
    return np.array(contain, dtype=np.int64), np.array(meet, dtype=np.int64)


def boxes_holding(lo: np.ndarray, hi: np.ndarray, pose: Pose) -> np.ndarray:
    """Indices of the closed boxes [lo, hi] (arrays (n, 3)) that contain the exact pose (phi not reduced)."""
    return boxes_containing(lo, hi, tuple((v, v) for v in pose))[0]  # type: ignore[arg-type]


def point_labels(geometry: Geometry, bounds: PoseBounds) -> tuple[bool | None, int]:
    """(in W, sign of det A) at the pose itself, proved in arb: True / False / None and 1 / -1 / 0.

    W is closed (rho_min_i <= rho_i <= rho_max_i): inside is proved by strict
    inequalities, outside by one strict violation; a pose on the boundary of W
    stays None, a singular pose (det A = 0) stays 0, whatever the precision.
    """
    in_w: bool | None = None
    sign = 0
    for prec in PRECISIONS:
        with ctx.workprec(prec):
            x, y, phi = (_arb(a).union(_arb(b)) for a, b in bounds)
            r2 = rho_sq_arb(geometry, x, y, phi)
            lo_w = [_arb(v * v) for v in geometry.rho_min]
            hi_w = [_arb(v * v) for v in geometry.rho_max]
            if all(r > a and r < b for r, a, b in zip(r2, lo_w, hi_w)):
                in_w = True
            elif any(r < a or r > b for r, a, b in zip(r2, lo_w, hi_w)):
                in_w = False
            det = det_a_arb(geometry, x, y, phi)
            sign = 1 if det > 0 else -1 if det < 0 else 0
        if in_w is not None and (sign != 0 or in_w is False):
            break
    return in_w, sign


def label_from_boxes(pose: Pose, in_workspace: np.ndarray, det_sign: np.ndarray, region: np.ndarray,
                     domain: np.ndarray) -> PoseLabel:
    """The label of a pose from the columns of the boxes certainly holding it (arrays (k,)).

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
    if aspect is not None:
        why = (f"certified in {aspect}, but the boxes holding the pose may meet a characteristic surface, or "
               "their sheet is not identified at this depth")
    else:
        why = "the boxes holding the pose are on the undecided layer of W or of det A = 0 at this depth"
    return PoseLabel(pose, boxes, True if inside_w else None, aspect, None, None, Status.UNDECIDED, why)


def check_pose_domain(pose: Pose, domain: np.ndarray) -> None:
    """Refuse (InputError, one line) a pose whose x or y lies outside the paved domain (3, 2)."""
    for j, name in ((0, "x"), (1, "y")):
        lo, hi = (Fraction(float(v)) for v in domain[j])
        if not lo <= pose[j] <= hi:
            raise InputError(f"pose: {name} = {exact_text(pose[j])} is outside the paved domain "
                             f"[{float(lo):g}, {float(hi):g}] of {name}, which holds the whole workspace")


def label_pose_in(paving: LabelledBoxes, pose: Sequence, geometry: Geometry | None = None,
                  grid: JointGrid | None = None, refine: bool = True) -> PoseLabel:
    """Certified labels of a pose: the boxes holding it, then (with ``geometry``) the point and a path.

    ``grid`` (the joint cells) guides the search for a path through joint space
    (:func:`~intervalkin.space.pose_path.path_to_region`).  The search costs up
    to a few seconds when it fails (a pose on or near a characteristic surface);
    ``refine=False`` skips it (the point's own labels are still proved).

    Raises :class:`InputError` when the pose is not three finite numbers or its
    (x, y) lies outside the paved domain.
    """
    exact = read_pose(pose)
    check_pose_domain(exact, paving.domain)
    for prec in PRECISIONS:
        bounds = pose_enclosure(exact, prec)
        idx, meet = boxes_containing(paving.lo, paving.hi, bounds)
        if idx.size or not meet.size:
            break  # otherwise the enclosure straddles a face: narrow it
    reduced = None if bounds[2][0] == bounds[2][1] == exact[2] else bounds[2]
    lab = label_from_boxes(exact, paving.in_workspace[idx], paving.det_sign[idx], paving.region[idx],
                           paving.uniqueness_domain[idx])
    lab = PoseLabel(*[getattr(lab, f) for f in ("pose", "boxes", "in_workspace", "aspect", "basic_region",
                                                 "uniqueness_domain", "status", "why")], phi_reduced=reduced)
    if geometry is None or lab.in_workspace is False or lab.basic_region is not None:
        return lab
    in_w, sign = point_labels(geometry, bounds)
    box_sign = {"WA1": 1, "WA2": -1}.get(lab.aspect or "", 0)
    # a certified box label and the point's own proof cannot disagree
    assert not (lab.in_workspace is True and in_w is False) and not (box_sign and sign and box_sign != sign), \
        f"the point labels of {exact} contradict the paving's certified labels"
    if in_w is False:
        return PoseLabel(exact, lab.boxes, False, None, None, None, Status.CERTIFIED,
                         "the pose is certified outside the workspace W (a leg length outside its limits, "
                         "proved in arb at the pose)", reduced)
    in_w = True if lab.in_workspace else in_w
    sign = sign or box_sign
    aspect = {1: "WA1", -1: "WA2"}.get(sign)
    if in_w is None or aspect is None:
        missing = ("on the boundary of W (a leg at a joint limit)" if in_w is None else
                   "on the singular surface det A = 0, or too close to it for the precision tried")
        return PoseLabel(exact, lab.boxes, in_w, aspect, None, None, Status.UNDECIDED,
                         f"the pose is {missing}: no aspect or basic region can be given", reduced)
    if not refine:
        return PoseLabel(exact, lab.boxes, True, aspect, None, None, Status.UNDECIDED,
                         f"certified in {aspect} (W and the sign of det A proved at the pose); basic region "
                         "undecided: the boxes holding the pose may meet a characteristic surface, and no local "
                         "refinement was asked", reduced)
    found = path_to_region(geometry, bounds, sign, paving, grid)
    if found.region is None:
        return PoseLabel(exact, lab.boxes, True, aspect, None, None, Status.UNDECIDED,
                         f"certified in {aspect} (W and the sign of det A proved at the pose); basic region "
                         f"undecided: {found.why}", reduced)
    return PoseLabel(exact, lab.boxes, True, aspect, found.region, found.domain, Status.CERTIFIED,
                     f"certified in {aspect} at the pose; {found.why}", reduced)
