"""Cusp windows retracted along the lifted roots (solve.window_cusp, proofs/lemma-joint-retraction.md)."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from intervalkin.solve.dkp import solve
from intervalkin.solve.simple_roots import ReducedBoxes
from intervalkin.solve.window_cusp import (AXIS_PAIRS, cusp_retractions, cusp_retractions_where, cusp_windows,
                                          lifted_pair_signs)
from intervalkin.solve.window_fold import base_signature, critical_pieces, pair_windows, window_kinds
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


def _grad(geometry, r: np.ndarray, phi: float) -> np.ndarray:
    """df/dr at (phi; r), floats."""
    rho = np.sqrt(r)
    data = ReducedBoxes(geometry, np.stack([rho, rho], axis=-1)[None])
    own, at = np.zeros(1, dtype=np.int64), np.array([phi])
    return np.array([float(data.r_slope(own, at, at, i).mid()[0]) for i in range(3)])


@pytest.fixture(scope="module")
def beside_pairs(fold_paving, paper_geometry):
    """Boxes with one cusp window, pair windows beside it and otherwise windows of fixed count (the cusp patterns'
    boxes), their lifted ways and the signs of the pair windows along them (both sides, side-major)."""
    models = fold_paving.windows.models
    cusp, pair = cusp_windows(models), pair_windows(models)
    n = len(models.ok)
    constant = window_kinds(models)[3]
    count = lambda w: np.bincount(models.window_box, weights=w, minlength=n)  # noqa: E731
    rows = np.flatnonzero(models.ok & (count(cusp) == 1) & (count(pair) >= 1) & (count(~pair & ~constant & ~cusp) == 0))
    cr = cusp_retractions(paper_geometry, models, rows)
    signs = lifted_pair_signs(paper_geometry, models, rows, np.concatenate([cr.drive_u] * 2, axis=1),
                              np.concatenate([cr.follow_v] * 2, axis=1), cr.follow_lo.reshape(rows.size, -1),
                              cr.follow_hi.reshape(rows.size, -1), 1)
    return models, rows, cr, signs


def test_pair_signs_along_lifted_ways_hold_at_sampled_points(beside_pairs, paper_geometry):
    """Property test (proofs/lemma-joint-retraction.md, "Cusp patterns: lifted paths"): where
    :func:`lifted_pair_signs` gives a pair window a sign for a way, s (D_u f - q D_v f) has that sign at points
    (r, phi, q) sampled in the box, the window's critical pieces and the way's hull of q.  An enclosure that lost
    a term, or a sign taken without s, fails."""
    models, rows, cr, signs = beside_pairs
    k = cr.faces.shape[2]
    slot = np.full(len(models.ok), -1, dtype=np.int64)
    slot[rows] = np.arange(rows.size)
    data = ReducedBoxes(paper_geometry, models.boxes[rows])
    on = np.isin(models.piece_window, np.flatnonzero(np.any(signs != 0, axis=1)))
    pw, lo, hi = critical_pieces(data, slot[models.window_box], models.end_signs[:, 0].astype(np.int64),
                                 models.piece_window[on], models.piece_lo[on], models.piece_hi[on], 1)
    rng = np.random.default_rng(17)
    checked, seen_signs = 0, set()
    for j in rng.permutation(pw.size)[:150]:
        w = pw[j]
        i = slot[models.window_box[w]]
        box = models.boxes[models.window_box[w]]
        s = float(models.end_signs[w, 0])
        for way in np.flatnonzero(signs[w]):
            q_lo = cr.follow_lo.reshape(rows.size, -1)[i, way]
            q_hi = cr.follow_hi.reshape(rows.size, -1)[i, way]
            u, v = cr.drive_u[i, way % k], cr.follow_v[i, way % k]
            for _ in range(2):
                rho = box[:, 0] + rng.random(3) * (box[:, 1] - box[:, 0])
                phi = lo[j] + rng.random() * (hi[j] - lo[j])
                q = q_lo + rng.random() * (q_hi - q_lo)
                g = _grad(paper_geometry, rho**2, phi)
                value = s * (g @ u - q * (g @ v))
                assert np.sign(value) == signs[w, way], (w, way, rho, phi, q, value)
                checked += 1
                seen_signs.add(int(signs[w, way]))
    assert checked >= 100 and seen_signs == {-1, 1}, (checked, seen_signs)


def test_the_follow_rate_lies_in_its_hull_at_the_followed_root(beside_pairs, paper_geometry):
    """Property test against independent certified solves: at sampled points of a side (one root or three in the
    cusp window), q = f_u / f_v at the followed root (the single one, or the middle of three) lies in the way's
    hull [follow_lo, follow_hi] for every way with a drive: the velocity set of the pair windows' signs holds the
    path's velocity."""
    models, rows, cr, _ = beside_pairs
    rng = np.random.default_rng(19)
    checked = 0
    for i in rng.permutation(rows.size)[:60]:
        on = models.piece_window == cr.window[i]
        wa, wb = models.piece_lo[on][0], models.piece_hi[on][-1]
        if wa >= wb or not cr.drive[i].any():
            continue
        box = models.boxes[rows[i]]
        for _ in range(4):
            x = box[:, 0] + rng.random(3) * (box[:, 1] - box[:, 0])
            got = _signature(paper_geometry, x)
            if got is None:
                continue
            inside = sorted(p for p in got[1] if wa <= p <= wb)
            side = int(len(inside) == 3)
            g = _grad(paper_geometry, x**2, inside[len(inside) // 2])
            for way in np.flatnonzero(cr.drive[i, side]):
                q = (g @ cr.drive_u[i, way]) / (g @ cr.follow_v[i, way])
                assert cr.follow_lo[i, side, way] - 1e-9 * abs(q) <= q <= cr.follow_hi[i, side, way] + 1e-9 * abs(q)
                checked += 1
    assert checked >= 30, checked


def test_ways_where_asked_are_those_of_the_rows_alone(beside_pairs, paper_geometry):
    """``cusp_retractions_where``: the rows asked for get the ways :func:`cusp_retractions` gives them (each box's
    ways come from its own box), the others none (no face, no drive, an empty hull of q), and every row its adds."""
    models, rows, cr, _ = beside_pairs
    where = np.arange(rows.size) % 3 == 0
    got = cusp_retractions_where(paper_geometry, models, rows, cr.window, where)
    for name in ("faces", "drive", "drive_u", "follow_v", "follow_lo", "follow_hi", "adds"):
        assert np.array_equal(getattr(got, name)[where], getattr(cr, name)[where]), name
    assert np.array_equal(got.adds, cr.adds) and np.array_equal(got.window, cr.window)
    assert not got.faces[~where].any() and not got.drive[~where].any()
    assert np.all(got.follow_lo[~where] > got.follow_hi[~where])
