"""Mutation tests of the checker's Krawczyk exclusion (proofs/lemma-clear-joint-box.md, points 5 and 6).

The exclusion discards small torus cells and, in cover mode, the slabs of a cell outside the pose box.  A
faulty exclusion would discard cells that hold singular poses: boxes around bracketed singular poses are never
excluded, and pose boxes of fold models cut in half (leaving singular poses out) are refused by the cover.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
from flint import arb, ctx
from hypothesis import given, settings
from hypothesis import strategies as st

from intervalkin.checker.joint_exclusion import excluded
from intervalkin.checker.joint_torus import torus_search
from intervalkin.checker.model import ArbModel
from intervalkin.core.geometry import default_geometry
from tests.solve.shared import first_det_change


@settings(max_examples=30, deadline=None)
@given(st.floats(-20, 25), st.floats(-3.1, 3.1), st.sampled_from([1e-2, 1e-4, 1e-7]))
def test_exclusion_never_discards_a_cell_holding_a_singular_pose(x, phi, width):
    """Mutation test of the exclusion: a pose box holding a bracketed singular pose (det A changes sign along y,
    proved in arb), with a joint box enclosing the joint vectors of the whole bracket (arb), is never excluded;
    the same box with the joint box moved off those joint vectors is (the test can fail both ways)."""
    g = default_geometry()
    ys = np.linspace(-25.0, 25.0, 4001)
    c = first_det_change(g, x, phi, ys)
    if c is None:
        return
    ctx.prec = 128
    model = ArbModel(g)
    y0 = ys[c]
    a, b = y0 - width, y0 + width
    while True:  # shrink the bracket towards the sign change of the float samples, keeping it proved
        da, db = model.det(arb(x), arb(a), arb(phi)), model.det(arb(x), arb(b), arb(phi))
        if (da < 0 and db > 0) or (da > 0 and db < 0):
            break
        a, b = a - width, b + width
        if b - a > 1.0:
            return
    seg = [arb(x), arb.union(arb(a), arb(b)), arb(phi)]
    r_sq = [v.union(v) for v in model.rho_sq(*seg)]  # every joint vector of the bracket, squared
    X = [arb.union(arb(x - width), arb(x + width)), seg[1], arb.union(arb(phi - width), arb(phi + width))]
    assert not excluded(model, X, r_sq, rounds=8), (x, phi, width)
    far = [v + 4 * (v.rad() + 1) for v in r_sq]  # the joint box moved off: no pose of X reaches it
    assert excluded(model, X, far), (x, phi, width)


def test_cover_refuses_half_pose_boxes(paper_geometry, fold_paving):
    """The cover by excluded slabs (small cells straddling a face of the pose box) is not too permissive: the
    first three library fold models whose pose box the checker's cover accepts, cut at the middle of any
    coordinate, on either side, leave singular poses of their joint box out and are refused."""
    ctx.prec = 128
    model = ArbModel(paper_geometry)
    pc, pav = fold_paving.pieces, fold_paving.paving
    tried = 0
    for t in range(len(pc)):
        leaf = int(pc.box[t])
        box = tuple((Fraction(float(a)), Fraction(float(b))) for a, b in zip(pav.lo[leaf], pav.hi[leaf]))
        pose = pc.models.pose[t]
        if not torus_search(model, box, pose.tolist())[0]:
            continue
        for a in range(3):
            for side in (0, 1):
                cut = pose.copy()
                cut[a, 1 - side] = pose[a].mean()
                assert not torus_search(model, box, cut.tolist())[0], (leaf, a, side)
        tried += 1
        if tried == 3:
            return
    raise AssertionError("fewer than three fold models covered")
