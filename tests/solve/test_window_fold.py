"""Window folds and window-clear boxes (solve.window_fold, proofs/lemma-window-fold.md).

The boxes are the window-modelled leaves of the session's depth-5 joint paving (``fold_paving``).

- the piece a point is placed in matches the roots of f counted at 50 digits in the pair window
  (0 or 2), and the piece's signature is the certified solver's;
- along random lines parallel to an axis the pair window's count changes at most once, from two
  roots to none in the direction the model says u grows (down-set / up-set), and reversing the
  directions is caught by the same check;
- ``ReducedBoxes.r_slope`` encloses df/dr_l computed in arb (f is quadratic in r: a central
  difference is exact); with ``mean_value`` also d^2 f / dr_l dphi, at the pieces' ends too.
"""

from __future__ import annotations

import dataclasses
from fractions import Fraction

import mpmath
import numpy as np
import pytest
from flint import arb, ctx, fmpq

from intervalkin.core.interval import Interval
from intervalkin.kinematics.sextic import laurent_value, reduction
from intervalkin.solve.simple_roots import ReducedBoxes
from intervalkin.solve.window_fold import CLEAR, FOLD, extreme_corners, fold_piece
from tests.solve.test_window_model import _f_mp, _roots_on_circle, _truth


@pytest.fixture(scope="module")
def windows(fold_paving):
    w = fold_paving.windows
    assert w is not None and w.folds is not None
    return w


def _points_in(windows, kind: int, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    rows = rng.choice(np.flatnonzero(windows.folds.kind == kind), n, replace=True)
    b = windows.models.boxes[rows]
    return rows, b[:, :, 0] + rng.uniform(size=(n, 3)) * (b[:, :, 1] - b[:, :, 0])


def _window_roots(geometry, windows, w: int, rho: np.ndarray) -> int | None:
    """Roots of f(.; rho^2) in window w, counted at 50 digits (None when one is too close to call)."""
    mpmath.mp.dps = 50
    roots = _roots_on_circle(_f_mp(geometry, rho))
    if roots is None:
        return None
    m = windows.models
    p = m.piece_window == w
    inside = 0
    for phi in roots:
        inside += any(mpmath.mpf(float(lo)) <= phi <= mpmath.mpf(float(hi))
                      or (mpmath.mpf(float(lo)) <= phi + 2 * mpmath.pi <= mpmath.mpf(float(hi)))
                      or (mpmath.mpf(float(lo)) <= phi - 2 * mpmath.pi <= mpmath.mpf(float(hi)))
                      for lo, hi in zip(m.piece_lo[p], m.piece_hi[p]))
    return inside


def test_folds_and_clear_boxes_are_found(windows):
    kind = windows.folds.kind
    assert np.count_nonzero(kind == FOLD) > 200 and np.count_nonzero(kind == CLEAR) > 50
    r, e = windows.folds.rising[kind == FOLD], windows.folds.edge_rising[kind == FOLD]
    full = (r != 0).all(axis=1)
    two = (np.count_nonzero(r, axis=1) == 2) & (e != 0).all(axis=1)
    assert np.all(full | two) and not np.any(e[full]) and full.sum() > 100 and two.sum() > 20
    assert np.all(windows.folds.signature[kind == FOLD, 1] - windows.folds.signature[kind == FOLD, 0] == [2, 1, 1])


def test_piece_counts_agree_with_high_precision_roots(paper_geometry, windows):
    """Random points of window folds: piece s holds exactly 2 s roots of f in the pair window (50 digits)."""
    rows, points = _points_in(windows, FOLD, 80, 1)
    piece = fold_piece(paper_geometry, windows.models, windows.folds, rows, points)
    assert (piece >= 0).mean() > 0.9
    checked = 0
    for r, q, s in zip(rows, points, piece):
        if s < 0:
            continue
        n = _window_roots(paper_geometry, windows, int(windows.folds.window[r]), q)
        if n is None:
            continue
        assert n == 2 * s, (r, q, s, n)
        checked += 1
    assert checked >= 60
    assert len(set(piece[piece >= 0])) == 2  # both pieces were sampled


def test_piece_signatures_are_the_solvers(paper_geometry, windows):
    """Points of window folds and window-clear boxes: the signature of their piece is the certified solver's."""
    rows_f, pts_f = _points_in(windows, FOLD, 30, 2)
    rows_c, pts_c = _points_in(windows, CLEAR, 15, 3)
    rows, points = np.r_[rows_f, rows_c], np.concatenate([pts_f, pts_c])
    piece = fold_piece(paper_geometry, windows.models, windows.folds, rows, points)
    ok = piece >= 0
    sig = windows.folds.signature[rows[ok], piece[ok]]
    assert np.array_equal(sig, _truth(paper_geometry, points[ok]))
    assert ok.sum() >= 40


def _violations(geometry, windows, folds, lines: int, seed: int) -> tuple[int, int]:
    """(lines whose piece sequence breaks the down-set / up-set rule, lines where the piece changes)."""
    rng = np.random.default_rng(seed)
    rows = rng.choice(np.flatnonzero(folds.kind == FOLD), lines)
    # an axis along which u is proved monotone on the whole box
    axis = np.array([rng.choice(np.flatnonzero(folds.rising[r] != 0)) for r in rows])
    b = windows.models.boxes[rows]
    base = b[:, :, 0] + rng.uniform(size=(lines, 3)) * (b[:, :, 1] - b[:, :, 0])
    return _along(geometry, windows, folds, rows, axis, base, folds.rising[rows, axis])


def _along(geometry, windows, folds, rows, axis, base, direction) -> tuple[int, int]:
    lines = len(rows)
    b = windows.models.boxes[rows]
    t = np.linspace(0.0, 1.0, 9)
    pts = np.repeat(base[:, None, :], len(t), axis=1)
    idx = np.arange(lines)
    pts[idx[:, None], np.arange(len(t))[None, :], axis[:, None]] = (b[idx, axis, 0][:, None]
                                                                     + t[None, :] * (b[idx, axis, 1] - b[idx, axis, 0])[:, None])
    piece = fold_piece(geometry, windows.models, folds, np.repeat(rows, len(t)), pts.reshape(-1, 3)).reshape(lines, -1)
    bad = changing = 0
    for line, d in zip(piece, direction):
        seq = line[line >= 0] if d > 0 else line[line >= 0][::-1]
        # in the direction where u grows the piece goes from 1 (two roots) to 0 (none), never back
        changing += len(set(seq)) > 1
        bad += bool(np.any(np.diff(seq.astype(int)) > 0))
    return bad, changing


def test_pieces_are_down_and_up_sets_along_every_axis(paper_geometry, windows):
    bad, changing = _violations(paper_geometry, windows, windows.folds, 300, 4)
    assert bad == 0 and changing >= 10


def test_two_axis_folds_are_monotone_on_their_edges(paper_geometry, windows):
    """Two-axis folds: along the free axis, on the edge towards -rising (and towards +rising), the window's
    count changes at most once in the direction of edge_rising; the extreme corners are ordered."""
    folds = windows.folds
    rows = np.flatnonzero((folds.kind == FOLD) & (folds.edge_rising != 0).all(axis=1))[:150]
    free = np.argmin(np.abs(folds.rising[rows]), axis=1)
    b = windows.models.boxes[rows]
    bad = changing = 0
    for end, toward in enumerate((-1, 1)):
        base = np.where(folds.rising[rows] * toward > 0, b[:, :, 1], b[:, :, 0])
        got = _along(paper_geometry, windows, folds, rows, free, base, folds.edge_rising[rows, end])
        bad, changing = bad + got[0], changing + got[1]
    assert bad == 0 and changing >= 5
    low, high = extreme_corners(b[:, :, 0], b[:, :, 1], folds.rising[rows], folds.edge_rising[rows])
    side_low = fold_piece(paper_geometry, windows.models, folds, rows, low)
    side_high = fold_piece(paper_geometry, windows.models, folds, rows, high)
    assert not np.any((side_high == 1) & (side_low == 0))


def test_a_flipped_slope_is_caught(paper_geometry, windows):
    """Directions reversed: the same lines break the rule, and the extreme corners land in the wrong pieces."""
    flipped = dataclasses.replace(windows.folds, rising=(-windows.folds.rising).astype(np.int8),
                                  edge_rising=(-windows.folds.edge_rising).astype(np.int8))
    bad, changing = _violations(paper_geometry, windows, flipped, 300, 4)
    assert bad >= 10 and bad == changing
    rows = np.flatnonzero(windows.folds.kind == FOLD)[:400]
    b = windows.models.boxes[rows]
    low, high = extreme_corners(b[:, :, 0], b[:, :, 1], windows.folds.rising[rows], windows.folds.edge_rising[rows])
    side_low = fold_piece(paper_geometry, windows.models, windows.folds, rows, low)
    side_high = fold_piece(paper_geometry, windows.models, windows.folds, rows, high)
    # the corner where u is smallest is in piece 1 whenever the corner where it is largest is
    assert not np.any((side_high == 1) & (side_low == 0))
    assert np.any((side_low == 1) & (side_high == 0))


def test_r_slope_encloses_the_derivative(paper_geometry, windows):
    """At random (r, phi) in pieces of pair windows, df/dr_l in arb lies in the enclosure over the piece."""
    m, folds = windows.models, windows.folds
    rng = np.random.default_rng(6)
    rows = rng.choice(np.flatnonzero(folds.kind == FOLD), 40)
    data = ReducedBoxes(paper_geometry, m.boxes[rows])
    checked = 0
    for i, r in enumerate(rows):
        p = np.flatnonzero(m.piece_window == folds.window[r])
        j = rng.choice(p)
        lo, hi = m.piece_lo[j], m.piece_hi[j]
        box = m.boxes[r]
        rho = box[:, 0] + rng.uniform(size=3) * (box[:, 1] - box[:, 0])
        phi = lo + rng.uniform() * (hi - lo)
        for axis in range(3):
            enc = data.r_slope(np.array([i]), np.array([lo]), np.array([hi]), axis)
            with ctx.workprec(200):
                rsq = [arb(fmpq(Fraction(float(v)).numerator ** 2, Fraction(float(v)).denominator ** 2)) for v in rho]
                h = arb(1)
                up, down = list(rsq), list(rsq)
                up[axis] += h
                down[axis] -= h
                z = arb(fmpq(Fraction(float(phi)).numerator, Fraction(float(phi)).denominator))
                d = (laurent_value(reduction(paper_geometry, up).f, z).real
                     - laurent_value(reduction(paper_geometry, down).f, z).real) / 2
                assert float(d.mid()) - float(d.rad()) >= enc.lo[0] and float(d.mid()) + float(d.rad()) <= enc.hi[0]
            checked += 1
    assert checked == 120


def test_direction_signs_hold_exactly_in_blocks_and_agree_with_interval_sums(rng):
    """The retraction's direction signs (root_directions._direction_signs: integer directions, two matrix products
    per end, taken in row blocks):
    where a sign is proved, the exact rational sum sum_l e_l x_l at sampled points of the boxes has it, for
    grads of very different magnitudes, one infinite end and a NaN; and they match the direction-by-direction
    interval sums except where a sum is within rounding of 0 (rows whose x_1 and x_2 are one float apart make
    such sums).  Fails if a block is skipped or misaligned."""
    from intervalkin.solve.root_directions import _SIGN_BLOCK, _direction_signs
    from intervalkin.space.retraction_nodes import DIRECTIONS

    m = 2 * _SIGN_BLOCK + 37  # three blocks, the last one short
    scale = 10.0 ** rng.integers(-3, 6, size=(m, 1))
    lo = rng.normal(size=(m, 3)) * scale
    hi = lo + np.abs(rng.normal(size=(m, 3))) * scale * rng.choice([0.0, 1e-12, 0.1], size=(m, 3))
    # rows where e = (1, -1, 0) cancels to within one ulp: x_1 and x_2 points one float apart
    near = rng.choice(m, 300, replace=False)
    lo[near, 1] = np.nextafter(lo[near, 0], np.inf)
    hi[near, :2] = lo[near, :2]
    lo[5, 2], hi[6, 0], lo[7, 1] = -np.inf, np.inf, np.nan
    grad = [Interval(lo[:, i], hi[:, i]) for i in range(3)]
    got = _direction_signs(grad, DIRECTIONS.astype(float))
    assert got.shape == (m, len(DIRECTIONS)) and got.dtype == np.int8
    assert not got[5].any() and not got[6].any() and not got[7].any()  # a non-finite end proves nothing
    with np.errstate(invalid="ignore"):  # inf * 0 in the reference: NaN, no sign
        ref = np.column_stack([np.where((g := grad[0] * e[0] + grad[1] * e[1] + grad[2] * e[2]).lo > 0, 1,
                                        np.where(g.hi < 0, -1, 0)) for e in DIRECTIONS.astype(float)])
    differ = got != ref
    assert differ.sum() <= 0.01 * got.size, "the blocked sums lost far more signs than rounding explains"
    rows = np.r_[near[:50], rng.choice(m, 200, replace=False)]
    for i in rows:
        if not np.isfinite(lo[i]).all() or not np.isfinite(hi[i]).all():
            continue
        for t in (0.0, 1.0, rng.random()):
            x = [Fraction(float(a)) + (Fraction(float(b)) - Fraction(float(a))) * Fraction(t).limit_denominator(1000)
                 for a, b in zip(lo[i], hi[i])]
            for c, e in enumerate(DIRECTIONS):
                v = sum(int(e[l]) * x[l] for l in range(3))
                assert got[i, c] == 0 or (v > 0 if got[i, c] > 0 else v < 0), (i, e, v, got[i, c])


def _laurent_phi_derivative(p: dict, phi):
    """d/dphi L(exp(i phi)) = sum_k i k c_k exp(i k phi), as an acb (the derivative of each term is exact)."""
    from flint import acb

    return laurent_value({k: c * acb(0, k) for k, c in p.items() if k}, phi)


def test_mean_value_r_slopes_enclose_the_derivatives(paper_geometry, windows):
    """With ``mean_value`` (what the cusp windows' lifted paths read), df/dr_l and d^2 f/dr_l dphi in arb lie in the
    enclosure at random points of the box and at points of the piece's ends, where the mean-value form's offset term
    is largest; and most enclosures are at least 10 % narrower than the natural form's."""
    m, folds = windows.models, windows.folds
    rng = np.random.default_rng(16)
    rows = rng.choice(np.flatnonzero(folds.kind == FOLD), 30)
    data = ReducedBoxes(paper_geometry, m.boxes[rows])
    checked, narrower, compared = 0, 0, 0
    for i, r in enumerate(rows):
        j = rng.choice(np.flatnonzero(m.piece_window == folds.window[r]))
        lo, hi = m.piece_lo[j], m.piece_hi[j]
        box = m.boxes[r]
        for u in (0.0, 1.0, rng.uniform()):
            rho = box[:, 0] + rng.uniform(size=3) * (box[:, 1] - box[:, 0])
            phi = lo + u * (hi - lo)
            for axis in range(3):
                for deriv in (0, 1):
                    args = (np.array([i]), np.array([lo]), np.array([hi]), axis, deriv)
                    enc = data.r_slope(*args, mean_value=True)
                    nat = data.r_slope(*args)
                    compared += 1
                    narrower += enc.hi[0] - enc.lo[0] < 0.9 * (nat.hi[0] - nat.lo[0])
                    with ctx.workprec(200):
                        rsq = [arb(fmpq(Fraction(float(v)).numerator ** 2, Fraction(float(v)).denominator ** 2))
                               for v in rho]
                        up, down = list(rsq), list(rsq)
                        up[axis] += 1
                        down[axis] -= 1  # f is quadratic in r: the central difference is the derivative
                        z = arb(fmpq(Fraction(float(phi)).numerator, Fraction(float(phi)).denominator))
                        value = laurent_value if deriv == 0 else _laurent_phi_derivative
                        d = (value(reduction(paper_geometry, up).f, z).real
                             - value(reduction(paper_geometry, down).f, z).real) / 2
                        assert float(d.mid()) - float(d.rad()) >= enc.lo[0], (r, axis, deriv, u)
                        assert float(d.mid()) + float(d.rad()) <= enc.hi[0], (r, axis, deriv, u)
                    checked += 1
    assert checked == 540
    assert narrower > 0.5 * compared
