"""``intervalkin paper`` end to end at a small depth, through the real entry point.

Depth 5 is the smallest depth at which the run finds basic regions and joint cells of
every count (depths 3 and 4 find no region); it takes about 5 s on one core.  The run
is checked for what it promises: the documented files, a report whose figures exist,
certificates that ``intervalkin verify`` accepts, and counts that agree with them.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import time

import pytest

DEPTH = 5
COUNTS = ("aspects", "basic_regions", "uniqueness_domains")


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("paper") / "run"
    t0 = time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "intervalkin", "paper", "--depth", str(DEPTH), "--out", str(out),
                        "--quiet"], capture_output=True, text=True, timeout=600)
    return out, r, time.perf_counter() - t0


@pytest.fixture(scope="module")
def summary(run):
    return json.loads((run[0] / "summary.json").read_text())


@pytest.fixture(scope="module")
def verified(run):
    """``intervalkin verify DIR/certificates``: (status, stdout lines, stderr)."""
    r = subprocess.run([sys.executable, "-m", "intervalkin", "verify", str(run[0] / "certificates")],
                       capture_output=True, text=True, timeout=600)
    return r.returncode, r.stdout.splitlines(), r.stderr


def test_run_succeeds_quietly(run):
    """Status 0; --quiet prints nothing on stdout and no error or traceback on stderr."""
    out, r, seconds = run
    assert r.returncode == 0, r.stderr
    assert r.stdout == ""
    assert "Traceback" not in r.stderr and "error" not in r.stderr.lower()
    assert "Warning:" not in r.stderr, r.stderr


def test_shallow_run_warns_of_nothing(tmp_path):
    """At depth 3 no joint cell has a certified count: the figures are drawn all the same,
    --quiet leaves stderr without a Python warning (e.g. matplotlib's "No artists with labels"
    from a legend over an empty scatter), and ``verify`` accepts the folder."""
    r = subprocess.run([sys.executable, "-m", "intervalkin", "paper", "--depth", "3", "--out", str(tmp_path / "run"),
                        "--quiet"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert "Warning:" not in r.stderr, r.stderr
    assert (tmp_path / "run" / "figures" / "joint_3d.png").is_file()
    # the counts of so shallow a run still agree with their certificates (the aspects' covers prove 2 there while
    # the regions paving certifies no box of either sign: a count of 0 was refused as below its certificates)
    v = subprocess.run([sys.executable, "-m", "intervalkin", "verify", str(tmp_path / "run")], capture_output=True,
                       text=True, timeout=300)
    assert v.returncode == 0, v.stdout + v.stderr
    assert json.loads((tmp_path / "run" / "summary.json").read_text())["aspects"]["lower"] == 2


def test_documented_files_are_written_completely(run, summary):
    """summary.json, report.md, the pavings, figures and certificates exist; every listed file exists;
    no temporary file is left; the folder is marked as an intervalkin output (so a rerun may reuse it).

    Would catch a file listed in summary.json but not written (or written under another
    name), an atomic writer leaving its .tmp file, or a missing certificates folder.
    """
    out = run[0]
    for name in ("summary.json", "report.md", "pavings/workspace.npz", "pavings/joint.npz", "pavings/workspace.vtu",
                 "certificates/index.json", "certificates/counts.json", "certificates/dkp.json"):
        assert (out / name).is_file(), name
    assert summary["files"] and all((out / f).is_file() for f in summary["files"]), \
        [f for f in summary["files"] if not (out / f).is_file()]
    assert not [p for p in out.rglob("*") if p.name.endswith(".tmp")]
    assert any(p.name.startswith(".intervalkin") for p in out.iterdir())
    assert summary["depth"]["workspace"] == DEPTH


def test_report_compares_the_paper_and_links_existing_figures(run):
    """report.md has the claims table (Table 1, aspects, 28 regions, 6 domains) and every image it shows exists."""
    out = run[0]
    text = (out / "report.md").read_text()
    for claim in ("Table 1", "2 aspects", "28 basic regions", "6 uniqueness domains"):
        assert claim in text, claim
    assert "6 certified solutions, completeness proved" in text
    images = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", text)
    assert images and all((out / p).is_file() for p in images), [p for p in images if not (out / p).is_file()]


def test_certificates_of_the_run_verify(verified, run):
    """``intervalkin verify DIR/certificates`` re-proves every claim: status 0, one 'verified:' line each.

    One line more than the certificates hold claims: the re-check of every box label of
    ``pavings/workspace.npz`` beside them (kind ``box_labels_all``).  Would catch a writer
    that puts in a claim its checker refuses, or a run whose files and certificates disagree
    (another geometry, another depth).
    """
    status, lines, err = verified
    assert status == 0, "\n".join(ln for ln in lines if not ln.startswith("verified"))
    assert lines and all(ln.startswith("verified: ") for ln in lines)
    index = json.loads((run[0] / "certificates" / "index.json").read_text())
    n_claims = sum(len(json.loads((run[0] / "certificates" / f).read_text())["claims"]) for f in index["files"])
    assert len(lines) == n_claims + 1 and "(box_labels_all): " in lines[-1]
    assert err.strip() == f"{n_claims + 1} of {n_claims + 1} claims verified"
    assert any("dkp.json#" in ln and "exactly 6 solutions" in ln for ln in lines)


def test_summary_lower_bounds_are_the_certified_ones(summary, run, verified):
    """Each lower bound in summary.json is the one declared in certificates/counts.json, and it does not
    exceed what the checker proves from the verified claims ('the supporting claims prove >= N'); or, for the
    basic regions, the claim's raised by the separation barriers, which their own verdict backs.

    Would catch a summary that prints a bound the certificates do not back.
    """
    counts = {c["name"]: c for c in json.loads((run[0] / "certificates" / "counts.json").read_text())["claims"]}
    _, lines, _ = verified
    for name in COUNTS:
        s = summary[name]
        assert isinstance(s["count"], int) and isinstance(s["lower_bound"], int)
        assert s["exact"] is (name == "aspects")  # the aspects also have a proved upper bound
        assert s["upper_bound"] == counts[name]["upper_bound"]
        line = next(ln for ln in lines if f"counts.json#{name} " in ln)
        proved = int(re.search(r"prove >= (\d+)", line).group(1))
        if s.get("barriers_at_least") is not None:  # raised by the separation barriers: backed by their verdict
            assert name == "basic_regions" and s["counts_claim_lower"] == counts[name]["lower_bound"] <= proved
            bound = next(ln for ln in lines if "(barrier_bound)" in ln)
            assert s["lower_bound"] == s["barriers_at_least"] <= int(re.search(r">= (\d+)", bound).group(1))
        else:
            assert s["lower_bound"] == counts[name]["lower_bound"] <= proved
    assert summary["aspects"]["lower_bound"] == summary["aspects"]["upper_bound"] == 2
    assert any("aspect_connected.json#WA1" in ln and "nonempty and connected" in ln for ln in lines)


def test_found_counts_never_sit_below_their_lower_bounds(summary):
    """count >= lower_bound for aspects, basic regions and uniqueness domains in summary.json.

    Would catch a 'found' number printed below the proved minimum (at depth 5 the run once
    reported 1 uniqueness domain beside a certified lower bound of 2)."""
    for name in COUNTS:
        assert summary[name]["count"] >= summary[name]["lower_bound"], (name, summary[name])


def test_found_counts_reach_what_the_certificates_prove(summary, verified):
    """count >= the lower bound the checker proves from the run's certificates ('prove >= N'): a number
    found below a proved minimum contradicts the certificates written beside it."""
    _, lines, _ = verified
    for name in COUNTS:
        line = next(ln for ln in lines if f"counts.json#{name} " in ln)
        proved = int(re.search(r"prove >= (\d+)", line).group(1))
        assert summary[name]["count"] >= proved, (name, summary[name]["count"], proved)


def test_joint_cells_and_table1_in_the_summary(summary):
    """Joint cells of 2, 4 and 6 certified solutions are found, each split equally between the aspects."""
    cells = summary["joint"]["cells"]
    counts = {c["count"] for c in cells}
    assert {2, 4, 6} <= counts
    for c in cells:
        if c["count"] >= 0:
            assert c["n_wa1"] + c["n_wa2"] == c["count"]
