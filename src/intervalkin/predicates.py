"""Tri-state predicates over arrays of boxes: joint limits (W), det A sign, aspects.

Every function here takes boxes of shape (n, 3, 2) (x, y, phi; phi in radians) and
returns (n,) ``uint8`` :class:`~intervalkin.paving.Label` arrays.  A label is made
only from outward-rounded :class:`~intervalkin.interval.Interval` operations, never
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

from typing import Callable

import numpy as np

from .geometry import Geometry
from .interval import Interval, fraction_bounds
from .kinematics import constants
from .paving import Label, Paving, and_labels, not_label, pave_multi, workspace_paving_domain

__all__ = [
    "rho_sq_tight",
    "det_a_tight",
    "workspace_labels",
    "det_sign_labels",
    "aspect_labels",
    "joint_limit_predicate",
    "det_sign_predicate",
    "workspace_predicate",
    "and_predicates",
    "not_predicate",
    "aspect_predicate",
    "pave_workspace",
    "WORKSPACE_LABELS",
    "aspect_components",
]

#: Label names written by :func:`pave_workspace`.
WORKSPACE_LABELS = ("W", "det_positive", "WA1", "WA2")
_SUBDIVISIONS = 8


# --------------------------------------------------------------------------------------
# Small helpers over Interval
# --------------------------------------------------------------------------------------
def _iv(lo, hi=None) -> Interval:
    lo = np.asarray(lo, dtype=np.float64)
    return Interval(lo, lo if hi is None else np.asarray(hi, dtype=np.float64))


def _take(x: Interval, idx: np.ndarray) -> Interval:
    lo, hi = np.broadcast_arrays(x.lo, x.hi)
    return Interval(lo[idx], hi[idx])


def _hull_last(x: Interval) -> Interval:
    """Hull over the last axis."""
    return Interval(np.min(x.lo, axis=-1), np.max(x.hi, axis=-1))


def _intersect(a: Interval, b: Interval) -> Interval:
    return a.intersect(b)


def _monotone(e: Interval, slope: Interval, at_lo: Interval, at_hi: Interval) -> Interval:
    """Intersect e with the monotonicity enclosure where the phi-slope has a certified sign."""
    up = slope.lo > 0
    down = slope.hi < 0
    lo = np.where(up, at_lo.lo, np.where(down, at_hi.lo, e.lo))
    hi = np.where(up, at_hi.hi, np.where(down, at_lo.hi, e.hi))
    return e.intersect(Interval(lo, hi))


class _Dual:
    """An Interval value with an Interval enclosure of its derivative in phi."""

    __slots__ = ("v", "d")

    def __init__(self, v: Interval, d: Interval):
        self.v, self.d = v, d

    def __add__(self, o):
        return _Dual(self.v + o.v, self.d + o.d) if isinstance(o, _Dual) else _Dual(self.v + o, self.d)

    def __sub__(self, o):
        return _Dual(self.v - o.v, self.d - o.d) if isinstance(o, _Dual) else _Dual(self.v - o, self.d)

    def __neg__(self):
        return _Dual(-self.v, -self.d)

    def __mul__(self, o):
        if isinstance(o, _Dual):
            return _Dual(self.v * o.v, self.d * o.v + self.v * o.d)
        return _Dual(self.v * o, self.d * o)


def _unique_phi(boxes: np.ndarray):
    """Distinct phi intervals of the boxes: (lo (u,), hi (u,), inverse index (n,))."""
    key = boxes[:, 2, 0] + 1j * boxes[:, 2, 1]
    u, inv = np.unique(key, return_inverse=True)
    return u.real.copy(), u.imag.copy(), inv.reshape(-1)


def _phi_samples(pl: np.ndarray, ph: np.ndarray):
    """Thin phi at lo, mid, hi (floats inside the interval) and S covering sub-intervals."""
    pm = np.minimum(np.maximum(0.5 * pl + 0.5 * ph, pl), ph)
    s = np.arange(_SUBDIVISIONS + 1, dtype=np.float64) / _SUBDIVISIONS
    cuts = pl[:, None] + (ph - pl)[:, None] * s[None, :]
    cuts[:, 0] = pl
    cuts[:, -1] = ph
    cuts = np.maximum.accumulate(np.minimum(np.maximum(cuts, pl[:, None]), ph[:, None]), axis=1)
    sub = Interval(cuts[:, :-1], cuts[:, 1:])  # consecutive pieces share their ends: they cover [pl, ph]
    return pm, sub


def _rot_dual(k, i: int, phi: Interval) -> tuple[_Dual, _Dual]:
    """r_i = L_i (cos(phi + alpha_i), sin(phi + alpha_i)) with its phi-derivative (-r_iy, r_ix)."""
    t = phi + k.alpha_iv[i]
    L = k.radius_iv[i]
    c = L * t.cos()
    s = L * t.sin()
    return _Dual(c, -s), _Dual(s, c)


# --------------------------------------------------------------------------------------
# det A
# --------------------------------------------------------------------------------------
def _det_coefficients(k, phi: Interval):
    """(a, b, c, d, e) of Q = det A / 8 as _Duals in phi, over the phi intervals given."""
    r2x, r2y = _rot_dual(k, 1, phi)
    r3x, r3y = _rot_dual(k, 2, phi)
    e2x = k.ax_iv[1] - k.ax_iv[0]
    e2y = k.ay_iv[1] - k.ay_iv[0]
    e3x = k.ax_iv[2] - k.ax_iv[0]
    e3y = k.ay_iv[2] - k.ay_iv[0]
    k2 = r2y * e2x - r2x * e2y
    k3 = r3y * e3x - r3x * e3y
    d2x, d2y = r2x - e2x, r2y - e2y
    d3x, d3y = r3x - e3x, r3y - e3y
    pX = r2y * d3y - r3y * d2y
    pY = r3x * d2y - r2x * d3y
    p0 = d2y * k3 - k2 * d3y
    rX = r2y * d3x - r3y * d2x
    rY = r3x * d2x - r2x * d3x
    r0 = d2x * k3 - k2 * d3x
    return pX, pY - rX, -rY, p0, -r0


def _quad(coef, Xm: Interval, Ym: Interval, U: Interval, V: Interval) -> Interval:
    """Enclosure of a X^2 + b XY + c Y^2 + d X + e Y for X = Xm + U, Y = Ym + V (Taylor, exact)."""
    a, b, c, d, e = coef
    q0 = Xm * (a * Xm + b * Ym + d) + Ym * (c * Ym + e)
    gx = (a * Xm) * 2.0 + b * Ym + d
    gy = b * Xm + (c * Ym) * 2.0 + e
    return q0 + gx * U + gy * V + a * U.sqr() + b * (U * V) + c * V.sqr()


def _xy_parts(boxes: np.ndarray, ox: Interval, oy: Interval):
    """Centres and offsets: X = x - ox = Xm + U over the box, same for y."""
    xl, xh = boxes[:, 0, 0], boxes[:, 0, 1]
    yl, yh = boxes[:, 1, 0], boxes[:, 1, 1]
    xm = np.minimum(np.maximum(0.5 * xl + 0.5 * xh, xl), xh)
    ym = np.minimum(np.maximum(0.5 * yl + 0.5 * yh, yl), yh)
    Xm = _iv(xm) - ox
    Ym = _iv(ym) - oy
    U = _iv(xl, xh) - xm
    V = _iv(yl, yh) - ym
    return Xm, Ym, U, V


def _det_q_tight(geometry: Geometry, boxes: np.ndarray) -> Interval:
    boxes = np.asarray(boxes, dtype=np.float64)
    k = constants(geometry)
    pl, ph, inv = _unique_phi(boxes)
    pm, sub = _phi_samples(pl, ph)
    c_lo = [c.v for c in _det_coefficients(k, _iv(pl))]
    c_mid = [c.v for c in _det_coefficients(k, _iv(pm))]
    c_hi = [c.v for c in _det_coefficients(k, _iv(ph))]
    c_rng = _det_coefficients(k, sub)
    c_val = [_hull_last(c.v) for c in c_rng]
    c_der = [_hull_last(c.d) for c in c_rng]

    def g(cs):
        return [_take(c, inv) for c in cs]

    Xm, Ym, U, V = _xy_parts(boxes, k.ax_iv[0], k.ay_iv[0])
    q_mid = _quad(g(c_mid), Xm, Ym, U, V)
    slope = _quad(g(c_der), Xm, Ym, U, V)
    dphi = _iv(boxes[:, 2, 0], boxes[:, 2, 1]) - pm[inv]
    e1 = q_mid + slope * dphi
    e2 = _quad(g(c_val), Xm, Ym, U, V)
    q = e1.intersect(e2)
    q = _monotone(q, slope, _quad(g(c_lo), Xm, Ym, U, V), _quad(g(c_hi), Xm, Ym, U, V))
    return q


def det_a_tight(geometry: Geometry, boxes: np.ndarray) -> Interval:
    """Enclosure of det A over each box, boxes (n, 3, 2) -> (n,) Interval. Certified.

    Intersection of the centred form in phi, the natural form in phi and (where the
    phi-slope has a certified sign) monotonicity, each with an exact Taylor
    enclosure in (x, y) (module docstring).  Sharper than
    :func:`intervalkin.kinematics.det_a_interval` near det A = 0.
    """
    return _det_q_tight(geometry, boxes) * 8.0


# --------------------------------------------------------------------------------------
# rho_i^2
# --------------------------------------------------------------------------------------
def rho_sq_tight(geometry: Geometry, boxes: np.ndarray) -> list[Interval]:
    """Enclosures of rho_i^2 over each box: boxes (n, 3, 2) -> three (n,) Intervals. Certified."""
    boxes = np.asarray(boxes, dtype=np.float64)
    k = constants(geometry)
    x = _iv(boxes[:, 0, 0], boxes[:, 0, 1])
    y = _iv(boxes[:, 1, 0], boxes[:, 1, 1])
    out = [(x - k.ax_iv[0]).sqr() + (y - k.ay_iv[0]).sqr()]
    pl, ph, inv = _unique_phi(boxes)
    pm, sub = _phi_samples(pl, ph)
    dphi = _iv(boxes[:, 2, 0], boxes[:, 2, 1]) - pm[inv]
    for i in (1, 2):
        X = x - k.ax_iv[i]
        Y = y - k.ay_iv[i]

        def at(phi: Interval):
            rx, ry = _rot_dual(k, i, phi)
            return _take(rx.v, inv), _take(ry.v, inv)

        def sq(rx, ry):
            return (X + rx).sqr() + (Y + ry).sqr()

        rxs, rys = _rot_dual(k, i, sub)
        Rx, Ry = _take(_hull_last(rxs.v), inv), _take(_hull_last(rys.v), inv)
        slope = (Rx * Y - Ry * X) * 2.0  # d rho_i^2 / d phi over the box
        mx, my = at(_iv(pm))
        e = sq(mx, my) + slope * dphi
        e = e.intersect(sq(Rx, Ry))
        lx, ly = at(_iv(pl))
        hx, hy = at(_iv(ph))
        e = _monotone(e, slope, sq(lx, ly), sq(hx, hy))
        out.append(e)
    return out


# --------------------------------------------------------------------------------------
# Labels
# --------------------------------------------------------------------------------------
def _limit_sq_bounds(geometry: Geometry):
    mins = [fraction_bounds(v * v) for v in geometry.rho_min]
    maxs = [fraction_bounds(v * v) for v in geometry.rho_max]
    return mins, maxs


def joint_limit_predicate(geometry: Geometry, leg: int) -> Callable[[np.ndarray], np.ndarray]:
    """Predicate rho_min_leg <= rho_leg <= rho_max_leg (leg 0, 1, 2), on rho^2 (no sqrt)."""
    def fn(boxes):
        return _limit_label(geometry, rho_sq_tight(geometry, boxes)[leg], leg)

    return fn


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
    from .paving import component_labels, shares_face

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
