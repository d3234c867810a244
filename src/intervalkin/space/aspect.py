"""Tri-state predicates over arrays of boxes: joint limits (W), det A sign, aspects.

Every function here takes boxes of shape (n, 3, 2) (x, y, phi; phi in radians) and
returns (n,) ``uint8`` :class:`~intervalkin.paving.labels.Label` arrays.  A label is made
only from outward-rounded :class:`~intervalkin.core.interval.Interval` operations, never
from a float comparison of approximate values.

Tight enclosures (what decides the undecided layer)
---------------------------------------------------

Both rho_i^2 and det A are, for fixed phi, polynomials of degree 2 in (x, y)
(kinematics module docstring).  Write Q = det A / 8 with X = x - a1x, Y = y - a1y:

    Q = a X^2 + b X Y + c Y^2 + d X + e Y,

where a..e are trigonometric polynomials in phi (products of the components of
r_2 = R(phi) p_2 and r_3 = R(phi) p_3 and the base offsets).  For every box:

1. the phi-dependent coefficients are enclosed once per distinct phi interval of
   the array (a paving level has at most 2**level of them), at the ends and the
   middle of the phi interval (thin), and over the whole interval (hull over 8
   sub-intervals), together with their phi-derivatives (forward mode);
2. a quadratic with given coefficients is enclosed over the (x, y) rectangle by its
   exact Taylor expansion at the centre, Q(m) + grad Q(m).(u, v) + a u^2 + b u v
   + c v^2 (no gradient overestimation; only the u v term is loose);
3. three sound enclosures are intersected: the centred form in phi
   Q(x, y, phi_m) + dQ/dphi(box) (phi - phi_m); the natural form in phi (coefficient
   ranges); and, where dQ/dphi(box) has a certified sign, monotonicity in phi
   (the minimum and maximum lie on the faces phi = phi_lo, phi = phi_hi).

rho_i^2 = (x - a_ix + r_ix)^2 + (y - a_iy + r_iy)^2 gets the same treatment: its
phi-derivative is 2 (r_ix (y - a_iy) - r_iy (x - a_ix)), linear in (x, y), and for
fixed phi the two squares are enclosed exactly.
"""

from __future__ import annotations

import numpy as np

from intervalkin.paving.adjacency import component_labels, shares_face
from intervalkin.paving.labels import Label
from intervalkin.paving.tree import Paving

__all__ = ['aspect_components']


def aspect_components(paving: Paving, edges: np.ndarray | None = None):
    """The aspects as connected components of INSIDE boxes of each sign of det A.

    Parameters
    ----------
    paving : a paving from :func:`pave_workspace` (labels WA1, WA2).
    edges : its face adjacency (2, m); computed with the phi seam when None.

    Returns
    -------
    aspect : ndarray (n,) int32, the component id of each box, -1 for boxes not
        certified in an aspect.  WA1 components come first (ids 0..c1-1), then WA2
        components, each group ordered by decreasing number of boxes.
    info : list of dicts (id, sign (+1 for det A > 0), boxes, volume), one per component.

    What is certified: each component is a union of face-adjacent boxes on which
    W holds and det A has the stated sign, so it is connected and lies inside one
    aspect.  Components of OPPOSITE signs lie in different aspects (the sign is the
    witness).  Two components of the SAME sign are not proved to be different
    aspects: they may be joined through the undecided layer, so the number of
    components of one sign is only an upper bound of the number of aspects of that
    sign seen at this depth, and each aspect met contains at least one of them.
    """

    if edges is None:
        edges = shares_face(paving.level, paving.ijk, paving.depth)
    n = len(paving)
    vol = paving.volume()
    aspect = np.full(n, -1, dtype=np.int32)
    info = []
    base = 0
    for name, sign in (("WA1", 1), ("WA2", -1)):
        comp = component_labels(n, edges, paving.labels[name] == Label.INSIDE)
        m = comp >= 0
        aspect[m] = comp[m] + base
        ncomp = int(comp.max()) + 1 if np.any(m) else 0
        counts = np.bincount(comp[m], minlength=ncomp)
        vols = np.bincount(comp[m], weights=vol[m], minlength=ncomp)
        for c in range(ncomp):
            info.append({"id": base + c, "aspect": name, "sign": sign, "boxes": int(counts[c]), "volume": float(vols[c])})
        base += ncomp
    return aspect, info


ASPECTS = ("WA1", "WA2")
