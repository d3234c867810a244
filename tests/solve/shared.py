"""Joint boxes that meet g(S), shared by the tests of the two clear-box tests (simple roots, joint box)."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import numpy as np

from intervalkin.solve.dkp import solve

DATA = Path(__file__).parents[1] / "data"


def split_of(result) -> tuple[int, int, int]:
    """(count, in WA1, in WA2) of a complete certified solve."""
    assert result.complete, result.completeness_reason
    wa1 = sum(1 for s in result.solutions if s.aspect == "WA1")
    return result.count, wa1, result.count - wa1


def box_across_singular_image(geometry) -> np.ndarray:
    """A (1, 3, 2) joint box about 1e-4 wide that holds a point of g(S).

    The segment between two joint vectors with different certified counts crosses
    g(S); exact bisection with certified solves keeps a sub-segment whose ends still
    have different counts, and the box is its hull widened by 1e-4.
    """
    a = [Fraction(20), Fraction(20), Fraction(20)]
    b = [Fraction(14), Fraction(26), Fraction(30)]
    ca, cb = split_of(solve(geometry, a)), split_of(solve(geometry, b))
    assert ca != cb
    lo_t, hi_t = Fraction(0), Fraction(1)
    while hi_t - lo_t > Fraction(1, 20000):
        mid = (lo_t + hi_t) / 2
        res = solve(geometry, [u + mid * (v - u) for u, v in zip(a, b)])
        if res.complete and split_of(res) == ca:
            lo_t = mid
        else:
            hi_t = mid
    pa = [float(u + lo_t * (v - u)) for u, v in zip(a, b)]
    pb = [float(u + hi_t * (v - u)) for u, v in zip(a, b)]
    return np.array([[min(x, y) - 1e-4, max(x, y) + 1e-4] for x, y in zip(pa, pb)])[None]


def concurrent_legs_box(width: float) -> np.ndarray:
    """A (1, 3, 2) box around a double root of the concurrent-legs manipulator (tests/data), within its limits."""
    q = np.array([15.0, 13.0, 10.0])
    box = np.stack([q - width, q + width], axis=-1)[None]
    box[0, 2, 0] = 10.0
    return box


def det_zeros_along_y(geometry, x: np.ndarray, phi: np.ndarray, ys: np.ndarray):
    """Every sign change of det A (float) along y on the lines (x_l, ., phi_l), bisected 60 times.

    Returns (line, a, b): the line of each change and its bracket, a on the side of the
    smaller sample (its sign), b across; b - a is then about one ulp.  Not certified: it
    makes test inputs on det A = 0, where enclosures and labels are hardest.
    """
    from intervalkin.kinematics.formulas import approx_det_a

    x, phi = np.asarray(x, dtype=float), np.asarray(phi, dtype=float)
    grid = np.stack(np.broadcast_arrays(x[:, None], ys[None, :], phi[:, None]), axis=-1)
    det = approx_det_a(geometry, grid.reshape(-1, 3)).reshape(len(x), len(ys))
    line, c = np.nonzero(np.sign(det[:, :-1]) * np.sign(det[:, 1:]) < 0)
    a, b, da = ys[c], ys[c + 1], det[line, c]
    for _ in range(60):
        m = 0.5 * (a + b)
        dm = approx_det_a(geometry, np.stack([x[line], m, phi[line]], axis=1))
        same = np.sign(dm) == np.sign(da)
        a, b, da = np.where(same, m, a), np.where(same, b, m), np.where(same, dm, da)
    return line, a, b



def first_det_change(geometry, x: float, phi: float, ys: np.ndarray) -> int | None:
    """Index c of the first float sign change of det A between ys[c] and ys[c + 1] on the line (x, ., phi),
    None when det A keeps one sign there.  Not certified: it only chooses where a test brackets in arb."""
    from intervalkin.kinematics.formulas import approx_det_a

    det = approx_det_a(geometry, np.stack([np.full_like(ys, x), ys, np.full_like(ys, phi)], axis=1))
    change = np.flatnonzero(np.sign(det[:-1]) * np.sign(det[1:]) < 0)
    return int(change[0]) if change.size else None
