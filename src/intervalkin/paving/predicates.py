"""Tri-state predicates over arrays of boxes: joint limits (W), sign of det A, the aspects.

Every label function takes boxes of shape (n, 3, 2) ((x, y, phi) x (lo, hi); phi in
radians) and returns an (n,) ``uint8`` array of :class:`~intervalkin.paving.labels.Label`:

* W (the workspace, DESIGN.md section 4): rho_min_i <= rho_i <= rho_max_i for the three
  legs.  Per leg, INSIDE when the enclosure of rho_i^2 lies in [rho_min_i^2, rho_max_i^2],
  OUTSIDE when it lies strictly below or above it; W is the AND of the three legs
  (OUTSIDE if one leg is, INSIDE only if all are).
* det A sign: INSIDE where det A > 0 on the whole box, OUTSIDE where det A < 0 on the
  whole box (both strict), BOUNDARY otherwise.
* aspects: WA1 = W and det A > 0, WA2 = W and det A < 0 (section 2's sign convention).

Certified: a label comes only from comparisons of outward-rounded enclosures
(:func:`intervalkin.kinematics.enclosures.rho_sq_interval`,
:func:`~intervalkin.kinematics.enclosures.det_a_interval`, the phi-tight forms) with
outward enclosures of the exact squared limits, never from a float value.  INSIDE
means the predicate holds at every point of the box (closed box), OUTSIDE that it fails
at every point; BOUNDARY claims nothing.  ``tests/paving/test_predicates_properties.py``
samples points of labelled boxes and checks each label in arb.
"""

from __future__ import annotations

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.kinematics.constants import constants
from intervalkin.kinematics.enclosures import det_a_interval, rho_sq_interval, rho_sq_leg_interval
from intervalkin.paving.contracted import ASPECT_NAMES, contract_labels
from intervalkin.paving.labels import Label, and_labels, not_label
from intervalkin.paving.tree import Paving, pave_multi, workspace_paving_domain

__all__ = ['WorkspacePredicate', 'workspace_labels', 'det_sign_labels', 'aspect_labels', 'workspace_predicate', 'det_sign_predicate', 'and_predicates', 'not_predicate', 'aspect_predicate', 'contract_paving', 'pave_workspace']


# --------------------------------------------------------------------------------------
# Labels
# --------------------------------------------------------------------------------------
def workspace_labels(geometry: Geometry, boxes: np.ndarray) -> np.ndarray:
    """W: rho_min_i <= rho_i <= rho_max_i for i = 1, 2, 3 (the AND of the three legs)."""
    r = rho_sq_interval(geometry, boxes)
    lab = None
    for i in range(3):
        leg = _leg_label(geometry, r.lo[:, i], r.hi[:, i], i)
        lab = leg if lab is None else and_labels(lab, leg)
    return lab


def _leg_label(geometry: Geometry, lo: np.ndarray, hi: np.ndarray, i: int) -> np.ndarray:
    """Leg i's limits as a label, from an enclosure [lo, hi] of rho_i^2."""
    k = constants(geometry)
    leg = np.full(lo.shape, Label.BOUNDARY, dtype=np.uint8)
    leg[(lo >= k.rho_min_sq_iv.hi[i]) & (hi <= k.rho_max_sq_iv.lo[i])] = Label.INSIDE
    leg[(hi < k.rho_min_sq_iv.lo[i]) | (lo > k.rho_max_sq_iv.hi[i])] = Label.OUTSIDE
    return leg


class WorkspacePredicate:
    """W as a predicate of the paver, and as the conjunction of its three legs' limits.

    ``pred(boxes)`` is :func:`workspace_labels`.  ``conjunct_labels(boxes, todo)`` labels
    only the legs asked for (``todo`` (n, 3) bool; the others come back BOUNDARY), so
    that the paver, which keeps each box's leg labels, re-evaluates in a child only the
    legs its parent left undecided (a sub-box of a box inside a leg's limits is inside
    them too): near the boundary of W usually one leg instead of three.
    """

    conjuncts = 3

    def __init__(self, geometry: Geometry):
        self.geometry = geometry

    def __call__(self, boxes: np.ndarray) -> np.ndarray:
        return workspace_labels(self.geometry, boxes)

    def conjunct_labels(self, boxes: np.ndarray, todo: np.ndarray) -> np.ndarray:
        out = np.full(todo.shape, Label.BOUNDARY, dtype=np.uint8)
        for i in range(3):
            rows = np.flatnonzero(todo[:, i])
            if rows.size:
                e = rho_sq_leg_interval(self.geometry, boxes[rows], i)
                out[rows, i] = _leg_label(self.geometry, e.lo, e.hi, i)
        return out


def det_sign_labels(geometry: Geometry, boxes: np.ndarray) -> np.ndarray:
    """Sign of det A as a label: INSIDE where det A > 0 on the whole box, OUTSIDE where
    det A < 0 on the whole box (strict both ways), BOUNDARY otherwise."""
    d = det_a_interval(geometry, boxes)
    lab = np.full(d.lo.shape, Label.BOUNDARY, dtype=np.uint8)
    lab[d.lo > 0] = Label.INSIDE
    lab[d.hi < 0] = Label.OUTSIDE
    return lab


def aspect_labels(w: np.ndarray, det_positive: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(WA1, WA2) labels: WA1 = W and det A > 0, WA2 = W and det A < 0.

    WA2 uses the negation of the det label, sound because that label's OUTSIDE
    means det A < 0 everywhere (not merely "not > 0").
    """
    return and_labels(w, det_positive), and_labels(w, not_label(det_positive))


def workspace_predicate(geometry: Geometry) -> WorkspacePredicate:
    return WorkspacePredicate(geometry)


def det_sign_predicate(geometry: Geometry):
    return lambda boxes: det_sign_labels(geometry, boxes)


def and_predicates(p, q):
    """Conjunction of two predicates (OUTSIDE if either is, INSIDE only if both are)."""
    return lambda boxes: and_labels(p(boxes), q(boxes))


def not_predicate(p):
    return lambda boxes: not_label(p(boxes))


def aspect_predicate(geometry: Geometry, sign: int):
    """WA1 (sign = +1) or WA2 (sign = -1) as a single predicate."""
    d = det_sign_predicate(geometry)
    return and_predicates(workspace_predicate(geometry), d if sign > 0 else not_predicate(d))


def contract_paving(geometry: Geometry, paving: Paving, refine: int = 0) -> dict:
    """Cut the BOUNDARY leaves of W, WA1 and WA2 into parts proved INSIDE / OUTSIDE.

    Returns name -> :class:`~intervalkin.paving.contracted.ContractedParts` (stored beside
    the grid, which is left unchanged); ``refine``: bisect-and-cut rounds of the remainders.
    """
    scale = (paving.domain[:, 1] - paving.domain[:, 0]) * 2.0 ** -paving.depth
    lab = paving.labels
    rows = np.flatnonzero(np.any([lab[n] == Label.BOUNDARY for n in ASPECT_NAMES], axis=0))
    det = lab["det_positive"][rows]
    det_sign = np.where(det == Label.INSIDE, 1, np.where(det == Label.OUTSIDE, -1, 0)).astype(np.int8)
    return contract_labels(geometry, paving.lo[rows], paving.hi[rows], rows,
                           {n: lab[n][rows] == Label.BOUNDARY for n in ASPECT_NAMES},
                           w_undecided=lab["W"][rows] == Label.BOUNDARY, det_sign=det_sign, refine=refine, scale=scale)


def pave_workspace(geometry: Geometry, depth: int, progress=None, split=None,
                   contract: bool = False, refine: int = 0) -> Paving:
    """Pave W, the sign of det A and the two aspects in one pass.

    Labels: ``W``, ``det_positive`` (INSIDE: det A > 0, OUTSIDE: det A < 0),
    ``WA1``, ``WA2``.  A box is split while W is undecided, or while W holds on it
    and the sign of det A is undecided (that is: while an aspect label is
    undecided).  det A is not evaluated on boxes certified outside W.  ``split``
    replaces that rule (labels -> bool mask of the boxes to subdivide).
    ``contract``: also cut the BOUNDARY leaves of W, WA1 and WA2 into proved parts
    (:func:`contract_paving`, ``refine`` rounds), stored in ``Paving.parts``.
    """
    def aspect_split(labels):
        w, d = labels["W"], labels["det_positive"]
        return (w == Label.BOUNDARY) | ((w == Label.INSIDE) & (d == Label.BOUNDARY))

    split = aspect_split if split is None else split

    p = pave_multi(
        workspace_paving_domain(geometry),
        [("W", workspace_predicate(geometry)), ("det_positive", det_sign_predicate(geometry))],
        depth,
        split=split,
        relevant={"det_positive": lambda labels: labels["W"] != Label.OUTSIDE},
        progress=progress,
    )
    p.labels["WA1"], p.labels["WA2"] = aspect_labels(p.labels["W"], p.labels["det_positive"])
    if contract:
        p.parts.update(contract_paving(geometry, p, refine))
    return p
