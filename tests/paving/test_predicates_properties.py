"""Properties of the paving predicates: every INSIDE or OUTSIDE label holds at every point of its box.

For W (joint limits), the sign of det A and the aspects WA1 / WA2, a box is drawn (anywhere,
thin, across or on the seam phi = +-pi, near det A = 0, near a joint limit, or with a corner on
an exactly singular pose), labelled by the vectorized predicate, and its corners and interior
points are evaluated in arb at 256 bits by an independent model written here from DESIGN.md
section 2 (B_i from the exact platform points, det A as the determinant of the 3x3 matrix with
rows 2 (u_i, r_i x u_i)), with the geometry's exact decimals.  A label is wrong when arb
certifies the opposite at some point.  Big runs are marked ``slow``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from flint import arb, arb_mat, ctx, fmpq
from hypothesis import given, settings
from hypothesis import strategies as st

from intervalkin.core.geometry import default_geometry, load_geometry
from intervalkin.kinematics.formulas import approx_det_a, approx_inverse_kinematics
from intervalkin.paving.labels import Label
from intervalkin.paving.predicates import aspect_labels, aspect_predicate, det_sign_labels, workspace_labels

from ..conftest import DATA

PREC = 256
GEOMETRIES = {
    "paper": default_geometry(),
    "offset_right": load_geometry(DATA / "offset_right.toml"),
    "coords_platform": load_geometry(DATA / "coords_platform.toml"),
    "concurrent_legs": load_geometry(DATA / "concurrent_legs.toml"),
}
KINDS = ("random", "thin", "seam", "singular", "limit", "exact_singular")


# --------------------------------------------------------------------------------------
# The independent reference: arb at 256 bits, exact geometry
# --------------------------------------------------------------------------------------
class _Exact:
    """rho_i^2 and det A of one geometry in arb, from its exact numbers (built at PREC bits)."""

    def __init__(self, g):
        def q(v):
            return arb(fmpq(v.numerator, v.denominator))

        self.a = [(q(ax), q(ay)) for ax, ay in g.base]
        self.p = [tuple(c.arb() for c in g.platform_point(i)) for i in range(3)]
        self.rmin2 = [q(v) ** 2 for v in g.rho_min]
        self.rmax2 = [q(v) ** 2 for v in g.rho_max]

    def legs(self, pt):
        """u_i = B_i - A_i and r_i = B_i - B1 at a float point (floats are exact in arb)."""
        x, y, phi = (v if isinstance(v, arb) else arb(float(v)) for v in pt)
        c, s = phi.cos(), phi.sin()
        out = []
        for (ax, ay), (px, py) in zip(self.a, self.p):
            rx, ry = px * c - py * s, px * s + py * c
            out.append((x + rx - ax, y + ry - ay, rx, ry))
        return out

    def in_w(self, pt):
        """True / False when arb decides rho_min_i^2 <= rho_i^2 <= rho_max_i^2 for all legs."""
        rs = [ux * ux + uy * uy for ux, uy, _, _ in self.legs(pt)]
        if any(r < lo or r > hi for r, lo, hi in zip(rs, self.rmin2, self.rmax2)):
            return False
        assert all(r >= lo and r <= hi for r, lo, hi in zip(rs, self.rmin2, self.rmax2)), "arb undecided"
        return True

    def det(self, pt):
        rows = [[2 * ux, 2 * uy, 2 * (rx * uy - ry * ux)] for ux, uy, rx, ry in self.legs(pt)]
        return arb_mat(rows).det()


_EXACT: dict[str, _Exact] = {}


def _exact(name: str) -> _Exact:
    if name not in _EXACT:
        with ctx.workprec(PREC):
            _EXACT[name] = _Exact(GEOMETRIES[name])
    return _EXACT[name]


# --------------------------------------------------------------------------------------
# Boxes
# --------------------------------------------------------------------------------------
def _root_along_x(f, y: float, phi: float, xs: np.ndarray, pick: int) -> float | None:
    """A root of x -> f(x, y, phi) (float) between grid points of xs, refined by bisection."""
    v = f(np.column_stack([xs, np.full_like(xs, y), np.full_like(xs, phi)]))
    idx = np.flatnonzero(np.sign(v[:-1]) * np.sign(v[1:]) < 0)
    if idx.size == 0:
        return None
    i = idx[pick % idx.size]
    lo, hi, flo = xs[i], xs[i + 1], v[i]
    for _ in range(60):
        m = 0.5 * (lo + hi)
        fm = f(np.array([[m, y, phi]]))[0]
        if np.sign(fm) == np.sign(flo):
            lo, flo = m, fm
        else:
            hi = m
    return 0.5 * (lo + hi)


def _box_near(rng, pt) -> np.ndarray:
    """A small box around or next to the point: half-widths h over many scales (thin in some
    axes), the point at offset t h from the centre, t in [-f, f] with f from 0.5 (inside) to
    10 (outside): the point often sits just inside or just outside a face."""
    h = 10.0 ** rng.uniform(-9, -1.5, 3) * np.array([1.0, 1.0, 0.1])
    f = rng.choice([0.5, 0.9, 1.0, 1.1, 2.0, 10.0], 3)
    c = np.asarray(pt, dtype=np.float64) - rng.uniform(-1, 1, 3) * f * h
    return np.stack([c - h, c + h], axis=1)


def draw_box(name: str, kind: str, seed: int) -> np.ndarray:
    """One box (3, 2) of the given kind for geometry ``name``, from a seeded RNG."""
    g = GEOMETRIES[name]
    rng = np.random.default_rng(seed)
    (xl, xh), (yl, yh), _ = g.workspace_domain
    xs = np.linspace(xl, xh, 257)
    y, phi = rng.uniform(yl, yh), rng.uniform(-math.pi, math.pi)
    if kind == "singular":
        x = _root_along_x(lambda X: approx_det_a(g, X), y, phi, xs, int(rng.integers(1 << 30)))
        if x is not None:
            return _box_near(rng, [x, y, phi])
    if kind == "limit":
        leg = int(rng.integers(3))
        lim = float((g.rho_min if rng.uniform() < 0.5 else g.rho_max)[leg])
        x = _root_along_x(lambda X: approx_inverse_kinematics(g, X)[:, leg] - lim, y, phi, xs,
                          int(rng.integers(1 << 30)))
        if x is not None:
            return _box_near(rng, [x, y, phi])
    if kind == "exact_singular" and name == "concurrent_legs":
        return _boxes_at_concurrent_pose(rng, 1)[0]
    c = np.array([rng.uniform(xl, xh), y, phi])
    h = 10.0 ** rng.uniform(-6, 0.5, 3) * np.array([1.0, 1.0, 0.1])
    if kind == "thin":
        h[rng.uniform(size=3) < 0.5] = rng.choice([0.0, 1e-12])
    if kind == "seam":
        # across phi = +-pi (unwrapped), or ending exactly on the float seam of the paving domain
        a, b = 10.0 ** rng.uniform(-7, -0.5, 2)
        side = rng.choice([-1.0, 1.0])
        seam = [(side * math.pi - a, side * math.pi + b), (math.pi - a, math.pi), (-math.pi, -math.pi + b)]
        plo, phi_hi = seam[int(rng.integers(3))]
        return np.array([[c[0] - h[0], c[0] + h[0]], [c[1] - h[1], c[1] + h[1]], [plo, phi_hi]])
    return np.stack([c - h, c + h], axis=1)


def _boxes_at_concurrent_pose(rng, n: int) -> np.ndarray:
    """concurrent_legs.toml: det A = 0 exactly at X* = (3, 4, atan2(1, 9)) (the legs meet at the
    origin).  Boxes (n, 3, 2) holding X*, often with x = 3 or y = 4 as a face, the phi range
    reaching at least one float past the nearest float to atan2(1, 9) on each side."""
    phi = math.atan2(1, 9)
    c = np.array([3.0, 4.0, phi])
    w = 10.0 ** rng.uniform(-12, -1, (n, 3))
    t = rng.uniform(0, 1, (n, 3))
    t[:, :2][rng.uniform(size=(n, 2)) < 0.5] = rng.choice([0.0, 1.0])
    lo, hi = c - t * w, c + (1 - t) * w
    lo[:, 2] = np.minimum(lo[:, 2], math.nextafter(phi, -math.inf))
    hi[:, 2] = np.maximum(hi[:, 2], math.nextafter(phi, math.inf))
    return np.stack([lo, hi], axis=-1)


def box_points(box: np.ndarray, fractions) -> list[np.ndarray]:
    """The 8 corners and the interior points lo + f (hi - lo), f in ``fractions`` (clipped into the box)."""
    corners = [np.array([box[j, (m >> j) & 1] for j in range(3)]) for m in range(8)]
    inner = [np.clip(box[:, 0] + np.asarray(f) * (box[:, 1] - box[:, 0]), box[:, 0], box[:, 1]) for f in fractions]
    return corners + inner


# --------------------------------------------------------------------------------------
# The label checks: boxes (n, 3, 2) of one geometry, labelled in one call; each returns
# the (box index, point) pairs where arb contradicts a label
# --------------------------------------------------------------------------------------
def w_violations(name: str, boxes: np.ndarray, fractions) -> list:
    labels = workspace_labels(GEOMETRIES[name], boxes)
    ex = _exact(name)
    bad = []
    with ctx.workprec(PREC):
        for k in np.flatnonzero(labels != Label.BOUNDARY):
            bad += [(k, p) for p in box_points(boxes[k], fractions) if ex.in_w(p) != (labels[k] == Label.INSIDE)]
    return bad


def det_violations(name: str, boxes: np.ndarray, fractions) -> list:
    labels = det_sign_labels(GEOMETRIES[name], boxes)
    ex = _exact(name)
    bad = []
    with ctx.workprec(PREC):
        for k in np.flatnonzero(labels != Label.BOUNDARY):
            for p in box_points(boxes[k], fractions):
                det = ex.det(p)
                if not ((det > 0) if labels[k] == Label.INSIDE else (det < 0)):
                    bad.append((k, p))
    return bad


def aspect_violations(name: str, boxes: np.ndarray, fractions) -> list:
    """WA1 / WA2 from :func:`aspect_labels` and from the single :func:`aspect_predicate`."""
    g = GEOMETRIES[name]
    wa1, wa2 = aspect_labels(workspace_labels(g, boxes), det_sign_labels(g, boxes))
    labelled = [(+1, wa1), (-1, wa2), (+1, aspect_predicate(g, +1)(boxes)), (-1, aspect_predicate(g, -1)(boxes))]
    ex = _exact(name)
    bad = []
    with ctx.workprec(PREC):
        for sign, labels in labelled:
            for k in np.flatnonzero(labels != Label.BOUNDARY):
                for p in box_points(boxes[k], fractions):
                    det = ex.det(p)
                    in_aspect = ((det > 0) if sign > 0 else (det < 0)) and ex.in_w(p)
                    off_aspect = ((det < 0) if sign > 0 else (det > 0)) or det == 0 or not ex.in_w(p)
                    if not (in_aspect if labels[k] == Label.INSIDE else off_aspect):
                        bad.append((k, p))
    return bad


# --------------------------------------------------------------------------------------
# Properties: each example checks one box of every kind for every geometry
# --------------------------------------------------------------------------------------
cases = st.tuples(st.integers(0, 2**32 - 1 - len(KINDS)),
                  st.lists(st.lists(st.floats(0, 1), min_size=3, max_size=3), min_size=1, max_size=3))


def _property(check, examples: int):
    @settings(max_examples=examples, deadline=None, derandomize=True)
    @given(case=cases)
    def prop(case):
        seed, fractions = case
        for name in GEOMETRIES:
            boxes = np.stack([draw_box(name, kind, seed + j) for j, kind in enumerate(KINDS)])
            bad = check(name, boxes, fractions)
            assert not bad, (name, seed, [(KINDS[k], boxes[k].tolist(), p.tolist()) for k, p in bad[:3]])

    return prop


test_w_labels_hold_in_arb = _property(w_violations, 40)
test_det_sign_labels_hold_in_arb = _property(det_violations, 40)
test_aspect_labels_hold_in_arb = _property(aspect_violations, 25)
test_w_labels_hold_in_arb_many = pytest.mark.slow(_property(w_violations, 160))
test_det_sign_labels_hold_in_arb_many = pytest.mark.slow(_property(det_violations, 160))
test_aspect_labels_hold_in_arb_many = pytest.mark.slow(_property(aspect_violations, 100))


def test_drawn_boxes_get_decided_labels_of_every_kind():
    """The properties are not vacuous: the drawn boxes include many INSIDE and OUTSIDE labels."""
    seen = {}
    for name in GEOMETRIES:
        for kind in KINDS:
            boxes = np.stack([draw_box(name, kind, s) for s in range(40)])
            g = GEOMETRIES[name]
            w, d = workspace_labels(g, boxes), det_sign_labels(g, boxes)
            for key, lab in (("W", w), ("det", d)) + tuple(zip(("WA1", "WA2"), aspect_labels(w, d))):
                for v in (Label.INSIDE, Label.OUTSIDE):
                    seen[(key, kind, int(v))] = seen.get((key, kind, int(v)), 0) + int(np.sum(lab == v))
    for key in ("W", "det", "WA1", "WA2"):
        for kind in ("random", "thin", "seam", "singular", "limit"):
            assert seen[(key, kind, int(Label.INSIDE))] + seen[(key, kind, int(Label.OUTSIDE))] > 0, (key, kind)
    # near det A = 0 and near the limits both signs are decided on some boxes
    assert seen[("det", "singular", int(Label.INSIDE))] > 0 and seen[("det", "singular", int(Label.OUTSIDE))] > 0
    assert seen[("W", "limit", int(Label.INSIDE))] > 0 and seen[("W", "limit", int(Label.OUTSIDE))] > 0


def test_exactly_singular_pose_is_never_decided():
    """concurrent_legs.toml: det A = 0 exactly at X* = (3, 4, atan2(1, 9)); no box holding X* gets a det sign."""
    g = GEOMETRIES["concurrent_legs"]
    with ctx.workprec(PREC):
        det = _exact("concurrent_legs").det([arb(3), arb(4), arb.atan2(arb(1), arb(9))])
        assert det.contains(0) and det.rad() < 1e-60
    boxes = _boxes_at_concurrent_pose(np.random.default_rng(4), 300)
    assert np.all(det_sign_labels(g, boxes) == Label.BOUNDARY)
    assert not np.any(aspect_labels(workspace_labels(g, boxes), det_sign_labels(g, boxes))[0] == Label.INSIDE)
