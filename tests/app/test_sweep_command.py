"""``intervalkin sweep``: one-line refusals before any work, the folder it writes, and the resume."""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import time

import pytest

from intervalkin.app.cli import main
from intervalkin.app.output import MARKER

pq = pytest.importorskip("pyarrow.parquet")

SWEEP = """
name = "two platforms and a flat one"
[analysis]
depth = 3
[vary]
"platform.b1b2" = [17.04, 16, 40]
"""


@pytest.fixture(autouse=True)
def restored_environment():
    """Dask's nannies write their worker settings into this process's environment: put it back."""
    saved = dict(os.environ)
    yield
    os.environ.clear()
    os.environ.update(saved)


def _err_line(capsys) -> str:
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    return err


@pytest.mark.parametrize("text, extra, expected", [
    ("[vary]\nbogus = [1]", [], "intervalkin: error: vary.'bogus': not a parameter of the base geometry"),
    ("[vary\n", [], "malformed TOML"),
    (SWEEP, ["--workers", "0"], "intervalkin: error: --workers: expected a positive integer, got 0"),
    (SWEEP, ["--workers", "2", "--scheduler", "tcp://127.0.0.1:1"],
     "intervalkin: error: --workers: sizes the LocalCluster"),
])
def test_bad_input_is_one_line_exit_2_and_no_folder(text, extra, expected, tmp_path, capsys):
    (tmp_path / "s.toml").write_text(text)
    out = tmp_path / "out"
    assert main(["sweep", str(tmp_path / "s.toml"), "--out", str(out), *extra]) == 2
    assert expected in _err_line(capsys)
    assert not out.exists()


def test_a_foreign_non_empty_folder_is_refused_without_force(tmp_path, capsys):
    (tmp_path / "s.toml").write_text(SWEEP)
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "notes.txt").write_text("mine")
    assert main(["sweep", str(tmp_path / "s.toml"), "--out", str(tmp_path / "out")]) == 2
    assert "is not empty (not an intervalkin output); use --force" in _err_line(capsys)


def test_the_folder_holds_table_plots_report_and_is_resumed(tmp_path, capsys):
    (tmp_path / "s.toml").write_text(SWEEP)
    out = tmp_path / "out"
    args = ["sweep", str(tmp_path / "s.toml"), "--out", str(out), "--workers", "1", "--no-dashboard"]
    assert main(args) == 0
    first = capsys.readouterr()
    assert "3 designs: 2 computed, 0 cached, 0 failed, 1 degenerate" in first.out
    assert "Dask: 1 worker, no dashboard; 2 designs to analyse" in first.err
    with open(out / "results.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [r["platform.b1b2"] for r in rows] == ["17.04", "16.0", "40.0"]
    assert [r["status"] for r in rows] == ["ok", "ok", "degenerate"]
    assert rows[2]["basic_regions_found"] == "" and "triangle inequality" in rows[2]["error"]
    table = pq.read_table(out / "results.parquet")
    assert table.num_rows == 3 and table.column("aspects_exact").to_pylist()[:2] == [True, True]  # the covers prove 2, even at depth 3
    assert (out / "plots" / "counts.png").stat().st_size > 1000 and (out / "plots" / "volumes.png").is_file()
    assert "## Designs not analysed" in (out / "report.md").read_text()
    manifest = json.loads((out / MARKER).read_text())
    assert manifest["complete"] and manifest["command"] == "sweep"
    assert len([f for f in manifest["files"] if f.startswith("designs/")]) == 2

    (out / "designs" / ".abc.json.1234.tmp").write_text("{")  # as a run killed mid-write would leave it
    assert main(args + ["--quiet"]) == 0  # the same folder again: resumed, nothing computed, no cluster
    assert not list(out.rglob(".*.tmp"))
    again = capsys.readouterr()
    assert again.out == "" and again.err == ""
    summary = json.loads((out / "summary.json").read_text())
    assert (summary["computed"], summary["reused"], summary["degenerate"]) == (0, 2, [2])
    assert summary["complete"] and summary["workers"] == 0

    assert main(args + ["--quiet", "--force"]) == 0  # --force starts afresh: the cache is recomputed
    assert json.loads((out / "summary.json").read_text())["computed"] == 2


def test_an_interrupted_sweep_restarts_where_it_stopped(tmp_path, capsys):
    # six designs of about 2 s each (rho_max 34 and 36; at rho_max 30 some take 9 to 13 s): the sweep is
    # interrupted after two, and the restart computes only the others
    (tmp_path / "s.toml").write_text('[analysis]\ndepth = 4\n[vary]\n"platform.scale" = [0.8, 1.0, 1.2]\n'
                                     '"limits.rho_max" = [34, 36]\n')
    out = tmp_path / "out"
    args = ["sweep", str(tmp_path / "s.toml"), "--out", str(out), "--workers", "1", "--no-dashboard", "--quiet"]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    # the child must see SIGINT as a user's Ctrl-C would: an ignored SIGINT is inherited across exec, and a
    # library that ran earlier in this test process (Dask's nannies, process pools) may have left it ignored
    run = subprocess.Popen([sys.executable, "-m", "intervalkin.app.cli", *args], env=env,
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                           preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and run.poll() is None and len(list((out / "designs").glob("*.json"))) < 2:
        time.sleep(0.05)
    run.send_signal(signal.SIGINT)
    _, err = run.communicate(timeout=60)
    done = len(list((out / "designs").glob("*.json")))
    assert run.returncode == 130 and "interrupted" in err and 2 <= done < 6, (run.returncode, err, done,
                                                                                 signal.getsignal(signal.SIGINT))
    assert not json.loads((out / MARKER).read_text())["complete"]
    assert not list(out.rglob(".*.tmp"))  # nothing half-written

    assert main(args) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert (summary["reused"], summary["computed"]) == (done, 6 - done)
    assert len(list((out / "designs").glob("*.json"))) == 6
