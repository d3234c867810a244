"""Certificates and the independent checker: honest files verify, tampered files are refused."""

from __future__ import annotations

import json
import math
import shutil
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import pytest
from flint import ctx

from intervalkin import checker
from intervalkin.checker.model import ArbModel as _Model
from intervalkin.checker.parse import Refused as _Refused
from intervalkin.checker.model import exact_ball as _q
from intervalkin.checker.solutions import count_solutions as _count_solutions
from intervalkin.checker.solutions import disjoint_mod_2pi as _disjoint_mod_2pi
from intervalkin.checker.solutions import reduced_sextic as _reduced_sextic
from intervalkin.certify.writer import write_certificates
from intervalkin.app.cli import main
from intervalkin.kinematics.sextic import reduction, sextic_coefficients
from ..approx import approx_solve
from intervalkin.solve.dkp import parse_joint_vector, solve
from intervalkin.core.geometry import load_geometry
from intervalkin.space.trajectory import trajectory

from ..conftest import DATA

TABLE1 = ["14.98", "15.38", "12.0"]


@pytest.fixture(scope="module")
def table1(paper_geometry):
    return solve(paper_geometry, parse_joint_vector(paper_geometry, TABLE1))


@pytest.fixture(scope="module")
def chain(regions_chain):
    """A small real chain: workspace depth 7, joint grid 2**6, regions at depth 7 (tests/conftest.py, built once a
    run for the region tests too)."""
    return regions_chain


@pytest.fixture(scope="module")
def paths(paper_geometry):
    """Certified paths between Table 1's solutions 2 -> 3 (phi_turns 0) and 3 -> 6 (phi_turns -1), depth 6."""
    return [trajectory(paper_geometry, TABLE1, i, j, depth=6) for i, j in ((2, 3), (3, 6))]


@pytest.fixture(scope="module")
def cert_dir(tmp_path_factory, paper_geometry, chain, table1, paths, aspect_topology, fold_paving):
    jp, ra = chain
    out = tmp_path_factory.mktemp("certificates")
    write_certificates(out, paper_geometry, dkp_results=[table1], joint=jp, regions=ra, box_sample=120, seed=7,
                       trajectories=paths, aspect_topology=aspect_topology, joint_cells=fold_paving,
                       separations=False)  # count barriers: tests/recheck/test_separation_file.py
    return out


def _copy(src: Path, tmp_path: Path) -> Path:
    """A copy to tamper with, without the aspect covers and the joint models and joins
    (tests/checker/test_aspects.py and tests/checker/test_joint_claims.py tamper with those;
    re-proving them in every verify here would cost seconds each): the aspects count in it goes
    back to its lower bound, which the remaining claims prove."""
    dst = tmp_path / "copy"
    shutil.copytree(src, dst)
    index = _load(dst, "index.json")
    for name in ("aspect_connected.json", "joint_fold_model.json", "joint_join.json"):
        index["files"].remove(name)
        (dst / name).unlink()
    _save(dst, "index.json", index)
    counts = _load(dst, "counts.json")
    for c in counts["claims"]:
        if c["name"] == "aspects":
            c.update(upper_bound=None, exact=False,
                     support=[r for r in c["support"] if not r.startswith("aspect_connected")])
    _save(dst, "counts.json", counts)
    return dst


def _load(d: Path, name: str) -> dict:
    return json.loads((d / name).read_text())


def _save(d: Path, name: str, doc: dict) -> None:
    (d / name).write_text(json.dumps(doc, indent=1))


def _failed(d: Path) -> list[checker.CheckResult]:
    return [r for r in checker.verify_directory(d) if not r.verified]


def _refused(d: Path, capsys, file: str, claim: str | None = None) -> str:
    """Assert the CLI exits 2 (bad certificates) and prints a FAILED line for the claim; return that line."""
    bad = _failed(d)
    assert any(r.file == file and (claim is None or r.claim == claim) for r in bad), [r.line() for r in bad]
    assert main(["verify", str(d)]) == 2
    out = capsys.readouterr().out
    lines = [ln for ln in out.splitlines() if ln.startswith(f"FAILED: {file}#{claim or ''}")]
    assert lines, out
    return lines[0]


# --------------------------------------------------------------------------------------
# Honest certificates
# --------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def checked(cert_dir):
    """One re-proof of the whole folder by the checker alone, in a fresh process: {"lines": its verdict lines, as
    ``intervalkin verify`` prints them, "modules": the modules of the checked layers it imported}.  One run serves
    both tests below (re-proving every claim twice would double the file's longest test)."""
    code = (
        "import json, sys, intervalkin.checker as c\n"
        f"r = c.verify_directory({str(cert_dir)!r})\n"
        "layers = ['kinematics', 'paving', 'solve', 'space', 'certify', 'pipeline', 'app']\n"
        "mods = sorted(m for m in sys.modules for l in layers if m == 'intervalkin.' + l or m.startswith('intervalkin.' + l + '.'))\n"
        "print(json.dumps({'lines': [x.line() for x in r], 'modules': mods}))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def test_every_claim_of_the_chain_verifies(cert_dir, checked):
    out = checked["lines"]
    assert out and all(ln.startswith("verified: ") for ln in out), [ln for ln in out if not ln.startswith("verified: ")]
    kinds = {ln.split(" (", 1)[1].split(")", 1)[0] for ln in out}
    assert kinds == set(checker.KINDS)
    written = sum(len(_load(cert_dir, f)["claims"]) for f in _load(cert_dir, "index.json")["files"])
    assert len(out) == written  # one verdict per claim written, none skipped


def test_counts_are_backed_by_the_claims(cert_dir, chain):
    _, ra = chain
    declared = {c["name"]: c for c in _load(cert_dir, "counts.json")["claims"]}
    counts = ra.counts().to_json()
    for name in ("aspects", "basic_regions", "uniqueness_domains"):
        assert declared[name]["lower_bound"] == counts[name]["lower_bound"]
        assert declared[name]["exact"] is (name == "aspects") and declared[name]["support"]
    # the aspects: two signs, each proved connected by its cover (aspect_connected.json)
    assert declared["aspects"]["upper_bound"] == 2
    assert {"aspect_connected.json#WA1", "aspect_connected.json#WA2"} <= set(declared["aspects"]["support"])
    # the paper's six-solution cells: three solutions of each aspect
    assert declared["uniqueness_domains"]["lower_bound"] == 6


def test_table1_alone(tmp_path, paper_geometry, table1):
    paths = write_certificates(tmp_path, paper_geometry, dkp_results=[table1])
    assert [p.name for p in paths] == ["dkp.json", "index.json"]
    (r,) = checker.verify_directory(tmp_path)
    assert r.verified and "exactly 6 solutions (3 with det A > 0, 3 with det A < 0)" in r.message
    claim = _load(tmp_path, "dkp.json")["claims"][0]
    assert claim["rho"] == ["14.98", "15.38", "12"] and claim["complete"] is True
    assert max(b[1] - b[0] for s in claim["solutions"] for b in s["box"]) < 1e-9





def test_incomplete_solve_claims_only_its_unique_boxes(tmp_path, capsys):
    """q = (15, 13, 10) lies on g(S) (a double root): the claim says "not complete" and verifies as such;
    declaring it complete is refused, since the checker cannot isolate the double root."""
    g = load_geometry(DATA / "concurrent_legs.toml")
    res = solve(g, [Fraction(15), Fraction(13), Fraction(10)])
    assert not res.complete
    write_certificates(tmp_path, g, dkp_results=[res])
    (r,) = checker.verify_directory(tmp_path)
    assert r.verified and "completeness not claimed" in r.message
    doc = _load(tmp_path, "dkp.json")
    assert doc["claims"][0]["complete"] is False and "b3 = [5, -10]" in doc["geometry_toml"]
    doc["claims"][0].update(complete=True, phi0=0.0)
    _save(tmp_path, "dkp.json", doc)
    line = _refused(tmp_path, capsys, "dkp.json", "q-0")
    assert "isolated" in line or "real roots" in line or "leading coefficient" in line


def test_files_written_atomically_and_index_last(cert_dir):
    index = _load(cert_dir, "index.json")
    assert index["format"] == "intervalkin-certificate" and index["version"] == 1
    assert sorted(index["files"]) == sorted(f"{k}.json" for k in checker.KINDS)
    assert not list(cert_dir.glob(".*.tmp"))
    for name in index["files"]:
        doc = _load(cert_dir, name)
        assert doc["geometry_toml"] == index["geometry_toml"]


def test_sample_indices_reproducible_and_distinct():
    a = checker.sample_indices(3, 1000, 50)
    assert a == checker.sample_indices(3, 1000, 50)
    assert len(set(a)) == 50 and all(0 <= i < 1000 for i in a)
    assert checker.sample_indices(4, 1000, 50) != a
    assert sorted(checker.sample_indices(0, 5, 10)) == [0, 1, 2, 3, 4]


def test_reduced_sextic_agrees_with_the_solver_derivation(paper_geometry, rng):
    """The checker's real-polynomial derivation and dkp's Laurent one give overlapping coefficients."""
    for _ in range(5):
        rho = [Fraction(int(rng.integers(1000, 3200)), 100) for _ in range(3)]
        for phi0 in (0.0, round(math.pi / 6, 6)):
            with ctx.workprec(128):
                rs = [_q(r * r) for r in rho]
                mine = _reduced_sextic(_Model(paper_geometry), rs, phi0)
                theirs = sextic_coefficients(reduction(paper_geometry, rs), phi0)
            assert all(a.overlaps(b) for a, b in zip(mine, theirs))


def test_checker_root_count_agrees_with_float_solver(paper_geometry, rng):
    """The checker's certified count against an independent float solver that samples phi densely."""
    done = 0
    while done < 12:
        rho = [Fraction(int(rng.integers(1000, 3200)), 100) for _ in range(3)]
        with ctx.workprec(128):
            rs = [_q(r * r) for r in rho]
            try:
                n = _count_solutions(_Model(paper_geometry), rs, 0.0, 512)
            except _Refused:
                continue
        assert n == len(approx_solve(paper_geometry, [float(r) for r in rho]))
        done += 1


def test_checker_det_formula_is_the_jacobian_determinant(paper_geometry, rng):
    """The checker's short det A formula against the determinant of its own Jacobian rows, at points."""
    from flint import arb, arb_mat

    with ctx.workprec(128):
        model = _Model(paper_geometry)
        for _ in range(50):
            x, y, phi = (arb(float(v)) for v in rng.uniform([-30, -30, -math.pi], [30, 30, math.pi]))
            assert model.det(x, y, phi).overlaps(arb_mat(model.jacobian(x, y, phi)).det())


def test_disjointness_reads_phi_modulo_two_pi():
    a = ((0.0, 1.0), (0.0, 1.0), (3.1, 3.14))
    b = ((0.5, 1.5), (0.5, 1.5), (-3.18, -3.15))  # 3.1 .. 3.14 and 3.103 .. 3.133 overlap mod 2 pi
    c = ((0.5, 1.5), (0.5, 1.5), (-3.0, -2.9))
    assert not _disjoint_mod_2pi(a, b)
    assert _disjoint_mod_2pi(a, c)
    assert _disjoint_mod_2pi(a, ((1.5, 2.0), (0.0, 1.0), (3.1, 3.14)))


def test_box_label_refused_when_false(paper_geometry, cert_dir):
    """box_label_proved re-proves true labels and refuses false ones: a paving box of a region claim is
    proved inside W and not outside it; a box around A1 (rho_1 < 10) is proved outside W and not inside;
    BOUNDARY claims nothing (None).  Would catch a checker that proves whatever label it is given."""
    doc = _load(cert_dir, "region_distinct.json")
    b = doc["claims"][0]["solutions"][0]["paving_box"]["box"]
    assert checker.box_label_proved(paper_geometry, b, "W", 2)
    assert checker.box_label_proved(paper_geometry, b, "W", 1) is False
    wide = [[-2.0, 2.0], [-2.0, 2.0], [-3.0, 3.0]]  # around A1: rho_1 < 10, outside W
    assert checker.box_label_proved(paper_geometry, wide, "W", 1)
    assert checker.box_label_proved(paper_geometry, wide, "W", 2) is False
    assert checker.box_label_proved(paper_geometry, wide, "det_positive", 3) is None


# --------------------------------------------------------------------------------------
# Tampering: each change must be refused (FAILED, exit status 1)
# --------------------------------------------------------------------------------------
def _bump_digit(text: str) -> str:
    """Change the last digit of an exact decimal (or of the numerator of "p/q") by +1 (9 -> 8)."""
    head, sep, den = text.partition("/")
    d = int(head[-1])
    return head[:-1] + str(d + 1 if d < 9 else d - 1) + sep + den


def test_tamper_witness_digit_of_joint_cell(cert_dir, tmp_path, capsys):
    d = _copy(cert_dir, tmp_path)
    doc = _load(d, "joint_cell.json")
    claim = next(c for c in doc["claims"] if c["count"] > 0)
    claim["witness"][0] = _bump_digit(claim["witness"][0])
    _save(d, "joint_cell.json", doc)
    line = _refused(d, capsys, "joint_cell.json", claim["id"])
    assert "Krawczyk" in line or "real roots" in line


def test_tamper_witness_digit_of_region_claim(cert_dir, tmp_path, capsys):
    d = _copy(cert_dir, tmp_path)
    doc = _load(d, "region_distinct.json")
    doc["claims"][0]["rho"][2] = _bump_digit(doc["claims"][0]["rho"][2])
    _save(d, "region_distinct.json", doc)
    assert "Krawczyk" in _refused(d, capsys, "region_distinct.json", doc["claims"][0]["id"])


def test_tamper_dkp_joint_vector_digit(cert_dir, tmp_path, capsys):
    d = _copy(cert_dir, tmp_path)
    doc = _load(d, "dkp.json")
    doc["claims"][0]["rho"][1] = "15.39"
    _save(d, "dkp.json", doc)
    _refused(d, capsys, "dkp.json", "q-0")


def test_tamper_box_bound_moved_off_the_solution(cert_dir, tmp_path, capsys):
    d = _copy(cert_dir, tmp_path)
    doc = _load(d, "dkp.json")
    lo, hi = doc["claims"][0]["solutions"][2]["box"][0]
    doc["claims"][0]["solutions"][2]["box"][0][1] = lo + (hi - lo) / 4  # the upper x bound only
    _save(d, "dkp.json", doc)
    assert "Krawczyk" in _refused(d, capsys, "dkp.json", "q-0")


def test_tamper_box_bound_digit_makes_it_empty(cert_dir, tmp_path, capsys):
    d = _copy(cert_dir, tmp_path)
    doc = _load(d, "dkp.json")
    box = doc["claims"][0]["solutions"][0]["box"]
    s = repr(box[1][0])
    k = s.index(".") + 1  # first decimal digit: moves the bound by 0.1, past the other one
    up = box[1][0] >= 0
    box[1][0] = float(s[:k] + str((int(s[k]) + 1) % 10 if up else (int(s[k]) - 1) % 10) + s[k + 1:])
    _save(d, "dkp.json", doc)
    assert "empty interval" in _refused(d, capsys, "dkp.json", "q-0")


def test_tamper_paving_box_bound(cert_dir, tmp_path, capsys):
    d = _copy(cert_dir, tmp_path)
    doc = _load(d, "region_distinct.json")
    sol = doc["claims"][0]["solutions"][0]
    sol["paving_box"]["box"][2][0] = sol["box"][2][1]  # the paving box no longer holds the solution box
    _save(d, "region_distinct.json", doc)
    assert "not inside the stated paving box" in _refused(d, capsys, "region_distinct.json", doc["claims"][0]["id"])


@pytest.mark.parametrize("name, bump", [("aspects", 1), ("basic_regions", None), ("uniqueness_domains", 1)])
def test_tamper_declared_count(cert_dir, tmp_path, capsys, name, bump):
    d = _copy(cert_dir, tmp_path)
    doc = _load(d, "counts.json")
    claim = next(c for c in doc["claims"] if c["name"] == name)
    # just above what the evidence supports (12 basic regions: 2 + 4 + 6 solutions of the three splits)
    claim["lower_bound"] = (claim["lower_bound"] + bump) if bump else 13
    _save(d, "counts.json", doc)
    assert "exceeds" in _refused(d, capsys, "counts.json", name)


def test_tamper_joint_cell_count_and_exact_claim(cert_dir, tmp_path, capsys):
    d = _copy(cert_dir, tmp_path)
    doc = _load(d, "joint_cell.json")
    claim = next(c for c in doc["claims"] if c["count"] == 4)
    claim["count"] = 6
    _save(d, "joint_cell.json", doc)
    counts = _load(d, "counts.json")
    counts["claims"][1]["exact"] = True
    _save(d, "counts.json", counts)
    assert "declared count" in _refused(d, capsys, "joint_cell.json", claim["id"])
    assert "upper bound" in _refused(d, capsys, "counts.json", counts["claims"][1]["id"])


def test_tamper_det_sign(cert_dir, tmp_path, capsys):
    d = _copy(cert_dir, tmp_path)
    doc = _load(d, "dkp.json")
    s = doc["claims"][0]["solutions"][1]
    s["det_sign"] = -s["det_sign"]
    _save(d, "dkp.json", doc)
    assert "det A is not proved" in _refused(d, capsys, "dkp.json", "q-0")


def test_tamper_aspect_and_box_label(cert_dir, tmp_path, capsys):
    d = _copy(cert_dir, tmp_path)
    doc = _load(d, "aspect_distinct.json")
    doc["claims"][0]["boxes"][0]["aspect"] = "WA2"
    _save(d, "aspect_distinct.json", doc)
    labels = _load(d, "box_labels.json")
    item = next(b for b in labels["claims"][0]["boxes"] if b["labels"]["W"] in (1, 2))
    item["labels"]["W"] = 3 - item["labels"]["W"]  # INSIDE <-> OUTSIDE
    _save(d, "box_labels.json", labels)
    _refused(d, capsys, "aspect_distinct.json", "aspects")
    assert f"box index {item['index']}" in _refused(d, capsys, "box_labels.json", "sample")


def test_tamper_hand_picked_sample(cert_dir, tmp_path, capsys):
    d = _copy(cert_dir, tmp_path)
    doc = _load(d, "box_labels.json")
    doc["claims"][0]["boxes"][0]["index"] += 1
    _save(d, "box_labels.json", doc)
    assert "seed" in _refused(d, capsys, "box_labels.json", "sample")


def test_tamper_geometry_decimal_everywhere(cert_dir, tmp_path, capsys):
    """A2 = (15.91, 0) -> (15.92, 0) in every file: the solutions no longer solve, counts lose support."""
    d = _copy(cert_dir, tmp_path)
    for f in d.glob("*.json"):
        text = f.read_text()
        assert "15.91" in text
        f.write_text(text.replace("15.91", "15.92"))
    bad = {(r.file, r.claim) for r in _failed(d)}
    assert ("dkp.json", "q-0") in bad and ("counts.json", "basic_regions") in bad
    assert all(("joint_cell.json", c["id"]) in bad for c in _load(d, "joint_cell.json")["claims"] if c["count"] > 0)
    assert main(["verify", str(d)]) == 2
    capsys.readouterr()


def test_tamper_geometry_decimal_in_one_file(cert_dir, tmp_path, capsys):
    d = _copy(cert_dir, tmp_path)
    doc = _load(d, "box_labels.json")
    doc["geometry_toml"] = doc["geometry_toml"].replace("15.91", "15.92")
    _save(d, "box_labels.json", doc)
    assert "geometry differs" in _refused(d, capsys, "box_labels.json", "sample")


def test_tamper_dropped_solution_breaks_completeness(cert_dir, tmp_path, capsys):
    d = _copy(cert_dir, tmp_path)
    doc = _load(d, "dkp.json")
    doc["claims"][0]["solutions"].pop()
    doc["claims"][0]["count"] = 5
    _save(d, "dkp.json", doc)
    assert "6 real roots but 5 solution boxes" in _refused(d, capsys, "dkp.json", "q-0")


# --------------------------------------------------------------------------------------
# Malformed folders: one-line error, exit status 2
# --------------------------------------------------------------------------------------
def test_malformed_folders(cert_dir, tmp_path, capsys):
    assert main(["verify", str(tmp_path / "nowhere")]) == 2
    d = _copy(cert_dir, tmp_path)
    (d / "index.json").write_text("{not json")
    assert main(["verify", str(d)]) == 2
    index = _load(cert_dir, "index.json")
    _save(d, "index.json", dict(index, version=2))
    assert main(["verify", str(d)]) == 2
    _save(d, "index.json", dict(index, files=index["files"] + ["missing.json"]))
    assert main(["verify", str(d)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 4 and all(ln.startswith("intervalkin: error: ") for ln in err)
    with pytest.raises(checker.CertificateFormatError):
        checker.verify_directory(d)


def test_bad_sample_size_refused(tmp_path, paper_geometry):
    from intervalkin.core.errors import InputError

    with pytest.raises(InputError, match="box_sample"):
        write_certificates(tmp_path, paper_geometry, box_sample=-1)


# --------------------------------------------------------------------------------------
# Independence: the checker runs without the code it checks
# --------------------------------------------------------------------------------------
def test_checker_imports_none_of_the_checked_modules(checked):
    assert checked["lines"] and checked["modules"] == [], checked["modules"]


# --------------------------------------------------------------------------------------
# Trajectories: the certified motion re-proved from the file
# --------------------------------------------------------------------------------------
def test_trajectory_claims_verify_and_copy_the_segment_certificate(cert_dir, paths, paper_geometry):
    claims = {c["id"]: c for c in _load(cert_dir, "trajectory.json")["claims"]}
    assert sorted(claims) == ["2-3", "3-6"] and all(tr.certified for tr in paths)
    for tr in paths:
        c = claims[f"{tr.i_from}-{tr.i_to}"]
        cert = tr.certificate()
        assert [{k: s[k] for k in ("start", "end", "pieces")} for s in cert["segments"]] == c["segments"]
        assert c["rho"] == ["14.98", "15.38", "12"] and c["aspect"] == "WA1" and c["phi_turns"] == tr.phi_turns
    assert claims["3-6"]["phi_turns"] == -1  # the goal is reached across the seam
    # the two claims alone (the whole folder is re-proved once, by test_every_claim_of_the_chain_verifies)
    precision = _load(cert_dir, "trajectory.json")["precision"]
    results = [checker.check_claim(paper_geometry, "trajectory", c, precision) for c in claims.values()]
    assert len(results) == 2 and all(ok for ok, _ in results), results
    assert all("keeps det A > 0 and 10 <= rho_1 <= 32" in msg for _, msg in results)


def test_uncertified_trajectory_is_omitted(tmp_path, paper_geometry, paths):
    import dataclasses

    bad = dataclasses.replace(paths[0], certified=False, reason="test")
    write_certificates(tmp_path, paper_geometry, trajectories=[bad, paths[1]])
    assert [c["id"] for c in _load(tmp_path, "trajectory.json")["claims"]] == ["3-6"]
    assert _load(tmp_path, "index.json")["omitted"][0]["what"] == "trajectory 2-3"


def _set_end(claim: dict, k: int, coord: int, value: float) -> None:
    """Move the end point shared by segments k and k + 1 (and its waypoint) consistently."""
    h = value.hex()
    claim["segments"][k]["end"][coord] = [h, h]
    claim["segments"][k + 1]["start"][coord] = [h, h]
    claim["waypoints"][k + 1][coord] = h


def _tamper_waypoint_phi(c):  # turns the platform by 1.5 rad: det A changes sign on segment 1
    _set_end(c, 0, 2, float.fromhex(c["segments"][0]["end"][2][0]) + 1.5)


def _tamper_waypoint_x(c):  # 30 length units away: the legs leave [10, 32]
    _set_end(c, 0, 0, float.fromhex(c["segments"][0]["end"][0][0]) + 30.0)


def _tamper_discontinuous(c):  # segment 2 starts 1e-9 away from where segment 1 ends
    v = float.fromhex(c["segments"][1]["start"][1][0]) + 1e-9
    c["segments"][1]["start"][1] = [v.hex(), v.hex()]


def _tamper_piece_boundary(c):  # a gap in the pieces of the segment with the most pieces
    seg = max(c["segments"], key=lambda s: len(s["pieces"]))
    assert len(seg["pieces"]) > 1
    seg["pieces"][0][1] = (float.fromhex(seg["pieces"][0][1]) * 0.75).hex()


def _tamper_last_piece(c):  # the pieces stop short of t = 1
    c["segments"][-1]["pieces"][-1][1] = (0.875).hex()


def _tamper_aspect(c):
    c["aspect"], c["det_sign"] = "WA2", -1


def _tamper_det_sign(c):
    c["det_sign"] = -1


def _tamper_joint_vector(c):
    c["rho"][1] = _bump_digit(c["rho"][1])


def _tamper_solution_number(c):
    c["from"] = 1


def _tamper_phi_turns(c):
    c["phi_turns"] += 1


@pytest.mark.parametrize("tamper, why", [
    (_tamper_waypoint_phi, "piece"),
    (_tamper_waypoint_x, "a leg proved beyond its limit"),
    (_tamper_discontinuous, "not continuous"),
    (_tamper_piece_boundary, "do not tile [0, 1]"),
    (_tamper_last_piece, "do not tile [0, 1]"),
    (_tamper_aspect, "det A is not proved < 0"),
    (_tamper_det_sign, "det_sign"),
    (_tamper_joint_vector, "Krawczyk"),
    (_tamper_solution_number, "not inside the box of solution 1"),
    (_tamper_phi_turns, "goal_box"),
])
def test_tamper_trajectory(cert_dir, tmp_path, capsys, tamper, why):
    d = _copy(cert_dir, tmp_path)
    doc = _load(d, "trajectory.json")
    tamper(doc["claims"][0])
    _save(d, "trajectory.json", doc)
    line = _refused(d, capsys, "trajectory.json", doc["claims"][0]["id"])
    assert why in line, line
