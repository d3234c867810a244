"""Cusp windows retracted along the lifted roots (solve.window_cusp, proofs/lemma-joint-retraction.md)."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from intervalkin.solve.dkp import solve
from intervalkin.solve.simple_roots import ReducedBoxes
from intervalkin.solve.window_cusp import AXIS_PAIRS, cusp_retractions, cusp_windows
from intervalkin.solve.window_fold import base_signature
from intervalkin.solve.window_union import joined_windows


@pytest.fixture(scope="module", params=[3, 4], ids=["degree-3", "union-of-degree-4"])
def lifted(fold_paving, paper_geometry, request):
    """The cusp windows of the models (degree 3), or the unions of runs with Rolle bound 4 that the retraction
    reads as cusp windows too (``joined_windows(max_degree=4)``; only rows whose cusp window is such a union)."""
    models = fold_paving.windows.models
    if request.param == 4:
        models = joined_windows(models, max_degree=4)
    cusp = cusp_windows(models)
    one = np.bincount(models.window_box, weights=cusp, minlength=len(models.ok)) == 1
    of_degree = np.bincount(models.window_box, weights=cusp & (models.degree == request.param),
                            minlength=len(models.ok)) == 1
    rows = np.flatnonzero(models.ok & one & of_degree)
    return models, cusp_retractions(paper_geometry, models, rows)


def _f(geometry, r: np.ndarray, phi: float, v: np.ndarray) -> tuple[float, float]:
    """(f, grad_r f . v) at (phi; r), floats (the midpoints of point enclosures)."""
    rho = np.sqrt(r)
    data = ReducedBoxes(geometry, np.stack([rho, rho], axis=-1)[None])
    own, at = np.zeros(1, dtype=np.int64), np.array([phi])
    value = data.enclosure(own, at, at, 0).mid()[0]
    slope = sum(v[i] * data.r_slope(own, at, at, i).mid()[0] for i in range(3))
    return float(value), float(slope)


def _signature(geometry, rho) -> tuple[tuple[int, int, int], list[float]] | None:
    res = solve(geometry, [Fraction(float(x)) for x in rho])
    if not res.complete or any(s.status != "unique" or s.det_sign == 0 for s in res.solutions):
        return None
    n1 = sum(s.det_sign > 0 for s in res.solutions)
    return (len(res.solutions), n1, len(res.solutions) - n1), [float(s.box[2].mean()) for s in res.solutions]


def test_signatures_of_the_two_sides_differ_by_two_roots(lifted):
    models, cr = lifted
    assert cr.rows.size > 50
    assert np.all(cr.adds[:, 0, 0] == 1) and np.all(cr.adds[:, 1, 0] == 3)
    assert np.all(cr.adds[:, :, 1] + cr.adds[:, :, 2] == cr.adds[:, :, 0])
    # the three roots are the single root's side twice over plus one of the other aspect
    assert np.all(np.abs(cr.adds[:, 1, 1] - cr.adds[:, 1, 2]) == 1)
    assert np.all(cr.faces.any(axis=3) == (cr.drive != 0) | (cr.faces.sum(axis=3) == 1))
    assert np.all(cr.faces.shape[2] == len(AXIS_PAIRS) + 1)


def test_the_lifted_path_keeps_the_signature_up_to_a_face(lifted, paper_geometry):
    """Property test against independent certified solves: from a point of a side (its signature found by a solve),
    hold the window's root fixed (the middle one of three, or the single one) and move r along d u, correcting
    along v (Newton); every point of the path up to the box's boundary keeps the side's signature, and the
    path leaves through one of the way's faces."""
    models, cr = lifted
    base = base_signature(models)
    rng = np.random.default_rng(7)
    done = 0
    for i, side, way in zip(*np.nonzero(cr.drive)):
        if done >= 12:
            break
        row = cr.rows[i]
        box = models.boxes[row]
        on = models.piece_window == cr.window[i]
        wa, wb = models.piece_lo[on][0], models.piece_hi[on][-1]
        if wa >= wb:
            continue  # a window across phi = pi: skipped here
        want = tuple(base[row] + cr.adds[i, side])
        start = None
        for _ in range(40):
            x = box[:, 0] + rng.random(3) * (box[:, 1] - box[:, 0])
            got = _signature(paper_geometry, x)
            if got is not None and got[0] == want:
                inside = sorted(p for p in got[1] if wa <= p <= wb)
                if len(inside) == (3 if side else 1):
                    start, phi0 = x, inside[len(inside) // 2]
                    break
        if start is None:
            continue
        u, v, d = cr.drive_u[i, way], cr.follow_v[i, way], float(cr.drive[i, side, way])
        r0 = start**2
        step = 0.05 * float(np.min((box[:, 1] ** 2 - box[:, 0] ** 2)[u != 0])) / max(np.abs(u).max(), 1e-12)
        h, left = 0.0, None
        for k in range(1, 400):
            for _ in range(8):  # hold the root: f(phi0; r + h v) = 0
                value, slope = _f(paper_geometry, r0 + k * step * d * u + h * v, phi0, v)
                h -= value / slope
            rho = np.sqrt(r0 + k * step * d * u + h * v)
            out = np.flatnonzero((rho < box[:, 0]) | (rho > box[:, 1]))
            if out.size:
                ax = out[0]
                left = 2 * ax + int(rho[ax] > box[ax, 1])
                break
            if k % 3 == 0:
                got = _signature(paper_geometry, rho)
                assert got is None or got[0] == want, (row, side, way, rho, got)
        assert left is not None and cr.faces[i, side, way, left], (row, side, way, left)
        done += 1
    assert done >= 6


def test_unions_read_as_cusp_windows_hold_one_or_three_roots(fold_paving, paper_geometry):
    """Property test against independent certified solves: a union of runs with Rolle bound 4 and end signs that
    differ (a cusp window of ``joined_windows(max_degree=4)``) holds one or three solutions at sampled points,
    never 0, 2 or 4 (which a wrong degree bound or end sign would allow); and unions of bound 5 are not read as
    cusp windows."""
    models = joined_windows(fold_paving.windows.models, max_degree=6)
    cusp = cusp_windows(models)
    assert not np.any(cusp & (models.degree > 4))
    wins = np.flatnonzero(cusp & (models.degree == 4))
    assert wins.size > 100
    rng = np.random.default_rng(3)
    seen = {}
    for w in rng.choice(wins, 60, replace=False):
        box = models.boxes[models.window_box[w]]
        on = models.piece_window == w
        wa, wb = models.piece_lo[on][0], models.piece_hi[on][-1]  # wa > wb: across phi = pi
        for _ in range(4):
            got = _signature(paper_geometry, box[:, 0] + rng.random(3) * (box[:, 1] - box[:, 0]))
            if got is None:
                continue
            inside = [p for p in got[1] if (wa <= p <= wb if wa < wb else (p >= wa or p <= wb))]
            seen[len(inside)] = seen.get(len(inside), 0) + 1
    assert seen and set(seen) <= {1, 3}, seen
    assert sum(seen.values()) >= 100
