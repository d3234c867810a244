"""Counts that agree with their certificates: verify fails on a count below what the claims prove,
and on a summary.json that contradicts the certificates beside it."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from intervalkin import checker
from intervalkin.app.cli import main
from intervalkin.checker.consistency import check_found, check_summary_block, read_summary
from intervalkin.checker.parse import Refused

CLAIM = {"name": "basic_regions", "lower_bound": 12, "found": 24, "exact": False}
BLOCK = {"count": 24, "exact": False, "lower_bound": 12, "upper_bound": None, "why": "..."}


def test_a_found_count_below_the_proved_bound_is_refused():
    check_found("basic_regions", 12, 12)
    check_found("basic_regions", None, 12)  # older files carry no found count: nothing to compare
    with pytest.raises(Refused, match="found 11 basic regions, below the 12 that the verified claims prove"):
        check_found("basic_regions", 11, 12)


@pytest.mark.parametrize("edit, why", [
    ({"count": 23}, "count 23 but the claim says 24 found"),
    ({"lower_bound": 10}, "lower_bound 10 but the claim declares 12"),
    ({"count": 11, "lower_bound": 12}, "count 11 below its own lower_bound 12"),
    ({"upper_bound": 20}, "upper_bound 20 below the count 24"),
    ({"exact": True}, "exact is True"),
    ({"count": "24"}, "expected a non-negative integer"),
])
def test_summary_blocks_that_contradict_the_claim(edit, why):
    summary = {"complete": True, "basic_regions": {**BLOCK, **edit}}
    with pytest.raises(Refused, match="contradicts the certificates|expected a non-negative") as exc:
        check_summary_block("basic_regions", CLAIM, 12, summary)
    assert why in str(exc.value)


def test_summary_blocks_that_agree_or_cannot_be_compared():
    assert "agrees (count 24, lower bound 12)" in check_summary_block("basic_regions", CLAIM, 12,
                                                                      {"basic_regions": BLOCK})
    assert check_summary_block("basic_regions", CLAIM, 12, None) == ""
    assert "did not complete" in check_summary_block("basic_regions", CLAIM, 12, {"complete": False})
    with pytest.raises(Refused, match="count 24 below the 30"):
        check_summary_block("basic_regions", CLAIM, 30, {"basic_regions": BLOCK})
    with pytest.raises(Refused, match="no 'basic_regions' block"):
        check_summary_block("basic_regions", CLAIM, 12, {"complete": True})
    with pytest.raises(Refused, match="cannot be read"):
        check_summary_block("basic_regions", CLAIM, 12, {"unreadable": "summary.json cannot be read (x)"})


def test_a_lower_bound_raised_by_barriers_is_accepted_only_as_their_number():
    """The summary's basic-region bound may stand above the claim's only as barriers_at_least (which the recheck's
    barrier_bound verdict re-proves), with the claim's own bound beside it as counts_claim_lower."""
    raised = {**BLOCK, "lower_bound": 14, "barriers_at_least": 14, "counts_claim_lower": 12}
    text = check_summary_block("basic_regions", CLAIM, 12, {"basic_regions": raised})
    assert "lower bound 14: the claim's 12 raised by the count and pattern barriers" in text
    for edit, why in (({"lower_bound": 16}, "lower_bound 16 but the claim declares 12"),
                      ({"counts_claim_lower": 10}, "counts_claim_lower 10 is not the claim's lower_bound 12"),
                      ({"counts_claim_lower": None}, "is not the claim's lower_bound")):
        with pytest.raises(Refused, match="contradicts|counts_claim_lower") as exc:
            check_summary_block("basic_regions", CLAIM, 12, {"basic_regions": {**raised, **edit}})
        assert why in str(exc.value)
    # another count cannot borrow the basic regions' barriers
    with pytest.raises(Refused, match="lower_bound 14 but the claim declares 12"):
        check_summary_block("aspects", {**CLAIM, "name": "aspects"}, 12, {"aspects": raised})


def test_only_a_certificates_folder_reads_the_summary_beside_it(tmp_path):
    (tmp_path / "certificates").mkdir()
    (tmp_path / "summary.json").write_text('{"complete": true}')
    assert read_summary(tmp_path / "certificates") == {"complete": True}
    assert read_summary(tmp_path) is None  # a folder of another name: no summary is assumed
    (tmp_path / "summary.json").write_text("[1")
    assert "unreadable" in read_summary(tmp_path / "certificates")


# --------------------------------------------------------------------------------------
# A real output folder, then tampered copies of it
# --------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def output(analyze_depth4) -> Path:
    """``analyze --depth 4`` (the session's, tests/conftest.py): read only, tampered with in copies."""
    return analyze_depth4


def _copy(src: Path, tmp_path: Path) -> Path:
    """An honest copy to tamper with, without the aspect covers (aspect_connected.json): re-proving them
    costs about 8 s a verify, and tests/checker/test_aspects.py tampers with them.  The aspects count
    goes back to its lower bound, which aspect_distinct.json proves, in counts.json and in summary.json
    alike, so that the copy verifies in full until a test tampers with it (checked by
    :func:`_only_failure`); the basic regions and uniqueness domains keep their support."""
    d = tmp_path / "copy"
    shutil.copytree(src, d)
    certs = d / "certificates"
    index = json.loads((certs / "index.json").read_text())
    index["files"].remove("aspect_connected.json")
    (certs / "index.json").write_text(json.dumps(index))
    (certs / "aspect_connected.json").unlink()
    counts = json.loads((certs / "counts.json").read_text())
    for c in counts["claims"]:
        if c["name"] == "aspects":
            c.update(upper_bound=None, exact=False,
                     support=[r for r in c["support"] if not r.startswith("aspect_connected")])
    (certs / "counts.json").write_text(json.dumps(counts))
    s = json.loads((d / "summary.json").read_text())
    s["aspects"].update(upper_bound=None, exact=False)
    (d / "summary.json").write_text(json.dumps(s))
    return d


def _only_failure(folder: Path, claim: str) -> None:
    """Every claim of the tampered copy verifies but ``claim`` of counts.json."""
    failed = [(r.file, r.claim) for r in checker.verify_directory(folder / "certificates") if not r.verified]
    assert failed == [("counts.json", claim)], failed


def _counts_results(folder: Path) -> dict:
    return {r.claim: r for r in checker.verify_directory(folder / "certificates") if r.kind == "counts"}


def test_an_honest_output_folder_verifies_with_its_summary(output, capsys):
    assert main(["verify", str(output)]) == 0  # one run: every claim is re-proved once
    out, err = capsys.readouterr()
    assert err.endswith("claims verified\n")
    counts = [ln for ln in out.splitlines() if ln.startswith("verified: counts.json#")]
    assert sorted(ln.split("#", 1)[1].split(" ", 1)[0] for ln in counts) == ["aspects", "basic_regions",
                                                                             "uniqueness_domains"]
    assert all("summary.json agrees" in ln for ln in counts), counts


def test_a_summary_count_below_the_proof_fails_verify(output, tmp_path, capsys):
    """The user was shown fewer basic regions than the certificates prove: verify says so and exits 2."""
    d = _copy(output, tmp_path)
    s = json.loads((d / "summary.json").read_text())
    s["basic_regions"]["count"] = s["basic_regions"]["lower_bound"] - 1
    (d / "summary.json").write_text(json.dumps(s))
    r = _counts_results(d)["basic_regions"]
    assert not r.verified and "summary.json contradicts the certificates on basic_regions" in r.message
    _only_failure(d, "basic_regions")
    assert main(["verify", str(d)]) == 2
    out, err = capsys.readouterr()
    assert "FAILED: counts.json#basic_regions (counts)" in out and err.count("\n") == 1


def test_a_found_count_below_the_proof_in_the_certificate_fails_verify(output, tmp_path):
    d = _copy(output, tmp_path)
    path = d / "certificates" / "counts.json"
    doc = json.loads(path.read_text())
    claim = next(c for c in doc["claims"] if c["name"] == "uniqueness_domains")
    claim["found"] = 0
    path.write_text(json.dumps(doc))
    r = _counts_results(d)["uniqueness_domains"]
    assert not r.verified and "the library found 0 uniqueness domains" in r.message
    _only_failure(d, "uniqueness_domains")


def test_an_incomplete_run_is_not_compared(output, tmp_path):
    d = _copy(output, tmp_path)
    s = json.loads((d / "summary.json").read_text())
    s["complete"] = False
    s["aspects"]["count"] = 0  # would contradict, but the run says it did not finish
    (d / "summary.json").write_text(json.dumps(s))
    r = _counts_results(d)["aspects"]
    assert r.verified and "not compared: its run did not complete" in r.message
