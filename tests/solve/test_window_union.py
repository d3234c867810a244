"""Runs of sub-windows joined into one window (solve.window_union).

- the Rolle bound j + sum_i (d_i - j) on small cases, and on every union of a small paving's no-model
  leaves: at sampled rho, 50-digit mpmath finds at most that many roots of f in the union, of the parity
  of its outer end signs (which hold), with D of the union's sign; both bounds, 2 and 3, are reached at
  some sampled point (three roots in unions of runs of degrees 1, 3, 1 and 2, 3, 2), so a bound one lower,
  or the smallest run's degree, is refused;
- the joined models keep the boxes, their pieces (each now in its union) and the windows that were not runs.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

from intervalkin.solve.window_union import joined_degree, joined_windows
from tests.solve.test_window_model import _d_mp, _f_mp, _mp_value, _roots_on_circle


def test_joined_degree_small_cases():
    runs = [(3, 1), (2, 1), (2, 3), (1, 1), (2, 2), (3, 1, 3), (1, 3, 1), (3,)]
    degrees = np.concatenate([np.array(r) for r in runs])
    group = np.repeat(np.arange(len(runs)), [len(r) for r in runs])
    assert joined_degree(degrees, group, len(runs)).tolist() == [3, 2, 3, 1, 2, 5, 3, 3]


@pytest.fixture(scope="module")
def sub_window_models(fold_paving):
    """Window models of the leaves of the shared depth-5 paving that hold runs of sub-windows (its window models
    are those of the leaves with neither a clear label nor a fold model)."""
    models = fold_paving.windows.models
    runs = np.unique(models.window_box[np.any(models.end_signs == 0, axis=1)])
    assert runs.size >= 40
    return models.take(runs)


def test_joined_windows_bound_the_roots_at_high_precision(paper_geometry, sub_window_models):
    models = sub_window_models
    joined = joined_windows(models)
    size = np.bincount(joined.piece_window, minlength=len(joined.degree))
    # pieces kept, each window's pieces contiguous and in circle order, the windows sorted by box
    assert np.array_equal(joined.piece_lo, models.piece_lo) and np.all(np.diff(joined.piece_window) >= 0)
    assert np.all(np.diff(joined.window_box) >= 0) and size.sum() == models.piece_lo.size
    was_run = np.zeros(len(joined.degree), dtype=bool)
    runs_of = [np.unique(models.piece_window[joined.piece_window == w]) for w in range(len(joined.degree))]
    for w, r in enumerate(runs_of):
        was_run[w] = r.size > 1
    unions = np.flatnonzero(was_run)
    assert unions.size >= 30
    assert set(joined.degree[unions].tolist()) <= {2, 3}
    mpmath.mp.dps = 50
    d_coeff = _d_mp(paper_geometry)
    rng = np.random.default_rng(11)
    counts = []

    def check(w, points):
        """Sample ``points`` joint vectors of window w's box: the bound, the end signs, the parity and D's sign."""
        box = joined.boxes[joined.window_box[w]]
        p = joined.piece_window == w
        lo = [mpmath.mpf(float(x)) for x in joined.piece_lo[p]]
        hi = [mpmath.mpf(float(x)) for x in joined.piece_hi[p]]
        for _ in range(points):
            rho = box[:, 0] + rng.uniform(size=3) * (box[:, 1] - box[:, 0])
            coeff = _f_mp(paper_geometry, rho)
            roots = _roots_on_circle(coeff)
            if roots is None:
                continue
            turn = 2 * mpmath.pi
            inside = sum(any(a <= phi + k * turn <= b for k in (-1, 0, 1) for a, b in zip(lo, hi)) for phi in roots)
            ends = [int(mpmath.sign(_mp_value(coeff, lo[0]))), int(mpmath.sign(_mp_value(coeff, hi[-1])))]
            assert inside <= joined.degree[w], (w, inside)
            assert ends == joined.end_signs[w].tolist()
            assert inside % 2 == int(ends[0] != ends[1])
            at = [a + mpmath.mpf(rng.uniform()) * (b - a) for a, b in zip(lo, hi)]
            assert all(mpmath.sign(_mp_value(d_coeff, phi)) == joined.d_sign[w] for phi in at)
            counts.append((int(joined.degree[w]), inside, tuple(models.degree[runs_of[w]].tolist())))

    for w in rng.choice(unions, size=min(60, unions.size), replace=False):
        check(w, 4)
    assert len(counts) >= 100
    # the bounds are reached: a union bounded by one less (or by its smallest run) is refused at these points.
    # Three roots in a union of degree 3 are rare (about 3 % of the degree-3 unions at a sampled point): more of
    # those unions are sampled, one point each, until one is seen
    threes = unions[joined.degree[unions] == 3]
    for w in rng.permutation(threes)[:300]:
        if any(d == n == 3 for d, n, _ in counts):
            break
        check(w, 1)
    reached = {(d, n) for d, n, _ in counts if d == n}
    assert reached == {(2, 2), (3, 3)}, reached
