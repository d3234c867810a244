"""D-open windows cut at the zero of D into two firm halves (solve.window_plane, proofs/lemma-window-plane.md).

- structure: each split window is replaced by its halves (end sign +1 at the cut, a proved sign of D each,
  mutual twins), every other window and its pieces are kept;
- at sampled rho of split boxes, 50 digits: phi_D (a zero of D in the gap piece), the side of the plane
  (sign of s(phi_D; rho^2), never 0 at a sampled point), the roots of f in [a, phi_D] and [phi_D, b]: each
  half holds at most its degree, with the parity of its end signs, D of the half's sign at its roots, and
  the two together at most the whole window's degree; moving rho_l the way ``rising`` says raises s.
  With the cut's end sign taken as -1, or a half's sign of D flipped, these checks fail.
"""

from __future__ import annotations

from fractions import Fraction

import mpmath
import numpy as np
import pytest
from flint import arb, ctx, fmpq

from intervalkin.kinematics.sextic import aligned_laurent
from intervalkin.solve.window_plane import split_at_zeros_of_d
from intervalkin.solve.window_union import joined_windows
from tests.solve.test_window_model import _d_mp, _f_mp, _mp_value, _roots_on_circle


@pytest.fixture(scope="module")
def split(fold_paving, paper_geometry):
    models = joined_windows(fold_paving.windows.models)
    return models, split_at_zeros_of_d(paper_geometry, models)


def _s_mp(geometry, rho, phi):
    """s(phi; rho^2) = m_2 x N at 50 digits, from the exact reduction."""
    with ctx.workprec(240):
        rsq = [arb(fmpq(Fraction(float(v)).numerator ** 2, Fraction(float(v)).denominator ** 2)) for v in rho]
        s = aligned_laurent(geometry, rsq)[0]
        coeff = {k: mpmath.mpc(mpmath.mpf(c.real.mid().str(60, radius=False)), mpmath.mpf(c.imag.mid().str(60, radius=False)))
                 for k, c in s.items()}
    return _mp_value(coeff, phi)


def test_halves_replace_the_d_open_windows(split):
    models, sp = split
    new = sp.models
    halves = np.flatnonzero(sp.twin >= 0)
    assert np.unique(new.window_box[halves]).size >= 20, "the paving has boxes the plane crosses"
    assert np.array_equal(sp.twin[sp.twin[halves]], halves)
    assert np.all(new.d_sign[halves] != 0) and np.all(new.end_signs[halves] != 0)
    first = halves[halves < sp.twin[halves]]
    assert np.all(new.end_signs[first, 1] == 1) and np.all(new.end_signs[sp.twin[first], 0] == 1)
    assert np.all(new.d_sign[first] == -new.d_sign[sp.twin[first]])  # D changes sign once, at phi_D
    assert np.all(new.degree[halves] <= sp.window_degree[halves])
    split_boxes = np.flatnonzero(sp.plane != 0)
    assert np.all(np.isin(new.window_box[halves], split_boxes))
    assert np.all((sp.rising[split_boxes] != 0).any(axis=1)) and not sp.rising[sp.plane == 0].any()
    # the windows of the other boxes are untouched, pieces and all
    keep_old = ~np.isin(models.window_box, split_boxes)
    keep_new = ~np.isin(new.window_box, split_boxes)
    for a, b in ((models.degree, new.degree), (models.end_signs, new.end_signs), (models.d_sign, new.d_sign)):
        assert np.array_equal(a[keep_old], b[keep_new])
    on_old, on_new = keep_old[models.piece_window], keep_new[new.piece_window]
    assert np.array_equal(models.piece_lo[on_old], new.piece_lo[on_new])
    assert np.all(np.diff(new.window_box) >= 0) and np.all(np.diff(new.piece_window) >= 0)


def test_halves_count_the_roots_off_the_plane(paper_geometry, split):
    models, sp = split
    new = sp.models
    mpmath.mp.dps = 50
    d_coeff = _d_mp(paper_geometry)
    rng = np.random.default_rng(21)
    left = np.flatnonzero((sp.twin >= 0) & (np.arange(len(sp.twin)) < sp.twin))
    checked, sides, reached = 0, set(), 0
    for w in rng.choice(left, size=min(40, left.size), replace=False):
        t = sp.twin[w]
        box = new.boxes[new.window_box[w]]
        a = mpmath.mpf(float(new.piece_lo[new.piece_window == w][0]))
        b = mpmath.mpf(float(new.piece_hi[new.piece_window == t][-1]))
        guess = 0.5 * (float(new.piece_hi[new.piece_window == w][-1]) + float(new.piece_lo[new.piece_window == t][0]))
        phi_d = mpmath.findroot(lambda x: _mp_value(d_coeff, x), mpmath.mpf(guess))
        assert a < phi_d < b and abs(phi_d - guess) < 1e-8
        rho = box[:, 0] + rng.uniform(size=3) * (box[:, 1] - box[:, 0])
        side = mpmath.sign(_s_mp(paper_geometry, rho, phi_d))
        assert side != 0
        sides.add(int(side))
        coeff = _f_mp(paper_geometry, rho)
        roots = _roots_on_circle(coeff)
        if roots is None:
            continue
        turn = 2 * mpmath.pi
        total = 0
        for half, (lo, hi) in ((w, (a, phi_d)), (t, (phi_d, b))):
            inside = [r + k * turn for r in roots for k in (-1, 0, 1) if lo <= r + k * turn <= hi]
            ends = [int(mpmath.sign(_mp_value(coeff, lo))), int(mpmath.sign(_mp_value(coeff, hi)))]
            assert ends == new.end_signs[half].tolist(), (half, ends)
            assert len(inside) <= new.degree[half] and len(inside) % 2 == int(ends[0] != ends[1])
            assert all(mpmath.sign(_mp_value(d_coeff, x)) == new.d_sign[half] for x in inside)
            total += len(inside)
        assert total <= sp.window_degree[w]
        reached += total > 0
        # s(phi_D; rho^2) rises along rho_l where rising_l says so (s is affine in r: one step shows it)
        for axis in np.flatnonzero(sp.rising[new.window_box[w]]):
            step = np.zeros(3)
            step[axis] = 0.25
            change = _s_mp(paper_geometry, rho + step, phi_d) - _s_mp(paper_geometry, rho, phi_d)
            assert mpmath.sign(change) == sp.rising[new.window_box[w], axis]
        checked += 1
    assert checked >= 25 and sides == {-1, 1} and reached >= 5
