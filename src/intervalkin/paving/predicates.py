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

from intervalkin.core.exact import fraction_bounds
from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import Interval
from intervalkin.kinematics.quadratic import _det_q_tight, rho_sq_tight
from intervalkin.paving.labels import Label, and_labels, not_label
from intervalkin.paving.tree import Paving, pave_multi, workspace_paving_domain

__all__ = ['workspace_labels', 'det_sign_labels', 'aspect_labels', 'workspace_predicate', 'det_sign_predicate', 'and_predicates', 'not_predicate', 'aspect_predicate', 'pave_workspace']


# --------------------------------------------------------------------------------------
# Labels
# --------------------------------------------------------------------------------------
def _limit_sq_bounds(geometry: Geometry):
    mins = [fraction_bounds(v * v) for v in geometry.rho_min]
    maxs = [fraction_bounds(v * v) for v in geometry.rho_max]
    return mins, maxs


def _limit_label(geometry: Geometry, r: Interval, leg: int) -> np.ndarray:
    mins, maxs = _limit_sq_bounds(geometry)
    (mn_lo, mn_hi), (mx_lo, mx_hi) = mins[leg], maxs[leg]
    lab = np.full(r.lo.shape, Label.BOUNDARY, dtype=np.uint8)
    lab[(r.lo >= mn_hi) & (r.hi <= mx_lo)] = Label.INSIDE
    lab[(r.hi < mn_lo) | (r.lo > mx_hi)] = Label.OUTSIDE
    return lab


def workspace_labels(geometry: Geometry, boxes: np.ndarray) -> np.ndarray:
    """W: rho_min_i <= rho_i <= rho_max_i for i = 1, 2, 3 (the AND of the three legs)."""
    rs = rho_sq_tight(geometry, boxes)
    lab = _limit_label(geometry, rs[0], 0)
    for i in (1, 2):
        lab = and_labels(lab, _limit_label(geometry, rs[i], i))
    return lab


def det_sign_labels(geometry: Geometry, boxes: np.ndarray) -> np.ndarray:
    """Sign of det A as a label: INSIDE where det A > 0 on the whole box, OUTSIDE where
    det A < 0 on the whole box (strict both ways), BOUNDARY otherwise."""
    q = _det_q_tight(geometry, boxes)
    lab = np.full(q.lo.shape, Label.BOUNDARY, dtype=np.uint8)
    lab[q.lo > 0] = Label.INSIDE
    lab[q.hi < 0] = Label.OUTSIDE
    return lab


def aspect_labels(w: np.ndarray, det_positive: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(WA1, WA2) labels: WA1 = W and det A > 0, WA2 = W and det A < 0.

    WA2 uses the negation of the det label, sound because that label's OUTSIDE
    means det A < 0 everywhere (not merely "not > 0").
    """
    return and_labels(w, det_positive), and_labels(w, not_label(det_positive))


def workspace_predicate(geometry: Geometry):
    return lambda boxes: workspace_labels(geometry, boxes)


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


def pave_workspace(geometry: Geometry, depth: int, progress=None, split=None) -> Paving:
    """Pave W, the sign of det A and the two aspects in one pass.

    Labels: ``W``, ``det_positive`` (INSIDE: det A > 0, OUTSIDE: det A < 0),
    ``WA1``, ``WA2``.  A box is split while W is undecided, or while W holds on it
    and the sign of det A is undecided (that is: while an aspect label is
    undecided).  det A is not evaluated on boxes certified outside W.  ``split``
    replaces that rule (labels -> bool mask of the boxes to subdivide).
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
    return p
