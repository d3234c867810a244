"""The independent checker itself (src/intervalkin/checker/): what it reads, its arb model, its proofs.

The tamper tests in tests/certify/test_certificates.py change honest files and expect a refusal;
this file tests the checker's parts one by one:

* parsing: exact numbers (never a binary float for a joint vector), boxes, hex floats;
* its own arb model of the manipulator, against the package's arb formulas at random
  points of three geometries (two independent derivations must agree to 1e-25), and
  as an enclosure over boxes;
* its Krawczyk test and its certified root count, on joint vectors with 0, 2, 4 and 6
  solutions, a double root, boxes holding none or two solutions;
* malformed folders (a format error, status 2) and malformed claims (a FAILED line,
  never an exception).
"""

from __future__ import annotations

import json
import math
from fractions import Fraction

import numpy as np
import pytest
from flint import arb, ctx

from intervalkin import checker
from intervalkin.app.cli import main
from intervalkin.certify.writer import write_certificates
from intervalkin.checker.model import ArbModel as _Model
from intervalkin.checker.model import balls as _balls
from intervalkin.checker.parse import Refused as _Refused
from intervalkin.checker.parse import parse_exact
from intervalkin.checker.parse import read_box as _box
from intervalkin.checker.parse import read_hex_box as _hex_box
from intervalkin.checker.solutions import count_solutions as _count_solutions
from intervalkin.checker.solutions import krawczyk_unique as _krawczyk
from intervalkin.core.geometry import load_geometry
from intervalkin.kinematics.formulas import det_a_arb, jacobian_arb, residual_arb, rho_sq_arb
from intervalkin.solve.dkp import solve

from ..conftest import DATA

TABLE1 = (Fraction("14.98"), Fraction("15.38"), Fraction(12))
#: Joint vectors of the paper's manipulator with 0, 2, 4 and 6 solutions (witnesses of certified cells).
KNOWN = {
    0: (Fraction(193, 16), Fraction(501, 16), Fraction(171, 16)),
    2: (Fraction(223, 8), Fraction(135, 8), Fraction(245, 8)),
    4: (Fraction(347, 16), Fraction(391, 16), Fraction(435, 16)),
    6: TABLE1,
}


def _geometries(paper_geometry):
    return [paper_geometry, load_geometry(DATA / "offset_right.toml"), load_geometry(DATA / "coords_platform.toml")]


# --------------------------------------------------------------------------------------
# Exact numbers and boxes
# --------------------------------------------------------------------------------------
@pytest.mark.parametrize("text, value", [
    ("14.98", Fraction(1498, 100)),
    ("0.1", Fraction(1, 10)),  # not the binary64 number nearest 0.1
    ("1498/100", Fraction(1498, 100)),
    (" 12 ", Fraction(12)),
    ("-0.5", Fraction(-1, 2)),
    ("1e-3", Fraction(1, 1000)),
    ("15.380000000000000000001", Fraction(15380000000000000000001, 10**21)),
])
def test_parse_exact_reads_decimals_and_fractions_exactly(text, value):
    """Decimal and "p/q" strings become the exact rational: a rounded reading would certify another q."""
    assert parse_exact(text) == value


@pytest.mark.parametrize("bad", [14.98, 12, True, None, ["1"], "nan", "inf", "-Infinity", "1/0", "abc", "",
                                 "1.2.3", "0x10", "1/2/3"])
def test_parse_exact_refuses_everything_else(bad):
    """JSON numbers (already rounded to binary64), non-finite and malformed strings are refused, naming the field."""
    with pytest.raises(_Refused, match="rho\\[1\\]"):
        parse_exact(bad, "rho[1]")


def test_box_parsing_accepts_exactly_three_ordered_pairs():
    """A box is three [lo, hi] pairs of finite numbers with lo <= hi; the values are kept bit for bit."""
    b = _box([[0.1, 0.2], [-3, -3], [1e-300, 2.5]])
    assert b == ((0.1, 0.2), (-3.0, -3.0), (1e-300, 2.5))
    for bad, why in [
        ("box", "expected"),
        ([[0, 1], [0, 1]], "expected"),
        ([[0, 1], [0, 1], [0, 1], [0, 1]], "expected"),
        ([[0, 1], [0, 1, 2], [0, 1]], "expected \\[lo, hi\\]"),
        ([[0, 1], [0, 1], [2, 1]], "empty interval"),
        ([[0, 1], [0, 1], [0, float("nan")]], "not finite"),
        ([[0, 1], [float("-inf"), 1], [0, 1]], "not finite"),
        ([[0, 1], [0, 1], [False, 1]], "expected a number"),
        ([[0, 1], [0, 1], ["0", 1]], "expected a number"),
        ([[0, 1], [0, 1], [None, 1]], "expected a number"),
    ]:
        with pytest.raises(_Refused, match=why):
            _box(bad)


def test_hex_boxes_round_trip_exactly():
    """Hex float strings (float.hex) are read back to the same binary64 numbers; anything else is refused."""
    rng = np.random.default_rng(3)
    vals = np.sort(rng.normal(scale=20, size=(3, 2)), axis=1)
    text = [[float(lo).hex(), float(hi).hex()] for lo, hi in vals]
    assert _hex_box(text, "end") == tuple((float(lo), float(hi)) for lo, hi in vals)
    for bad, why in [
        ([[1.0, 2.0]] * 3, "hex float"),
        ([["0x1p+0", "zz"]] * 3, "not a hex float"),
        ([["0x1p+0", "inf"]] * 3, "not finite"),
        ([["0x1p+1", "0x1p+0"]] * 3, "empty interval"),
    ]:
        with pytest.raises(_Refused, match=why):
            _hex_box(bad, "end")


def test_hex_box_refuses_decimal_looking_strings():
    """A bound written "1.5" is not a hex float as float.hex writes it ("0x1.8000000000000p+0"): refused.

    float.fromhex alone would read "1.5" as 0x1.5 = 1.3125, silently reinterpreting a
    hand-edited file.  Signed hex strings and exponents past binary64 are covered too.
    """
    with pytest.raises(_Refused, match="not a hex float"):
        _hex_box([["1.5", "2.5"]] * 3, "end")
    for bad in ["15", " 0x1p+0", "-1.5p+0"]:
        with pytest.raises(_Refused, match="not a hex float"):
            _hex_box([[bad, "0x1p+4"]] * 3, "end")
    with pytest.raises(_Refused, match="not finite"):
        _hex_box([["0x1p+0", "0x1p+99999"]] * 3, "end")
    assert _hex_box([["-0x1.8p+0", "+0x1p+0"]] * 3, "end") == ((-1.5, 1.0),) * 3


# --------------------------------------------------------------------------------------
# The checker's arb model against the package's arb formulas
# --------------------------------------------------------------------------------------
def _close(a, b, tol=1e-25) -> bool:
    """Both balls tight and overlapping: two derivations of one exact number agree."""
    scale = 1.0 + abs(float(a.mid()))
    return a.overlaps(b) and float(a.rad()) < tol * scale and float(b.rad()) < tol * scale


def test_model_formulas_equal_the_package_formulas_at_random_points(paper_geometry):
    """rho_i^2, det A, F and the Jacobian: the checker's model and intervalkin.kinematics agree at 128 bits.

    Three geometries (paper, B3 on the right, platform by coordinates), 60 random poses
    each.  Would catch a sign or index slip in either derivation (the checker's det A
    is a short closed form; the package's is written differently), a mirrored B3, or a
    base point read with rounding.
    """
    rng = np.random.default_rng(21)
    with ctx.workprec(128):
        for g in _geometries(paper_geometry):
            model = _Model(g)
            rho_sq = [arb(v) for v in (200, 300, 400)]
            for _ in range(60):
                x, y, phi = (arb(float(v)) for v in rng.uniform([-30, -30, -math.pi], [30, 30, math.pi]))
                assert all(_close(a, b) for a, b in zip(model.rho_sq(x, y, phi), rho_sq_arb(g, x, y, phi)))
                assert _close(model.det(x, y, phi), det_a_arb(g, x, y, phi), 1e-22)
                assert all(_close(a, b) for a, b in zip(model.residual(x, y, phi, rho_sq),
                                                        residual_arb(g, x, y, phi, rho_sq)))
                for ra, rb in zip(model.jacobian(x, y, phi), jacobian_arb(g, x, y, phi)):
                    assert all(_close(a, b) for a, b in zip(ra, rb))


def test_model_encloses_the_formulas_over_boxes(paper_geometry):
    """Over a box (balls of width up to 2 and 0.3 rad), the model's rho_i^2 and det A hold the values
    at random points of the box (package formulas at 128 bits).

    Would catch a model that is only right at points, e.g. a polar form with the wrong
    angle offset, or a square of a ball straddling 0 taken with the wrong sign.
    """
    rng = np.random.default_rng(22)
    with ctx.workprec(128):
        model = _Model(paper_geometry)
        for _ in range(40):
            c = rng.uniform([-25, -25, -3], [25, 25, 3])
            w = rng.uniform([0.01, 0.01, 0.001], [2.0, 2.0, 0.3])
            box = tuple((float(a - b), float(a + b)) for a, b in zip(c, w / 2))
            balls = _balls(box)
            r_box, d_box = model.rho_sq(*balls), model.det(*balls)
            for _ in range(10):
                p = [arb(float(lo + rng.uniform() * (hi - lo))) for lo, hi in box]
                assert all(rb.contains(v) for rb, v in zip(r_box, rho_sq_arb(paper_geometry, *p)))
                assert d_box.contains(det_a_arb(paper_geometry, *p))
        # a ball straddling 0 squares to a ball holding 0, not a negative range
        r = model.rho_sq(arb(-0.5).union(arb(0.5)), arb(-0.5).union(arb(0.5)), arb(0))[0]
        assert r.contains(0) and r.lower() > -1e-6 and r.upper() < 0.51


# --------------------------------------------------------------------------------------
# Krawczyk and the certified root count on known joint vectors
# --------------------------------------------------------------------------------------
def _pad(box, d: float = 1e-9):
    return tuple((float(lo) - d, float(hi) + d) for lo, hi in np.asarray(box))


@pytest.mark.parametrize("n", sorted(KNOWN))
def test_root_count_and_krawczyk_on_known_joint_vectors(paper_geometry, n):
    """The checker counts exactly n solutions, proves each solver box by Krawczyk, and accepts the claim.

    Would catch a root count that misses complex-conjugate pairs or counts them as real,
    a sextic built with a wrong rho, or a Krawczyk test weaker than strict inclusion.
    """
    rho = KNOWN[n]
    res = solve(paper_geometry, rho)
    assert res.complete and res.count == n
    with ctx.workprec(128):
        model = _Model(paper_geometry)
        rs = [arb(r.numerator) / r.denominator for r in (v * v for v in rho)]
        assert _count_solutions(model, rs, 0.0, 512) == n
        for s in res.solutions:
            assert _krawczyk(model, _pad(s.box), rs)
    claim = {"id": "q", "rho": [str(v) for v in rho], "complete": True, "phi0": 0.0, "count": n,
             "solutions": [{"box": [list(b) for b in _pad(s.box)], "det_sign": s.det_sign} for s in res.solutions]}
    ok, msg = checker.check_claim(paper_geometry, "dkp", claim)
    assert ok, msg
    assert f"exactly {n} solutions" in msg
    if n:
        fewer = dict(claim, solutions=claim["solutions"][1:], count=n - 1)
        ok, msg = checker.check_claim(paper_geometry, "dkp", fewer)
        assert not ok and f"{n} real roots but {n - 1}" in msg
        twice = dict(claim, solutions=claim["solutions"] + claim["solutions"][:1], count=n + 1)
        ok, msg = checker.check_claim(paper_geometry, "dkp", twice)
        assert not ok and "not proved disjoint" in msg


def test_krawczyk_refuses_boxes_with_no_solution_or_two(paper_geometry):
    """Boxes beside a solution (every side), and a box holding two solutions, are not proved.

    Would catch an interior test in only some coordinates, or a Jacobian taken at the
    midpoint instead of enclosed over the box.
    """
    res = solve(paper_geometry, TABLE1)
    with ctx.workprec(128):
        model = _Model(paper_geometry)
        rs = [arb(r.numerator) / r.denominator for r in (v * v for v in TABLE1)]
        for s in res.solutions:
            r = np.array([1e-3, 1e-3, 1e-4])
            assert _krawczyk(model, tuple(zip(s.midpoint - r, s.midpoint + r)), rs)
            for j in range(3):
                for sign in (-1, 1):
                    c = s.midpoint.copy()
                    c[j] += sign * 2 * r[j]
                    assert not _krawczyk(model, tuple(zip(c - r, c + r)), rs)
        # a box centred on one solution and wide enough to hold a second one
        for i, j in ((1, 2), (2, 3), (3, 4)):
            a, b = res.solutions[i].midpoint, res.solutions[j].midpoint
            r = 1.1 * np.abs(b - a)
            assert not _krawczyk(model, tuple(zip(a - r, a + r)), rs)


def test_double_root_is_refused_not_counted():
    """q = (15, 13, 10) on g(S) of the concurrent-legs manipulator: a double root; the count is refused."""
    g = load_geometry(DATA / "concurrent_legs.toml")
    with ctx.workprec(128):
        rs = [arb(v * v) for v in (15, 13, 10)]
        with pytest.raises(_Refused):
            _count_solutions(_Model(g), rs, 0.0, 512)


# --------------------------------------------------------------------------------------
# Malformed folders and claims
# --------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def honest(tmp_path_factory, paper_geometry):
    """A small certificate folder: the Table 1 solve alone."""
    out = tmp_path_factory.mktemp("honest")
    write_certificates(out, paper_geometry, dkp_results=[solve(paper_geometry, TABLE1)])
    assert all(r.verified for r in checker.verify_directory(out))
    return out


def _folder(src, tmp_path, edit_index=None, edit_dkp=None, raw=None):
    import shutil

    d = tmp_path / "f"
    shutil.copytree(src, d)
    if edit_index is not None:
        doc = json.loads((d / "index.json").read_text())
        (d / "index.json").write_text(json.dumps(edit_index(doc)))
    if edit_dkp is not None:
        doc = json.loads((d / "dkp.json").read_text())
        (d / "dkp.json").write_text(json.dumps(edit_dkp(doc)))
    for name, data in (raw or {}).items():
        (d / name).write_bytes(data)
    return d


def _set(doc, **kw):
    doc.update(kw)
    return doc


@pytest.mark.parametrize("case", [
    dict(raw={"index.json": b"[1, 2]"}),
    dict(raw={"index.json": b"\xff\xfe not text"}),
    dict(edit_index=lambda d: _set(d, format="something-else")),
    dict(edit_index=lambda d: _set(d, kind="dkp")),
    dict(edit_index=lambda d: _set(d, files="dkp.json")),
    dict(edit_index=lambda d: _set(d, files=["../dkp.json"])),
    dict(edit_index=lambda d: _set(d, files=[])),
    dict(edit_dkp=lambda d: _set(d, kind="unknown")),
    dict(edit_dkp=lambda d: _set(d, claims={"id": "q-0"})),
    dict(edit_dkp=lambda d: _set(d, claims=[d["claims"][0], d["claims"][0]])),
    dict(edit_dkp=lambda d: _set(d, claims=[dict(d["claims"][0], id=7)])),
], ids=["index-list", "index-binary", "format", "index-kind", "files-string", "files-path", "no-claims",
        "claim-kind", "claims-object", "duplicate-ids", "id-number"])
def test_malformed_folder_is_a_format_error(honest, tmp_path, capsys, case):
    """A folder that is not in the documented format: CertificateFormatError, and status 2 with one line.

    Would catch a checker that reads files outside the folder ("../"), crashes on a
    list where an object is expected, or "verifies" a folder with nothing in it.
    """
    d = _folder(honest, tmp_path, **case)
    with pytest.raises(checker.CertificateFormatError):
        checker.verify_directory(d)
    assert main(["verify", str(d)]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and err.startswith("intervalkin: error: ")


def _edit_claim(**kw):
    def edit(doc):
        doc["claims"][0].update(kw)
        return doc
    return edit


def _edit_solution(**kw):
    def edit(doc):
        doc["claims"][0]["solutions"][0].update(kw)
        return doc
    return edit


@pytest.mark.parametrize("edit, why", [
    (_edit_claim(rho=[14.98, 15.38, 12]), "exact string"),
    (_edit_claim(rho=["14.98", "15.38"]), "three exact strings"),
    (_edit_claim(rho=["14.98", "-15.38", "12"]), "positive"),
    (_edit_claim(complete="yes"), "true or false"),
    (_edit_claim(solutions={"box": []}), "expected a list"),
    (_edit_claim(precision=10), "precision"),
    (_edit_claim(precision=1 << 20), "precision"),
    (_edit_claim(phi0="zero"), "phi0"),
    (_edit_solution(box=[[0, 1], [0, 1]]), "expected"),
    (_edit_solution(det_sign=0), "det_sign"),
    (_edit_solution(box=[[-6, -5], [-14, -13], [-0.5, 0.7]]), "phi width"),
    (lambda d: _set(d, geometry_toml="name = ["), "geometry differs"),
], ids=["rho-floats", "rho-short", "rho-negative", "complete-str", "solutions-object", "prec-low", "prec-high",
        "phi0-str", "box-short", "sign-zero", "phi-wide", "geometry"])
def test_malformed_claim_is_a_failed_line_not_a_crash(honest, tmp_path, capsys, edit, why):
    """A claim with a malformed field is FAILED with the reason; the checker does not raise.

    The command exits 2 (the certificates given are bad input), with the verdicts on
    stdout and one error line on stderr.
    """
    d = _folder(honest, tmp_path, edit_dkp=edit)
    (r,) = checker.verify_directory(d)
    assert not r.verified and why in r.message, r.message
    assert main(["verify", str(d)]) == 2
    out, err = capsys.readouterr()
    assert out.startswith("FAILED: dkp.json#q-0 (dkp) because ")
    assert err.count("\n") == 1 and err.startswith("intervalkin: error: 0 of 1 claims verified")


def test_malformed_geometry_toml_fails_each_claim(honest, tmp_path):
    """A geometry TOML that is malformed in index.json and every file: each claim FAILED as malformed TOML."""
    d = _folder(honest, tmp_path, edit_index=lambda doc: _set(doc, geometry_toml="name = ["),
                edit_dkp=lambda doc: _set(doc, geometry_toml="name = ["))
    (r,) = checker.verify_directory(d)
    assert not r.verified and "malformed TOML" in r.message
