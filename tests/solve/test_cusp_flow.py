"""The inflection flow of a cusp window (solve.cusp_flow, proofs/lemma-joint-retraction.md "Cusp windows: the
inflection flow"), followed numerically and checked against independent certified solves."""

from __future__ import annotations

import json
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from intervalkin.solve.cusp_flow import FLOW_AXES, flow_ways, inflection_flows
from intervalkin.solve.dkp import solve
from intervalkin.solve.simple_roots import ReducedBoxes
from intervalkin.solve.window_cusp import cusp_windows, lifted_pair_signs
from intervalkin.solve.window_fold import pair_windows, window_kinds
from intervalkin.solve.window_model import window_models
from intervalkin.solve.window_plane import split_at_zeros_of_d
from intervalkin.solve.window_union import joined_windows


@pytest.fixture(scope="module")
def flows(paper_geometry):
    """Leaves of the default paving near its cusp edges (``tests/data/cusp_flow_leaves.json``: boxes only), modelled
    again as the retraction reads them (runs of sub-windows joined, windows cut at the zeros of D); the rows with
    one cusp window, the others of fixed count and no plane, and their flows."""
    boxes = np.array(json.loads((Path(__file__).parents[1] / "data" / "cusp_flow_leaves.json").read_text())["boxes"])
    split = split_at_zeros_of_d(paper_geometry, joined_windows(window_models(paper_geometry, boxes)))
    models = split.models
    cusp, n = cusp_windows(models), len(models.ok)
    fixed = np.bincount(models.window_box, weights=~cusp & ~window_kinds(models)[3], minlength=n) == 0
    one = np.bincount(models.window_box, weights=cusp, minlength=n) == 1
    crow = np.flatnonzero(models.ok & one & fixed & (split.plane == 0))
    return models, crow, inflection_flows(paper_geometry, models, crow)


def _point(geometry, r: np.ndarray) -> ReducedBoxes:
    rho = np.sqrt(r)
    return ReducedBoxes(geometry, np.stack([rho, rho], axis=-1)[None])


def _field(geometry, r: np.ndarray, wa: float, wb: float, j: int) -> np.ndarray | None:
    """V(r) in floats: psi the zero of g'' in [wa, wb] (bisection), V_j = 0, grad g(psi) . V = 0, grad g' . V = -1."""
    data = _point(geometry, r)
    own = np.zeros(1, dtype=np.int64)

    def d(order: int, phi: float) -> float:
        return float(data.enclosure(own, np.array([phi]), np.array([phi]), order).mid()[0])

    s3 = np.sign(d(3, 0.5 * wa + 0.5 * wb))
    a_, b_ = wa, wb
    if not (s3 * d(2, a_) < 0 < s3 * d(2, b_)):
        return None
    for _ in range(40):  # the window is under 1 rad wide: psi to 1e-12
        c = 0.5 * a_ + 0.5 * b_
        a_, b_ = (c, b_) if s3 * d(2, c) < 0 else (a_, c)
    psi = np.array([0.5 * a_ + 0.5 * b_])
    grad = np.array([s3 * data.r_slope(own, psi, psi, i, 0).mid()[0] for i in range(3)])
    grad1 = np.array([s3 * data.r_slope(own, psi, psi, i, 1).mid()[0] for i in range(3)])
    i, k = [x for x in range(3) if x != j]
    det = grad[i] * grad1[k] - grad[k] * grad1[i]
    v = np.zeros(3)
    v[i], v[k] = grad[k] / det, -grad[i] / det
    return v


def _in_windows(geometry, rho: np.ndarray, arcs) -> list[int] | None:
    """The number of solutions with phi in each [wa, wb] of ``arcs``, from one independent certified solve (None:
    not complete)."""
    res = solve(geometry, [Fraction(float(x)) for x in rho])
    if not res.complete or any(s.status != "unique" for s in res.solutions):
        return None
    return [sum(wa <= float(s.box[2].mean()) <= wb for s in res.solutions) for wa, wb in arcs]


def _in_window(geometry, rho: np.ndarray, wa: float, wb: float) -> int | None:
    """The number of solutions with phi in [wa, wb] (:func:`_in_windows`)."""
    got = _in_windows(geometry, rho, [(wa, wb)])
    return None if got is None else got[0]


def test_flows_are_found_near_the_cusp_edges(flows):
    children, crow, faces = flows
    assert crow.size >= 40
    found = faces.any(axis=(2, 3))
    assert found.any(axis=1).sum() >= 30
    # both sides of a flow are proved together, along +V and -V: their faces mirror each other
    assert np.array_equal(found[:, 0], found[:, 1])
    assert faces.shape[2] == len(FLOW_AXES)


def test_the_flow_keeps_the_count_of_the_window_up_to_a_face(flows, paper_geometry):
    """From a point of a side (its count in the window found by a certified solve), follow V (three roots) or -V
    (one root) in small steps; the count in the window stays the side's at every point checked, and the path leaves
    through one of the way's faces.  With the three-root side sent along -V instead, it fails."""
    children, crow, faces = flows
    assert _follow_flows(paper_geometry, children, crow, faces, np.random.default_rng(11), 6) >= 5


def test_flows_proved_only_near_the_critical_points_keep_the_count(flows, paper_geometry):
    """The same paths on the ways that only the near-critical Taylor bound proves (h'' bounded between the
    inflection and the pieces where g' may vanish, not over the whole window): there are some, and they keep the
    count up to a face too."""
    children, crow, faces = flows
    whole = flow_ways(paper_geometry, children, crow, near_critical=False).faces
    assert not (whole & ~faces).any()  # the closer bound proves every way the whole-window one does
    only = np.where((faces & ~whole).any(axis=3, keepdims=True), faces, False)
    assert only.any(axis=(1, 2, 3)).sum() >= 5
    assert _follow_flows(paper_geometry, children, crow, only, np.random.default_rng(13), 6) >= 4


def _follow_flows(geometry, children, crow, faces, rng, most: int) -> int:
    """Follow up to ``most`` flows of ``faces`` from solved points of their side; returns how many were followed."""
    done = 0
    for n, side, way in zip(*np.nonzero(faces.any(axis=3))):
        if done >= most:
            break
        row = crow[n]
        box = children.boxes[row]
        wa, wb = _arc(children, _cusp_window(children, row))
        if wa >= wb:
            continue  # a window across phi = pi: skipped here
        want = 3 if side else 1
        start = None
        for _ in range(20):
            x = box[:, 0] + rng.random(3) * (box[:, 1] - box[:, 0])
            if _in_window(geometry, x, wa, wb) == want:
                start = x
                break
        if start is None:
            continue
        r, j = start**2, FLOW_AXES[way]
        toward = 1.0 if side else -1.0
        step = 0.02 * float(np.min(box[:, 1] ** 2 - box[:, 0] ** 2))
        left = None
        for k in range(1, 300):
            v = _field(geometry, r, wa, wb, j)
            assert v is not None, (row, side, way, np.sqrt(r))
            r = r + toward * step * v / np.linalg.norm(v)
            rho = np.sqrt(r)
            out = np.flatnonzero((rho < box[:, 0]) | (rho > box[:, 1]))
            if out.size:
                ax = out[0]
                left = 2 * ax + int(rho[ax] > box[ax, 1])
                break
            if k % 5 == 0:
                got = _in_window(geometry, rho, wa, wb)
                assert got is None or got == want, (row, side, way, rho, got)
        assert left is not None and faces[n, side, way, left], (row, side, way, left)
        done += 1
    return done


@pytest.fixture(scope="module")
def ways(flows, paper_geometry):
    """The same rows' flows in the form of a lifted path (:func:`flow_ways`)."""
    children, crow, _ = flows
    return flow_ways(paper_geometry, children, crow)


def test_flow_ways_carry_the_faces_and_a_drive_where_proved(flows, ways):
    """The faces of :func:`flow_ways` are :func:`inflection_flows`'; a way has a drive exactly where it has faces,
    the same u and v on both sides, opposite drives (+V on the three-root side, -V on the one-root side), u and v
    unit vectors of two axes other than the held one, and a nonempty hull of q."""
    _, _, faces = flows
    assert np.array_equal(ways.faces, faces)
    driven = ways.drive[:, 1] != 0
    assert np.array_equal(driven, faces[:, 1].any(axis=2)) and np.array_equal(ways.drive[:, 0], -ways.drive[:, 1])
    assert driven.sum() >= 30
    for way, j in enumerate(FLOW_AXES):
        on = driven[:, way]
        u, v = ways.drive_u[on, way], ways.follow_v[on, way]
        assert np.all(u.sum(axis=1) == 1) and np.all(v.sum(axis=1) == 1) and np.all((u * v).sum(axis=1) == 0)
        assert not u[:, j].any() and not v[:, j].any()
        assert np.all(ways.follow_lo[on, way] <= ways.follow_hi[on, way])
        assert np.all(ways.follow_lo[~on, way] > ways.follow_hi[~on, way])


def test_the_field_is_the_drive_along_u_minus_q_v(flows, ways, paper_geometry):
    """Property test (proofs/lemma-joint-retraction.md, "Cusp patterns: the inflection flow"): at points sampled
    in a box with a driven way, the field V of the held axis (followed in floats, :func:`_field`) is a positive
    multiple of drive (u - q v) on the three-root side, q = -V.v / V.u in the way's hull [follow_lo, follow_hi]:
    the velocity set handed to the pair windows' signs holds the flow's velocity.  A drive of the wrong sign, or a
    hull of a_k / a_i for a_i / a_k, fails."""
    children, crow, _ = flows
    rng = np.random.default_rng(23)
    checked = 0
    for n, way in zip(*np.nonzero(ways.drive[:, 1])):
        if checked >= 120:
            break
        row = crow[n]
        box = children.boxes[row]
        wa, wb = _arc(children, _cusp_window(children, row))
        if wa >= wb:
            continue
        u, v = ways.drive_u[n, way], ways.follow_v[n, way]
        lo, hi = ways.follow_lo[n, way], ways.follow_hi[n, way]
        for _ in range(3):
            rho = box[:, 0] + rng.random(3) * (box[:, 1] - box[:, 0])
            field = _field(paper_geometry, rho**2, wa, wb, FLOW_AXES[way])
            if field is None:
                continue
            assert np.sign(field @ u) == ways.drive[n, 1, way], (row, way, rho, field)
            q = -(field @ v) / (field @ u)
            slack = 1e-9 * max(1.0, abs(q))
            assert lo - slack <= q <= hi + slack, (row, way, rho, q, lo, hi)
            checked += 1
    assert checked >= 60, checked


@pytest.fixture(scope="module")
def beside_pairs(paper_geometry):
    """Leaves of the default paving with one cusp window and pair windows beside it
    (``tests/data/cusp_pattern_flow_leaves.json``: boxes only), modelled again as the retraction reads them; the
    rows with no plane and windows of fixed count otherwise, their flows and the pair windows' signs along them."""
    boxes = np.array(json.loads((Path(__file__).parents[1] / "data" / "cusp_pattern_flow_leaves.json").read_text())["boxes"])
    split = split_at_zeros_of_d(paper_geometry, joined_windows(window_models(paper_geometry, boxes)))
    models = split.models
    cusp, pair, n = cusp_windows(models), pair_windows(models), len(models.ok)
    count = lambda w: np.bincount(models.window_box, weights=w, minlength=n)  # noqa: E731
    fixed = count(~pair & ~cusp & ~window_kinds(models)[3]) == 0
    rows = np.flatnonzero(models.ok & (count(cusp) == 1) & (count(pair) >= 1) & fixed & (split.plane == 0))
    ways = flow_ways(paper_geometry, models, rows)
    signs = lifted_pair_signs(paper_geometry, models, rows, ways.drive_u, ways.follow_v, ways.follow_lo,
                              ways.follow_hi, 1)
    return models, rows, ways, signs


def _cusp_window(models, row: int) -> int:
    return int(np.flatnonzero((models.window_box == row) & cusp_windows(models))[0])


def _arc(models, window: int) -> tuple[float, float]:
    on = models.piece_window == window
    return float(models.piece_lo[on][0]), float(models.piece_hi[on][-1])


def test_the_flow_keeps_the_pair_windows_it_signs(beside_pairs, paper_geometry):
    """Property test of the cusp patterns' curved way (lemma "Cusp patterns: the inflection flow"): from points of
    a side of the cusp window (counts by certified solves), follow V (three roots) or -V (one root); a pair window
    whose roots' minimum moves with d sigma = +1 (sigma its proved sign along the way, d the drive) stays empty
    when it starts empty, one with d sigma = -1 keeps its two roots when it starts with them, at every point
    checked up to the exit.  Cases where the status would be kept anyway are counted apart; the test needs paths
    on which a sign was actually relied on."""
    models, rows, ways, signs = beside_pairs
    assert rows.size >= 15 and ways.drive.any(axis=(1, 2)).sum() >= 15
    rng = np.random.default_rng(29)
    relied, paths = 0, 0
    for n, way in zip(*np.nonzero(ways.drive[:, 1])):
        if paths >= 12:
            break
        row = rows[n]
        box = models.boxes[row]
        wa, wb = _arc(models, _cusp_window(models, row))
        held = [w for w in np.flatnonzero((models.window_box == row) & (signs[:, way] != 0)) if np.less(*_arc(models, w))]
        if wa >= wb or not held:
            continue
        for _ in range(3):
            x = box[:, 0] + rng.random(3) * (box[:, 1] - box[:, 0])
            got = _in_windows(paper_geometry, x, [(wa, wb)] + [_arc(models, w) for w in held])
            if got is None or got[0] not in (1, 3):
                continue
            side = int(got[0] == 3)
            d = int(ways.drive[n, side, way])
            start = dict(zip(held, got[1:]))
            # the windows the sign keeps: empty ones whose minimum rises, full ones whose minimum falls
            kept = [w for w in held if d * signs[w, way] == (1 if start[w] == 0 else -1)]
            if not kept:
                continue
            r, step = x**2, 0.02 * float(np.min(box[:, 1] ** 2 - box[:, 0] ** 2))
            for k in range(1, 300):
                v = _field(paper_geometry, r, wa, wb, FLOW_AXES[way])
                assert v is not None, (row, side, way, np.sqrt(r))
                r = r + (1.0 if side else -1.0) * step * v / np.linalg.norm(v)
                rho = np.sqrt(r)
                if np.any((rho < box[:, 0]) | (rho > box[:, 1])):
                    break
                if k % 4 == 0:
                    now = _in_windows(paper_geometry, rho, [_arc(models, w) for w in kept])
                    assert now is None or now == [start[w] for w in kept], (row, side, way, kept, rho, now)
            relied += len(kept)
            paths += 1
    assert paths >= 10 and relied >= 12, (paths, relied)
