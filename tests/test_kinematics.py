"""g, A and det A: the interval forms enclose arb at sampled points; float agrees with arb."""

from __future__ import annotations

import numpy as np
import pytest
from flint import arb, arb_mat, ctx
from hypothesis import given, settings
from hypothesis import strategies as st

from intervalkin.kinematics.constants import constants
from intervalkin.kinematics.enclosures import _IntervalOps, _box_intervals, det_a_interval, rho_sq_interval
from intervalkin.kinematics.formulas import _det_formula, approx_det_a, approx_inverse_kinematics, approx_jacobian, det_a_arb, inverse_kinematics_arb, jacobian_arb, rho_sq_arb
from intervalkin.core.geometry import load_geometry

from .conftest import DATA


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
                assert not (exact_r[i] < arb(float(rho2[i].lo[k])) or exact_r[i] > arb(float(rho2[i].hi[k])))
            assert not (exact_d < arb(float(det.lo[k])) or exact_d > arb(float(det.hi[k])))


@settings(max_examples=300, deadline=None)
@given(
    st.floats(-32, 32),
    st.floats(-32, 32),
    st.floats(-np.pi, np.pi),
    st.floats(1e-12, 1.0),
)
def test_thin_boxes_enclose(x, y, phi, w):
    from intervalkin.core.geometry import default_geometry

    g = default_geometry()
    box = np.array([[[x, x + w], [y, y + w / 2], [phi, phi + w / 8]]])
    det = det_a_interval(g, box)
    exact = det_a_arb(g, arb(x), arb(y), arb(phi))
    assert not (exact < arb(float(det.lo[0])) or exact > arb(float(det.hi[0])))
    r = rho_sq_interval(g, box)
    ex = rho_sq_arb(g, arb(x + w), arb(y + w / 2), arb(phi + w / 8))
    for i in range(3):
        assert not (ex[i] < arb(float(r[i].lo[0])) or ex[i] > arb(float(r[i].hi[0])))


def test_det_formula_equals_determinant_of_jacobian(paper_geometry):
    """The quadratic form of det A is the determinant of the 3x3 Jacobian (fast vs slow path)."""
    rng = np.random.default_rng(3)
    for _ in range(50):
        x, y, phi = (arb(float(v)) for v in (rng.uniform(-30, 30), rng.uniform(-30, 30), rng.uniform(-3, 3)))
        J = jacobian_arb(paper_geometry, x, y, phi)
        d = arb_mat(J).det()
        assert abs(d - det_a_arb(paper_geometry, x, y, phi)) < 1e-20 * (1 + abs(d))


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


def test_centred_form_sharpens_small_boxes(paper_geometry):
    rng = np.random.default_rng(9)
    boxes = _random_boxes(rng, 500, [2.0**-8])
    det = det_a_interval(paper_geometry, boxes)
    # the natural form alone, for comparison
    x, y, phi = _box_intervals(boxes)
    natural = _det_formula(_IntervalOps, constants(paper_geometry), x, y, phi) * 8.0
    assert np.all(det.hi - det.lo <= natural.hi - natural.lo)
    assert np.median((det.hi - det.lo) / (natural.hi - natural.lo)) < 0.9
