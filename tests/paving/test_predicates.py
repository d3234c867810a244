"""Soundness of the tri-state predicates, audited at high precision with arb.

Boxes are drawn from real pavings (depth 5 and 6) and points inside them (corners
included, where the monotone enclosures are sharp); arb at 128 bits must agree
with every label and lie in every enclosure.
"""

from __future__ import annotations

import numpy as np
import pytest
from flint import arb, ctx, fmpq
from hypothesis import given, settings, strategies as st

from intervalkin.core.geometry import default_geometry
from intervalkin.kinematics.enclosures import det_a_interval, rho_sq_interval
from intervalkin.kinematics.formulas import det_a_arb, rho_sq_arb
from intervalkin.paving.labels import Label
from intervalkin.paving.adjacency import shares_face
from intervalkin.space.aspect import aspect_components
from intervalkin.paving.predicates import aspect_labels, aspect_predicate, det_sign_labels, pave_workspace, workspace_labels

GEOM = default_geometry()
RMIN2 = [arb(fmpq(v.numerator, v.denominator)) ** 2 for v in GEOM.rho_min]
RMAX2 = [arb(fmpq(v.numerator, v.denominator)) ** 2 for v in GEOM.rho_max]


@pytest.fixture(scope="module")
def paving6():
    p = pave_workspace(GEOM, 6)
    edges = shares_face(p.level, p.ijk, p.depth)
    aspect, info = aspect_components(p, edges)
    return p, edges, aspect, info


def _risky(p):
    """Boxes worth auditing: small decided boxes (they touch the undecided layer)."""
    decided = (p.labels["W"] != Label.BOUNDARY) | (p.labels["det_positive"] != Label.BOUNDARY)
    return np.flatnonzero((p.level == p.depth) & decided)


def _point(box, fr):
    return [float(box[j, 0] + fr[j] * (box[j, 1] - box[j, 0])) if fr[j] not in (0.0, 1.0) else float(box[j, int(fr[j])]) for j in range(3)]


def _arb_at(pt):
    return [arb(v) for v in pt]  # floats are exact reals


fractions = st.lists(st.sampled_from([0.0, 1.0]) | st.floats(0, 1), min_size=3, max_size=3)



def _arb_values(x, y, phi):
    """rho_i^2 and det A at an arb point, at 128 bits."""
    old = ctx.prec
    ctx.prec = 128
    try:
        return rho_sq_arb(GEOM, x, y, phi), det_a_arb(GEOM, x, y, phi)
    finally:
        ctx.prec = old

@settings(max_examples=250, deadline=None, derandomize=True)
@given(pick=st.integers(0, 10**9), fr=fractions)
def test_workspace_and_det_labels_hold_at_points(paving6, pick, fr):
    p, _, _, _ = paving6
    idx = _risky(p)
    b = idx[pick % idx.size]
    box = np.stack([p.lo[b], p.hi[b]], -1)
    x, y, phi = _arb_at(_point(box, fr))
    rs, det = _arb_values(x, y, phi)
    w = p.labels["W"][b]
    if w == Label.INSIDE:
        assert all(r >= lo and r <= hi for r, lo, hi in zip(rs, RMIN2, RMAX2))
    elif w == Label.OUTSIDE:
        assert any(r < lo or r > hi for r, lo, hi in zip(rs, RMIN2, RMAX2))
    d = p.labels["det_positive"][b]
    if d == Label.INSIDE:
        assert det > 0
    elif d == Label.OUTSIDE:
        assert det < 0


@settings(max_examples=250, deadline=None, derandomize=True)
@given(pick=st.integers(0, 10**9), fr=fractions)
def test_enclosures_contain_arb_values(paving6, pick, fr):
    """The tight enclosures (what makes the labels) contain the arb value at any point."""
    p, _, _, _ = paving6
    idx = _risky(p)
    b = idx[pick % idx.size]
    box = np.stack([p.lo[b], p.hi[b]], -1)[None]
    pt = _point(box[0], fr)
    x, y, phi = _arb_at(pt)
    rs, det = _arb_values(x, y, phi)
    d = det_a_interval(GEOM, box)
    assert arb(d.lo[0]) <= det and det <= arb(d.hi[0]), (d.lo[0], det, d.hi[0])
    e = rho_sq_interval(GEOM, box)
    for i, r in enumerate(rs):
        assert arb(e.lo[0, i]) <= r and r <= arb(e.hi[0, i])


@settings(max_examples=60, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10**6), scale=st.sampled_from([1e-6, 1e-3, 0.05, 0.5, 3.0]))
def test_enclosures_on_random_boxes(seed, scale):
    """Arbitrary (not grid-aligned, thin or wide) boxes: corners and random points."""
    rng = np.random.default_rng(seed)
    c = rng.uniform([-32, -32, -np.pi], [32, 32, np.pi], (4, 3))
    h = rng.uniform(0, 1, (4, 3)) * scale * np.array([1, 1, 0.2])
    boxes = np.stack([c - h, c + h], -1)
    d = det_a_interval(GEOM, boxes)
    rs = rho_sq_interval(GEOM, boxes)
    old = ctx.prec
    ctx.prec = 128
    try:
        for k in range(4):
            for fr in rng.integers(0, 2, (8, 3)).astype(float).tolist() + rng.uniform(0, 1, (4, 3)).tolist():
                x, y, phi = _arb_at(_point(boxes[k], fr))
                det = det_a_arb(GEOM, x, y, phi)
                assert arb(d.lo[k]) <= det and det <= arb(d.hi[k])
                for i, r in enumerate(rho_sq_arb(GEOM, x, y, phi)):
                    assert arb(rs.lo[k, i]) <= r and r <= arb(rs.hi[k, i])
    finally:
        ctx.prec = old


def test_aspects_compose_by_and_rule(paving6):
    p, _, _, _ = paving6
    wa1, wa2 = aspect_labels(p.labels["W"], p.labels["det_positive"])
    assert np.array_equal(wa1, p.labels["WA1"]) and np.array_equal(wa2, p.labels["WA2"])
    assert not np.any((wa1 == Label.INSIDE) & (wa2 == Label.INSIDE))
    # the composed single predicate agrees with (or is sharper than) the paving's labels
    b = p.boxes[:3000]
    single = aspect_predicate(GEOM, +1)(b)
    assert np.all((single & p.labels["WA1"][:3000]) != 0)


def test_aspect_ids_consistent_with_components(paving6):
    p, edges, aspect, info = paving6
    by_id = {d["id"]: d for d in info}
    # every certified aspect box carries an id, every other box -1
    inside = (p.labels["WA1"] == Label.INSIDE) | (p.labels["WA2"] == Label.INSIDE)
    assert np.array_equal(aspect >= 0, inside)
    # id sign agrees with the box labels
    for lab, sign in (("WA1", 1), ("WA2", -1)):
        ids = np.unique(aspect[p.labels[lab] == Label.INSIDE])
        assert all(by_id[int(i)]["sign"] == sign for i in ids)
    # adjacent INSIDE boxes of one sign share their id; ids differ across signs
    a, b = edges
    same_sign = inside[a] & inside[b] & (p.labels["det_positive"][a] == p.labels["det_positive"][b])
    assert np.all(aspect[a][same_sign] == aspect[b][same_sign])
    # the two main aspects: one big component per sign, volumes reported
    big = [d for d in info if d["volume"] > 500]
    assert sorted(d["sign"] for d in big) == [-1, 1]
    # det sign at the centre of a few boxes of each id, in arb
    rng = np.random.default_rng(5)
    for i in list(by_id)[:6]:
        boxes = np.flatnonzero(aspect == i)
        for bi in rng.choice(boxes, size=min(3, boxes.size), replace=False):
            c = 0.5 * (p.lo[bi] + p.hi[bi])
            det = det_a_arb(GEOM, *_arb_at(c.tolist()))
            assert (det > 0) if by_id[i]["sign"] > 0 else (det < 0)


def test_labels_from_functions_match_paving(paving6):
    p, _, _, _ = paving6
    b = p.boxes
    w = workspace_labels(GEOM, b)
    # re-evaluating a leaf gives a label compatible with its stored one (never contradicts)
    assert np.all((w & p.labels["W"]) != 0)
    d = det_sign_labels(GEOM, b[p.labels["W"] != Label.OUTSIDE])
    assert np.all((d & p.labels["det_positive"][p.labels["W"] != Label.OUTSIDE]) != 0)
