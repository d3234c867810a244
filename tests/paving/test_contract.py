"""Contractors and contracted parts: no solution is dropped, every INSIDE / OUTSIDE part holds in arb.

The reference is the independent arb model of ``test_predicates_properties`` (256 bits, the
geometry's exact decimals, det A as the determinant of the 3x3 matrix).  Points are the
corners of boxes, interior points and the floats just outside a contracted box, where a
contractor that shrinks too far is caught (the mutation tests at the end check that it is).
"""

from __future__ import annotations

import decimal
import tomllib

import numpy as np
import pytest
from flint import arb, ctx, fmpq
from hypothesis import given, settings
from hypothesis import strategies as st

import intervalkin.paving.contract as contract_module
import intervalkin.paving.contracted as contracted_module
from intervalkin.core.geometry import parse_geometry
from intervalkin.kinematics.constants import constants
from intervalkin.paving.contract import contract_det, contract_leg
from intervalkin.paving.contracted import box_minus, contract_label
from intervalkin.paving.labels import Label
from intervalkin.paving.predicates import pave_workspace

from .test_predicates_properties import GEOMETRIES, KINDS, PREC, _exact, box_points, draw_box


def _boxes(name: str, seeds: range) -> np.ndarray:
    return np.stack([draw_box(name, kind, s * len(KINDS) + j) for s in seeds for j, kind in enumerate(KINDS)])


def _holds(ex, name: str, p) -> bool | None:
    """The predicate ``name`` (W, WA1, WA2) at a float point in arb: True, False, or None (undecided)."""
    legs = ex.legs(p)
    rs = [ux * ux + uy * uy for ux, uy, _, _ in legs]
    if any(r < lo or r > hi for r, lo, hi in zip(rs, ex.rmin2, ex.rmax2)):
        return False
    if not all(r >= lo and r <= hi for r, lo, hi in zip(rs, ex.rmin2, ex.rmax2)):
        return None
    if name == "W":
        return True
    det = ex.det(p)
    want = det > 0 if name == "WA1" else det < 0
    if want:
        return True
    return False if (det <= 0 if name == "WA1" else det >= 0) else None


def _outside_points(b_lo, b_hi, c_lo, c_hi, rng, n_random: int):
    """Points of the box B that are not in the box C: random ones, and the floats just past C's faces."""
    pts = [b_lo + rng.uniform(0, 1, 3) * (b_hi - b_lo) for _ in range(n_random)]
    mid = 0.5 * (b_lo + b_hi) if np.any(c_lo > c_hi) else np.clip(0.5 * (c_lo + c_hi), b_lo, b_hi)
    for j in range(3):
        for v in (np.nextafter(c_lo[j], -np.inf), np.nextafter(c_hi[j], np.inf)):
            if b_lo[j] <= v <= b_hi[j]:
                for base in (mid, c_lo, c_hi):
                    p = np.clip(base.copy(), b_lo, b_hi)
                    p[j] = v
                    pts.append(p)
    return [p for p in pts if not np.all((c_lo <= p) & (p <= c_hi))]


# --------------------------------------------------------------------------------------
# The contractors keep every solution
# --------------------------------------------------------------------------------------
def _dropped_solutions(name: str, seeds: range) -> tuple[list, int, int]:
    """(solutions outside the contracted box, boxes contracted, points checked) over drawn boxes."""
    g = GEOMETRIES[name]
    k = constants(g)
    ex = _exact(name)
    rng = np.random.default_rng(7)
    boxes = _boxes(name, seeds)
    lo, hi = boxes[:, :, 0], boxes[:, :, 1]
    bad, contracted, checked = [], 0, 0
    with ctx.workprec(PREC):
        for leg in range(3):
            targets = {"low": ((-np.inf, k.rho_min_sq_iv.hi[leg]), lambda r: r <= ex.rmin2[leg]),
                       "high": ((k.rho_max_sq_iv.lo[leg], np.inf), lambda r: r >= ex.rmax2[leg]),
                       "hold": ((k.rho_min_sq_iv.lo[leg], k.rho_max_sq_iv.hi[leg]),
                                lambda r: r >= ex.rmin2[leg] and r <= ex.rmax2[leg])}
            for kind, (target, sat) in targets.items():
                c_lo, c_hi, empty = contract_leg(g, lo, hi, leg, target)
                for b in range(len(boxes)):
                    c = (np.full(3, np.inf), np.full(3, -np.inf)) if empty[b] else (c_lo[b], c_hi[b])
                    contracted += int(empty[b] or np.any((c_lo[b] > lo[b]) | (c_hi[b] < hi[b])))
                    for p in _outside_points(lo[b], hi[b], *c, rng, 4):
                        checked += 1
                        ux, uy, _, _ = ex.legs(p)[leg]
                        if sat(ux * ux + uy * uy):
                            bad.append((leg, kind, b, p.tolist()))
        for sign in (1, -1):
            c_lo, c_hi, empty = contract_det(g, lo, hi, sign)
            for b in range(len(boxes)):
                c = (np.full(3, np.inf), np.full(3, -np.inf)) if empty[b] else (c_lo[b], c_hi[b])
                contracted += int(empty[b] or np.any((c_lo[b] > lo[b]) | (c_hi[b] < hi[b])))
                for p in _outside_points(lo[b], hi[b], *c, rng, 4):
                    checked += 1
                    det = ex.det(p)
                    if (det >= 0) if sign > 0 else (det <= 0):
                        bad.append(("det", sign, b, p.tolist()))
    return bad, contracted, checked


@pytest.mark.parametrize("name", sorted(GEOMETRIES))
def test_contractors_keep_every_solution(name):
    """A point of B outside the contracted box C (or anywhere in B when C is empty) violates the constraint."""
    bad, contracted, checked = _dropped_solutions(name, range(8))
    assert not bad, bad[:3]
    n = 8 * len(KINDS)
    assert contracted > n and checked > 20 * n, "almost nothing contracted: a vacuous test"


def test_mutation_contractor_that_cuts_into_solutions_is_caught(monkeypatch):
    """Every backward intersection shrunk inward by 2**-40 of its width: solutions are dropped, and seen."""
    meet = contract_module._meet

    def shrinking_meet(a, b):
        m, empty = meet(a, b)
        w = (m.hi - m.lo) * 2.0**-40
        return type(m)(m.lo + w, m.hi - w), empty

    monkeypatch.setattr(contract_module, "_meet", shrinking_meet)
    bad, _, _ = _dropped_solutions("paper", range(2))
    assert bad


# --------------------------------------------------------------------------------------
# Parts: they tile their leaves, and every decided part holds in arb
# --------------------------------------------------------------------------------------
def _part_violations(geometry_name: str, parts, rng) -> tuple[list, int]:
    """(violations, points checked): every INSIDE / OUTSIDE part at its corners and one interior point."""
    ex = _exact(geometry_name)
    bad, n = [], 0
    with ctx.workprec(PREC):
        for name, pt in parts.items():
            for i in np.flatnonzero(pt.label != Label.BOUNDARY):
                box = np.stack([pt.lo[i], pt.hi[i]], axis=-1)
                for p in box_points(box, [rng.uniform(0, 1, 3)]):
                    n += 1
                    h = _holds(ex, name, p)
                    if h is not None and h != (pt.label[i] == Label.INSIDE):
                        bad.append((name, int(pt.label[i]), box.tolist(), p.tolist()))
    return bad, n


def test_parts_of_a_paving_hold_in_arb(paper_geometry):
    """Depth 3 with one bisect-and-cut round: every decided part of W, WA1 and WA2 (about 2300) is checked."""
    p = pave_workspace(paper_geometry, 3, contract=True, refine=1)
    bad, n = _part_violations("paper", p.parts, np.random.default_rng(3))
    assert not bad, bad[:3]
    assert n > 10000


def _drawn_parts_hold(examples: int):
    """Property: for seeded boxes of every kind (near the limits, near det A = 0, thin, across the seam,
    on an exactly singular pose) of every geometry, every decided part of W, WA1, WA2 holds in arb."""
    @settings(max_examples=examples, deadline=None, derandomize=True)
    @given(seed=st.integers(0, 2**31), refine=st.integers(0, 1))
    def prop(seed, refine):
        for name, g in GEOMETRIES.items():
            boxes = np.stack([draw_box(name, kind, seed + j) for j, kind in enumerate(KINDS)])
            parts = {n: contract_label(g, n, boxes[:, :, 0], boxes[:, :, 1], np.arange(len(boxes)), refine=refine)
                     for n in ("W", "WA1", "WA2")}
            bad, _ = _part_violations(name, parts, np.random.default_rng(seed))
            assert not bad, (name, seed, bad[:3])

    return prop


test_parts_of_drawn_boxes_hold_in_arb = _drawn_parts_hold(12)
test_parts_of_drawn_boxes_hold_in_arb_many = pytest.mark.slow(_drawn_parts_hold(40))


def test_parts_tile_their_leaves_and_the_grid_is_unchanged(paper_geometry):
    plain = pave_workspace(paper_geometry, 5)
    p = pave_workspace(paper_geometry, 5, contract=True, refine=1)
    assert np.array_equal(plain.lo, p.lo) and np.array_equal(plain.ijk, p.ijk)
    assert all(np.array_equal(plain.labels[n], p.labels[n]) for n in plain.labels)
    leaf_vol = p.volume()
    for name, pt in p.parts.items():
        assert np.array_equal(np.unique(pt.leaf), np.flatnonzero(p.labels[name] == Label.BOUNDARY))
        assert np.all((p.lo[pt.leaf] <= pt.lo) & (pt.lo <= pt.hi) & (pt.hi <= p.hi[pt.leaf]))
        s = np.bincount(pt.leaf, weights=np.prod(pt.hi - pt.lo, axis=1), minlength=len(p))
        cut = np.unique(pt.leaf)
        np.testing.assert_allclose(s[cut], leaf_vol[cut], rtol=1e-12)
        grid, cont = p.volume_by_label(name), p.volume_by_label(name, contracted=True)
        assert cont["inside"] > grid["inside"] * 1.05 and cont["boundary"] < grid["boundary"] * 0.7
        assert sum(cont.values()) == pytest.approx(sum(grid.values()), rel=1e-12)
    sub = p.subset(p.labels["W"] == Label.BOUNDARY)
    assert np.array_equal(sub.lo[sub.parts["W"].leaf], p.lo[p.parts["W"].leaf])
    assert sub.volume_by_label("W", contracted=True)["inside"] == pytest.approx(
        p.volume_by_label("W", contracted=True)["inside"] - p.volume_by_label("W")["inside"])


def test_parts_do_not_overlap(paper_geometry):
    """Within a leaf, two parts share at most a face (checked pairwise on the leaves of depth 3)."""
    p = pave_workspace(paper_geometry, 3, contract=True, refine=1)
    for pt in p.parts.values():
        order = np.argsort(pt.leaf, kind="stable")
        leaf, lo, hi = pt.leaf[order], pt.lo[order], pt.hi[order]
        starts = np.flatnonzero(np.r_[True, leaf[1:] != leaf[:-1]])
        for a, b in zip(starts, np.r_[starts[1:], len(leaf)]):
            ov = np.all(np.minimum(hi[a:b, None], hi[None, a:b]) > np.maximum(lo[a:b, None], lo[None, a:b]), axis=2)
            assert np.count_nonzero(ov) == b - a  # only the diagonal


def test_box_minus_tiles():
    rng = np.random.default_rng(1)
    a_lo = rng.uniform(-1, 0, (50, 3))
    a_hi = a_lo + rng.uniform(0.1, 1, (50, 3))
    t = np.sort(rng.uniform(0, 1, (50, 3, 2)), axis=2)
    t[:10, :, 0] = 0.0  # faces shared with a
    c_lo, c_hi = a_lo + t[:, :, 0] * (a_hi - a_lo), a_lo + t[:, :, 1] * (a_hi - a_lo)
    lo, hi, row = box_minus(a_lo, a_hi, c_lo, c_hi)
    v = np.bincount(row, weights=np.prod(hi - lo, axis=1), minlength=50) + np.prod(c_hi - c_lo, axis=1)
    np.testing.assert_allclose(v, np.prod(a_hi - a_lo, axis=1), rtol=1e-12)
    assert np.bincount(row, minlength=50).max() <= 6


# --------------------------------------------------------------------------------------
# Mutations: a contractor that shrinks too far is caught
# --------------------------------------------------------------------------------------
def _limit_geometry(rho_min: str):
    """The paper's manipulator with another (inexact) rho_min and A1 off the origin."""
    text = (contracted_module.__file__.rsplit("/paving/", 1)[0] + "/data/wenger_chablat_1997.toml")
    src = open(text).read().replace("rho_min = 10", f"rho_min = {rho_min}").replace("a1 = [0, 0]", "a1 = [0.3, 0]")
    return parse_geometry(tomllib.loads(src, parse_float=decimal.Decimal), source="test")


def _thin_limit_violations(g, leg_min: float) -> list:
    """Boxes thin in y and phi across the circle rho_1 = rho_min: every part of W checked in arb."""
    xs = 0.3 + leg_min + np.linspace(-0.4, 0.4, 9)
    lo = np.column_stack([xs - 0.05, np.zeros(9), np.full(9, 0.25)])
    hi = np.column_stack([xs + 0.05, np.zeros(9), np.full(9, 0.25)])
    parts = contract_label(g, "W", lo, hi, np.arange(9))
    a = [arb(fmpq(3, 10)), arb(0)]
    r2 = arb(fmpq(*decimal.Decimal(str(leg_min)).as_integer_ratio())) ** 2
    bad = []
    with ctx.workprec(PREC):
        for i in np.flatnonzero(parts.label != Label.BOUNDARY):
            for x in (parts.lo[i, 0], parts.hi[i, 0]):
                rho1 = (arb(float(x)) - a[0]) ** 2 + (arb(float(parts.lo[i, 1])) - a[1]) ** 2
                if (parts.label[i] == Label.INSIDE and rho1 < r2) or (parts.label[i] == Label.OUTSIDE and rho1 > r2):
                    bad.append((i, float(x)))
    return bad


def test_tight_case_is_sound_and_contracts_to_the_ulp():
    """Across rho_1 = 10.37 (inexact square), the parts meet the circle within a few ulps, on the right side."""
    g = _limit_geometry("10.37")
    assert not _thin_limit_violations(g, 10.37)
    parts = contract_label(g, "W", np.array([[10.57, 0.0, 0.25]]), np.array([[10.77, 0.0, 0.25]]), np.array([0]))
    edge = parts.lo[parts.label == Label.INSIDE, 0].min()
    assert 0 < edge - 10.67 < 1e-13


@pytest.mark.parametrize("ulps", [4, 1 << 20])
def test_mutation_shrinking_contractor_is_caught(monkeypatch, ulps):
    """Hold and fail boxes shrunk inward (a few ulps, or a relative 2**-32) instead of widened: the checks fail."""
    def shrunk(b_lo, b_hi, lo, hi):
        lo2 = lo + ulps * np.spacing(np.abs(lo))
        hi2 = hi - ulps * np.spacing(np.abs(hi))
        return np.minimum(np.maximum(lo2, b_lo), hi2), np.maximum(np.minimum(hi2, b_hi), lo2)

    monkeypatch.setattr(contracted_module, "_widen", shrunk)
    assert _thin_limit_violations(_limit_geometry("10.37"), 10.37)
    if ulps > 4:
        p = pave_workspace(GEOMETRIES["paper"], 3, contract=True)
        bad, _ = _part_violations("paper", p.parts, np.random.default_rng(3))
        assert bad


def test_mutation_contractor_without_outward_rounding_is_caught(monkeypatch):
    """rho_min = 10.059, A1 = (0.3, 0): a box thin in y and phi across the circle rho_1 = rho_min.  Without
    the one-ulp widening of the cut the parts are still sound (the contractor rounds outward); with the
    outward rounding of the interval layer switched off as well, the INSIDE part starts inside the circle,
    and exact rational arithmetic sees it."""
    import intervalkin.core.interval as interval_module

    g = _limit_geometry("10.059")
    x = float(decimal.Decimal("10.359"))  # 0.3 + 10.059: the circle crosses the box's middle
    lo, hi = np.array([[x - 0.05, 0.0, 0.25]]), np.array([[x + 0.05, 0.0, 0.25]])
    r2 = (fmpq(10059, 1000)) ** 2

    def inside_part_starts_inside_the_circle() -> bool:
        parts = contract_label(g, "W", lo, hi, np.array([0]))
        start = parts.lo[parts.label == Label.INSIDE, 0].min()
        return (fmpq(*float(start).as_integer_ratio()) - fmpq(3, 10)) ** 2 < r2

    monkeypatch.setattr(contracted_module, "_widen", lambda b_lo, b_hi, c_lo, c_hi: (np.maximum(c_lo, b_lo),
                                                                                      np.minimum(c_hi, b_hi)))
    assert not inside_part_starts_inside_the_circle()

    def unrounded(v):
        return np.asarray(v, dtype=np.float64)

    monkeypatch.setattr(interval_module, "round_down", unrounded)
    monkeypatch.setattr(interval_module, "round_up", unrounded)
    assert inside_part_starts_inside_the_circle()
