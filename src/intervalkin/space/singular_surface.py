"""The type-2 singular surface S (det A = 0) inside W, and an outer enclosure of its image g(S).

A pose X of W is singular when det A(X) = 0 (paper section 2.2): there the
platform may move with locked legs, and the direct-kinematic solutions of
g(X) merge.  The singular points of W are covered by the paving boxes that may
hold one, those whose det A sign is undecided and that are not certainly
outside W (:func:`may_be_singular`); :func:`pave_singular_layer` refines only
those boxes, so the layer costs about 4x per level rather than 8x.  Every other
box is certified free of singular points of W.

The interval images g(b) of the layer's boxes (:func:`singular_image`) form an
outer enclosure of g(S) in joint space, which :mod:`intervalkin.space.joint_space`
uses to find the cells of constant solution count.
"""

from __future__ import annotations

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.kinematics.enclosures import rho_interval
from intervalkin.paving.labels import Label
from intervalkin.paving.predicates import pave_workspace

__all__ = ['may_be_singular', 'singular_image', 'pave_singular_layer']


def singular_image(geometry: Geometry, boxes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Interval images g(b) of workspace boxes (m, 3, 2): (lo, hi) each (m, 3) in rho. Certified."""
    r = rho_interval(geometry, boxes)
    return r.lo, r.hi


def may_be_singular(labels) -> np.ndarray:
    """Boxes (from their labels W and det_positive) that may hold a singular point of W."""
    return (labels["W"] != Label.OUTSIDE) & (labels["det_positive"] == Label.BOUNDARY)


def pave_singular_layer(geometry: Geometry, depth: int, progress=None) -> np.ndarray:
    """Workspace boxes (m, 3, 2) at ``depth`` covering every singular point of W.

    A paving that splits only the boxes that may hold a singular point of W
    (det A sign undecided and not certainly outside W): the layer is a surface,
    so its size grows about 4x per level, not 8x.  Every other box is certified
    free of singular points of W.
    """
    p = pave_workspace(geometry, depth, progress=progress, split=may_be_singular)
    return p.boxes[may_be_singular(p.labels)]
