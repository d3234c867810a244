"""``label``: Table 1's solutions at the default depth, phi modulo 2 pi, the domain, the point in arb,
and the local refinement (a certified path to a labelled box) that cannot cross a characteristic surface."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from flint import arb, ctx

import intervalkin
from intervalkin.app.cli import QUESTION_DEPTH
from intervalkin.core.errors import InputError
from intervalkin.core.interval import Interval
from intervalkin.core.status import Status
from intervalkin.pipeline import analyse
from intervalkin.space.pose_label import point_labels, pose_enclosure
from intervalkin.space.pose_path import followed_into, joint_segment_is_clear, segment_is_clear
from intervalkin.kinematics.enclosures import rho_interval

TABLE1 = ["14.98", "15.38", "12.0"]


@pytest.fixture(scope="module")
def default():
    """The analysis ``intervalkin label`` runs by default."""
    return analyse(None, QUESTION_DEPTH)


@pytest.fixture(scope="module")
def table1():
    return intervalkin.solve(TABLE1)


def _centre(s) -> list[Fraction]:
    return [Fraction(float(v)) for v in 0.5 * (np.asarray(s.box)[:, 0] + np.asarray(s.box)[:, 1])]


def test_table1_solutions_are_labelled_in_full_at_the_default_depth(default, table1):
    """Each of the six solutions: its own certified aspect, a certified basic region and uniqueness domain.

    Theorem 1 checks the answers: the six solutions of one joint vector lie in six
    different basic regions, all above a cell of six solutions, and in six different
    uniqueness domains.  Would catch a path proof that crosses a characteristic surface
    (two solutions would share a region) or a region read from the wrong sheet.
    """
    labels = [default.label(_centre(s)) for s in table1.solutions]
    regions = {r.id: r for r in default.regions.regions}
    for s, lab in zip(table1.solutions, labels):
        assert lab.status is Status.CERTIFIED and lab.in_workspace is True, lab.why
        assert lab.aspect == s.aspect
        assert regions[lab.basic_region].aspect == s.aspect and regions[lab.basic_region].cell_count == 6
    assert len({lab.basic_region for lab in labels}) == 6
    assert len({lab.uniqueness_domain for lab in labels}) == 6


def test_phi_is_reduced_modulo_2pi(default, table1):
    """phi + 2 pi k labels as phi does (the reduced angle is within 1e-30 of the solution's)."""
    s = table1.solutions[0]
    x, y, phi = _centre(s)
    base = default.label([x, y, phi])
    assert base.phi_reduced is None
    for turns in (1, -2, 5):
        with ctx.workprec(200):
            shifted = arb(phi.numerator) / phi.denominator + 2 * turns * arb.pi()
            text = shifted.mid().str(60, radius=False)  # a decimal within 1e-55 of phi + 2 pi turns
        lab = default.label([x, y, text])
        assert lab.phi_reduced is not None
        lo, hi = lab.phi_reduced
        assert lo <= hi and abs(float(lo) - float(phi)) < 1e-40 and float(hi - lo) < 1e-30
        assert (lab.aspect, lab.basic_region, lab.uniqueness_domain) == (base.aspect, base.basic_region,
                                                                          base.uniqueness_domain)


@pytest.mark.parametrize("phi", [Fraction(4), Fraction(-4), Fraction(22, 7) * 3, Fraction(10**6)])
def test_pose_enclosure_is_in_the_principal_range(phi):
    (_, _), (_, _), (lo, hi) = pose_enclosure((Fraction(0), Fraction(0), phi))
    k = round((float(phi)) / (2 * math.pi))
    assert -math.pi < float(lo) <= float(hi) <= math.pi
    assert abs(float(lo) - (float(phi) - 2 * math.pi * k)) < 1e-6
    assert pose_enclosure((Fraction(0), Fraction(0), Fraction(3)))[2] == (Fraction(3), Fraction(3))  # already there


def test_a_pose_outside_the_paved_domain_is_refused(default):
    for pose in (["60", "0", "0"], ["0", "-32.5", "1"]):
        with pytest.raises(InputError, match="^pose: [xy] = .* is outside the paved domain"):
            default.label(pose)


def test_point_labels_in_arb(paper_geometry):
    """At a point: inside W and a det A sign where they hold strictly; None on the boundary of W."""
    exact = lambda *v: tuple((Fraction(a), Fraction(a)) for a in v)  # noqa: E731
    assert point_labels(paper_geometry, exact(0, 0, 0))[0] is False  # B1 on A1: leg 1 of length 0
    # B1 at distance exactly rho_min = 10 from A1 = (0, 0): leg 1 at its limit
    in_w, _ = point_labels(paper_geometry, exact(10, 0, Fraction(1, 3)))
    assert in_w is None
    r = intervalkin.solve(TABLE1)
    for s in r.solutions:
        c = tuple((v, v) for v in _centre(s))
        assert point_labels(paper_geometry, c) == (True, s.det_sign)


def test_no_certified_path_joins_two_different_basic_regions(default, paper_geometry):
    """Boxes of regions above cells of different certified counts are in different basic regions (certified):
    neither a workspace segment nor a followed joint segment between them may be proved.

    Would catch a clearance test that passes a box meeting g(S), or continuation that jumps sheets.
    """
    ra = default.regions
    by_count = {}
    for r in ra.regions:
        if r.aspect == "WA1" and r.n_boxes:
            by_count.setdefault(r.cell_count, r.id)
    (c1, r1), (c2, r2) = sorted(by_count.items())[:2]
    p = ra.paving
    i = int(np.flatnonzero(ra.region == r1)[0])
    j = int(np.flatnonzero(ra.region == r2)[0])
    a = Interval.point(0.5 * (p.lo[i] + p.hi[i]))
    b = Interval.point(0.5 * (p.lo[j] + p.hi[j]))
    assert segment_is_clear(paper_geometry, a, b) == 0
    qa = rho_interval(paper_geometry, np.stack([a.lo, a.hi], -1)[None])[0]
    qb = rho_interval(paper_geometry, np.stack([b.lo, b.hi], -1)[None])[0]
    assert not (joint_segment_is_clear(paper_geometry, qa, qb) and followed_into(paper_geometry, a, qa, qb,
                                                                                   p.lo[j], p.hi[j]))
