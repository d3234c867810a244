"""The inflection flow of a cusp window (solve.cusp_flow, proofs/lemma-joint-retraction.md "Cusp windows: the
inflection flow"), followed numerically and checked against independent certified solves."""

from __future__ import annotations

import json
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from intervalkin.solve.cusp_flow import FLOW_AXES, inflection_flows
from intervalkin.solve.dkp import solve
from intervalkin.solve.simple_roots import ReducedBoxes
from intervalkin.solve.window_cusp import cusp_windows
from intervalkin.solve.window_fold import window_kinds
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
    for _ in range(60):
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


def _in_window(geometry, rho: np.ndarray, wa: float, wb: float) -> int | None:
    """The number of solutions with phi in [wa, wb], from an independent certified solve (None: not complete)."""
    res = solve(geometry, [Fraction(float(x)) for x in rho])
    if not res.complete or any(s.status != "unique" for s in res.solutions):
        return None
    return sum(wa <= float(s.box[2].mean()) <= wb for s in res.solutions)


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
    rng = np.random.default_rng(11)
    done = 0
    for n, side, way in zip(*np.nonzero(faces.any(axis=3))):
        if done >= 6:
            break
        row = crow[n]
        box = children.boxes[row]
        window = np.flatnonzero((children.window_box == row) & cusp_windows(children))[0]
        on = children.piece_window == window
        wa, wb = children.piece_lo[on][0], children.piece_hi[on][-1]
        if wa >= wb:
            continue  # a window across phi = pi: skipped here
        want = 3 if side else 1
        start = None
        for _ in range(20):
            x = box[:, 0] + rng.random(3) * (box[:, 1] - box[:, 0])
            if _in_window(paper_geometry, x, wa, wb) == want:
                start = x
                break
        if start is None:
            continue
        r, j = start**2, FLOW_AXES[way]
        toward = 1.0 if side else -1.0
        step = 0.02 * float(np.min(box[:, 1] ** 2 - box[:, 0] ** 2))
        left = None
        for k in range(1, 300):
            v = _field(paper_geometry, r, wa, wb, j)
            assert v is not None, (row, side, way, np.sqrt(r))
            r = r + toward * step * v / np.linalg.norm(v)
            rho = np.sqrt(r)
            out = np.flatnonzero((rho < box[:, 0]) | (rho > box[:, 1]))
            if out.size:
                ax = out[0]
                left = 2 * ax + int(rho[ax] > box[ax, 1])
                break
            if k % 5 == 0:
                got = _in_window(paper_geometry, rho, wa, wb)
                assert got is None or got == want, (row, side, way, rho, got)
        assert left is not None and faces[n, side, way, left], (row, side, way, left)
        done += 1
    assert done >= 5
