"""Characteristic surfaces: the boxes of an aspect certified off S_c, paved with W and det A.

Definition (the paper's Definition 2; DESIGN.md section 5): the characteristic
surface of an aspect WA is S_c(WA) = {X in WA : g(X) in g(S)}, the poses that
share their joint vector with a singular pose (the joint-limit part of the
aspect's boundary maps onto the boundary of the joint box, not into g(S)).

Certified here: a workspace box b is *off S_c* (label INSIDE of ``off_Sc``) when
its interval image g(b) meets no marked voxel of the joint-space enclosure of
g(S) (:mod:`intervalkin.space.joint_space`): then no point of b has its joint
vector on g(S).  No box is ever labelled OUTSIDE (lying wholly on S_c is never
proved); the boxes of an aspect that are not certified off S_c form an outer
enclosure of S_c.  :func:`pave_regions` paves the four labels in one pass.
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
