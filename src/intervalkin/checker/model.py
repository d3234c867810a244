"""The checker's own model of the 3-RPR in arb: rho_i^2, det A, F, F' and D, over balls.

These formulas exist twice in the package on purpose.  :mod:`intervalkin.kinematics`
is what the library computes with; this module is what the checker re-proves
with, written out again from the mathematics (DESIGN.md sections 1-2) so that a
slip in one is not silently shared by the other.  The tests compare the two
(``tests/certify/test_certificates.py::test_checker_det_formula_is_the_jacobian_determinant``,
``::test_reduced_sextic_agrees_with_the_solver_derivation``).

Notation: B1 = (x, y), r_i = R(phi) p_i (r_1 = 0), u_i = B1 + r_i - A_i,
rho_i^2 = |u_i|^2, F_i = rho_i^2 - (given rho_i)^2 (paper eq. 1-3), and row i of
A = dF/dX is 2 (u_ix, u_iy, r_i x u_i) with a x b = a_x b_y - a_y b_x.

Every function takes arb balls and returns balls that enclose the exact value
for every point of its arguments (python-flint's guarantee).  A box of the
certificate files, read as binary64 bounds, becomes balls through :func:`balls`.
"""

from __future__ import annotations

from fractions import Fraction

from flint import arb, fmpq

from intervalkin.core.geometry import Geometry

__all__ = ['ArbModel', 'exact_ball', 'interval_ball', 'balls', 'has_sign', 'leg_sq']

def exact_ball(v: Fraction):
    """The rational ``v`` as a ball (exact when the precision allows, else a tight enclosure)."""
    return arb(fmpq(v.numerator, v.denominator))


def interval_ball(lo: float, hi: float):
    """A ball containing the real interval [lo, hi] (binary64 bounds)."""
    return arb.union(arb(lo), arb(hi))


def balls(box) -> list:
    """The three balls (x, y, phi) containing a box ((lo, hi), (lo, hi), (lo, hi))."""
    return [interval_ball(lo, hi) for lo, hi in box]


def has_sign(d, sign: int) -> bool:
    """PROVED: every point of the ball ``d`` is > 0 (``sign`` 1) or < 0 (``sign`` -1)."""
    return bool(d > 0 if sign > 0 else d < 0)


def _sqr(v):
    """v^2 as a ball, without the sign loss of v * v when v straddles 0."""
    if v > 0 or v < 0:
        return v * v
    u = v.abs_upper()
    return arb.union(arb(0), u * u)


class ArbModel:
    """Constants of one geometry at the current precision, and the formulas over balls."""

    def __init__(self, geometry: Geometry):
        self.geometry = geometry
        self.A = [(exact_ball(ax), exact_ball(ay)) for ax, ay in geometry.base]
        self.p = [tuple(c.arb() for c in geometry.platform_point(i)) for i in range(3)]
        # polar form of p_i (one occurrence of phi per coordinate: tighter over wide boxes)
        self.L = [exact_ball(geometry.platform_radius_sq(i)).sqrt() for i in range(3)]
        self.alpha = [arb(0)] + [arb.atan2(self.p[i][1], self.p[i][0]) for i in (1, 2)]
        self.rmin2 = [exact_ball(v * v) for v in geometry.rho_min]
        self.rmax2 = [exact_ball(v * v) for v in geometry.rho_max]

    # --- r_i in two forms -------------------------------------------------------------
    def rot(self, phi, i: int):
        """r_i = R(phi) p_i from the Cartesian platform coordinates (for points and thin boxes)."""
        c, s = phi.cos(), phi.sin()
        px, py = self.p[i]
        return px * c - py * s, px * s + py * c

    def rot_polar(self, phi, i: int):
        """r_i = L_i (cos(phi + alpha_i), sin(phi + alpha_i)) (for wide boxes)."""
        t = phi + self.alpha[i]
        return self.L[i] * t.cos(), self.L[i] * t.sin()

    # --- formulas -----------------------------------------------------------------------
    def rho_sq(self, x, y, phi) -> list:
        """rho_i^2 = (x + r_ix - A_ix)^2 + (y + r_iy - A_iy)^2, enclosed over balls."""
        out = []
        for i in range(3):
            ax, ay = self.A[i]
            if i == 0:
                out.append(_sqr(x - ax) + _sqr(y - ay))
            else:
                rx, ry = self.rot_polar(phi, i)
                out.append(_sqr(x + rx - ax) + _sqr(y + ry - ay))
        return out

    def in_limits(self, r) -> bool:
        """PROVED: rho_min_i^2 <= r_i <= rho_max_i^2 for the three legs (r from :meth:`rho_sq`)."""
        return all(r[i] >= self.rmin2[i] and r[i] <= self.rmax2[i] for i in range(3))

    def beyond_limits(self, r) -> bool:
        """PROVED: some leg has r_i < rho_min_i^2 or r_i > rho_max_i^2."""
        return any(r[i] < self.rmin2[i] or r[i] > self.rmax2[i] for i in range(3))

    def det(self, x, y, phi):
        """det A = 8 [u1x (d2y w3 - w2 d3y) - u1y (d2x w3 - w2 d3x)].

        Row 1 of A is 2 (u_1, 0) (r_1 = 0); subtracting it from rows 2 and 3 leaves
        2 (d_i, w_i) with d_i = u_i - u_1 = r_i - A_i + A_1 and
        w_i = r_i x u_i = r_i x (B1 - A_i) (r_i x r_i = 0); expanding along the
        third column gives the formula (degree 2 in x, y: the cubic terms cancel).
        """
        a1x, a1y = self.A[0]
        u1x, u1y = x - a1x, y - a1y
        d, w = [], []
        for i in (1, 2):
            ax, ay = self.A[i]
            rx, ry = self.rot_polar(phi, i)
            d.append((rx - ax + a1x, ry - ay + a1y))
            w.append(rx * (y - ay) - ry * (x - ax))
        (d2x, d2y), (d3x, d3y) = d
        w2, w3 = w
        return 8 * (u1x * (d2y * w3 - w2 * d3y) - u1y * (d2x * w3 - w2 * d3x))

    def residual(self, x, y, phi, rho_sq) -> list:
        """F_i = |B_i - A_i|^2 - rho_i^2 (the original system, paper eq. 1-3)."""
        out = []
        for i in range(3):
            ax, ay = self.A[i]
            rx, ry = (0, 0) if i == 0 else self.rot(phi, i)
            out.append((x + rx - ax) ** 2 + (y + ry - ay) ** 2 - rho_sq[i])
        return out

    def jacobian(self, x, y, phi) -> list[list]:
        """F' = A, rows 2 (u_ix, u_iy, r_i x u_i) (r_1 = 0)."""
        rows = []
        for i in range(3):
            ax, ay = self.A[i]
            if i == 0:
                ux, uy = x - ax, y - ay
                rows.append([2 * ux, 2 * uy, 0 * ux])
            else:
                rx, ry = self.rot(phi, i)
                ux, uy = x + rx - ax, y + ry - ay
                rows.append([2 * ux, 2 * uy, 2 * (rx * uy - ry * ux)])
        return rows

    def D(self, phi):
        """D(phi) = m_2 x m_3, m_i = 2 (r_i - (A_i - A_1)): the determinant of the 2x2 system."""
        a1x, a1y = self.A[0]
        m = []
        for i in (1, 2):
            rx, ry = self.rot(phi, i)
            ax, ay = self.A[i]
            m.append((2 * (rx - (ax - a1x)), 2 * (ry - (ay - a1y))))
        return m[0][0] * m[1][1] - m[0][1] * m[1][0]


def leg_sq(model: ArbModel, l: int):
    """rho_l^2 as a function of (x, y, phi) with products only (for jet arguments, checker.taylor)."""
    ax, ay = model.A[l]

    def f(x, y, phi):
        if l == 0:
            ux, uy = x - ax, y - ay
        else:
            rx, ry = model.rot_polar(phi, l)
            ux, uy = x + rx - ax, y + ry - ay
        return ux * ux + uy * uy
    return f
