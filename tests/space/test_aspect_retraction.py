"""Retraction directions against arb: points of retracting boxes moved along their direction.

proofs/lemma-aspect-retraction.md: on a RET box every constraint (rho_i^2 - rho_min_i^2,
rho_max_i^2 - rho_i^2, s det A) is certified satisfied on the box or nondecreasing along e.
Property: sample points of RET boxes, walk along e to the exit face, evaluate each constraint
in arb at high precision: it never decreases, or it stays satisfied; a point of the aspect
stays in the aspect.  Would catch a wrong gradient enclosure, a direction stored with the wrong
phi scale, or exit faces computed on the wrong side.
"""

from __future__ import annotations

import numpy as np
import pytest
from flint import arb, ctx

from intervalkin.checker.model import ArbModel
from intervalkin.space.aspect_retraction import DIRECTIONS, PHI_DIVISOR, classify_boxes, exit_faces
from intervalkin.space.aspect_topology import OUT, RET


def _constraints(model: ArbModel, x: float, y: float, phi: float, sign: int) -> list:
    """The seven constraint values at an exact float pose, as arb balls (tiny at 200 bits)."""
    r = model.rho_sq(arb(x), arb(y), arb(phi))
    return [r[i] - model.rmin2[i] for i in range(3)] + [model.rmax2[i] - r[i] for i in range(3)] + \
        [sign * model.det(arb(x), arb(y), arb(phi))]


@pytest.mark.parametrize("which", [0, 1])
def test_points_moved_along_the_direction_keep_their_constraints(aspect_topology, paper_geometry, which):
    cover = aspect_topology.covers[which]
    rng = np.random.default_rng(20261124 + which)
    ret = np.flatnonzero(cover.kind == RET)
    rows = rng.choice(ret, size=60, replace=False)
    boxes = cover.boxes(np.isin(np.arange(len(cover.kind)), rows))
    e_all = cover.direction[np.sort(rows)]
    model = ArbModel(paper_geometry)
    moved = 0
    with ctx.workprec(200):
        for box, e in zip(boxes, e_all):
            ev = e.astype(float) * np.array([1.0, 1.0, 1.0 / PHI_DIVISOR])
            for _ in range(3):
                p = box[:, 0] + rng.random(3) * (box[:, 1] - box[:, 0])
                # the largest step that stays in the box along e (to the exit face)
                room = np.where(ev > 0, (box[:, 1] - p) / np.where(ev > 0, ev, 1),
                                np.where(ev < 0, (box[:, 0] - p) / np.where(ev < 0, ev, 1), np.inf))
                tmax = float(np.min(room))
                path = [p + t * ev for t in np.linspace(0.0, tmax, 6)]
                vals = [_constraints(model, *q, cover.sign) for q in path]
                for j in range(7):
                    seq = [v[j] for v in vals]
                    ok_sign = all(v > 0 for v in seq) if j == 6 else all(v >= 0 for v in seq)
                    nondecreasing = all(not (b < a) for a, b in zip(seq, seq[1:]))
                    assert ok_sign or nondecreasing, (box.tolist(), e.tolist(), j)
                start_in = all(v >= 0 for v in vals[0][:6]) and vals[0][6] > 0
                if start_in:
                    moved += 1
                    assert all(all(v >= 0 for v in w[:6]) and w[6] > 0 for w in vals), (box.tolist(), e.tolist())
    assert moved > 0  # the walk started in the aspect at least once


def test_exit_faces_and_the_phi_scale():
    """(1, 0, -1) exits through +x and -phi; the phi component is divided by PHI_DIVISOR."""
    f = exit_faces(np.array([[1, 0, -1]]))[0]
    assert f.tolist() == [False, True, False, False, True, False]
    assert DIRECTIONS[:6].tolist() == [[16, 0, 0], [-16, 0, 0], [0, 16, 0], [0, -16, 0], [0, 0, 16], [0, 0, -16]]
    assert PHI_DIVISOR & (PHI_DIVISOR - 1) == 0  # a power of two: e is exact in binary


def test_a_reversed_direction_is_not_certified(aspect_topology, paper_geometry):
    """The fixed direction chosen for a RET box is certified again on it, and its reverse mostly is not:
    would catch a directional derivative whose sign is ignored (every direction would pass)."""
    cover = aspect_topology.covers[0]
    ret = np.flatnonzero(cover.kind == RET)[:400]
    c = classify_boxes(paper_geometry, cover.boxes(np.isin(np.arange(len(cover.kind)), ret)), cover.sign)
    index = {tuple(d): j for j, d in enumerate(DIRECTIONS.tolist())}
    reversed_refused = 0
    for k, e in enumerate(cover.direction[ret].tolist()):
        if c.inside[k] or tuple(e) not in index:
            continue  # an IN box retracts along anything; a per-box direction has no fixed column
        assert c.ok[k, index[tuple(e)]]
        reversed_refused += not c.ok[k, index[tuple(-v for v in e)]]
    assert reversed_refused > 50


def test_points_of_boxes_out_by_a_combination_are_not_in_the_aspect(aspect_topology, paper_geometry):
    """OUT boxes proved by a combination sum_j w_j f_j < 0 (the module docstring): at sampled points, in arb
    at 200 bits, the combination is negative and some constraint with a positive weight is violated.
    Would catch a wrong gradient in the centred form or weights put on the wrong constraints."""
    model = ArbModel(paper_geometry)
    rng = np.random.default_rng(20261125)
    seen = 0
    with ctx.workprec(200):
        for cover in aspect_topology.covers:
            rows = np.flatnonzero(np.any(cover.weights > 0, axis=1))
            assert rows.size > 0 and np.all(cover.kind[rows] == OUT)
            for box, w in zip(cover.boxes(np.isin(np.arange(len(cover.kind)), rows)), cover.weights[rows]):
                assert np.all(w >= 0) and np.count_nonzero(w) >= 2
                for _ in range(4):
                    p = box[:, 0] + rng.random(3) * (box[:, 1] - box[:, 0])
                    vals = _constraints(model, *p, cover.sign)
                    assert sum(int(wj) * v for wj, v in zip(w, vals)) < 0, (box.tolist(), w.tolist())
                    assert any(wj > 0 and v < 0 for wj, v in zip(w, vals))
                    seen += 1
    assert seen > 100


def test_a_thin_corner_gets_a_fine_direction(monkeypatch):
    """Where rho_1 = rho_min, rho_2 = rho_min and det A = 0 meet with nearly dependent gradients (smallest
    singular value about 0.025 after normalising), the valid directions form a cone a few hundredths of a
    radian wide: none of the fixed directions lies in it, and the per-box direction rounded to the coarse
    grid (components up to GRID) falls outside it; rounded to FINE_GRID it stays inside."""
    from pathlib import Path

    from intervalkin.core.geometry import load_geometry
    from intervalkin.space import aspect_retraction

    g = load_geometry(Path(__file__).parents[1] / "data" / "concurrent_legs.toml")
    box = np.array([[[16.1167, 16.1192], [13.1628, 13.1652], [0.19255, 0.19275]]])
    c = classify_boxes(g, box, -1)
    assert not c.out[0] and not c.inside[0]
    assert not np.any(c.ok[0, :len(DIRECTIONS)])
    assert np.any(c.ok[0, len(DIRECTIONS):])
    monkeypatch.setattr(aspect_retraction, "FINE_GRID", aspect_retraction.GRID)
    coarse = classify_boxes(g, box, -1)
    assert not np.any(coarse.ok[0])
