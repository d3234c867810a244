"""Certified continuation (solve/continuation.py): the parameter Krawczyk test and the tracker.

Every claim is checked against something the continuation code does not use:
the certified direct-kinematics solver at exact joint vectors q(t) (t dyadic, so
q(t) is rational), mpmath Newton at 60 digits, and float Newton along many small
steps.  The segment from q_a = (15, 20, 18) to q_b = (15.5, 19.5, 18) has six
solutions all along and no fold; the fold segment crosses g(S).
"""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath
import numpy as np
import pytest

from intervalkin.core.interval import Interval
from intervalkin.solve.continuation import (
    _newton,
    certify_start,
    compare_mod_2pi,
    krawczyk_segment,
    new_tracks,
    track,
)
from intervalkin.solve.dkp import solve

from .test_dkp import mp_refine

QA = (Fraction(15), Fraction(20), Fraction(18))
QB = (Fraction(31, 2), Fraction(39, 2), Fraction(18))


def _q(t: Fraction) -> tuple[Fraction, ...]:
    """The exact joint vector q(t) = q_a + t (q_b - q_a)."""
    return tuple(a + t * (b - a) for a, b in zip(QA, QB))


def _ends(m: int = 1) -> tuple[Interval, Interval]:
    """q_a and q_b as point intervals, repeated m times (both are exact floats)."""
    return (Interval.point(np.tile([float(v) for v in QA], (m, 1))),
            Interval.point(np.tile([float(v) for v in QB], (m, 1))))


@pytest.fixture(scope="module")
def sol_a(paper_geometry):
    res = solve(paper_geometry, QA)
    assert res.complete and res.count == 6
    return res


@pytest.fixture(scope="module")
def sol_b(paper_geometry):
    res = solve(paper_geometry, QB)
    assert res.complete and res.count == 6
    return res


def _float_path(geometry, start: np.ndarray, t0: float, t1: float, steps: int = 200) -> np.ndarray:
    """Solution positions along q(t), t0 -> t1, by float Newton in small steps (not certified).

    ``start`` is one pose (3,) or several (m, 3); the result is (steps + 1, 3) or (steps + 1, m, 3).
    """
    qa, qb = (np.array([float(v) for v in q]) for q in (QA, QB))
    x = np.atleast_2d(np.asarray(start, dtype=np.float64))
    out = []
    for t in np.linspace(t0, t1, steps + 1):
        x, conv = _newton(geometry, x, np.tile(qa + t * (qb - qa), (len(x), 1)), iters=8)
        assert np.all(conv)
        out.append(x)
    path = np.array(out)
    return path[:, 0] if np.ndim(start) == 1 else path


def _certified_inside(res, lo, hi) -> tuple[int, int]:
    """(number of certified solution boxes inside [lo, hi], number not proved disjoint from it); phi mod 2 pi."""
    m = len(res.solutions)
    boxes = np.array([s.box for s in res.solutions])
    inside, apart = compare_mod_2pi(np.repeat(lo[None], m, 0), np.repeat(hi[None], m, 0), boxes[:, :, 0],
                                    boxes[:, :, 1])
    return int(inside.sum()), int((~apart).sum())


def _box_around(points: np.ndarray, margin: float) -> tuple[np.ndarray, np.ndarray]:
    return points.min(axis=0) - margin, points.max(axis=0) + margin


# --------------------------------------------------------------------------------------
# The parameter Krawczyk test, checked at exact joint vectors
# --------------------------------------------------------------------------------------
@pytest.mark.parametrize("k", [0, 4])
def test_accepted_box_holds_exactly_one_solution_for_every_sampled_t(paper_geometry, sol_a, k):
    """ok over T = [0, 1] means: at every q(t), t in T, exactly one solution in the box.

    One box around the whole path of solution k (it moves by about 0.5 in x and y) is
    accepted; then at 33 dyadic t the certified solver finds exactly one solution
    inside it and proves the five others disjoint from it.  Would catch a K that is
    too narrow (an accepted box that the solution leaves, or that holds two solutions).
    """
    path = _float_path(paper_geometry, sol_a.solutions[k].midpoint, 0.0, 1.0, 64)
    r = 0.25 * np.ptp(path, axis=0).max() * np.array([1.0, 1.0, 0.1])
    lo, hi = path.min(axis=0) - r, path.max(axis=0) + r
    qa, qb = _ends()
    ok, _, _ = krawczyk_segment(paper_geometry, lo[None], hi[None], qa, qb, np.array([0.0]), np.array([1.0]))
    assert ok[0]
    for j in range(33):
        res = solve(paper_geometry, _q(Fraction(j, 32)))
        assert res.complete
        assert _certified_inside(res, lo, hi) == (1, 1), j


@pytest.mark.parametrize("k, frac", [(1, 0.2), (4, 0.4)])
def test_box_holding_the_solution_for_part_of_T_only_is_refused(paper_geometry, sol_a, sol_b, k, frac):
    """A box around the solution at t = 1/2 that misses it at t = 0 and t = 1 (certified) is refused over [0, 1].

    The same box passes over T = {1/2} alone (so the refusal is about T).  Would catch a
    Krawczyk operator that drops the (T - tm) Y dF/dt term (K over [0, 1] would equal K
    at tm = 1/2) or halves it (dF/dt = -rho dq instead of -2 rho dq: the box of
    half-width 0.4 |x(1) - x(0)| would then pass).
    """
    path = _float_path(paper_geometry, sol_a.solutions[k].midpoint, 0.0, 1.0, 200)
    mid = path[100]
    r = frac * np.abs(path[-1] - path[0])
    lo, hi = mid - r, mid + r
    # certified: at t = 0 and t = 1 no solution lies in the box
    assert _certified_inside(sol_a, lo, hi) == (0, 0)
    assert _certified_inside(sol_b, lo, hi) == (0, 0)
    qa, qb = _ends()
    half = np.array([0.5])
    ok_point, _, _ = krawczyk_segment(paper_geometry, lo[None], hi[None], qa, qb, half, half)
    assert ok_point[0]
    ok, _, _ = krawczyk_segment(paper_geometry, lo[None], hi[None], qa, qb, np.array([0.0]), np.array([1.0]))
    assert not ok[0]


@pytest.mark.parametrize("pair", [(0, 2), (0, 3), (0, 4)])
def test_box_holding_two_solutions_is_refused(paper_geometry, sol_a, pair):
    """A box holding two certified solutions of q_a is never accepted (acceptance claims exactly one).

    Would catch a Krawczyk operator with the Jacobian taken at the box centre instead of
    enclosed over the box (then K is about a Newton step from the centre, which can land
    inside a box that holds two solutions).
    """
    i, j = pair
    P = np.array([sol_a.solutions[i].midpoint, sol_a.solutions[j].midpoint])
    r = 0.5 * np.ptp(P, axis=0) + 1e-3
    lo, hi = P.min(axis=0) - r, P.max(axis=0) + r
    assert _certified_inside(sol_a, lo, hi)[0] >= 2
    qa, _ = _ends()
    z = np.zeros(1)
    ok, _, _ = krawczyk_segment(paper_geometry, lo[None], hi[None], qa, qa, z, z)
    assert not ok[0]


@pytest.mark.parametrize("j", [0, 1, 2])
def test_box_missing_the_solution_in_one_coordinate_is_refused(paper_geometry, sol_a, j):
    """A box that holds the solution of q_a in two coordinates but misses it in the third is refused.

    It holds no solution (certified: every solver box is proved apart from it), so an
    acceptance would be false.  Would catch an interior test that accepts when K is
    inside X in SOME coordinate instead of in all three.
    """
    s = sol_a.solutions[0]
    r = np.array([0.05, 0.05, 0.005])
    shift = np.zeros(3)
    shift[j] = 1.5 * r[j]
    lo, hi = s.midpoint + shift - r, s.midpoint + shift + r
    assert _certified_inside(sol_a, lo, hi) == (0, 0)
    qa, _ = _ends()
    z = np.zeros(1)
    ok, _, _ = krawczyk_segment(paper_geometry, lo[None], hi[None], qa, qa, z, z)
    assert not ok[0]
    # the same box centred on the solution passes: the refusal is about the shift
    ok, _, _ = krawczyk_segment(paper_geometry, (lo - shift)[None], (hi - shift)[None], qa, qa, z, z)
    assert ok[0]


@pytest.mark.parametrize("t0", [0.0, 0.5, 1.0])
def test_end_box_holds_the_solution_at_t1_even_when_refused(paper_geometry, sol_b, t0):
    """[z_lo, z_hi] = K1 n X at t1 holds every solution of q(t1) in X, whether ok or not.

    X is a box around the solution at t1 = 1; over [0, 1] it is refused (the solution
    leaves it), over [1/2, 1] or {1} it may pass; in every case z must hold the
    certified solution of q_b.  Would catch K1 evaluated at the wrong parameter (tm
    or t0 instead of t1) or z clipped to the wrong side.
    """
    s = sol_b.solutions[1]
    r = 0.05 * np.array([1.0, 1.0, 0.05])
    lo, hi = s.midpoint - r, s.midpoint + r
    qa, qb = _ends()
    ok, z_lo, z_hi = krawczyk_segment(paper_geometry, lo[None], hi[None], qa, qb, np.array([t0]), np.array([1.0]))
    if t0 == 0.0:
        assert not ok[0]
    assert np.all(z_hi[0] - z_lo[0] < hi - lo)  # z says more than X
    inside, _ = compare_mod_2pi(z_lo, z_hi, s.box[None, :, 0], s.box[None, :, 1])
    assert inside[0]


# --------------------------------------------------------------------------------------
# Tracks
# --------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def tracked(paper_geometry, sol_a):
    m = sol_a.count
    A, B = _ends(m)
    boxes = np.array([s.box for s in sol_a.solutions])
    return track(paper_geometry, new_tracks(A, B, boxes.mean(axis=2), boxes[:, :, 0], boxes[:, :, 1]))


def test_tracked_box_holds_the_certified_solution_at_the_end(tracked, sol_a, sol_b):
    """Tracks between two exact joint vectors end in boxes holding exactly the solver's solutions there.

    Each track's final box holds exactly one certified solution of q_b and is proved apart
    from the five others; the six tracks end on six different solutions of the same
    aspect as their start (no fold on the way).
    """
    tr = tracked
    m = sol_a.count
    assert np.all(tr.status == 1)
    ends = np.array([s.box for s in sol_b.solutions])
    seen = []
    for i in range(m):
        inside, apart = compare_mod_2pi(np.repeat(tr.x_lo[i:i + 1], m, 0), np.repeat(tr.x_hi[i:i + 1], m, 0),
                                        ends[:, :, 0], ends[:, :, 1])
        assert inside.sum() == 1 and apart.sum() == m - 1  # each track ends on exactly one solution
        j = int(np.flatnonzero(inside)[0])
        assert sol_a.solutions[i].det_sign == sol_b.solutions[j].det_sign
        seen.append(j)
    assert sorted(seen) == list(range(m))


def test_tracks_follow_their_own_branch(paper_geometry, tracked, sol_a, sol_b):
    """The solution each track ends on is the one reached by float Newton in 200 small steps.

    The previous test would accept a tracker that swaps two solutions of one aspect
    (still a bijection, still the same signs); this one would not.
    """
    ends = np.array([s.box for s in sol_b.solutions])
    x_end = _float_path(paper_geometry, np.array([s.midpoint for s in sol_a.solutions]), 0.0, 1.0)[-1]
    for i, x1 in enumerate(x_end):
        j_float = int(np.argmin(np.max(np.abs(ends.mean(axis=2) - x1), axis=1)))
        inside, _ = compare_mod_2pi(tracked.x_lo[i:i + 1], tracked.x_hi[i:i + 1], ends[j_float:j_float + 1, :, 0],
                                    ends[j_float:j_float + 1, :, 1])
        assert inside[0], (i, j_float)


def test_proved_end_box_contains_the_high_precision_solution(paper_geometry, tracked):
    """The narrow end box [z_lo, z_hi] (width ~1e-8) holds the root found by mpmath at 60 digits.

    mpmath Newton starts from the box centre; its root must satisfy F = 0 to 1e-40 and lie
    in z (phi read modulo 2 pi).  Would catch a z computed from the predicted float
    point instead of the enclosure, or left unwidened by the rounding errors.
    """
    for i in range(len(tracked.status)):
        zl, zh = tracked.z_lo[i], tracked.z_hi[i]
        assert np.all(zh - zl < 1e-6) and np.all(tracked.x_lo[i] <= zl) and np.all(zh <= tracked.x_hi[i])
        X, res, _ = mp_refine(paper_geometry, 0.5 * (zl + zh), QB)
        assert res < mpmath.mpf(10) ** -40
        turns = mpmath.nint((X[2] - 0.5 * (zl[2] + zh[2])) / (2 * mpmath.pi))
        point = (X[0], X[1], X[2] - 2 * mpmath.pi * turns)
        for j in range(3):
            assert mpmath.mpf(zl[j]) <= point[j] <= mpmath.mpf(zh[j]), (i, j)


def test_certify_start_boxes_hold_the_solver_solutions(paper_geometry, sol_a):
    """Boxes proved by certify_start around perturbed guesses each hold one solver solution, and only it."""
    guesses = np.array([s.midpoint for s in sol_a.solutions]) + 1e-5
    ok, lo, hi, p = certify_start(paper_geometry, _ends(len(guesses))[0], guesses)
    assert np.all(ok)
    ends = np.array([s.box for s in sol_a.solutions])
    for i in range(len(guesses)):
        m = len(ends)
        inside, apart = compare_mod_2pi(np.repeat(lo[i:i + 1], m, 0), np.repeat(hi[i:i + 1], m, 0),
                                        ends[:, :, 0], ends[:, :, 1])
        assert inside[i] and apart.sum() == m - 1


# --------------------------------------------------------------------------------------
# A fold: q(t) crosses g(S)
# --------------------------------------------------------------------------------------
def _fold_segment(geometry):
    """A singular pose X_s of W, q_s = g(X_s), and a joint step dq that crosses g(S) there.

    Along q_s + s dq the two solutions near X_s exist for s < 0 and merge at s = 0.
    """
    from intervalkin.kinematics.formulas import approx_det_a, approx_inverse_kinematics, approx_jacobian

    xs = np.linspace(-30, 30, 6001)
    P = np.stack([xs, np.full_like(xs, -10.0), np.full_like(xs, 0.3)], axis=1)
    d = approx_det_a(geometry, P)
    for i in np.flatnonzero(np.sign(d[:-1]) != np.sign(d[1:])):
        a, b = P[i].copy(), P[i + 1].copy()
        for _ in range(60):
            mid = 0.5 * (a + b)
            if np.sign(approx_det_a(geometry, mid[None])[0]) == np.sign(approx_det_a(geometry, a[None])[0]):
                a = mid
            else:
                b = mid
        x_s = 0.5 * (a + b)
        q_s = approx_inverse_kinematics(geometry, x_s[None])[0]
        if np.all((q_s > 12) & (q_s < 30)):
            break
    else:  # pragma: no cover
        pytest.fail("no singular pose on the search line")
    u, _, _ = np.linalg.svd(approx_jacobian(geometry, x_s[None])[0])
    dq = u[:, 2] / (2 * q_s)  # moves rho^2 along the left null vector of A: across the fold
    dq = 0.02 * dq / np.linalg.norm(dq)
    return x_s, q_s, dq


def test_parameter_krawczyk_refuses_steps_across_a_fold(paper_geometry):
    """Krawczyk over [t0, t1] holding the fold is refused; tracking stops before it, never past it.

    Would catch a test that accepts a box on which det A changes sign (then the two
    solutions that merge at the fold would both be "the unique one"), and a tracker
    that steps over a refused stretch.
    """
    x_s, q_s, dq = _fold_segment(paper_geometry)
    side = None
    for s in (-1.0, 1.0):
        p, conv = _newton(paper_geometry, x_s[None] + 0.05, (q_s + s * dq)[None], iters=40)
        if conv[0] and np.max(np.abs(p[0] - x_s)) < 2.0:
            side, start = s, p[0]
    assert side is not None
    qa = Interval.point((q_s + side * dq)[None])
    qb = Interval.point((q_s - side * dq)[None])  # q(1/2) = q_s is on g(S)
    # any box around the singular pose, over a parameter range holding t = 1/2: refused
    for r in (1e-3, 1e-2, 0.1, 1.0):
        lo, hi = x_s[None] - r, x_s[None] + r
        ok, _, _ = krawczyk_segment(paper_geometry, lo, hi, qa, qb, np.array([0.4]), np.array([0.6]))
        assert not ok[0]
    # from the side with solutions, across the fold: the track must give up
    z = np.stack([start - 1e-9, start + 1e-9])
    tr = track(paper_geometry, new_tracks(qa, qb, start[None], z[0][None], z[1][None]))
    assert tr.status[0] == -1 and tr.t[0] < 0.5
    # the same solution tracked to just before the fold: certified, and it ends near the fold
    near = Interval.point((q_s + side * 0.1 * dq)[None])
    tr = track(paper_geometry, new_tracks(qa, near, start[None], z[0][None], z[1][None]))
    assert tr.status[0] == 1
    assert np.all(tr.x_lo[0] <= tr.p[0]) and np.all(tr.p[0] <= tr.x_hi[0])


# --------------------------------------------------------------------------------------
# Boxes compared modulo 2 pi
# --------------------------------------------------------------------------------------
def test_compare_mod_2pi_reads_phi_on_the_circle():
    """inside / apart across the seam: a box written near -pi is the same as one near +pi."""

    def box(phi_lo, phi_hi, x=(0.0, 1.0)):
        return np.array([[x[0], x[1]], [0.0, 1.0], [phi_lo, phi_hi]])[None]

    big = box(math.pi - 0.2, math.pi + 0.1)
    cases = [
        (box(-math.pi - 0.05, -math.pi + 0.05), True, False),  # the same angles, written 2 pi lower
        (box(math.pi - 0.1, math.pi), True, False),  # plainly inside
        (box(-math.pi + 0.05, -math.pi + 0.2), False, False),  # sticks out of the big box past the seam
        (box(0.0, 0.5), False, True),  # far away on the circle
        (box(-math.pi - 0.05, -math.pi + 0.05, x=(2.0, 3.0)), False, True),  # apart in x
        (box(math.pi - 0.1, math.pi + 4 * math.pi), False, False),  # wider than 3: never "apart"
    ]
    for z, want_inside, want_apart in cases:
        inside, apart = compare_mod_2pi(big[:, :, 0], big[:, :, 1], z[:, :, 0], z[:, :, 1])
        assert (bool(inside[0]), bool(apart[0])) == (want_inside, want_apart), z
