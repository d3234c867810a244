"""The signs of D_e f at the double roots of f read from the singular poses (solve/singular_directions.py).

- the identity D_e f = -8 D sum_l e_l rho_l w_l at singular poses, in arb at 200 bits against central differences
  of f in r (both geometries, poses anywhere and beside the zeros of D);
- ``singular_direction_signs`` on boxes and pieces around singular poses: never says a piece holding one is
  quiet, and every sign it proves is that of D_e f there (arb); it proves signs the elimination's forms do not;
- a piece far from every singular pose of its box is quiet, and a sign is never given where D is not signed,
  unless asked (``gap``) with the sign of f'' at the double roots: then the signs read without D (``fold_signs``:
  left null vector, kernel and second derivative of rho^2 at the pose) hold there too, beside the zeros of D.
"""

from __future__ import annotations

import numpy as np
import pytest
from flint import arb, ctx

from intervalkin.solve.root_directions import double_root_signs, root_direction_signs
from intervalkin.kinematics.enclosures import jacobian_interval
from intervalkin.solve.singular_directions import (denominator_signs, fold_signs, singular_direction_signs,
                                                   singular_pose_cells)
from intervalkin.solve.window_split import d_zeros
from intervalkin.space.retraction_nodes import DIRECTIONS
from tests.solve.shared import det_zeros_along_y
from tests.solve.test_window_split import _arb_parts, _fold_points, signs_agree


def _legs(geometry, pose):
    """(u_l = B_l - A_l as (3, 2) floats, the platform offsets) at a float pose (x, y, phi)."""
    x, y, phi = pose
    c, s = np.cos(phi), np.sin(phi)
    u = []
    for i in range(3):
        px, py = (float(v) for v in geometry.platform_point(i))
        ax, ay = (float(v) for v in geometry.base[i])
        u.append((x + c * px - s * py - ax, y + s * px + c * py - ay))
    return np.array(u)


def _singular_poses(geometry, rng, count):
    """(x, y, phi) poses with det A = 0 to about an ulp (float bisection along y) and rho inside the limits."""
    lo, hi = float(max(geometry.rho_min)), float(min(geometry.rho_max))
    x = rng.uniform(-25, 25, 4000)
    phi = rng.uniform(-np.pi, np.pi, 4000)
    line, a, b = det_zeros_along_y(geometry, x, phi, np.linspace(-30, 30, 121))
    out = []
    for k in rng.permutation(line.size):
        pose = np.array([x[line[k]], 0.5 * (a[k] + b[k]), phi[line[k]]])
        rho = np.hypot(*_legs(geometry, pose).T)
        if np.all((lo + 0.5 < rho) & (rho < hi - 0.5)):
            out.append(pose)
            if len(out) == count:
                break
    return out


def _kernel(geometry, pose):
    """The kernel vector (k_x, k_y, 1) of A at a float singular pose (the least singular vector, scaled)."""
    from intervalkin.kinematics.formulas import approx_jacobian

    _, _, vt = np.linalg.svd(approx_jacobian(geometry, pose[None])[0])
    return vt[-1] / vt[-1][2]


def _det_gradient(geometry, pose):
    """grad det A at a float pose, by central differences of the float det A."""
    from intervalkin.kinematics.formulas import approx_det_a

    out = np.zeros(3)
    for axis in range(3):
        step = np.zeros(3)
        step[axis] = 1e-6
        up, down = approx_det_a(geometry, (pose + step)[None])[0], approx_det_a(geometry, (pose - step)[None])[0]
        out[axis] = (up - down) / 2e-6
    return out


def _df_arb(geometry, rho, phi):
    """D_e f for the unit axes, (3,) floats: central differences in r of f in arb at 200 bits."""
    r = rho ** 2
    grad = []
    for axis in range(3):
        step = np.zeros(3)
        step[axis] = 1e-7
        up, down = _arb_parts(geometry, r + step, phi)[0], _arb_parts(geometry, r - step, phi)[0]
        run = arb(float((r + step)[axis])) - arb(float((r - step)[axis]))
        grad.append(2 * rho[axis] * float(((up - down) / run).mid()))
    return np.array(grad)


@pytest.mark.parametrize("which", ["paper", "second"])
def test_the_identity_at_singular_poses(which, paper_geometry, second_geometry, rng):
    """At singular poses, f and f' vanish at the pose's phi, D_e f = -8 D sum_l e_l rho_l w_l (w_l = u_m x u_n) and
    f'' = D grad det A . k (k the kernel of A with k_phi = 1).  A factor 4 instead of 8, w_l taken as u_n x u_m,
    or f'' without its factor D, fails."""
    geometry = paper_geometry if which == "paper" else second_geometry
    poses = _singular_poses(geometry, rng, 25)
    assert len(poses) >= 20
    with ctx.workprec(200):
        for pose in poses:
            u = _legs(geometry, pose)
            rho = np.hypot(*u.T)
            w = np.array([u[(l + 1) % 3, 0] * u[(l + 2) % 3, 1] - u[(l + 1) % 3, 1] * u[(l + 2) % 3, 0]
                          for l in range(3)])
            f, _, _, _, d = _arb_parts(geometry, rho ** 2, pose[2])
            scale = float(abs(_arb_parts(geometry, rho ** 2 + 1.0, pose[2])[0]).mid())
            assert abs(float(f.mid())) < 1e-7 * scale
            predicted = -8.0 * float(d.mid()) * rho * w
            grad = _df_arb(geometry, rho, pose[2])
            assert np.allclose(grad, predicted, rtol=1e-5, atol=1e-9 * np.abs(predicted).sum()), (pose, grad, predicted)
            # f'' = D (grad det A . k) with k the kernel of A, k_phi = 1
            h = 1e-5
            f0, fp, fm = (_arb_parts(geometry, rho ** 2, pose[2] + t)[0] for t in (0.0, h, -h))
            second = float(((fp - 2 * f0 + fm) / (arb(h) ** 2)).mid())
            kernel = _kernel(geometry, pose)
            expected = float(d.mid()) * float(np.dot(_det_gradient(geometry, pose), kernel))
            assert abs(second - expected) <= 1e-4 * abs(expected) + 1e-9 * scale, (pose, second, expected)


def _f_second(geometry, rho, phi):
    """f'' at (phi, rho), central differences in phi in arb."""
    h = 1e-5
    f0, fp, fm = (_arb_parts(geometry, rho ** 2, phi + t)[0] for t in (0.0, h, -h))
    return float(((fp - 2 * f0 + fm) / (arb(h) ** 2)).mid())


def _check_signs(geometry, rng, points):
    """Boxes and pieces around (phi, rho) double roots: never quiet; proved signs are those of D_e f (arb), and with
    ``fold`` those of f'' D_e f.  Returns (signs proved, of which the elimination's forms leave open)."""
    proved = beyond = 0
    with ctx.workprec(200):
        for phi, rho in points:
            width = 10 ** rng.uniform(-3, -1.5)
            box = np.stack([rho - rng.uniform(0, width, 3), rho + rng.uniform(0, width, 3)], axis=1)[None]
            lo, hi = np.array([phi - 10 ** rng.uniform(-5, -3)]), np.array([phi + 10 ** rng.uniform(-5, -3)])
            one = np.zeros(1, dtype=np.int64)
            signs, quiet = singular_direction_signs(geometry, box, one, lo, hi, DIRECTIONS)
            if denominator_signs(geometry, lo, hi)[0] == 0:
                assert not signs.any() and not quiet[0]
                continue
            assert not quiet[0], "a piece holding a singular pose called quiet"
            old, _ = root_direction_signs(geometry, box, one, lo, hi, DIRECTIONS)
            double, _ = double_root_signs(geometry, box, one, lo, hi, DIRECTIONS)
            grad = _df_arb(geometry, rho, phi)
            got, new = signs_agree(signs[0], grad, (old[0] == 0) & (double[0] == 0), (phi, rho))
            folded, fold_quiet = singular_direction_signs(geometry, box, one, lo, hi, DIRECTIONS, fold=True)
            assert not fold_quiet[0]
            # f'' D_e f has the sign of e . (sign(f'') grad)
            got_fold, _ = signs_agree(folded[0], np.sign(_f_second(geometry, rho, phi)) * grad, folded[0] == 0,
                                      (phi, rho, "fold"))
            proved, beyond = proved + got + got_fold, beyond + new
    return proved, beyond


@pytest.mark.parametrize("which", ["paper", "second"])
def test_signs_hold_at_singular_poses_anywhere(which, paper_geometry, second_geometry, rng):
    """Around singular poses anywhere in the joint box.  With the sign of D dropped, or the minus, it fails."""
    geometry = paper_geometry if which == "paper" else second_geometry
    points = []
    for pose in _singular_poses(geometry, rng, 25):
        points.append((pose[2], np.hypot(*_legs(geometry, pose).T)))
    proved, _ = _check_signs(geometry, rng, points)
    assert proved >= 200, proved


@pytest.mark.parametrize("which", ["paper", "second"])
def test_signs_hold_at_the_folds_beside_the_zeros_of_d(which, paper_geometry, second_geometry, rng):
    """At double roots of f near the zeros of D (float Newton), where the elimination's forms fail most: the signs
    hold, and some of them are signs that neither root_direction_signs nor double_root_signs proves."""
    geometry = paper_geometry if which == "paper" else second_geometry
    folds = [(phi, np.sqrt(r)) for phi, r in _fold_points(geometry, rng, 20)]
    assert len(folds) >= 10, len(folds)
    proved, beyond = _check_signs(geometry, rng, folds)
    assert proved >= 100 and beyond >= 10, (proved, beyond)


@pytest.mark.parametrize("which", ["paper", "second"])
def test_fold_signs_are_those_of_f2_times_the_slope_at_singular_poses(which, paper_geometry, second_geometry, rng):
    """At float singular poses (point boxes), the signs read without D, -sign(y . E) sign(y . H[kappa, kappa]), are
    those of f'' D_e f (arb central differences), and nearly all of them are proved.  With the kappa_phi^2 term of
    the second derivative dropped, or its minus, it fails."""
    geometry = paper_geometry if which == "paper" else second_geometry
    poses = _singular_poses(geometry, rng, 20)
    proved = 0
    with ctx.workprec(200):
        for pose in poses:
            rho = np.hypot(*_legs(geometry, pose).T)
            point = np.stack([pose, pose], axis=-1)[None]
            signs = fold_signs(geometry, point, jacobian_interval(geometry, point),
                               np.stack([rho, rho], axis=-1)[None], DIRECTIONS)[0]
            grad = np.sign(_f_second(geometry, rho, pose[2])) * _df_arb(geometry, rho, pose[2])
            got, _ = signs_agree(signs, grad, signs == 0, pose)
            proved += got
    assert proved >= 0.9 * len(poses) * len(DIRECTIONS), proved


def _gap_piece(geometry, phi):
    """A piece from the fold's phi across the nearest zero of D (D not signed on it)."""
    zero = d_zeros(geometry)[np.argmin(np.abs(d_zeros(geometry) - phi))]
    return np.array([min(phi, zero) - 1e-4]), np.array([max(phi, zero) + 1e-4])


@pytest.mark.parametrize("which", ["paper", "second"])
def test_signs_without_d_hold_on_pieces_across_the_zeros_of_d(which, paper_geometry, second_geometry, rng):
    """Folds beside the zeros of D (float Newton), on pieces from the fold across the zero: D is not signed there, so
    nothing is proved without ``gap``; with it and the sign of f'' at the double roots, the signs are those of D_e f
    (arb), with ``fold`` those of f'' D_e f, the pieces holding a singular pose are never quiet, and signs are
    proved.  With the curvature's sign flipped, it fails."""
    geometry = paper_geometry if which == "paper" else second_geometry
    folds = [(phi, np.sqrt(r)) for phi, r in _fold_points(geometry, rng, 14)]
    assert len(folds) >= 8, len(folds)
    proved = 0
    with ctx.workprec(200):
        for phi, rho in folds:
            lo, hi = _gap_piece(geometry, phi)
            assert denominator_signs(geometry, lo, hi)[0] == 0
            box = np.stack([rho - rng.uniform(0, 1e-3, 3), rho + rng.uniform(0, 1e-3, 3)], axis=1)[None]
            one = np.zeros(1, dtype=np.int64)
            plain, _ = singular_direction_signs(geometry, box, one, lo, hi, DIRECTIONS)
            assert not plain.any()
            curvature = np.array([np.sign(_f_second(geometry, rho, phi))], dtype=np.int8)
            grad = _df_arb(geometry, rho, phi)
            signs, quiet = singular_direction_signs(geometry, box, one, lo, hi, DIRECTIONS, curvature=curvature,
                                                    gap=True)
            assert not quiet[0], "a piece holding a singular pose called quiet"
            got, _ = signs_agree(signs[0], grad, signs[0] == 0, (phi, rho))
            folded, _ = singular_direction_signs(geometry, box, one, lo, hi, DIRECTIONS, fold=True, gap=True)
            got_fold, _ = signs_agree(folded[0], curvature[0] * grad, folded[0] == 0, (phi, rho, "fold"))
            proved += got + got_fold
    assert proved >= 200, proved


def test_pieces_away_from_the_singular_poses_are_quiet(paper_geometry, rng):
    """A box around a joint vector with 6 solutions (far from g(S)) holds no singular pose for any phi: every piece of
    the circle where D is signed is quiet and gets no sign; the cells cover nothing there."""
    box = np.array([[[14.96, 15.0], [15.36, 15.4], [11.98, 12.02]]])  # Table 1's joint vector, 6 solutions
    cuts = np.linspace(-3.14, 3.14, 61)
    lo, hi = cuts[:-1], cuts[1:]
    owner = np.zeros(lo.size, dtype=np.int64)
    signs, quiet = singular_direction_signs(paper_geometry, box, owner, lo, hi, DIRECTIONS)
    signed = denominator_signs(paper_geometry, lo, hi) != 0
    assert signed.sum() >= 50
    assert quiet[signed].all() and not quiet[~signed].any() and not signs.any()
    cell_of, _ = singular_pose_cells(paper_geometry, box, owner, lo, hi)
    assert cell_of.size == 0


def test_directions_past_two_are_refused(paper_geometry):
    box = np.array([[[15.0, 15.1], [15.0, 15.1], [15.0, 15.1]]])
    with pytest.raises(ValueError, match="-2..2"):
        singular_direction_signs(paper_geometry, box, np.zeros(1, dtype=np.int64), np.array([0.5]), np.array([0.6]),
                                 np.array([[3, 0, 0]]))
