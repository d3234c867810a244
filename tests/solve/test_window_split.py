"""The reduced equation near the zeros of D (kinematics.reduced_equation.aligned_numerator, solve.window_split).

- in arb, f - (s^2 / |m_2|^2 - r_1 D^2) = |N|^2 - (m_2 x N)^2 / |m_2|^2 >= 0 at random (phi, r), and it
  vanishes at the zeros of D (N parallel to the normal of m_2 there): the identity the gap bound rests on;
- ``gap_positive`` on random boxes near the two zeros of D: wherever it says f > 0, 50-digit arb finds
  f > 0 at sampled (phi, r) of the gap piece; it says so on most boxes the plane f(phi_D; r) = 0 misses,
  and never on a box that holds a point of that plane (where f(phi_D) = 0: a bound without the square,
  or with the wrong sign of r_1 D^2, claims those);
- in arb, f |m_2|^2 = s^2 - D^2 V with V = r_1 |m_2|^2 - (r_2 - r_1 - |m_2|^2 / 4)^2 at random (phi, r);
  ``line_misses_circle`` on random boxes and pieces: wherever it says f > 0, 50-digit arb finds f > 0 and
  V < 0 at sampled points, and it never says so where a sampled point has V > 0 (with the sign of V
  reversed, the test fails);
- ``root_direction_signs`` at roots of f beside the zeros of D (joint vectors a little off the plane of double
  roots, each root refined in arb): every sign it proves is the sign of D_e f there (170-bit central
  differences), it never calls a piece holding a root rootless, and on the paper's manipulator it proves signs
  that ``aligned_r_slopes`` alone does not (on the second design, none at these box sizes); with the D^2 term's
  sign flipped, or |s| bounded by |D| V / 1000 instead of |D| sqrt(V), it fails;
- ``aligned_r_slopes`` holds df/dr_l (arb, by a central difference at 170 bits) at sampled points of random
  boxes and pieces, near the zeros of D as well (a slope with the D^2 term dropped, or the factor 2 on s lost,
  fails; so does a centred form of s, c_l and L without its slope term);
- ``denominator_enclosure`` (with its monotone hull) holds D at sampled points of each piece, and signs
  the pieces that end next to a zero of D;
- ``branch_slopes`` holds the phi-slopes of the branches s -+ D sqrt(V) (arb) on tiny boxes, and where
  ``simple_on_branches`` says a piece holds no double root, sampled points keep one sign of each slope;
- ``double_root_signs`` at double roots of f beside the zeros of D (float Newton): never says their pieces hold
  none, and every sign it proves is that of D_e f there (arb).
"""

from __future__ import annotations

import numpy as np
import pytest
from flint import arb, ctx, fmpq

from intervalkin.kinematics.reduced_equation import HARMONICS, aligned_numerator
from intervalkin.kinematics.sextic import laurent_value, reduction
from intervalkin.core.interval import Interval
from intervalkin.kinematics.reduced_equation import denominator
from intervalkin.solve.root_directions import root_direction_signs
from intervalkin.solve.window_split import (D_GAP, aligned_r_slopes, d_zeros, denominator_enclosure, gap_positive,
                                          line_misses_circle)
from intervalkin.space.retraction_nodes import DIRECTIONS


def _q(v):
    return fmpq(v.numerator, v.denominator)


def _arb_parts(geometry, r, phi):
    """(f, |N|^2, m_2 x N, |m_2|^2, D) in arb at r (three floats) and phi (a float), 200 bits."""
    red = reduction(geometry, [arb(float(v)) for v in r])
    ph = arb(float(phi))
    n = laurent_value(red.N, ph)
    p = [geometry.platform_point(i) for i in range(3)]
    a = [(_q(bx - geometry.base[0][0]), _q(by - geometry.base[0][1])) for bx, by in geometry.base]
    c, s = ph.cos(), ph.sin()
    px, py = p[1][0].arb(), p[1][1].arb()
    m2 = (2 * (c * px - s * py - a[1][0]), 2 * (s * px + c * py - a[1][1]))
    cross = m2[0] * n.imag - m2[1] * n.real
    return (laurent_value(red.f, ph).real, n.real ** 2 + n.imag ** 2, cross, m2[0] ** 2 + m2[1] ** 2,
            laurent_value(red.D, ph).real)


def _trig(phi: float) -> np.ndarray:
    return np.array([np.cos(k * phi) if s == 0 else np.sin(k * phi) for k, s in HARMONICS])


@pytest.mark.parametrize("which", ["paper", "second"])
def test_aligned_numerator_bounds_f_and_meets_it_at_the_zeros_of_d(which, paper_geometry, second_geometry, rng):
    geometry = paper_geometry if which == "paper" else second_geometry
    aligned = aligned_numerator(geometry)
    with ctx.workprec(200):
        for _ in range(40):
            r, phi = rng.uniform(50, 1100, 3), rng.uniform(-3.1, 3.1)
            f, n2, cross, leg, d = _arb_parts(geometry, r, phi)
            assert (f - (cross ** 2 / leg - arb(float(r[0])) * d ** 2)).mid() >= -1e-20 * abs(float(n2.mid()))
            # the float coefficients reproduce s and |m_2|^2
            w = _trig(phi)
            s_float = w @ aligned.coefficients.mid() @ np.r_[1.0, r]
            assert abs(s_float - float(cross.mid())) <= 1e-9 * (1 + abs(s_float))
            assert abs(w @ aligned.leg_square.mid() - float(leg.mid())) <= 1e-9 * float(leg.mid())
        for phi in d_zeros(geometry):
            r = rng.uniform(50, 1100, 3)
            f, n2, cross, leg, d = _arb_parts(geometry, r, phi)
            assert abs(float(d.mid())) < 1e-9
            # |N|^2 = s^2 / |m_2|^2 up to the float distance to the true zero of D
            assert abs(float((n2 - cross ** 2 / leg).mid())) <= 1e-6 * float(n2.mid())


@pytest.mark.parametrize("which", ["paper", "second"])
def test_line_misses_circle_is_sound_and_only_where_the_line_misses(which, paper_geometry, second_geometry, rng):
    geometry = paper_geometry if which == "paper" else second_geometry
    lo_j, hi_j = np.asarray(geometry.rho_min, dtype=float), np.asarray(geometry.rho_max, dtype=float)
    claimed = met = 0
    with ctx.workprec(170):
        for _ in range(25):  # the identity f L = s^2 - D^2 V
            r, phi = rng.uniform(50, 1100, 3), rng.uniform(-3.1, 3.1)
            f, n2, cross, leg, d = _arb_parts(geometry, r, phi)
            v = arb(float(r[0])) * leg - (arb(float(r[1])) - arb(float(r[0])) - leg / 4) ** 2
            assert abs(float((f * leg - (cross ** 2 - d ** 2 * v)).mid())) <= 1e-25 * float((n2 * leg).mid())
        for _ in range(300):
            width = 10 ** rng.uniform(-2.5, -0.5)
            centre = lo_j + rng.uniform(size=3) * (hi_j - lo_j)
            box = np.stack([centre - width / 2, centre + width / 2], axis=1)[None]
            lo = rng.uniform(-3.1, 3.0)
            hi = lo + 10 ** rng.uniform(-4, -1.5)
            ok = line_misses_circle(geometry, box, np.zeros(1, dtype=np.int64), np.array([lo]), np.array([hi]))[0]
            for _ in range(4):
                rho = box[0, :, 0] + rng.uniform(size=3) * width
                phi = lo + rng.uniform() * (hi - lo)
                f, n2, cross, leg, d = _arb_parts(geometry, rho ** 2, phi)
                v = arb(float(rho[0] ** 2)) * leg - (arb(float(rho[1] ** 2)) - arb(float(rho[0] ** 2)) - leg / 4) ** 2
                if ok:
                    assert f > 0 and v < 0
                elif v > 0:
                    met += 1
            claimed += ok
    assert claimed >= 20 and met >= 100, (claimed, met)


@pytest.mark.parametrize("which", ["paper", "second"])
def test_aligned_r_slopes_hold_at_high_precision(which, paper_geometry, second_geometry, rng):
    geometry = paper_geometry if which == "paper" else second_geometry
    lo_j, hi_j = np.asarray(geometry.rho_min, dtype=float), np.asarray(geometry.rho_max, dtype=float)
    zeros = d_zeros(geometry)
    tight = 0
    with ctx.workprec(170):
        for k in range(60):
            width = 10 ** rng.uniform(-2.5, -0.5)
            centre = lo_j + rng.uniform(size=3) * (hi_j - lo_j)
            box = np.stack([centre - width / 2, centre + width / 2], axis=1)[None]
            lo = zeros[k % 2] + rng.uniform(-0.05, 0.05) if k % 3 else rng.uniform(-3.1, 3.0)
            hi = lo + 10 ** rng.uniform(-4, -2)
            slopes = aligned_r_slopes(geometry, box, np.zeros(1, dtype=np.int64), np.array([lo]), np.array([hi]))
            for _ in range(3):
                rho = box[0, :, 0] + rng.uniform(size=3) * width
                phi = lo + rng.uniform() * (hi - lo)
                r = rho ** 2
                for axis in range(3):
                    step = np.zeros(3)
                    step[axis] = 1e-6
                    up = _arb_parts(geometry, r + step, phi)[0]
                    down = _arb_parts(geometry, r - step, phi)[0]
                    run = arb(float((r + step)[axis])) - arb(float((r - step)[axis]))  # the steps taken, exactly
                    slope = float(((up - down) / run).mid())  # f is quadratic in r: exact up to rounding
                    assert slopes[axis].lo[0] - 1e-9 * abs(slope) <= slope <= slopes[axis].hi[0] + 1e-9 * abs(slope)
                    tight += np.isfinite(slopes[axis].hi[0]) and slopes[axis].hi[0] < np.inf
    assert tight >= 400


def _plane_point(geometry, phi, r23):
    """r with s(phi; r) = 0 (float), r_2 and r_3 given: s is affine in r."""
    w = _trig(phi)
    c = w @ aligned_numerator(geometry).coefficients.mid()  # s = c0 + c1 r1 + c2 r2 + c3 r3
    return np.array([-(c[0] + c[2] * r23[0] + c[3] * r23[1]) / c[1], *r23])


@pytest.mark.parametrize("which", ["paper", "second"])
def test_gap_positive_is_sound_and_refuses_boxes_on_the_spurious_plane(which, paper_geometry, second_geometry, rng):
    geometry = paper_geometry if which == "paper" else second_geometry
    lo_j, hi_j = float(max(geometry.rho_min)), float(min(geometry.rho_max))
    zeros = d_zeros(geometry)
    assert zeros.size == 2
    proved = refused = on_plane = 0
    with ctx.workprec(170):
        for phi_d in zeros:
            for k in range(90):
                # boxes around points of the plane f(phi_D; r) = 0, shifted by 0 to 5 widths
                r = _plane_point(geometry, phi_d, rng.uniform(lo_j ** 2, hi_j ** 2, 2))
                if not (lo_j ** 2 < r[0] < hi_j ** 2):
                    continue
                width = 10 ** rng.uniform(-3, -0.5)
                centre = np.sqrt(r) + rng.choice([0.0, 2.0, 5.0]) * width * rng.uniform(-1, 1, 3)
                box = np.stack([centre - width / 2, centre + width / 2], axis=1)[None]
                # s(phi_D; .) is affine in r = rho^2: its range over the box is spanned by the corners
                corners = np.stack(np.meshgrid(*box[0] ** 2, indexing="ij"), axis=-1).reshape(-1, 3)
                values = [_trig(phi_d) @ aligned_numerator(geometry).coefficients.mid() @ np.r_[1.0, c] for c in corners]
                holds_plane = min(values) <= 0 <= max(values)
                ok = gap_positive(geometry, box, np.zeros(1, dtype=np.int64), np.array([phi_d - D_GAP]),
                                  np.array([phi_d + D_GAP]))[0]
                if holds_plane:
                    on_plane += 1
                    assert not ok, "f > 0 claimed on a box that holds a zero of f(phi_D; .)"
                    continue
                if not ok:
                    refused += 1
                    continue
                proved += 1
                for _ in range(6):
                    rho = box[0, :, 0] + rng.uniform(size=3) * width
                    f = _arb_parts(geometry, rho ** 2, phi_d + rng.uniform(-D_GAP, D_GAP))[0]
                    assert f > 0
    assert on_plane >= 20 and proved >= 25 and refused <= proved // 10, (on_plane, proved, refused)


@pytest.mark.parametrize("which", ["paper", "second"])
def test_denominator_enclosure_holds_and_signs_pieces_next_to_a_gap(which, paper_geometry, second_geometry, rng):
    geometry = paper_geometry if which == "paper" else second_geometry
    lo = rng.uniform(-3.1, 3.0, 300)
    hi = lo + 10 ** rng.uniform(-8, -0.5, 300)
    enc = denominator_enclosure(geometry, lo, hi)
    with ctx.workprec(120):
        for i in range(0, 300, 5):
            for t in (0.0, rng.uniform(), 1.0):
                x = lo[i] + t * (hi[i] - lo[i])
                d = laurent_value(reduction(geometry, [arb(0)] * 3).D, arb(x)).real
                assert enc.lo[i] <= d.mid() <= enc.hi[i]
    z = d_zeros(geometry)
    left = denominator_enclosure(geometry, z - 0.05, z - D_GAP)
    right = denominator_enclosure(geometry, z + D_GAP, z + 0.05)
    for side in (left, right):
        assert np.all((side.hi < 0) | (side.lo > 0))
    assert np.all(np.sign(left.lo) * np.sign(right.lo) < 0)


def _float_f_times_leg(geometry, r, phi):
    """F = f |m_2|^2 = s^2 - D^2 V in floats at r and an array of phi: only to locate roots, refined in arb."""
    aligned = aligned_numerator(geometry)
    w = np.array([np.cos(k * phi) if t == 0 else np.sin(k * phi) for k, t in HARMONICS]).T
    s = w @ aligned.coefficients.mid() @ np.r_[1.0, r]
    leg = w @ aligned.leg_square.mid()
    d = denominator(geometry).mid()
    dd = d[0] + d[1] * np.cos(phi) + d[2] * np.sin(phi)
    return s ** 2 - dd ** 2 * (r[0] * leg - (r[1] - r[0] - leg / 4) ** 2)


def _arb_root(geometry, r, a, b):
    """A root of f(.; r) in [a, b] (f changes sign there), to about 1e-30 by bisection in arb."""
    fa = _arb_parts(geometry, r, a)[0]
    for _ in range(100):
        m = 0.5 * (a + b)
        fm = _arb_parts(geometry, r, m)[0]
        if (fm > 0) == (fa > 0):
            a, fa = m, fm
        else:
            b = m
    return 0.5 * (a + b)


@pytest.mark.parametrize("which", ["paper", "second"])
def test_root_direction_signs_hold_at_the_roots_beside_the_zeros_of_d(which, paper_geometry, second_geometry, rng):
    geometry = paper_geometry if which == "paper" else second_geometry
    lo_j, hi_j = float(max(geometry.rho_min)), float(min(geometry.rho_max))
    zeros = d_zeros(geometry)
    roots = proved = beyond = 0
    with ctx.workprec(170):
        for k in range(120):
            phi_d = zeros[k % 2]
            r = _plane_point(geometry, phi_d, rng.uniform(lo_j ** 2, hi_j ** 2, 2))
            if not (lo_j ** 2 < r[0] < hi_j ** 2):
                continue
            width = 10 ** rng.uniform(-2.5, -1)
            rho = np.sqrt(r) + width * rng.uniform(-1, 1, 3)
            grid = phi_d + np.linspace(-0.1, 0.1, 4001)
            values = _float_f_times_leg(geometry, rho ** 2, grid)
            change = np.flatnonzero(np.sign(values[:-1]) != np.sign(values[1:]))
            for i in change[:2]:
                phi = _arb_root(geometry, rho ** 2, float(grid[i]), float(grid[i + 1]))
                if abs(phi - phi_d) < 1e-6:
                    continue  # D = 0 there: not a solution
                roots += 1
                box = np.stack([rho - rng.uniform(0, width), rho + rng.uniform(0, width)], axis=1)[None]
                lo, hi = phi - 10 ** rng.uniform(-5, -2), phi + 10 ** rng.uniform(-5, -2)
                one = np.zeros(1, dtype=np.int64)
                signs, rootless = root_direction_signs(geometry, box, one, np.array([lo]), np.array([hi]), DIRECTIONS)
                assert not rootless[0], "a piece holding a root of f called rootless"
                slopes = aligned_r_slopes(geometry, box, one, np.array([lo]), np.array([hi]))
                grad = []
                for axis in range(3):
                    step = np.zeros(3)
                    step[axis] = 1e-6
                    up = _arb_parts(geometry, rho ** 2 + step, phi)[0]
                    down = _arb_parts(geometry, rho ** 2 - step, phi)[0]
                    run = arb(float((rho ** 2 + step)[axis])) - arb(float((rho ** 2 - step)[axis]))
                    grad.append(2 * rho[axis] * float(((up - down) / run).mid()))  # D_{e_l} = 2 rho_l d/dr_l
                for c, e in enumerate(DIRECTIONS):
                    if signs[0, c] == 0:
                        continue
                    proved += 1
                    value = float(np.dot(e, grad))
                    assert np.sign(value) == signs[0, c], (e, value, signs[0, c])
                    # what the slopes over the whole piece could not sign
                    old = [sl * Interval(2 * box[:, a, 0], 2 * box[:, a, 1]) * float(x)
                           for a, (x, sl) in enumerate(zip(e, slopes))]
                    total = old[0] + old[1] + old[2]
                    beyond += bool(total.lo[0] <= 0 <= total.hi[0])
    assert roots >= 40, roots
    if which == "paper":  # on the second design |D| sqrt(V) stays far above what the s-term allows: no sign
        assert proved >= roots and beyond >= 20, (roots, proved, beyond)


def _branch_slopes(geometry, r, phi, h=1e-7):
    """(g_+', g_-', V, D) at (phi, r) in arb, g_+- = s -+ D sqrt(V): central differences at 170 bits."""
    def g(p):
        _, _, s, leg, d = _arb_parts(geometry, r, p)
        k = arb(float(r[1])) - arb(float(r[0])) - leg / 4
        v = arb(float(r[0])) * leg - k * k
        root = v.sqrt() if v > 0 else arb(0)
        return s - d * root, s + d * root, v, d
    up, down, mid = g(phi + h), g(phi - h), g(phi)
    run = arb(phi + h) - arb(phi - h)
    return (float(((up[0] - down[0]) / run).mid()), float(((up[1] - down[1]) / run).mid()),
            float(mid[2].mid()), float(mid[3].mid()))


@pytest.mark.parametrize("which", ["paper", "second"])
def test_branch_slopes_hold_and_simple_on_branches_keeps_one_sign(which, paper_geometry, second_geometry, rng):
    """g_+- = s -+ D sqrt(V), the two branches of f near the zeros of D.  On tiny boxes and pieces, the
    enclosures of branch_slopes hold g_+-' (arb, central differences at 170 bits) at their centres: with
    V' = L' (r_1 - k / 2) instead of L' (r_1 + k / 2), or the D V' term dropped, they miss it.  On boxes and
    pieces of the paving's sizes, where simple_on_branches says a piece holds no double root, sampled points
    have V > 0, D != 0 and one sign of each g_+-'; on the paper's manipulator it says so of pieces that
    root_direction_signs can neither sign nor call rootless (the pieces it is there for)."""
    from intervalkin.solve.root_directions import branch_slopes, simple_on_branches

    geometry = paper_geometry if which == "paper" else second_geometry
    lo_j, hi_j = float(max(geometry.rho_min)), float(min(geometry.rho_max))
    zeros = d_zeros(geometry)

    def sample(m, box_exp, piece_exp):
        centre = rng.uniform(lo_j, hi_j, (m, 3))
        width = 10 ** rng.uniform(*box_exp, (m, 1))
        phi = zeros[rng.integers(0, 2, m)] + rng.choice([-1, 1], m) * 10 ** rng.uniform(-2.5, -1, m)
        half = 10 ** rng.uniform(*piece_exp, m)
        return np.stack([centre - width, centre + width], axis=2), phi - half, phi + half

    boxes, lo, hi = sample(400, (-8, -7), (-9, -8))
    ok, plus, minus = branch_slopes(geometry, boxes, np.arange(len(lo)), lo, hi)
    held = 0
    with ctx.workprec(170):
        for i in np.flatnonzero(ok)[:40]:
            rho = boxes[i].mean(axis=1)
            p = 0.5 * (lo[i] + hi[i])
            gp, gm, v, d = _branch_slopes(geometry, rho ** 2, p)
            assert v > 0 and d != 0
            for value, enc in ((gp, plus), (gm, minus)):
                slack = 1e-6 * (abs(value) + 1e-9)  # the central difference's own error
                assert enc.lo[i] - slack <= value <= enc.hi[i] + slack, (i, value, enc.lo[i], enc.hi[i])
            held += 1
    assert held >= 20, held

    boxes, lo, hi = sample(3000, (-2.5, -1), (-4, -2.5))
    owner = np.arange(len(lo))
    said = simple_on_branches(geometry, boxes, owner, lo, hi)
    checked = 0
    with ctx.workprec(170):
        for i in np.flatnonzero(said)[:15]:
            seen = set()
            for _ in range(5):
                rho = rng.uniform(boxes[i, :, 0], boxes[i, :, 1])
                gp, gm, v, d = _branch_slopes(geometry, rho ** 2, float(rng.uniform(lo[i], hi[i])))
                assert v > 0 and d != 0, (i, v, d)
                seen.add((np.sign(gp), np.sign(gm)))
            assert len(seen) == 1 and 0 not in next(iter(seen)), (i, seen)
            checked += 1
    assert checked >= 10, (which, int(said.sum()))
    if which == "paper":
        signs, rootless = root_direction_signs(geometry, boxes, owner, lo, hi, DIRECTIONS)
        assert (said & ~rootless & ~(signs != 0).any(axis=1)).sum() >= 5


def _fold_points(geometry, rng, count):
    """(phi, r) pairs near the zeros of D where f(.; r) has a double root at phi (float Newton on (F, F') in (r_1,
    r_2) with phi and r_3 fixed, F = f |m_2|^2): the points where a pair of roots is born."""
    from scipy.optimize import fsolve

    lo_j, hi_j = float(max(geometry.rho_min)), float(min(geometry.rho_max))
    zeros = d_zeros(geometry)
    out = []
    for _ in range(40 * count):
        phi = zeros[rng.integers(0, 2)] + rng.choice([-1, 1]) * 10 ** rng.uniform(-2.3, -1)
        r3 = rng.uniform(lo_j, hi_j) ** 2

        def eqs(x):
            r = np.array([x[0], x[1], r3])
            h = 1e-6
            grid = np.array([phi - h, phi, phi + h])
            f = _float_f_times_leg(geometry, r, grid)
            return [f[1], (f[2] - f[0]) / (2 * h)]
        x, _, done, _ = fsolve(eqs, rng.uniform(lo_j, hi_j, 2) ** 2, full_output=True)
        r = np.array([x[0], x[1], r3])
        if done == 1 and np.all((lo_j ** 2 < r) & (r < hi_j ** 2)) and abs(eqs(x)[0]) < 1e-6:
            out.append((phi, r))
            if len(out) == count:
                break
    return out


@pytest.mark.parametrize("which", ["paper", "second"])
def test_double_root_signs_hold_at_the_folds_beside_the_zeros_of_d(which, paper_geometry, second_geometry, rng):
    """At double roots of f near the zeros of D (the folds where a pair of roots is born; float Newton), boxes and
    pieces around them are never said to hold no double root, and every sign double_root_signs proves there is
    the sign of D_e f (arb, central differences in r at 170 bits).  With the sigma^2 term of Q dropped, or the
    sign of its D^2 V' term reversed, it fails; it proves signs that root_direction_signs does not."""
    from intervalkin.solve.root_directions import double_root_signs

    geometry = paper_geometry if which == "paper" else second_geometry
    folds = _fold_points(geometry, rng, 30)
    assert len(folds) >= 15, len(folds)
    proved = beyond = 0
    with ctx.workprec(170):
        for phi, r in folds:
            rho = np.sqrt(r)
            width = 10 ** rng.uniform(-3, -1.3)
            box = np.stack([rho - rng.uniform(0, width, 3), rho + rng.uniform(0, width, 3)], axis=1)[None]
            lo, hi = phi - 10 ** rng.uniform(-5, -3), phi + 10 ** rng.uniform(-5, -3)
            one = np.zeros(1, dtype=np.int64)
            signs, none = double_root_signs(geometry, box, one, np.array([lo]), np.array([hi]), DIRECTIONS)
            assert not none[0], "a piece holding a double root of f called free of them"
            old, _ = root_direction_signs(geometry, box, one, np.array([lo]), np.array([hi]), DIRECTIONS)
            grad = []
            for axis in range(3):
                step = np.zeros(3)
                step[axis] = 1e-6
                up = _arb_parts(geometry, r + step, phi)[0]
                down = _arb_parts(geometry, r - step, phi)[0]
                run = arb(float((r + step)[axis])) - arb(float((r - step)[axis]))
                grad.append(2 * rho[axis] * float(((up - down) / run).mid()))
            got, new = signs_agree(signs[0], np.array(grad), old[0] == 0, (phi, r))
            proved, beyond = proved + got, beyond + new
    assert proved >= 100 and beyond >= 20, (proved, beyond)


def signs_agree(signs: np.ndarray, grad: np.ndarray, fresh: np.ndarray, where) -> tuple[int, int]:
    """Every proved sign (c,) over DIRECTIONS is that of e . grad (the arb gradient of f at a double root), where that
    is clear of zero; returns (signs checked, of which ``fresh``: not proved by an earlier form)."""
    scale = np.abs(grad).sum()
    proved = beyond = 0
    for c, e in enumerate(DIRECTIONS):
        value = float(np.dot(e, grad))
        if signs[c] == 0 or abs(value) < 1e-6 * scale:
            continue
        proved += 1
        beyond += bool(fresh[c])
        assert np.sign(value) == signs[c], (where, e, value, signs[c])
    return proved, beyond
