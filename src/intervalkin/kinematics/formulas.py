"""The formulas of the 3-RPR (g, A, det A), written once, evaluated in float and in arb.

Notation (DESIGN.md sections 1 and 2).  A pose is X = (x, y, phi), B1 = (x, y).  Leg i
has base point A_i and platform point p_i (p_1 = 0), turned by the orientation:
r_i = R(phi) p_i, so B_i = B1 + r_i.  With d_i = B1 - A_i:

    rho_i^2 = |d_i + r_i|^2                                       (inverse kinematics g)
    F_i(X, q) = rho_i(X)^2 - q_i^2,  A = dF/dX,
    row i of A = 2 (d_ix + r_ix, d_iy + r_iy, w_i),   w_i = r_i x d_i = r_ix d_iy - r_iy d_ix.

Because dr_i/dphi = (-r_iy, r_ix), the derivative of rho_i^2 in phi is 2 w_i: row i of
A is the gradient of rho_i^2, and d w_i / d phi = -(r_i . d_i) is w_i with r_i turned
by a right angle.  For det A put X = x - a_1x, Y = y - a_1y, e_i = A_i - A_1 (i = 2, 3)
and k_i = r_iy e_ix - r_ix e_iy.  Expanding det A along the structure of its rows,

    det A = 8 Q,   Q = a X^2 + b X Y + c Y^2 + d X + e Y,

a quadratic form in (X, Y) without constant term, whose coefficients are
trigonometric polynomials in phi (:func:`det_coefficients`).  det A = 0 exactly when
the three leg lines meet in one point or are parallel.

The functions :func:`leg_rho_sq`, :func:`leg_moment`, :func:`det_coefficients`,
:func:`quadratic` and :func:`quadratic_gradient` use only ``+ - *`` and so work in every
number system of the package: float arrays here (``approx_*``, not certified), arb
balls here (``*_arb``, the trusted reference, sound at any precision), and intervals
and phi-derivatives in :mod:`intervalkin.kinematics.enclosures` (certified
enclosures over boxes).  Only the rotation r_i(phi) differs between the systems: in
float L_i (cos, sin)(phi + alpha_i) with rounded constants; in arb the exact
platform point turned by the ball's cos and sin.
"""

from __future__ import annotations

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import Interval
from intervalkin.kinematics.constants import constants

__all__ = ['leg_rho_sq', 'leg_moment', 'leg_vectors', 'det_from_legs',
           'det_coefficients', 'quadratic', 'quadratic_gradient', 'quadratic_with_gradient',
           'approx_rho_sq', 'approx_inverse_kinematics', 'approx_det_a', 'approx_jacobian',
           'rho_sq_arb', 'inverse_kinematics_arb', 'det_a_arb', 'residual_arb', 'jacobian_arb']


# --------------------------------------------------------------------------------------
# The formulas, for any number system with + - *
# --------------------------------------------------------------------------------------
def _square(v):
    """v^2; over an Interval the range of the square (one occurrence of v), not v * v."""
    return v.sqr() if isinstance(v, Interval) else v * v


def leg_rho_sq(dx, dy, rx=None, ry=None):
    """rho_i^2 = |d_i + r_i|^2 from d_i = B1 - A_i and r_i = R(phi) p_i (None: p_i = 0)."""
    if rx is None:
        return _square(dx) + _square(dy)
    return _square(dx + rx) + _square(dy + ry)


def leg_moment(dx, dy, rx, ry):
    """w_i = r_i x d_i = r_ix d_iy - r_iy d_ix: half of d(rho_i^2)/d(phi), entry (i, phi) of A / 2."""
    return rx * dy - ry * dx


def det_coefficients(r2x, r2y, r3x, r3y, e2x, e2y, e3x, e3y) -> tuple:
    """(a, b, c, d, e) of Q = det A / 8 = a X^2 + b X Y + c Y^2 + d X + e Y.

    Arguments: r_2, r_3 (platform vectors at phi) and e_i = A_i - A_1.  With
    D_i = r_i - e_i (= d_i + r_i - d_1, leg i's vector relative to leg 1) and
    k_i = r_iy e_ix - r_ix e_iy, one has w_i = r_ix Y - r_iy X + k_i and
    Q = X (D_2y w_3 - w_2 D_3y) - Y (D_2x w_3 - w_2 D_3x) (row reduction of A by row 1);
    collecting powers of X and Y,

        a = r_2y D_3y - r_3y D_2y,      b = (r_3x D_2y - r_2x D_3y) - (r_2y D_3x - r_3y D_2x),
        c = r_2x D_3x - r_3x D_2x,      d = D_2y k_3 - k_2 D_3y,    e = k_2 D_3x - D_2x k_3.

    ``tests/kinematics/test_enclosures.py`` checks 8 Q against the determinant of A in arb.
    """
    k2 = r2y * e2x - r2x * e2y
    k3 = r3y * e3x - r3x * e3y
    d2x, d2y = r2x - e2x, r2y - e2y
    d3x, d3y = r3x - e3x, r3y - e3y
    a = r2y * d3y - r3y * d2y
    b = (r3x * d2y - r2x * d3y) - (r2y * d3x - r3y * d2x)
    c = -(r3x * d2x - r2x * d3x)
    d = d2y * k3 - k2 * d3y
    e = -(d2x * k3 - k2 * d3x)
    return a, b, c, d, e


def quadratic(coef, X, Y):
    """a X^2 + b X Y + c Y^2 + d X + e Y, evaluated as X (a X + b Y + d) + Y (c Y + e)."""
    a, b, c, d, e = coef
    return X * (a * X + b * Y + d) + Y * (c * Y + e)


def quadratic_gradient(coef, X, Y) -> tuple:
    """(d/dX, d/dY) of :func:`quadratic`: (2 a X + b Y + d, b X + 2 c Y + e)."""
    a, b, c, d, e = coef
    return (a * X) * 2.0 + b * Y + d, b * X + (c * Y) * 2.0 + e


def quadratic_with_gradient(coef, X, Y) -> tuple:
    """(:func:`quadratic`, :func:`quadratic_gradient`) with their common products a X, b Y, c Y
    computed once: the same operations in the same order, so bit for bit the same results."""
    a, b, c, d, e = coef
    aX, bY, cY = a * X, b * Y, c * Y
    return X * (aX + bY + d) + Y * (cY + e), (aX * 2.0 + bY + d, b * X + cY * 2.0 + e)


def leg_vectors(base, rotation, x, y, phi) -> list[tuple]:
    """[(d_ix, d_iy, r_ix, r_iy)] for the three legs; r_1 = (None, None)."""
    out = []
    for i in range(3):
        ax, ay = base[i]
        rx, ry = (None, None) if i == 0 else rotation(i, phi)
        out.append((x - ax, y - ay, rx, ry))
    return out


def det_from_legs(base, legs, x, y):
    """det A = 8 Q from the legs' rotations (any number system)."""
    (_, _, r2x, r2y), (_, _, r3x, r3y) = legs[1], legs[2]
    e2x, e2y = base[1][0] - base[0][0], base[1][1] - base[0][1]
    e3x, e3y = base[2][0] - base[0][0], base[2][1] - base[0][1]
    coef = det_coefficients(r2x, r2y, r3x, r3y, e2x, e2y, e3x, e3y)
    return quadratic(coef, x - base[0][0], y - base[0][1]) * 8


def _jacobian_rows(legs, zero) -> list[list]:
    """A = dF/dX: row i = 2 (d_ix + r_ix, d_iy + r_iy, w_i); leg 1 has w_1 = ``zero``."""
    rows = []
    for dx, dy, rx, ry in legs:
        if rx is None:
            rows.append([dx * 2, dy * 2, zero])
        else:
            rows.append([(dx + rx) * 2, (dy + ry) * 2, leg_moment(dx, dy, rx, ry) * 2])
    return rows


# --------------------------------------------------------------------------------------
# float64 (approximate: predictors, plots, tests; never a label)
# --------------------------------------------------------------------------------------
def _float_legs(geometry: Geometry, X):
    k = constants(geometry)
    X = np.asarray(X, dtype=np.float64)
    x, y, phi = X[..., 0], X[..., 1], X[..., 2]
    base = list(zip(k.ax, k.ay))

    def rotation(i, phi):
        t = phi + k.alpha[i]
        return k.radius[i] * np.cos(t), k.radius[i] * np.sin(t)

    return base, leg_vectors(base, rotation, x, y, phi), x, y


def approx_rho_sq(geometry: Geometry, X: np.ndarray) -> np.ndarray:
    """rho_i^2 in float64 for poses X of shape (..., 3); returns shape (..., 3). Not certified."""
    _, legs, _, _ = _float_legs(geometry, X)
    return np.stack([leg_rho_sq(*leg) for leg in legs], axis=-1)


def approx_inverse_kinematics(geometry: Geometry, X: np.ndarray) -> np.ndarray:
    """rho = g(X) in float64 for poses X of shape (..., 3); returns shape (..., 3). Not certified."""
    return np.sqrt(approx_rho_sq(geometry, X))


def approx_det_a(geometry: Geometry, X: np.ndarray) -> np.ndarray:
    """det A in float64 for poses X of shape (..., 3); returns shape (...). Not certified."""
    base, legs, x, y = _float_legs(geometry, X)
    return det_from_legs(base, legs, x, y)


def approx_jacobian(geometry: Geometry, X: np.ndarray) -> np.ndarray:
    """A = dF/dX in float64 for poses X of shape (..., 3); returns shape (..., 3, 3). Not certified."""
    _, legs, x, _ = _float_legs(geometry, X)
    A = np.empty(np.shape(x) + (3, 3))
    for i, row in enumerate(_jacobian_rows(legs, 0.0)):
        for j, v in enumerate(row):
            A[..., i, j] = v
    return A


# --------------------------------------------------------------------------------------
# arb (the trusted reference: balls at the current ctx.prec, wide arguments allowed)
# --------------------------------------------------------------------------------------
def _arb_legs(geometry: Geometry, x, y, phi):
    base, platform = constants(geometry).arb()
    c, s = phi.cos(), phi.sin()

    def rotation(i, phi):
        px, py = platform[i]
        return px * c - py * s, px * s + py * c

    return base, leg_vectors(base, rotation, x, y, phi)


def rho_sq_arb(geometry: Geometry, x, y, phi) -> list:
    """[rho_1^2, rho_2^2, rho_3^2] as arb balls for arb arguments."""
    _, legs = _arb_legs(geometry, x, y, phi)
    return [leg_rho_sq(*leg) for leg in legs]


def inverse_kinematics_arb(geometry: Geometry, x, y, phi) -> list:
    """[rho_1, rho_2, rho_3] as arb balls for arb arguments."""
    return [r.sqrt() for r in rho_sq_arb(geometry, x, y, phi)]


def det_a_arb(geometry: Geometry, x, y, phi):
    """det A as an arb ball for arb arguments."""
    base, legs = _arb_legs(geometry, x, y, phi)
    return det_from_legs(base, legs, x, y)


def residual_arb(geometry: Geometry, x, y, phi, rho_sq) -> list:
    """F_i = |B_i - A_i|^2 - rho_i^2 as arb balls; ``rho_sq`` are arb balls (the exact squares)."""
    return [a - b for a, b in zip(rho_sq_arb(geometry, x, y, phi), rho_sq)]


def jacobian_arb(geometry: Geometry, x, y, phi) -> list[list]:
    """A = dF/dX as a 3x3 nested list of arb balls; the arguments may be wide balls."""
    _, legs = _arb_legs(geometry, x, y, phi)
    return _jacobian_rows(legs, 0 * x)
