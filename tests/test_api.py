"""The library API: intervalkin.solve, analyse, Analysis.label / locate / counts, verify.

Each answer is checked against an independent path: the labels against det A
written out here in arb from the paper's formulas, the joint-cell counts against
a certified solve at the same joint vector, the checker's verdict against a
tampered certificate.
"""

from __future__ import annotations

import dataclasses
import json
import subprocess
import sys
from fractions import Fraction

import numpy as np
import pytest
from flint import arb, ctx, fmpq

import intervalkin
from intervalkin import Count, InputError, Status
from intervalkin.certify.writer import write_certificates
from intervalkin.solve import dkp
from intervalkin.space.pose_label import boxes_holding

from .app.shared import chain

TABLE1_RHO = ("14.98", "15.38", "12.0")


@pytest.fixture(scope="module")
def analysis():
    return chain(6)  # intervalkin.analyse(depth=6), made once a session (the figure tests read the same one)


# --------------------------------------------------------------------------------------
# solve
# --------------------------------------------------------------------------------------
def test_solve_table1_six_certified_solutions():
    r = intervalkin.solve(TABLE1_RHO)
    assert isinstance(r, intervalkin.DkpResult)
    assert r.count == 6 and r.complete
    assert all(s.status == "unique" and s.det_sign in (1, -1) for s in r.solutions)
    # the paper: solutions 2, 3 and 6 share one aspect, the one with det A > 0
    assert [i for i, s in enumerate(r.solutions, 1) if s.aspect == "WA1"] == [2, 3, 6]


def test_solve_reads_numbers_exactly():
    by_text = intervalkin.solve(TABLE1_RHO)
    for rho in ([14.98, 15.38, 12.0], [Fraction(1498, 100), Fraction(769, 50), 12]):
        r = intervalkin.solve(rho)
        assert r.rho == by_text.rho == (Fraction(749, 50), Fraction(769, 50), Fraction(12))
        assert [s.aspect for s in r.solutions] == [s.aspect for s in by_text.solutions]


def test_solve_geometry_argument_and_bad_input(paper_geometry):
    assert intervalkin.solve(TABLE1_RHO, paper_geometry).count == 6
    with pytest.raises(InputError, match=r"^rho_3: 40 is outside the joint limits \[10, 32\]$"):
        intervalkin.solve(["14.98", "15.38", "40"])


def test_solve_stays_callable_beside_its_subpackage():
    """``intervalkin.solve`` is the solve/ layer, callable: importing its modules does not hide the function."""
    code = ("import intervalkin.solve.dkp, intervalkin\n"
            "from intervalkin import solve\n"
            "print(solve(['14.98', '15.38', '12.0']).count, intervalkin.solve.dkp.MAX_WIDTH > 0)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["6", "True"]


# --------------------------------------------------------------------------------------
# analyse: typed results, no printing, progress
# --------------------------------------------------------------------------------------
def test_analyse_prints_nothing_and_reports_progress(capfd):
    events = []
    a = intervalkin.analyse(depth=4, progress=events.append)
    out, err = capfd.readouterr()
    assert out == "" and err == ""
    starts = [e.stage for e in events if e.kind == "start"]
    dones = [e.stage for e in events if e.kind == "done"]
    assert starts == dones == list(a.timings) and len(starts) == 5
    levels = [e for e in events if e.kind == "level"]
    assert levels and all({"level", "depth", "boxes", "split"} <= set(e.level) for e in levels)
    assert a.depth == 4 and a.singular_depth == 5 and a.joint_depth == 3


def test_analyse_refuses_a_bad_depth_naming_the_parameter():
    for depth in (2, 12, "8", True):
        with pytest.raises(InputError, match=r"^depth: expected an integer in 3\.\.9, got "):
            intervalkin.analyse(depth=depth)


def test_result_types_are_frozen_and_typed(analysis):
    for obj in (analysis, analysis.counts(), analysis.counts().basic_regions, analysis.refinement[0],
                analysis.label(("0", "0", "0")), analysis.locate(TABLE1_RHO)):
        assert dataclasses.is_dataclass(obj)
        assert type(obj).__dataclass_params__.frozen, type(obj).__name__
        assert all(f.type not in ("object", object) for f in dataclasses.fields(obj))
        field = dataclasses.fields(obj)[0].name
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(obj, field, None)


# --------------------------------------------------------------------------------------
# Counts
# --------------------------------------------------------------------------------------
@pytest.mark.parametrize("found,lower,upper,exact", [
    (2, 3, None, False),   # found below the certified lower bound
    (5, 3, 4, False),      # found above the certified upper bound
    (3, 3, 3, False),      # bounds meet but not declared exact
    (3, 2, None, True),    # declared exact without an upper bound
    (-1, 0, None, False),  # negative
])
def test_count_refuses_inconsistent_bounds(found, lower, upper, exact):
    with pytest.raises(ValueError):
        Count(found, lower, upper, exact, "")


def test_count_status_and_json():
    assert Count(6, 6, 6, True, "").status is Status.CERTIFIED
    assert Count(28, 12, None, False, "").status is Status.LOWER_BOUND
    assert Count(0, 0, None, False, "").status is Status.UNDECIDED
    assert Count(28, 12, None, False, "w").to_json() == {"count": 28, "exact": False, "lower_bound": 12,
                                                          "upper_bound": None, "why": "w", "found": 28,
                                                          "lower": 12, "upper": None, "undecided": {}}
    assert Count(6, 6, 6, True, "", {"volume": 0.5}).to_json()["undecided"] == {"volume": 0.5}


def test_analysis_counts(analysis):
    c = analysis.counts()
    for count in (c.basic_regions, c.uniqueness_domains):
        assert count.lower <= count.found and count.upper is None and not count.exact
        assert count.status is Status.LOWER_BOUND and count.why
    # the aspects: 2 proved from below (opposite signs) and from above (each sign's cover closes)
    assert (c.aspects.found, c.aspects.lower, c.aspects.upper, c.aspects.exact) == (2, 2, 2, True)
    assert c.aspects.status is Status.CERTIFIED
    # basic regions: counted over every cell of the direct joint paving (Theorem 1), never below the bound
    from_cells = sum(cell.count for cell in analysis.cells.cells if cell.count >= 0)
    assert c.basic_regions.found == max(from_cells, c.basic_regions.lower)
    assert c.basic_regions.lower >= analysis.regions.counts().basic_regions.lower
    # the six-solution cell has three solutions of each aspect: at least 3 + 3 domains
    assert c.uniqueness_domains.lower >= 6
    doc = c.to_json()
    assert doc["basic_regions"]["count"] == c.basic_regions.found
    assert json.loads(json.dumps(doc)) == doc


# --------------------------------------------------------------------------------------
# label: the certified aspect is the sign of det A, evaluated independently in arb
# --------------------------------------------------------------------------------------
def _det_a_arb(geometry, pose) -> arb:
    """det A at an exact pose, from DESIGN.md section 2: row i is 2 (u_ix, u_iy, r_i x u_i)."""
    x, y, phi = (arb(fmpq(v.numerator, v.denominator)) for v in pose)
    c, s = phi.cos(), phi.sin()
    rows = []
    for i in range(3):
        px, py = (v.arb() for v in geometry.platform_point(i))
        rx, ry = c * px - s * py, s * px + c * py
        ax, ay = (arb(fmpq(v.numerator, v.denominator)) for v in geometry.base[i])
        ux, uy = x + rx - ax, y + ry - ay
        rows.append((2 * ux, 2 * uy, 2 * (rx * uy - ry * ux)))
    (a, b, c3), (d, e, f), (g, h, k) = rows
    return a * (e * k - f * h) - b * (d * k - f * g) + c3 * (d * h - e * g)


def test_label_aspect_is_the_sign_of_det_a(analysis, paper_geometry):
    p = analysis.regions.paving
    rng = np.random.default_rng(12)
    certified = 0
    for i in rng.choice(len(p), size=300, replace=False):
        pose = [repr(float(v)) for v in p.lo[i] + rng.random(3) * (p.hi[i] - p.lo[i])]
        lab = analysis.label(pose, refine=False)  # no path search: 300 poses (tests/app/test_label.py tries it)
        assert lab.boxes >= 1
        if lab.aspect is None:
            continue
        certified += 1
        with ctx.workprec(200):
            det = _det_a_arb(paper_geometry, lab.pose)
        assert (det > 0) if lab.aspect == "WA1" else (det < 0), (pose, lab.aspect, det)
        assert lab.in_workspace is True
        if lab.basic_region is not None:
            assert lab.status is Status.CERTIFIED
            region = analysis.regions.regions[lab.basic_region]
            assert region.aspect == lab.aspect
            assert lab.uniqueness_domain is not None and lab.basic_region in analysis.regions.domains[lab.uniqueness_domain]
    assert certified > 50


def test_label_outside_and_undecided(analysis):
    out = analysis.label(("0", "0", "0"))  # B1 on A1: leg 1 has length 0
    assert out.in_workspace is False and out.status is Status.CERTIFIED and out.aspect is None
    with pytest.raises(InputError, match="^pose: x = 60 is outside the paved domain"):
        analysis.label((60, 60, 0))  # the domain holds W: a lookup there would say nothing
    with pytest.raises(InputError, match="^pose: "):
        analysis.label(("1", "2", "x"))


def test_boxes_holding_is_exact_next_to_an_inexact_decimal():
    """boxes_holding finds exactly the closed boxes around an exact pose that no float equals.

    1/10 lies strictly between the floats d < 1/10 < u = float(0.1): boxes ending at d
    or starting at u do not hold it; boxes ending at u or starting at d do.  Would catch the
    float filter taken for the exact test (box [u, 1] kept for 1/10), a filter or test with
    open bounds (boxes meeting the pose u at a face lost), or an enclosure of 1/10 that
    misses it.
    """
    u = 0.1
    d = float(np.nextafter(u, -np.inf))
    assert Fraction(d) < Fraction(1, 10) < Fraction(u)
    lo = np.array([[0.0, 0, 0], [u, 0, 0], [0.0, 0, 0], [d, 0, 0], [d, 0, 0]])
    hi = np.array([[d, 1, 1], [1.0, 1, 1], [u, 1, 1], [1.0, 1, 1], [u, 1, 1]])
    pose = (Fraction(1, 10), Fraction(1, 2), Fraction(1, 2))
    assert boxes_holding(lo, hi, pose).tolist() == [2, 3, 4]
    assert boxes_holding(lo, hi, (Fraction(u), Fraction(0), Fraction(1))).tolist() == [1, 2, 3, 4]


def test_label_of_table1_solutions_lies_in_their_aspect(analysis):
    """Each certified solution of Table 1: a label given is the solution's own certified aspect."""
    r = intervalkin.solve(TABLE1_RHO)
    for s in r.solutions:
        mid = [Fraction(float(v)) for v in 0.5 * (s.box[:, 0] + s.box[:, 1])]
        lab = analysis.label(mid)
        assert lab.aspect in (s.aspect, None)


# --------------------------------------------------------------------------------------
# locate: the cell's certified count is the count of an independent certified solve
# --------------------------------------------------------------------------------------
def test_locate_matches_a_certified_solve(analysis, paper_geometry):
    jp = analysis.joint
    rng = np.random.default_rng(3)
    seen_cells = set()
    for cell in [c for c in jp.cells if c.count >= 0][:12]:
        vox = np.argwhere(jp.cell == cell.id)
        v = vox[rng.integers(len(vox))]
        # an exact point inside the voxel, off its centre (the cell's witness is a centre)
        q = tuple(jp.rho_min[i] + (Fraction(int(v[i])) + Fraction(int(rng.integers(1, 8)), 8)) * jp.step[i]
                  for i in range(3))
        loc = analysis.locate(q)
        assert loc.cell == cell.id and loc.status is Status.CERTIFIED
        res = dkp.solve(paper_geometry, q)
        assert res.complete
        n1 = sum(1 for s in res.solutions if s.det_sign > 0)
        assert (loc.count, loc.n_wa1, loc.n_wa2) == (res.count, n1, res.count - n1)
        seen_cells.add(cell.count)
    assert {2, 4} <= seen_cells


def test_locate_on_the_undecided_layer_solves_at_the_point(analysis):
    loc = analysis.locate(TABLE1_RHO)
    assert analysis.joint.cell_at(loc.rho) == -1 or loc.cell is not None
    assert loc.status is Status.CERTIFIED and (loc.count, loc.n_wa1, loc.n_wa2) == (6, 3, 3)
    with pytest.raises(InputError, match="^rho_1: "):
        analysis.locate(["9", "20", "20"])


# --------------------------------------------------------------------------------------
# verify
# --------------------------------------------------------------------------------------
def test_verify_passes_then_fails_on_a_tampered_certificate(tmp_path, paper_geometry):
    folder = tmp_path / "run" / "certificates"
    write_certificates(folder, paper_geometry, dkp_results=[intervalkin.solve(TABLE1_RHO)])
    report = intervalkin.verify(tmp_path / "run")  # an output folder: its certificates/ are checked
    assert isinstance(report, intervalkin.VerifyReport)
    assert report.folder == folder and report.verified and not report.failed
    doc = json.loads((folder / "dkp.json").read_text())
    text = json.dumps(doc)
    claim = doc["claims"][0]
    key = next(k for k in ("solutions", "boxes") if k in claim)
    claim[key] = claim[key][:-1]  # drop one solution: completeness no longer holds
    assert json.dumps(doc) != text
    (folder / "dkp.json").write_text(json.dumps(doc))
    report = intervalkin.verify(folder)
    assert not report.verified and len(report.failed) == 1


def test_verify_refuses_a_folder_without_certificates(tmp_path):
    with pytest.raises(InputError):
        intervalkin.verify(tmp_path / "nothing")
