"""Window models (solve.window_model): joint boxes near cusps and crossings of g(S).

- the signature a window model proves at a point equals the independent certified solve
  there (no wrong answer, most points decided), on real no-model leaves of a small paving,
  and in particular in the leaves that only D-open windows and sub-windows model;
- at sampled (r, phi) in a modelled box, 50-digit mpmath counts the roots of f in each
  window: within the window's degree, of the parity its end signs give, and the end signs
  and the sign of the proved derivative hold (sub-windows and D-open windows included);
- the sign rule det A = DET_SIGN * sign(D) * sign(df/dphi) at a root holds in arb at
  certified solutions;
- mutations (a window's degree lowered, an end sign flipped, the sign constant
  negated, the sign of D at the roots of a D-open window flipped, signs claimed at the
  inner cuts of sub-windows) are caught by these comparisons.
"""

from __future__ import annotations

import dataclasses
import inspect
from fractions import Fraction

import mpmath
import numpy as np
import pytest
from flint import arb, ctx, fmpq

import intervalkin.solve.window_count as wc
import intervalkin.solve.window_model as wm
from intervalkin.kinematics.sextic import laurent_value, reduction
from intervalkin.solve.dkp import solve
from intervalkin.solve.window_count import window_signature
from intervalkin.solve.window_model import window_models
from intervalkin.solve.window_split import root_d_signs
from tests.solve.shared import box_across_singular_image, split_of


@pytest.fixture(scope="module")
def no_model_leaves(paper_geometry) -> np.ndarray:
    """A seeded sample of the leaves of a small joint paving with no local model (cell < 0, no fold model)."""
    from intervalkin.space.joint_paving import pave_joint_space

    p = pave_joint_space(paper_geometry, 5, model_levels=1, face_levels=0)
    none = p.cell < 0
    if p.pieces is not None and len(p.pieces):
        none[p.pieces.box] = False
    boxes = np.stack([p.paving.lo[none], p.paving.hi[none]], axis=-1)
    assert len(boxes) > 1000
    return boxes[np.random.default_rng(7).choice(len(boxes), 240, replace=False)]


@pytest.fixture(scope="module")
def models(paper_geometry, no_model_leaves):
    return window_models(paper_geometry, no_model_leaves)


def _points(models, rng, per_box: int, only: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    rows = np.repeat(np.flatnonzero(models.ok if only is None else only), per_box)
    b = models.boxes[rows]
    return rows, b[:, :, 0] + rng.uniform(size=(len(rows), 3)) * (b[:, :, 1] - b[:, :, 0])


def _truth(geometry, points: np.ndarray) -> np.ndarray:
    return np.array([split_of(solve(geometry, [Fraction(float(v)) for v in p])) for p in points])


def _kinds(models) -> tuple[np.ndarray, np.ndarray]:
    """(w,) bool masks of the D-open windows (d_sign 0, certified ends) and of the sub-windows (an end sign 0)."""
    sub = np.any(models.end_signs == 0, axis=1)
    return (models.d_sign == 0) & ~sub, sub


def _boxes_with(models, windows: np.ndarray) -> np.ndarray:
    out = np.zeros(len(models.ok), dtype=bool)
    out[models.window_box[windows]] = True
    return out


def test_models_cover_most_no_model_leaves(models):
    """Nearly all sampled no-model leaves get a window model.  Box-wide windows (certified end signs and D
    sign) are pairs or triples; D-open windows are pairs or triples with d_sign 0; sub-windows (degree 1 to
    3) have an end sign 0 at each inner cut, which is the start of the next sub-window of the same box."""
    assert models.ok.mean() > 0.9
    assert np.all(models.off[models.ok] >= 0) and np.all(models.off[~models.ok] == -1)
    wide = models.box_wide()
    d_open, sub = _kinds(models)
    assert np.all(wide | d_open | sub) and d_open.sum() >= 20 and sub.sum() >= 40 and wide.sum() >= 100
    assert set(np.unique(models.degree[wide | d_open])) == {2, 3} and set(np.unique(models.degree[sub])) == {1, 2, 3}
    inner = np.flatnonzero(models.end_signs[:, 1] == 0)
    assert np.all(models.end_signs[inner + 1, 0] == 0) and np.all(models.window_box[inner + 1] == models.window_box[inner])
    assert np.sum(models.end_signs[:, 0] == 0) == inner.size
    last = np.searchsorted(models.piece_window, inner, side="right") - 1
    first = np.searchsorted(models.piece_window, inner + 1, side="left")
    assert np.array_equal(models.piece_hi[last], models.piece_lo[first])


def test_signatures_agree_with_the_certified_solver(paper_geometry, models):
    """At random points of modelled boxes the window signature is the solver's (count, n_wa1, n_wa2)."""
    rows, points = _points(models, np.random.default_rng(3), 2)
    sig = window_signature(paper_geometry, models, rows, points)
    decided = sig[:, 0] >= 0
    assert decided.mean() > 0.9
    truth = _truth(paper_geometry, points[decided])
    wrong = np.flatnonzero(np.any(sig[decided] != truth, axis=1))
    assert wrong.size == 0, (points[decided][wrong[:3]], sig[decided][wrong[:3]], truth[wrong[:3]])
    assert len(np.unique(truth[:, 0])) >= 3  # boxes of several counts were sampled


def test_signatures_in_leaves_only_the_fixes_model(paper_geometry, models):
    """Boxes with a D-open window (the sign of D proved at each root) or with sub-windows (the signs at
    their inner cuts proved at the point): the window signature at random points is the solver's."""
    d_open, sub = _kinds(models)
    rng = np.random.default_rng(13)
    for kind in (d_open, sub):
        rows, points = _points(models, rng, 3, only=_boxes_with(models, kind))
        assert len(rows) >= 90
        sig = window_signature(paper_geometry, models, rows, points)
        decided = sig[:, 0] >= 0
        assert decided.mean() > 0.95
        truth = _truth(paper_geometry, points[decided])
        wrong = np.flatnonzero(np.any(sig[decided] != truth, axis=1))
        assert wrong.size == 0, (points[decided][wrong[:3]], sig[decided][wrong[:3]], truth[wrong[:3]])


def test_a_box_across_a_fold_gets_both_counts(paper_geometry):
    """A 1e-4 box holding a point of g(S): modelled, and its two ends get their (different) solver signatures."""
    box = box_across_singular_image(paper_geometry)
    m = window_models(paper_geometry, box)
    assert m.ok[0] and len(m.degree) >= 1
    corners = np.array([[box[0, i, (c >> i) & 1] for i in range(3)] for c in range(8)])
    sig = window_signature(paper_geometry, m, np.zeros(8, dtype=np.int64), corners)
    truth = _truth(paper_geometry, corners)
    assert len(set(truth[:, 0])) == 2
    assert np.all(sig[:, 0] >= 0) and np.array_equal(sig, truth)


def _f_mp(geometry, rho: np.ndarray):
    """f(.; rho^2) at 50 digits: the solver's Laurent reduction (independent of the float matrix C)."""
    with ctx.workprec(240):
        rsq = [arb(fmpq(Fraction(float(v)).numerator ** 2, Fraction(float(v)).denominator ** 2)) for v in rho]
        f = reduction(geometry, rsq).f
        coeff = {k: mpmath.mpc(mpmath.mpf(c.real.mid().str(60, radius=False)), mpmath.mpf(c.imag.mid().str(60, radius=False)))
                 for k, c in f.items()}
    return coeff


def _mp_value(coeff: dict, phi, deriv: int = 0):
    w = mpmath.expj(phi)
    return sum(c * (1j * k) ** deriv * w**k for k, c in coeff.items()).real


_ASCENDING = "asc" in inspect.signature(mpmath.polyroots).parameters


def _roots_on_circle(coeff: dict) -> list | None:
    """The angles of the roots of f on the circle (z^3 f(z), degree 6, 50 digits); None if one is too close to call."""
    poly = [coeff.get(k, 0) for k in range(3, -4, -1)]  # highest degree first
    if _ASCENDING:  # mpmath >= 1.4 deprecates the descending order
        roots = mpmath.polyroots(poly[::-1], maxsteps=200, extraprec=200, asc=True)
    else:
        roots = mpmath.polyroots(poly, maxsteps=200, extraprec=200)
    out = []
    for z in roots:
        gap = abs(abs(z) - 1)
        if gap < mpmath.mpf(10) ** -25:
            out.append(mpmath.arg(z))
        elif gap < mpmath.mpf(10) ** -8:
            return None
    return out


def _d_mp(geometry) -> dict:
    """D's Laurent coefficients at 50 digits, from the solver's reduction (D does not depend on r)."""
    with ctx.workprec(240):
        d = reduction(geometry, [arb(0), arb(0), arb(0)]).D
        return {k: mpmath.mpc(mpmath.mpf(c.real.mid().str(60, radius=False)), mpmath.mpf(c.imag.mid().str(60, radius=False)))
                for k, c in d.items()}


def _check_window(geometry, models, w: int, rng) -> bool:
    """At a random rho of window w's box, 50 digits: at most `degree` roots of f in the window, of the parity
    of the signs of f at its ends, which are the certified ones where those are not 0; f^(degree) of one
    sign on its pieces, and D of the sign d_sign where that is not 0.  False if a root is too close to call."""
    mpmath.mp.dps = 50
    box = models.boxes[models.window_box[w]]
    rho = box[:, 0] + rng.uniform(size=3) * (box[:, 1] - box[:, 0])
    coeff = _f_mp(geometry, rho)
    roots = _roots_on_circle(coeff)
    if roots is None:
        return False
    p = models.piece_window == w
    lo, hi = [mpmath.mpf(float(x)) for x in models.piece_lo[p]], [mpmath.mpf(float(x)) for x in models.piece_hi[p]]
    turn = 2 * mpmath.pi
    inside = sum(any(a <= phi + k * turn <= b for k in (-1, 0, 1) for a, b in zip(lo, hi)) for phi in roots)
    ends = [mpmath.sign(_mp_value(coeff, lo[0])), mpmath.sign(_mp_value(coeff, hi[-1]))]
    assert inside <= models.degree[w], (w, inside)
    assert all(c == 0 or e == c for e, c in zip(ends, models.end_signs[w])), (w, ends)
    assert inside % 2 == int(ends[0] != ends[1])
    at = [a + mpmath.mpf(rng.uniform()) * (b - a) for a, b in zip(lo, hi)]
    signs = {mpmath.sign(_mp_value(coeff, phi, int(models.degree[w]))) for phi in at}
    assert len(signs) == 1 and 0 not in signs, (w, signs)
    if models.d_sign[w] != 0:
        d = _d_mp(geometry)
        assert all(mpmath.sign(_mp_value(d, phi)) == models.d_sign[w] for phi in at)
    return True


def test_windows_bound_the_roots_at_high_precision(paper_geometry, models):
    """At random rho in modelled boxes: the roots of f in each window number at most its degree, with the
    parity of its end signs; f has the certified signs at the window ends, and f^(degree) its proved sign."""
    rng = np.random.default_rng(5)
    picked = rng.choice(len(models.degree), size=min(40, len(models.degree)), replace=False)
    assert sum(_check_window(paper_geometry, models, int(w), rng) for w in picked) >= 20


def test_new_windows_bound_the_roots_at_high_precision(paper_geometry, models):
    """The same for D-open windows and for sub-windows (whose inner end signs are not claimed)."""
    rng = np.random.default_rng(6)
    for kind in _kinds(models):
        picked = rng.choice(np.flatnonzero(kind), size=30, replace=False)
        assert sum(_check_window(paper_geometry, models, int(w), rng) for w in picked) >= 20


def det_sign_rule(geometry, rho) -> list[int]:
    """For each certified solution of rho: DET_SIGN * sign D * sign f' * sign det A, in arb (1 when the rule holds)."""
    out = []
    with ctx.workprec(200):
        rsq = [arb(fmpq(r.numerator**2, r.denominator**2)) for r in rho]
        red = reduction(geometry, rsq)
        df = {k: c * 1j * k for k, c in red.f.items()}
        for s in solve(geometry, rho).solutions:
            phi = arb.union(arb(float(s.box[2, 0])), arb(float(s.box[2, 1])))
            d, fp = laurent_value(red.D, phi).real, laurent_value(df, phi).real
            assert not d.contains(0) and not fp.contains(0)
            out.append(wm.DET_SIGN * (1 if d > 0 else -1) * (1 if fp > 0 else -1) * s.det_sign)
    return out


def test_det_sign_rule_holds_and_its_negation_is_caught(paper_geometry, monkeypatch):
    """sign det A = DET_SIGN * sign D * sign f' at every certified solution of several joint vectors
    (Table 1 included); with the constant negated the check fails at every solution."""
    vectors = [[Fraction("14.98"), Fraction("15.38"), Fraction(12)], [Fraction(20), Fraction(20), Fraction(20)],
               [Fraction(14), Fraction(26), Fraction(30)], [Fraction(25), Fraction(17), Fraction(22)]]
    rules = [v for rho in vectors for v in det_sign_rule(paper_geometry, rho)]
    assert len(rules) >= 10 and set(rules) == {1}
    monkeypatch.setattr(wm, "DET_SIGN", -wm.DET_SIGN)
    assert set(det_sign_rule(paper_geometry, vectors[0])) == {-1}


def test_a_lowered_degree_is_caught(paper_geometry, models):
    """Every window's degree lowered by one (a triple called a pair, a pair called a single root) gives
    wrong or refused signatures at some points, and every change is wrong or refused.  (Points where a
    triple window holds three roots are rare in these leaves, so the pairs carry most of this test.)"""
    rows, points = _points(models, np.random.default_rng(9), 3)
    bad = dataclasses.replace(models, degree=(models.degree - 1).astype(np.int8))
    good_sig = window_signature(paper_geometry, models, rows, points)
    bad_sig = window_signature(paper_geometry, bad, rows, points)
    changed = np.flatnonzero(np.any(bad_sig != good_sig, axis=1))
    assert changed.size >= 5
    truth = _truth(paper_geometry, points[changed[:40]])
    assert np.all(np.any(bad_sig[changed[:40]] != truth, axis=1))


def test_a_flipped_end_sign_is_caught(paper_geometry, models):
    """Flipping one certified end sign in every box (of its first window: the last end, or the first for a
    sub-window whose last end is an inner cut) changes that window's count by one wherever it is decided:
    every signature is wrong or refused, and the solver exposes it."""
    flipped = models.end_signs.copy()
    first = np.flatnonzero(np.r_[True, models.window_box[1:] != models.window_box[:-1]])
    end = np.where(flipped[first, 1] != 0, 1, 0)
    flipped[first, end] *= -1
    bad = dataclasses.replace(models, end_signs=flipped)
    rows, points = _points(models, np.random.default_rng(4), 1, only=_boxes_with(models, first) & models.ok)
    sig = window_signature(paper_geometry, bad, rows[:80], points[:80])
    truth = _truth(paper_geometry, points[:80])
    assert np.all(np.any(sig != truth, axis=1))


def test_a_flipped_d_sign_at_the_roots_is_caught(paper_geometry, models, monkeypatch):
    """The sign of D proved at the roots of D-open windows, negated: the aspect split moves at every decided
    point with a root in such a window, and the solver exposes each change."""
    d_open, _ = _kinds(models)
    rows, points = _points(models, np.random.default_rng(21), 3, only=_boxes_with(models, d_open))
    good = window_signature(paper_geometry, models, rows, points)
    monkeypatch.setattr(wc, "root_d_signs", lambda *a, **k: -root_d_signs(*a, **k))
    bad = window_signature(paper_geometry, models, rows, points)
    changed = np.flatnonzero(np.any(bad != good, axis=1))
    assert changed.size >= 20 and np.all(bad[changed, 0] == good[changed, 0])
    solved = [solve(paper_geometry, [Fraction(float(v)) for v in p]) for p in points[changed]]
    complete = [s.complete for s in solved]  # the solver leaves a root very near a zero of D open
    truth = np.array([split_of(s) for s in solved if s.complete])
    assert len(truth) >= 20 and np.all(np.any(bad[changed][complete] != truth, axis=1))


def test_claimed_inner_cut_signs_are_caught(paper_geometry, models):
    """Signs claimed over the box at the inner cuts of sub-windows (every end sign 0 replaced by +1, then
    by -1): wherever f has the other sign at the point, the signature changes, and every change is wrong or
    refused."""
    _, sub = _kinds(models)
    rows, points = _points(models, np.random.default_rng(22), 2, only=_boxes_with(models, sub))
    good = window_signature(paper_geometry, models, rows, points)
    for claim in (1, -1):
        bad = dataclasses.replace(models, end_signs=np.where(models.end_signs == 0, claim, models.end_signs).astype(np.int8))
        sig = window_signature(paper_geometry, bad, rows, points)
        changed = np.flatnonzero(np.any(sig != good, axis=1) & (good[:, 0] >= 0))
        assert changed.size >= 10
        truth = _truth(paper_geometry, points[changed])
        assert np.all(np.any(sig[changed] != truth, axis=1))


def test_take_is_the_model_of_those_boxes_alone(paper_geometry, no_model_leaves, models):
    # each box is modelled on its own, so the rows taken from the models of many boxes must be, array for
    # array, the models of those boxes computed alone (a window, piece or root arc moved to another box fails)
    rows = np.flatnonzero(models.ok)[1::7][:40]
    rows = np.sort(np.concatenate([rows, np.flatnonzero(~models.ok)[:3]]))
    taken, alone = models.take(rows), window_models(paper_geometry, no_model_leaves[rows])
    for name in taken.__dataclass_fields__:
        assert np.array_equal(getattr(taken, name), getattr(alone, name)), name
    assert len(taken.degree) > len(rows) and len(taken.root_box) > 0


def test_points_only_in_boxes_without_windows_are_counted(paper_geometry, models):
    # a call whose boxes have no window at all (once an IndexError): the count is the roots off the windows
    _, n = models.windows_of(np.arange(len(models.ok)))
    rows = np.flatnonzero(models.ok & (n == 0))[:3]
    assert rows.size
    points = models.boxes[rows].mean(axis=2)
    sig = window_signature(paper_geometry, models, rows, points)
    assert np.array_equal(sig, models.off[rows])
    truth = np.array([split_of(solve(paper_geometry, [Fraction(float(v)) for v in p])) for p in points])
    assert np.array_equal(sig, truth)
