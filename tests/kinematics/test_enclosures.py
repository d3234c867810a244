"""g, A and det A: the interval forms enclose arb at sampled points; float agrees with arb."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from flint import arb, arb_mat, ctx
from hypothesis import given, settings
from hypothesis import strategies as st

from intervalkin.core.errors import InputError
from intervalkin.core.geometry import default_geometry, load_geometry
from intervalkin.core.interval import Interval
from intervalkin.kinematics.constants import constants
from intervalkin.kinematics.enclosures import (
    det_a_gradient_interval,
    det_a_interval,
    jacobian_interval,
    rho_interval,
    rho_sq_interval,
)
from intervalkin.kinematics.formulas import (
    approx_det_a,
    approx_rho_sq,
    approx_inverse_kinematics,
    approx_jacobian,
    det_a_arb,
    det_coefficients,
    inverse_kinematics_arb,
    jacobian_arb,
    quadratic,
    quadratic_gradient,
    quadratic_with_gradient,
    rho_sq_arb,
)
from intervalkin.paving.predicates import pave_workspace

from ..conftest import DATA


@pytest.fixture(autouse=True)
def _prec():
    old = ctx.prec
    ctx.prec = 200
    yield
    ctx.prec = old


def _random_boxes(rng, n, widths):
    c = np.column_stack([rng.uniform(-32, 32, n), rng.uniform(-32, 32, n), rng.uniform(-np.pi, np.pi, n)])
    w = rng.choice(widths, size=(n, 1)) * np.array([64.0, 64.0, 2 * np.pi])
    return np.stack([c - w / 2, c + w / 2], axis=-1)


def _points_in(rng, boxes, m):
    t = rng.uniform(0, 1, (m,) + boxes.shape[:2])
    pts = boxes[None, :, :, 0] + t * (boxes[None, :, :, 1] - boxes[None, :, :, 0])
    corners = boxes[None, :, :, 0].copy()
    return np.concatenate([pts, corners, boxes[None, :, :, 1]], axis=0)


@pytest.mark.parametrize("geometry_file", [None, "offset_right.toml", "coords_platform.toml"])
def test_interval_forms_enclose_arb_values(paper_geometry, geometry_file):
    g = paper_geometry if geometry_file is None else load_geometry(DATA / geometry_file)
    rng = np.random.default_rng(11)
    boxes = _random_boxes(rng, 300, [2.0**-3, 2.0**-6, 2.0**-10, 2.0**-20])
    rho2 = rho_sq_interval(g, boxes)
    det = det_a_interval(g, boxes)
    pts = _points_in(rng, boxes, 3)
    for p in pts:
        for k in range(len(boxes)):
            x, y, phi = (arb(float(v)) for v in p[k])
            exact_r = rho_sq_arb(g, x, y, phi)
            exact_d = det_a_arb(g, x, y, phi)
            for i in range(3):
                assert not (exact_r[i] < arb(float(rho2.lo[k, i])) or exact_r[i] > arb(float(rho2.hi[k, i])))
            assert not (exact_d < arb(float(det.lo[k])) or exact_d > arb(float(det.hi[k])))


@settings(max_examples=300, deadline=None)
@given(
    st.floats(-32, 32),
    st.floats(-32, 32),
    st.floats(-np.pi, np.pi),
    st.floats(1e-12, 1.0),
)
def test_thin_boxes_enclose(x, y, phi, w):
    g = default_geometry()
    box = np.array([[[x, x + w], [y, y + w / 2], [phi, phi + w / 8]]])
    det = det_a_interval(g, box)
    exact = det_a_arb(g, arb(x), arb(y), arb(phi))
    assert not (exact < arb(float(det.lo[0])) or exact > arb(float(det.hi[0])))
    r = rho_sq_interval(g, box)
    ex = rho_sq_arb(g, arb(x + w), arb(y + w / 2), arb(phi + w / 8))
    for i in range(3):
        assert not (ex[i] < arb(float(r.lo[0, i])) or ex[i] > arb(float(r.hi[0, i])))


def test_det_formula_equals_determinant_of_jacobian(paper_geometry):
    """The quadratic form of det A is the determinant of the 3x3 Jacobian (fast vs slow path)."""
    rng = np.random.default_rng(3)
    for _ in range(50):
        x, y, phi = (arb(float(v)) for v in (rng.uniform(-30, 30), rng.uniform(-30, 30), rng.uniform(-3, 3)))
        J = jacobian_arb(paper_geometry, x, y, phi)
        d = arb_mat(J).det()
        assert abs(d - det_a_arb(paper_geometry, x, y, phi)) < 1e-20 * (1 + abs(d))


def test_quadratic_with_gradient_is_the_two_formulas_bit_for_bit():
    """The shared-product form gives the very floats of quadratic and quadratic_gradient (intervals)."""
    rng = np.random.default_rng(8)

    def iv(n):
        a, b = rng.uniform(-30, 30, (2, n))
        return Interval(np.minimum(a, b), np.maximum(a, b))

    coef, X, Y = [iv(500) for _ in range(5)], iv(500), iv(500)
    q, (gx, gy) = quadratic_with_gradient(coef, X, Y)
    for got, want in ((q, quadratic(coef, X, Y)), (gx, quadratic_gradient(coef, X, Y)[0]),
                      (gy, quadratic_gradient(coef, X, Y)[1])):
        assert np.array_equal(got.lo, want.lo) and np.array_equal(got.hi, want.hi)


def test_float_versions_agree_with_arb(paper_geometry):
    rng = np.random.default_rng(5)
    X = np.column_stack([rng.uniform(-30, 30, 200), rng.uniform(-30, 30, 200), rng.uniform(-3, 3, 200)])
    rho = approx_inverse_kinematics(paper_geometry, X)
    det = approx_det_a(paper_geometry, X)
    jac = approx_jacobian(paper_geometry, X)
    for k in range(len(X)):
        x, y, phi = (arb(float(v)) for v in X[k])
        r = inverse_kinematics_arb(paper_geometry, x, y, phi)
        assert np.allclose(rho[k], [float(v.mid()) for v in r], rtol=1e-12)
        assert abs(det[k] - float(det_a_arb(paper_geometry, x, y, phi).mid())) < 1e-9 * (1 + abs(det[k]))
        assert np.isclose(np.linalg.det(jac[k]), det[k], rtol=1e-8, atol=1e-6)


def test_paper_solutions_2_3_6_have_positive_det(paper_geometry):
    """Sign convention (DESIGN.md section 2) on the paper's Table 1 rows."""
    rows = np.array(
        [
            [-8.715, 12.183, -0.987],
            [-5.495, -13.935, -0.047],
            [-14.894, 1.596, 0.244],
            [-13.417, -6.660, 0.585],
            [14.920, -1.337, 1.001],
            [14.673, -3.013, 2.133],
        ]
    )
    signs = np.sign(approx_det_a(paper_geometry, rows))
    assert list(signs) == [-1, 1, 1, -1, -1, 1]


def _natural_det(geometry, boxes):
    """det A by the natural interval extension of the same formula (each occurrence of x, y, phi independent)."""
    k = constants(geometry)
    x, y, phi = (Interval(boxes[:, j, 0], boxes[:, j, 1]) for j in range(3))
    r = [(k.radius_iv[i] * (phi + k.alpha_iv[i]).cos(), k.radius_iv[i] * (phi + k.alpha_iv[i]).sin()) for i in (1, 2)]
    e = [(k.ax_iv[i] - k.ax_iv[0], k.ay_iv[i] - k.ay_iv[0]) for i in (1, 2)]
    coef = det_coefficients(*r[0], *r[1], *e[0], *e[1])
    return quadratic(coef, x - k.ax_iv[0], y - k.ay_iv[0]) * 8.0


def test_centred_form_sharpens_small_boxes(paper_geometry):
    rng = np.random.default_rng(9)
    boxes = _random_boxes(rng, 500, [2.0**-8])
    det = det_a_interval(paper_geometry, boxes)
    natural = _natural_det(paper_geometry, boxes)
    assert np.all(det.hi - det.lo <= natural.hi - natural.lo)
    assert np.median((det.hi - det.lo) / (natural.hi - natural.lo)) < 0.9


def test_phi_tight_det_is_sharper_than_natural_form(paper_geometry):
    """On the leaves of a depth-6 paving the phi-tight form beats the natural form of the same formula."""
    p = pave_workspace(paper_geometry, 6)
    b = p.boxes[p.level == p.depth][:5000]
    old = _natural_det(paper_geometry, b)
    new = det_a_interval(paper_geometry, b)
    assert np.median(new.hi - new.lo) < np.median(old.hi - old.lo)
    # the two sound enclosures of one quantity always intersect
    assert np.all(np.maximum(old.lo, new.lo) <= np.minimum(old.hi, new.hi))


def _arb_hull(lo: float, hi: float):
    return arb(float(lo)).union(arb(float(hi)))


def _mixed_boxes(rng, n):
    """Boxes of many sizes, some thin, some across phi = +-pi (unwrapped)."""
    boxes = _random_boxes(rng, n, [2.0**-2, 2.0**-5, 2.0**-9, 2.0**-16, 0.0])
    thin = rng.uniform(size=(n, 3)) < 0.2
    boxes[..., 1] = np.where(thin, boxes[..., 0], boxes[..., 1])
    seam = rng.uniform(size=n) < 0.2
    boxes[seam, 2] = np.pi + np.sort(rng.uniform(-0.05, 0.05, (int(seam.sum()), 2)), axis=1)
    return boxes


@pytest.mark.parametrize("geometry_file", [None, "coords_platform.toml"])
def test_jacobian_interval_encloses_arb(paper_geometry, geometry_file):
    """Every entry of A at sampled points (corners included) lies in the enclosure over the box."""
    g = paper_geometry if geometry_file is None else load_geometry(DATA / geometry_file)
    rng = np.random.default_rng(21)
    boxes = _mixed_boxes(rng, 200)
    J = jacobian_interval(g, boxes)
    assert J.lo.shape == (200, 3, 3)
    for p in _points_in(rng, boxes, 2):
        for k in range(len(boxes)):
            A = jacobian_arb(g, *(arb(float(v)) for v in p[k]))
            for i in range(3):
                for j in range(3):
                    assert not (A[i][j] < arb(float(J.lo[k, i, j])) or A[i][j] > arb(float(J.hi[k, i, j])))


def test_jacobian_is_the_gradient_of_rho_sq(paper_geometry):
    """Row i of A is grad rho_i^2: central differences of the float rho_i^2 agree with approx_jacobian."""
    rng = np.random.default_rng(8)
    X = np.column_stack([rng.uniform(-20, 20, 50), rng.uniform(-20, 20, 50), rng.uniform(-3, 3, 50)])
    h = 1e-6
    fd = np.stack([(approx_rho_sq(paper_geometry, X + h * e) - approx_rho_sq(paper_geometry, X - h * e)) / (2 * h)
                   for e in np.eye(3)], axis=-1)
    assert np.allclose(fd, approx_jacobian(paper_geometry, X), rtol=1e-6, atol=1e-5)


def test_det_gradient_satisfies_the_mean_value_theorem(paper_geometry):
    """det A(q) - det A(p) lies in grad det A(box) . (q - p) for points p, q of the box (arb)."""
    rng = np.random.default_rng(12)
    boxes = _mixed_boxes(rng, 150)
    G = det_a_gradient_interval(paper_geometry, boxes)
    pts = _points_in(rng, boxes, 2)
    for k in range(len(boxes)):
        for p, q in ((pts[0][k], pts[1][k]), (pts[2][k], pts[3][k]), (pts[1][k], pts[3][k])):
            ap, aq = [arb(float(v)) for v in p], [arb(float(v)) for v in q]
            diff = det_a_arb(paper_geometry, *aq) - det_a_arb(paper_geometry, *ap)
            bound = sum(_arb_hull(G.lo[k, j], G.hi[k, j]) * (aq[j] - ap[j]) for j in range(3))
            assert diff.overlaps(bound), (k, diff, bound)


def test_rho_interval_is_the_root_of_rho_sq(paper_geometry):
    rng = np.random.default_rng(2)
    boxes = _mixed_boxes(rng, 100)
    r, r2 = rho_interval(paper_geometry, boxes), rho_sq_interval(paper_geometry, boxes)
    assert r.lo.shape == r2.lo.shape == (100, 3)
    assert np.all(r.lo <= np.sqrt(np.maximum(r2.lo, 0.0))) and np.all(r.hi >= np.sqrt(r2.hi))


def test_empty_and_malformed_box_arrays(paper_geometry):
    empty = np.zeros((0, 3, 2))
    assert rho_sq_interval(paper_geometry, empty).lo.shape == (0, 3)
    assert det_a_interval(paper_geometry, empty).lo.shape == (0,)
    assert jacobian_interval(paper_geometry, empty).lo.shape == (0, 3, 3)
    with pytest.raises(InputError, match="boxes"):
        det_a_interval(paper_geometry, np.zeros((4, 3)))


def test_constants_are_cached_by_identity(paper_geometry):
    k = constants(paper_geometry)
    assert constants(paper_geometry) is k
    other = load_geometry(DATA / "offset_right.toml")
    assert constants(other) is not k and constants(other).geometry is other
    # the interval constants enclose the exact ones (arb at 200 bits)
    for i in range(3):
        px, py = paper_geometry.platform_point(i)
        radius = (px.arb() ** 2 + py.arb() ** 2).sqrt()
        assert arb(float(k.radius_iv.lo[i])) <= radius <= arb(float(k.radius_iv.hi[i]))
        lo, hi = k.rho_min_sq_iv.lo[i], k.rho_min_sq_iv.hi[i]
        v = paper_geometry.rho_min[i] ** 2
        assert Fraction(lo) <= v <= Fraction(hi)


@pytest.mark.parametrize("geometry_file", [None, "offset_right.toml"])
def test_leg_forms_enclose_arb_values(paper_geometry, geometry_file):
    """rho_i^2 at points of a box lies in the natural form and in the centred-in-phi form of rho_sq_leg_forms."""
    from intervalkin.kinematics.enclosures import rho_sq_leg_forms

    g = paper_geometry if geometry_file is None else load_geometry(DATA / geometry_file)
    rng = np.random.default_rng(12)
    boxes = _random_boxes(rng, 120, [2.0**-3, 2.0**-7, 2.0**-12])
    pts = _points_in(rng, boxes, 2)
    for leg in range(3):
        f = rho_sq_leg_forms(g, boxes, leg)
        assert np.all((boxes[:, 2, 0] <= f.phi_mid) & (f.phi_mid <= boxes[:, 2, 1]))
        for p in pts:
            x, y = Interval.point(p[:, 0]), Interval.point(p[:, 1])
            natural = (x + f.cx).sqr() + (y + f.cy).sqr()
            centred = (x + f.cx_mid).sqr() + (y + f.cy_mid).sqr() + f.slope * (Interval.point(p[:, 2]) - f.phi_mid)
            for k in range(len(boxes)):
                exact = rho_sq_arb(g, *(arb(float(v)) for v in p[k]))[leg]
                for e in (natural, centred):
                    assert not (exact < arb(float(e.lo[k])) or exact > arb(float(e.hi[k])))
