"""The whole chain from the command line: outputs, their schema, bad input, interrupted runs."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from intervalkin.app.cli import main


@pytest.fixture(scope="module")
def analysed(tmp_path_factory):
    out = tmp_path_factory.mktemp("analysis")
    status = main(["analyze", "--depth", "5", "--out", str(out), "--quiet", "--force"])
    assert status == 0
    return out


def test_outputs_and_summary_schema(analysed):
    s = json.loads((analysed / "summary.json").read_text())
    assert s["aspects"]["count"] == 2 and s["aspects"]["lower_bound"] == 2
    for key in ("aspects", "basic_regions", "uniqueness_domains"):
        assert {"count", "exact", "lower_bound", "upper_bound", "why"} <= set(s[key])
        # a count never falls below its certified lower bound; none is exact without an upper bound (the aspects
        # have one: each sign's cover closes)
        assert 0 <= s[key]["lower_bound"] <= s[key]["count"]
        if key == "aspects":
            assert s[key]["exact"] is True and s[key]["upper_bound"] == 2
            assert {c["components_at_most"] for c in s[key]["covers"].values()} == {1}
        else:
            assert s[key]["exact"] is False and s[key]["upper_bound"] is None
    with np.load(analysed / "pavings" / "workspace.npz") as z:
        assert {"lo", "hi", "depth", "in_workspace", "det_sign", "aspect", "basic_region", "uniqueness_domain"} <= set(z.files)
        n = z["lo"].shape[0]
        assert z["basic_region"].shape == (n,) and z["uniqueness_domain"].dtype == np.int32
        # a box with a region is certified inside an aspect
        br = z["basic_region"] >= 0
        assert np.all(z["in_workspace"][br] == 1) and np.all(z["det_sign"][br] != 0)
    with np.load(analysed / "pavings" / "joint.npz") as z:
        assert set(z.files) == {"lo", "hi", "cell", "count", "n_wa1", "n_wa2"}
    assert (analysed / "pavings" / "workspace.vtu").exists()
    assert all((analysed / f).exists() for f in s["files"])


def test_json_prints_one_object(analyze_depth4):
    """``analyze --depth 4 --quiet --json`` (the run of tests/conftest.py): one line, the summary written."""
    out = (analyze_depth4.parent / "stdout.txt").read_text()
    assert out.count("\n") == 1
    printed = json.loads(out)
    assert printed["aspects"]["count"] == 2
    assert printed == json.loads((analyze_depth4 / "summary.json").read_text())


def test_refuses_a_foreign_non_empty_folder(tmp_path, capsys):
    d = tmp_path / "mine"
    d.mkdir()
    (d / "thesis.tex").write_text("precious")
    assert main(["analyze", "--depth", "4", "--out", str(d), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--force" in err
    assert (d / "thesis.tex").read_text() == "precious"


@pytest.mark.parametrize(
    "argv,fragment",
    [
        (["analyze", "--depth", "0"], "depth: expected an integer in 3..9, got 0"),
        (["analyze", "--depth", "40"], "depth: expected an integer in 3..9, got 40"),
        (["analyze", "--depth", "5", "--refine-to", "4"], "refine_to: expected an integer in 5..9, got 4"),
        (["analyze", "--geometry", "/nonexistent.toml"], "not found"),
        (["joint", "--depth", "12"], "--depth"),
        (["label", "1", "2", "x", "--from", "/nonexistent"], "pose"),
    ],
)
def test_bad_input_one_line_status_2(tmp_path, capsys, argv, fragment):
    assert main(argv + ["--out", str(tmp_path / "o")] if argv[0] != "label" else argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and fragment in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()  # refused before the output folder is made


def test_unwritable_out(tmp_path, capsys):
    f = tmp_path / "afile"
    f.write_text("x")
    assert main(["analyze", "--depth", "4", "--out", str(f / "sub"), "--quiet"]) == 2
    assert "--out" in capsys.readouterr().err


def test_interrupted_run_leaves_no_partial_file(tmp_path):
    """SIGTERM in the middle of a run: every file present is complete, no temporary file is left."""
    out = tmp_path / "run"
    env = dict(os.environ)
    proc = subprocess.Popen([sys.executable, "-m", "intervalkin", "analyze", "--depth", "6", "--out", str(out),
                             "--quiet"], env=env, stderr=subprocess.PIPE, stdout=subprocess.PIPE)
    # wait until the run has started writing, then stop it
    deadline = time.time() + 120
    while time.time() < deadline and not (out / "pavings").exists():
        time.sleep(0.05)
    time.sleep(0.3)
    proc.send_signal(signal.SIGTERM)
    proc.wait(timeout=60)
    assert proc.returncode != 0
    leftovers = [p for p in out.rglob("*") if p.name.endswith(".tmp")]
    assert leftovers == []
    for p in out.rglob("*.npz"):
        with np.load(p) as z:
            assert z.files
    for p in out.rglob("*.json"):
        json.loads(p.read_text())
    # the folder says it is incomplete, wherever the run was stopped
    manifest = json.loads((out / ".intervalkin-output").read_text())
    assert manifest["complete"] is False
    if (out / "summary.json").exists():
        assert json.loads((out / "summary.json").read_text())["complete"] is False
    # every file there is listed in the manifest (it is listed before it appears)
    present = {p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()} - {".intervalkin-output"}
    assert present <= set(manifest["files"]), present - set(manifest["files"])
    # a second run needs --force, and is not confused by the first
    assert main(["analyze", "--depth", "4", "--out", str(out), "--quiet"]) == 2
    assert main(["analyze", "--depth", "4", "--out", str(out), "--quiet", "--force"]) == 0
    assert json.loads((out / "summary.json").read_text())["complete"] is True


def test_label_from_an_earlier_output(analysed, capsys):
    """``label --from`` reads the npz; it answers as the in-memory analysis of the same run does."""
    with np.load(analysed / "pavings" / "workspace.npz") as z:
        lo, hi, region, domain = z["lo"], z["hi"], z["basic_region"], z["uniqueness_domain"]
    i = int(np.flatnonzero(region >= 0)[0])
    centre = [repr(float(v)) for v in 0.5 * (lo[i] + hi[i])]
    assert main(["label", *centre, "--from", str(analysed), "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["pose"] == centre and res["in_workspace"] == "yes" and res["aspect"] in ("WA1", "WA2")
    assert res["basic_region"] == int(region[i]) and res["uniqueness_domain"] == int(domain[i])
    assert "note" not in res
    # certified outside W: B1 on the base point A1 puts leg 1 at length 0
    assert main(["label", "0", "0", "0", "--from", str(analysed), "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["in_workspace"] == "no" and res["aspect"] == res["basic_region"] == "none (outside W)"
    # outside the paved domain: bad input, one line
    assert main(["label", "60", "60", "0", "--from", str(analysed), "--json"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and "outside the paved domain" in err


def test_label_from_npz_matches_the_analysis(analysed):
    """The npz lookup and the in-memory lookup agree pose by pose (same depth, same seed)."""
    from intervalkin.app.label import label_from_npz
    from intervalkin.pipeline import analyse

    a = analyse(None, 5)
    with np.load(analysed / "pavings" / "workspace.npz") as z:
        lo, hi = z["lo"], z["hi"]
    rng = np.random.default_rng(5)
    picks = rng.choice(len(lo), size=15, replace=False)  # each may run a path search: few, but varied
    poses = [[repr(float(v)) for v in lo[i] + rng.random(3) * (hi[i] - lo[i])] for i in picks]
    # a shared face: the lower corner of a box lies in every box around it
    poses.append([repr(float(v)) for v in lo[picks[0]]])
    for pose in poses:
        assert label_from_npz(analysed, pose) == a.label(pose)


def test_joint_command(tmp_path, capsys):
    assert main(["joint", "--depth", "4", "--out", str(tmp_path / "j")]) == 0
    s = json.loads((tmp_path / "j" / "summary.json").read_text())
    counts = {c["count"] for c in s["joint"]["cells"]}
    assert {2, 4} <= counts
    assert "count" in capsys.readouterr().out


def test_refinement_deepens_until_consistent_or_limit():
    from intervalkin.core.errors import InputError
    from intervalkin.pipeline import analyse

    a = analyse(None, 5, refine_to=6)
    h = list(a.refinement)
    assert h[0].depth == 5 and 1 <= len(h) <= 2
    assert h[-1].consistent or h[-1].depth == 6
    assert a.depth == h[-1].depth == a.regions.paving.depth
    assert h[-1].stopped and not any(step.stopped for step in h[:-1])
    with pytest.raises(InputError, match=r"^refine_to: expected an integer in 5\.\.9, got 4$"):
        analyse(None, 5, refine_to=4)


@pytest.mark.parametrize("depth, extra", [(4, []), (5, ["--refine-to", "6"])])
def test_files_written_beside_the_joint_paving_or_after_it_are_the_regions_of_the_summary(tmp_path, depth, extra,
                                                                                          request):
    """Without --refine-to the regions' files are written while the joint cells are paved; with it the regions
    may be paved again afterwards, so everything is written after: either way the workspace paving on disk is the
    one the summary describes, and every file listed exists.  (Depth 4 without options is the run of
    tests/conftest.py, shared with other files.)"""
    if extra:
        out = tmp_path / "run"
        assert main(["analyze", "--depth", str(depth), "--out", str(out), "--quiet", *extra]) == 0
    else:
        out = request.getfixturevalue("analyze_depth4")
    s = json.loads((out / "summary.json").read_text())
    files = s["files"]
    assert len(files) == len(set(files)) and all((out / f).is_file() for f in files)
    assert {"pavings/workspace.npz", "pavings/joint.npz", "pavings/joint_cells.npz", "pavings/workspace.vtu"} <= set(files)
    assert any(f.startswith("figures/") for f in files) and any(f.startswith("certificates/") for f in files)
    with np.load(out / "pavings" / "workspace.npz") as z:
        assert z["lo"].shape[0] == sum(s["W"]["boxes"].values())
    assert s["depth"]["workspace"] == s["refinement"][-1]["depth"] == (6 if extra else depth)  # depth 5 is refined
