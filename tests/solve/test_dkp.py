"""Certified direct kinematics: proofs re-checked independently, hard cases written out.

Independent checks used here:

* ``mp_refine``: mpmath at 60 digits, its own formulas for F and A built from the
  exact geometry (Fractions and surds), Newton from the box midpoint; the
  converged point must lie in the certified box with residual < 1e-40, and the
  sign of det A there must equal the certified sign.
* ``tests.approx.approx_solve``: float64 dense phi sampling (no arb, no
  polynomial), whose count must agree with the certified count.
"""

from __future__ import annotations

import decimal
import json
import math
import tomllib
from fractions import Fraction

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings, HealthCheck
from hypothesis import strategies as st

from intervalkin.app.cli import main
from intervalkin.solve.dkp import MAX_WIDTH, DkpResult, parse_joint_vector, solve
from ..approx import approx_solve
from intervalkin.app.text import format_dkp_table
from intervalkin.core.errors import InputError
from intervalkin.core.geometry import Geometry, load_geometry, parse_geometry
from intervalkin.kinematics.formulas import approx_det_a, approx_inverse_kinematics

from ..conftest import DATA

# ------------------------------------------------------------------------------------------
# independent high-precision re-check
# ------------------------------------------------------------------------------------------
_MP = mpmath.mp.clone() if hasattr(mpmath.mp, "clone") else mpmath.mp


def _mpq(q: Fraction):
    return mpmath.mpf(q.numerator) / q.denominator


def _mp_geometry(g: Geometry):
    def surd(s):
        return _mpq(s.coef) * mpmath.sqrt(_mpq(s.radicand))

    p = [tuple(surd(c) for c in g.platform_point(i)) for i in range(3)]
    a = [tuple(_mpq(c) for c in pt) for pt in g.base]
    return p, a


def _mp_F_J(g: Geometry, X, rho):
    p, a = _mp_geometry(g)
    x, y, phi = X
    c, s = mpmath.cos(phi), mpmath.sin(phi)
    F, J = [], []
    for i in range(3):
        rx = p[i][0] * c - p[i][1] * s
        ry = p[i][0] * s + p[i][1] * c
        ux, uy = x + rx - a[i][0], y + ry - a[i][1]
        F.append(ux**2 + uy**2 - _mpq(Fraction(rho[i])) ** 2)
        J.append([2 * ux, 2 * uy, 2 * (rx * uy - ry * ux)])
    return mpmath.matrix(F), mpmath.matrix(J)


def mp_refine(g: Geometry, start, rho, dps: int = 60):
    """Newton in mpmath at ``dps`` digits from ``start``; returns (X, max|F|, det A)."""
    with mpmath.workdps(dps):
        X = mpmath.matrix([mpmath.mpf(float(v)) for v in start])
        for _ in range(12):
            F, J = _mp_F_J(g, X, rho)
            X = X - mpmath.lu_solve(J, F)
        F, J = _mp_F_J(g, X, rho)
        return [X[i] for i in range(3)], max(abs(v) for v in F), mpmath.det(J)


def check_certified(g: Geometry, result: DkpResult) -> None:
    """Every unique box: narrow, holds a high-precision root, det sign agrees."""
    for s in result.solutions:
        if s.status != "unique":
            continue
        assert s.width < MAX_WIDTH
        assert np.all(s.box[:, 0] <= s.box[:, 1])
        X, res, det = mp_refine(g, s.midpoint, result.rho)
        assert res < mpmath.mpf(10) ** -40
        phi = X[2]
        # phi modulo 2 pi inside the box's phi interval
        k = mpmath.nint((phi - mpmath.mpf(s.midpoint[2])) / (2 * mpmath.pi))
        phi = phi - 2 * mpmath.pi * k
        for j, v in enumerate((X[0], X[1], phi)):
            assert mpmath.mpf(s.box[j, 0]) <= v <= mpmath.mpf(s.box[j, 1]), (j, v, s.box[j])
        assert int(mpmath.sign(det)) == s.det_sign
        assert s.aspect == ("WA1" if s.det_sign > 0 else "WA2")
        # phi listed in (-pi, pi]: the interval meets it
        assert s.box[2, 1] > -math.pi and s.box[2, 0] <= math.pi


def random_rho(g: Geometry, rng, digits: int = 4):
    lo = np.array([float(v) for v in g.rho_min])
    hi = np.array([float(v) for v in g.rho_max])
    q = np.round(rng.uniform(lo, hi), digits)
    q = np.clip(q, lo, hi)
    return [Fraction(repr(float(v))) for v in q]


# ------------------------------------------------------------------------------------------
# parsing
# ------------------------------------------------------------------------------------------
def test_parse_joint_vector_is_exact(paper_geometry):
    rho = parse_joint_vector(paper_geometry, ["14.98", "15.38", "12.0"])
    assert rho == (Fraction(1498, 100), Fraction(1538, 100), Fraction(12))
    assert parse_joint_vector(paper_geometry, ["10", "32", "1e1"]) == (10, 32, 10)


@pytest.mark.parametrize(
    "values, fragment",
    [
        (["abc", "15", "15"], "rho_1"),
        (["15", "nan", "15"], "rho_2"),
        (["15", "15", "inf"], "rho_3"),
        (["9.99", "15", "15"], "rho_1"),
        (["15", "32.0000001", "15"], "rho_2"),
        (["15", "15", "-12"], "rho_3"),
    ],
)
def test_parse_joint_vector_rejects(paper_geometry, values, fragment):
    with pytest.raises(InputError) as err:
        parse_joint_vector(paper_geometry, values)
    msg = str(err.value)
    assert fragment in msg and "\n" not in msg
    assert "[10, 32]" in msg  # the allowed range is named


def test_parse_joint_vector_wrong_length(paper_geometry):
    with pytest.raises(InputError):
        parse_joint_vector(paper_geometry, ["15", "15"])


# ------------------------------------------------------------------------------------------
# random joint vectors: certified vs the float solver, boxes re-checked in mpmath
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("geometry_file", [None, "offset_right.toml", "coords_platform.toml"])
def test_random_vectors_agree_with_float_solver(paper_geometry, geometry_file, rng):
    g = paper_geometry if geometry_file is None else load_geometry(DATA / geometry_file)
    counts = set()
    for _ in range(40):
        rho = random_rho(g, rng)
        result = solve(g, rho)
        assert result.complete, result.completeness_reason
        assert all(s.status == "unique" for s in result.solutions)
        approx = approx_solve(g, [float(r) for r in rho])
        assert result.count == len(approx), (rho, result.count, len(approx))
        for X in approx:  # each float solution falls in one certified box
            hits = [s for s in result.solutions if np.all(np.abs(X - s.midpoint) < 1e-6)]
            assert len(hits) == 1
        counts.add(result.count)
    assert len(counts) >= 2  # the sample is not degenerate


@pytest.mark.parametrize("geometry_file", [None, "offset_right.toml", "coords_platform.toml"])
def test_certified_boxes_hold_high_precision_roots(paper_geometry, geometry_file, rng):
    g = paper_geometry if geometry_file is None else load_geometry(DATA / geometry_file)
    checked = 0
    while checked < 12:
        result = solve(g, random_rho(g, rng))
        check_certified(g, result)
        checked += result.count


@settings(max_examples=25, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.tuples(*[st.integers(min_value=1000, max_value=3200)] * 3))
def test_random_centi_vectors_solutions_satisfy_equations(paper_geometry, centi):
    """Joint vectors drawn by hypothesis: each certified midpoint maps back onto rho."""
    rho = [Fraction(c, 100) for c in centi]
    result = solve(paper_geometry, rho)
    if not result.complete:  # allowed, but then it must say why
        assert result.completeness_reason
        return
    assert result.count in (0, 2, 4, 6)
    for s in result.solutions:
        q = approx_inverse_kinematics(paper_geometry, s.midpoint)
        assert np.allclose(q, [float(r) for r in rho], atol=1e-9)


def test_pose_round_trip(paper_geometry, rng):
    found = 0
    while found < 10:
        X = np.array([rng.uniform(-20, 20), rng.uniform(-20, 20), rng.uniform(-math.pi, math.pi)])
        q = approx_inverse_kinematics(paper_geometry, X)
        if np.any(q < 10) or np.any(q > 32):
            continue
        rho = [Fraction(format(v, ".15g")) for v in q]
        result = solve(paper_geometry, rho)
        assert result.complete
        near = [s for s in result.solutions if np.max(np.abs(s.midpoint - X)) < 1e-8]
        assert len(near) == 1
        found += 1


def test_solutions_sorted_and_unique_boxes_disjoint(paper_geometry):
    """Table 1's six boxes are listed by increasing phi and are pairwise disjoint, phi read modulo 2 pi
    (checked here directly on the bounds, not with the solver's own disjointness test)."""
    result = solve(paper_geometry, parse_joint_vector(paper_geometry, ["14.98", "15.38", "12.0"]))
    phis = [s.midpoint[2] for s in result.solutions]
    assert phis == sorted(phis)
    boxes = [np.asarray(s.box) for s in result.solutions]
    for a in range(len(boxes)):
        for b in range(a + 1, len(boxes)):
            A, B = boxes[a], boxes[b]
            apart_xy = any(A[j, 1] < B[j, 0] or B[j, 1] < A[j, 0] for j in (0, 1))
            apart_phi = all(A[2, 1] < B[2, 0] + k * 2 * math.pi or B[2, 1] + k * 2 * math.pi < A[2, 0]
                            for k in (-1, 0, 1))
            assert apart_xy or apart_phi, (a, b)
    assert result.precision == 64
    assert "isolated" in result.completeness_reason


# ------------------------------------------------------------------------------------------
# hard cases
# ------------------------------------------------------------------------------------------
def _singular_pose(g: Geometry, rng):
    """A float pose with det A = 0 (bisection in y) whose image is inside the limits."""
    while True:
        x, phi = rng.uniform(-25, 25), rng.uniform(-3, 3)
        ys = np.linspace(-30, 30, 2001)
        d = approx_det_a(g, np.stack([np.full_like(ys, x), ys, np.full_like(ys, phi)], -1))
        for i in np.nonzero(np.sign(d[:-1]) != np.sign(d[1:]))[0]:
            lo, hi = ys[i], ys[i + 1]
            slo = np.sign(d[i])
            for _ in range(80):
                m = 0.5 * (lo + hi)
                if np.sign(approx_det_a(g, np.array([x, m, phi]))) == slo:
                    lo = m
                else:
                    hi = m
            X = np.array([x, 0.5 * (lo + hi), phi])
            q = approx_inverse_kinematics(g, X)
            if np.all(q > 10.5) and np.all(q < 31.5):
                return X, q


def test_joint_vector_on_image_of_singular_surface_never_wrong(paper_geometry, rng):
    """q = g(X), X singular, rounded: either honest failure or a count we can re-check."""
    for _ in range(6):
        X, q = _singular_pose(paper_geometry, rng)
        for digits in (17, 9):
            rho = [Fraction(format(v, f".{digits}g")) for v in q]
            result = solve(paper_geometry, rho)
            check_certified(paper_geometry, result)
            if not result.complete:
                assert result.completeness_reason
                continue
            assert all(s.status == "unique" for s in result.solutions)
            assert result.count % 2 == 0
            # the float solver can only miss (close pairs), never add
            assert len(approx_solve(paper_geometry, [float(r) for r in rho])) <= result.count





def _inline(text: str) -> Geometry:
    return parse_geometry(tomllib.loads(text, parse_float=decimal.Decimal), source="inline")


def test_exactly_singular_joint_vector_is_not_certified():
    """B = (3,4), (12,5), (8,-6) with A_i on the rays from the origin: the three legs meet
    at the origin, det A = 0 exactly, q = (15, 13, 10) exactly on g(S): a double root."""
    g = load_geometry(DATA / "concurrent_legs.toml")
    X = np.array([3.0, 4.0, math.atan2(1, 9)])
    assert np.allclose(approx_inverse_kinematics(g, X), [15, 13, 10])
    assert abs(approx_det_a(g, X)) < 1e-9
    result = solve(g, [Fraction(15), Fraction(13), Fraction(10)])
    assert not result.complete
    assert "not isolated" in result.completeness_reason
    check_certified(g, result)
    for s in result.solutions:  # no unique box around the singular pose
        if s.status == "unique":
            assert np.max(np.abs(s.midpoint - X)) > 1e-3
    unknown = [s for s in result.solutions if s.status == "unknown"]
    assert unknown and all(s.reason for s in unknown)
    assert any(np.max(np.abs(s.midpoint - X)) < 1e-5 for s in unknown)
    payload = result.to_json()
    assert payload["complete"] is False
    assert all("reason" in d for d in payload["solutions"] if d["status"] == "unknown")


_SEAM = """
name = "exact pose at phi = pi"
[base]
a1 = [-8, -10]
a2 = [3, -7]
a3 = [-11, 10]
[platform]
b1 = [0, 0]
b2 = [10, 0]
b3 = [4, 7]
[limits]
rho_min = 5
rho_max = 40
"""


def test_solution_exactly_at_phi_pi():
    """X = (1, 2, pi): B = (1,2), (-9,2), (-3,-5); A_i - B_i are (-9,-12), (12,-9), (-8,15):
    q = (15, 15, 17) exactly, with a solution exactly on the seam (t = tan(phi/2) infinite)."""
    g = _inline(_SEAM)
    assert np.allclose(approx_inverse_kinematics(g, np.array([1.0, 2.0, math.pi])), [15, 15, 17])
    result = solve(g, [Fraction(15), Fraction(15), Fraction(17)])
    assert result.complete, result.completeness_reason
    # f(pi) = 0 exactly: the substitution must have been shifted off phi0 = 0
    assert "tan((phi - 0)/2)" not in result.completeness_reason
    check_certified(g, result)
    assert result.count == len(approx_solve(g, [15, 15, 17]))
    seam = [s for s in result.solutions if abs(s.midpoint[2] - math.pi) < 1e-9]
    assert len(seam) == 1
    s = seam[0]
    assert s.box[2, 0] <= math.pi <= s.box[2, 1] + 1e-15  # holds pi, written around +pi
    assert s.box[2, 0] > -math.pi
    assert np.allclose(s.midpoint[:2], [1, 2], atol=1e-12)
    assert result.solutions[-1] is s  # largest phi: listed last


def test_solution_near_phi_pi_in_paper_geometry(paper_geometry):
    """q = g(X) for a pose at phi = pi, rho computed in arb (60 digits) and rounded."""
    from flint import arb, ctx

    X = (-12.5, 3.25)
    old = ctx.prec
    ctx.prec = 200
    try:
        from intervalkin.kinematics.formulas import inverse_kinematics_arb

        rho = inverse_kinematics_arb(paper_geometry, arb(X[0]), arb(X[1]), arb.pi())
        rho = [Fraction(r.str(40, radius=False)) for r in rho]
    finally:
        ctx.prec = old
    result = solve(paper_geometry, rho)
    assert result.complete
    check_certified(paper_geometry, result)
    near = [s for s in result.solutions if np.max(np.abs(s.midpoint[:2] - X)) < 1e-9]
    assert len(near) == 1
    s = near[0]
    assert abs(abs(s.midpoint[2]) - math.pi) < 1e-12
    assert -math.pi < s.midpoint[2] <= math.pi or s.box[2, 0] <= math.pi
    assert result.count == len(approx_solve(paper_geometry, [float(r) for r in rho]))


def _d_roots(g: Geometry) -> list[float]:
    """Angles where the 2x2 system m_i . z = k_i (i = 2, 3) is singular (float)."""
    from intervalkin.kinematics.constants import constants

    k = constants(g)

    def D(phi):
        v = [(k.radius[i] * np.cos(phi + k.alpha[i]) - (k.ax[i] - k.ax[0]),
              k.radius[i] * np.sin(phi + k.alpha[i]) - (k.ay[i] - k.ay[0])) for i in (1, 2)]
        return v[0][0] * v[1][1] - v[0][1] * v[1][0]

    grid = np.linspace(-math.pi, math.pi, 4001)
    vals = D(grid)
    out = []
    for i in np.nonzero(np.sign(vals[:-1]) != np.sign(vals[1:]))[0]:
        lo, hi = grid[i], grid[i + 1]
        for _ in range(80):
            m = 0.5 * (lo + hi)
            if np.sign(D(m)) == np.sign(D(lo)):
                lo = m
            else:
                hi = m
        out.append(0.5 * (lo + hi))
    return out


@pytest.mark.parametrize("geometry_file", [None, "offset_right.toml"])
def test_joint_vector_with_singular_2x2_system(paper_geometry, geometry_file, rng):
    """A pose at an angle where the 2x2 system is singular: the reduced equation has a
    (nearly) double root there that is NOT a singularity; both solutions must be found."""
    g = paper_geometry if geometry_file is None else load_geometry(DATA / geometry_file)
    roots = _d_roots(g)
    assert roots
    lo = np.array([float(v) for v in g.rho_min])
    hi = np.array([float(v) for v in g.rho_max])
    done = 0
    while done < 4:
        phi = roots[done % len(roots)]
        X = np.array([rng.uniform(-25, 25), rng.uniform(-25, 25), phi])
        q = approx_inverse_kinematics(g, X)
        if np.any(q < lo) or np.any(q > hi) or abs(approx_det_a(g, X)) < 1e2:
            continue
        rho = [Fraction(format(v, ".17g")) for v in q]
        result = solve(g, rho)
        assert result.complete, result.completeness_reason
        check_certified(g, result)
        near = [s for s in result.solutions if np.max(np.abs(s.midpoint - X)) < 1e-7]
        assert len(near) == 1
        # the partner: another certified solution with (nearly) the same phi
        partner = [s for s in result.solutions if s is not near[0] and abs(s.midpoint[2] - phi) < 1e-6]
        assert len(partner) == 1
        done += 1


def test_geometry_is_not_rounded(paper_geometry):
    """Changing the last decimal of a platform side changes the certified boxes."""
    other = _inline(paper_geometry.to_toml().replace("b1b2 = 17.04", "b1b2 = 17.0400000001"))
    rho = parse_joint_vector(paper_geometry, ["14.98", "15.38", "12.0"])
    a = solve(paper_geometry, rho)
    b = solve(other, rho)
    assert a.count == b.count == 6
    assert any(not np.array_equal(s.box, t.box) for s, t in zip(a.solutions, b.solutions))


# ------------------------------------------------------------------------------------------
# output and CLI
# ------------------------------------------------------------------------------------------
def test_format_table(paper_geometry):
    result = solve(paper_geometry, parse_joint_vector(paper_geometry, ["14.98", "15.38", "12.0"]))
    text = format_dkp_table(result)
    lines = text.splitlines()
    assert lines[0].startswith("rho = (14.98, 15.38, 12): 6 solution(s)")
    assert [ln.split()[0] for ln in lines[3:9]] == ["1", "2", "3", "4", "5", "6"]
    assert "completeness PROVED" in lines[-1]
    assert all("WA1" in lines[2 + i] for i in (2, 3, 6))


def test_cli_dkp_json(capsys):
    assert main(["dkp", "14.98", "15.38", "12.0", "--json"]) == 0
    out = capsys.readouterr().out
    assert out.count("\n") == 1
    payload = json.loads(out)
    assert list(payload) == ["rho", "count", "complete", "solutions"]
    assert payload["rho"] == [14.98, 15.38, 12.0]
    assert payload["count"] == 6 and payload["complete"] is True
    for s in payload["solutions"]:
        assert list(s) == ["x", "y", "phi", "det_sign", "aspect", "status"]
        assert s["status"] == "unique"
        assert all(s[k][1] - s[k][0] < 1e-9 for k in ("x", "y", "phi"))
    assert [s["aspect"] for s in payload["solutions"]] == ["WA2", "WA1", "WA1", "WA2", "WA2", "WA1"]


def test_cli_dkp_human(capsys):
    assert main(["dkp", "14.98", "15.38", "12.0"]) == 0
    assert "completeness PROVED" in capsys.readouterr().out


def test_cli_dkp_other_geometry(capsys):
    assert main(["dkp", "20", "20", "20", "--geometry", str(DATA / "offset_right.toml"), "--json"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["complete"] is True
    assert payload["count"] == len(approx_solve(load_geometry(DATA / "offset_right.toml"), [20, 20, 20]))


@pytest.mark.parametrize(
    "argv",
    [
        ["dkp", "9", "15", "15"],
        ["dkp", "15", "40", "15", "--json"],
        ["dkp", "15", "x", "15"],
        ["dkp", "15", "nan", "15"],
    ],
)
def test_cli_dkp_bad_joint_vector(capsys, argv):
    assert main(argv) == 2
    err = capsys.readouterr()
    assert err.out == ""
    assert err.err.count("\n") == 1 and err.err.startswith("intervalkin: error:")
    assert "Traceback" not in err.err


def test_cli_dkp_bad_geometry(capsys, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[base]\na1 = [0, 0]\n")
    assert main(["dkp", "15", "15", "15", "--geometry", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert main(["dkp", "15", "15", "15", "--geometry", str(tmp_path / "missing.toml")]) == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_box_separation_reads_phi_modulo_two_pi():
    from intervalkin.solve.krawczyk import disjoint_mod_2pi as _disjoint

    def box(x, y, phi, r=1e-12):
        return np.array([[x - r, x + r], [y - r, y + r], [phi - r, phi + r]])

    assert _disjoint(box(1, 2, 0.5), box(1.1, 2, 0.5))  # apart in x
    assert _disjoint(box(1, 2, 0.5), box(1, 2, 0.5 + 1e-9))  # apart in phi
    assert not _disjoint(box(1, 2, 0.5), box(1, 2, 0.5 + 1e-12))  # overlapping
    # the same pose written at +pi and at -pi: the same point of the circle
    assert not _disjoint(box(1, 2, math.pi), box(1, 2, -math.pi))
    assert not _disjoint(box(1, 2, 0.25), box(1, 2, 0.25 + 2 * math.pi, r=1e-11))
    assert _disjoint(box(1, 2, math.pi - 1e-6), box(1, 2, -math.pi + 1e-6))
