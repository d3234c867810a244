"""Window models (solve.window_model): joint boxes near cusps and crossings of g(S).

- the signature a window model proves at a point equals the independent certified solve
  there (no wrong answer, most points decided), on real no-model leaves of a small paving;
- at sampled (r, phi) in a modelled box, 50-digit mpmath counts the roots of f in each
  window: within the window's degree, of the parity its end signs give, and the end signs
  and the sign of the proved derivative hold;
- the sign rule det A = DET_SIGN * sign(D) * sign(df/dphi) at a root holds in arb at
  certified solutions;
- mutations (a window's degree lowered, an end sign flipped, the sign constant
  negated) are caught by these comparisons.
"""

from __future__ import annotations

import dataclasses
from fractions import Fraction

import mpmath
import numpy as np
import pytest
from flint import arb, ctx, fmpq

import intervalkin.solve.window_model as wm
from intervalkin.core.interval import PI_HI
from intervalkin.kinematics.sextic import laurent_value, reduction
from intervalkin.solve.dkp import solve
from intervalkin.solve.window_model import window_models, window_signature
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


def test_models_cover_most_no_model_leaves(models):
    """Most sampled no-model leaves get a window model; windows are pairs or triples."""
    assert models.ok.mean() > 0.4
    assert set(np.unique(models.degree)) <= {2, 3} and np.any(models.degree == 3)
    assert np.all(models.off[models.ok] >= 0) and np.all(models.off[~models.ok] == -1)
    assert np.all(models.end_signs != 0) and np.all(models.d_sign != 0)


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


def _roots_on_circle(coeff: dict) -> list | None:
    """The angles of the roots of f on the circle (z^3 f(z), degree 6, 50 digits); None if one is too close to call."""
    poly = [coeff.get(k, 0) for k in range(3, -4, -1)]
    roots = mpmath.polyroots(poly, maxsteps=200, extraprec=200)
    out = []
    for z in roots:
        gap = abs(abs(z) - 1)
        if gap < mpmath.mpf(10) ** -25:
            out.append(mpmath.arg(z))
        elif gap < mpmath.mpf(10) ** -8:
            return None
    return out


def test_windows_bound_the_roots_at_high_precision(paper_geometry, models):
    """At random rho in modelled boxes: the roots of f in each window number at most its degree, with the
    parity of its end signs; f has the certified signs at the window ends, and f^(degree) its proved sign."""
    mpmath.mp.dps = 50
    rng = np.random.default_rng(5)
    checked = 0
    for w in rng.choice(len(models.degree), size=min(40, len(models.degree)), replace=False):
        box = models.boxes[models.window_box[w]]
        rho = box[:, 0] + rng.uniform(size=3) * (box[:, 1] - box[:, 0])
        coeff = _f_mp(paper_geometry, rho)
        roots = _roots_on_circle(coeff)
        if roots is None:
            continue
        p = models.piece_window == w
        lo, hi = models.piece_lo[p], models.piece_hi[p]
        a, b = mpmath.mpf(float(lo[0])), mpmath.mpf(float(hi[-1]))
        inside = 0
        for phi in roots:
            for l, h in zip(lo, hi):
                if mpmath.mpf(float(l)) <= phi <= mpmath.mpf(float(h)) or (h == PI_HI and abs(phi - mpmath.pi) < 1e-40):
                    inside += 1
                    break
        assert inside <= models.degree[w], (w, inside)
        assert mpmath.sign(_mp_value(coeff, a)) == models.end_signs[w, 0]
        assert mpmath.sign(_mp_value(coeff, b)) == models.end_signs[w, 1]
        assert inside % 2 == int(models.end_signs[w, 0] != models.end_signs[w, 1])
        for l, h in zip(lo, hi):
            phi = mpmath.mpf(float(l)) + mpmath.mpf(rng.uniform()) * (mpmath.mpf(float(h)) - mpmath.mpf(float(l)))
            signs = mpmath.sign(_mp_value(coeff, phi, int(models.degree[w])))
            assert signs == mpmath.sign(_mp_value(coeff, mpmath.mpf(float(lo[0])), int(models.degree[w])))
        checked += 1
    assert checked >= 20


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
    """Flipping the end sign of every window gives wrong or refused signatures that the solver exposes."""
    flipped = models.end_signs.copy()
    flipped[:, 1] *= -1
    bad = dataclasses.replace(models, end_signs=flipped)
    has = np.zeros(len(models.ok), dtype=bool)
    has[models.window_box] = True
    rows, points = _points(models, np.random.default_rng(4), 1, only=has & models.ok)
    sig = window_signature(paper_geometry, bad, rows[:60], points[:60])
    truth = _truth(paper_geometry, points[:60])
    assert np.all(np.any(sig != truth, axis=1))
