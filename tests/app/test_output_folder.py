"""Output folders that never lie: a manifest of what a run wrote, no stale file after a re-run,
``"complete": false`` until the end, nothing left by a refused run, one file mode.

Runs are small (depth 3 and 4); the module makes one workspace paving, and shares the session's
``analyze --depth 4`` folder (tests/conftest.py) with checker/test_consistency.py.
"""

from __future__ import annotations

import json
import os
import shutil
import stat
from pathlib import Path

import pytest

from intervalkin.app import commands
from intervalkin.app.cli import main
from intervalkin.app.output import MARKER, OutputFolder
from intervalkin.core.errors import InputError, NoPathError
from intervalkin.core.files import atomic_write_bytes, watching_writes
from intervalkin.core.geometry import default_geometry, load_geometry


def _manifest(folder: Path) -> dict:
    return json.loads((folder / MARKER).read_text())


def _present(folder: Path) -> set[str]:
    return {p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file()} - {MARKER}


@pytest.fixture(scope="module")
def run4(analyze_depth4) -> Path:
    """``analyze --depth 4`` (the session's, tests/conftest.py): read only, copied by the test that changes it."""
    return analyze_depth4


def test_the_manifest_lists_exactly_the_files_of_the_run(run4):
    """Every file in the folder is in the manifest and the other way round; the run says it completed.

    Would catch a writer that bypasses core.files (its file would be missing from the
    manifest, and a re-run would leave it behind as a stale file).
    """
    m = _manifest(run4)
    assert m["format"] == "intervalkin-output" and m["command"] == "analyze" and m["complete"] is True
    assert set(m["files"]) == _present(run4)
    s = json.loads((run4 / "summary.json").read_text())
    assert s["complete"] is True and set(s["files"]) <= set(m["files"])
    assert {"summary.json", "geometry.toml", "certificates/index.json", "pavings/workspace.npz"} <= set(m["files"])
    assert load_geometry(run4 / "geometry.toml").to_toml() == default_geometry().to_toml()


def test_one_file_mode_for_every_output(run4):
    """Certificates, pavings, figures, summary and manifest: all 0o666 less the umask (mkstemp would give 0600)."""
    mask = os.umask(0)
    os.umask(mask)
    modes = {p.relative_to(run4).as_posix(): stat.S_IMODE(p.stat().st_mode) for p in run4.rglob("*") if p.is_file()}
    assert set(modes.values()) == {0o666 & ~mask}, modes


def test_a_forced_rerun_replaces_what_the_earlier_run_owned(run4, tmp_path, capsys):
    """``pave --force`` into an earlier analyze output: the analysis files are gone, the user's file stays.

    The earlier output is given a trajectories/ folder, as ``paper`` writes one: it is listed
    in the manifest, so it is the run's and must go (issue 15: old trajectories/ survived).
    """
    d = tmp_path / "out"
    shutil.copytree(run4, d)
    atomic_write_bytes(d / "trajectories" / "2-3" / "trajectory.json", b"{}")
    m = _manifest(d)
    m["files"].append("trajectories/2-3/trajectory.json")
    (d / MARKER).write_text(json.dumps(m))
    (d / "notes.txt").write_text("mine")
    assert main(["pave", "--depth", "3", "--out", str(d), "--quiet"]) == 2  # non-empty: --force needed
    capsys.readouterr()
    assert main(["pave", "--depth", "3", "--out", str(d), "--quiet", "--force"]) == 0
    m = _manifest(d)
    assert m["command"] == "pave" and m["complete"] is True
    assert _present(d) == set(m["files"]) | {"notes.txt"}
    assert not (d / "trajectories").exists() and not (d / "certificates").exists()
    assert not (d / "pavings" / "joint.npz").exists()
    assert (d / "notes.txt").read_text() == "mine"


def test_force_into_a_foreign_folder_keeps_its_files(tmp_path):
    d = tmp_path / "thesis"
    (d / "figures").mkdir(parents=True)
    (d / "thesis.tex").write_text("precious")
    (d / "figures" / "mine.png").write_bytes(b"png")
    folder = OutputFolder.open(d, force=True, command="test")
    with folder.recording():
        atomic_write_bytes(d / "figures" / "ours.png", b"ours")
    folder.finish()
    assert (d / "thesis.tex").read_text() == "precious" and (d / "figures" / "mine.png").exists()
    assert _manifest(d)["files"] == ["figures/ours.png"]
    # a forced re-run removes ours only
    OutputFolder.open(d, force=True, command="test")
    assert _present(d) == {"thesis.tex", "figures/mine.png"}


def test_a_manifest_naming_files_outside_the_folder_is_refused(tmp_path):
    outside = tmp_path / "precious.txt"
    outside.write_text("keep")
    d = tmp_path / "out"
    d.mkdir()
    (d / MARKER).write_text(json.dumps({"format": "intervalkin-output", "files": ["../precious.txt"]}))
    with pytest.raises(InputError, match="outside the folder"):
        OutputFolder.open(d, force=True, command="test")
    assert outside.read_text() == "keep"


def test_incomplete_mid_run_and_nothing_left_by_a_user_error(tmp_path, monkeypatch, capsys):
    """Mid-run, summary.json and the manifest say complete: false; an IntervalkinError then (e.g. no
    path found) gives one line and status 2, and removes everything the run wrote, folder included.

    (A finished run says complete: true: test_the_manifest_lists_exactly_the_files_of_the_run; a killed
    one keeps complete: false: test_commands.test_interrupted_run_leaves_no_partial_file.)
    """
    out = tmp_path / "out"
    seen = {}

    def analyse_then_fail(*args, **kwargs):
        seen["summary"] = json.loads((out / "summary.json").read_text())["complete"]
        seen["manifest"] = _manifest(out)["complete"]
        atomic_write_bytes(out / "certificates" / "partial.json", b"{}")
        raise NoPathError("no certified path between the two solutions")

    monkeypatch.setattr(commands, "analyse", analyse_then_fail)
    assert main(["analyze", "--depth", "3", "--out", str(out), "--quiet"]) == 2
    assert seen == {"summary": False, "manifest": False}
    assert capsys.readouterr().err == "intervalkin: error: no certified path between the two solutions\n"
    assert not out.exists()


def test_watching_writes_reports_before_the_file_appears(tmp_path):
    """The watcher sees each destination while it does not exist yet, and only inside the block."""
    seen = []

    def watch(path):
        seen.append((Path(path).name, Path(path).exists()))

    with watching_writes(watch):
        atomic_write_bytes(tmp_path / "a.txt", b"1")
        atomic_write_bytes(tmp_path / "a.txt", b"2")  # a replacement: the old file exists
    atomic_write_bytes(tmp_path / "b.txt", b"3")
    assert seen == [("a.txt", False), ("a.txt", True)]

    def refuse(path):
        raise RuntimeError("no")

    with watching_writes(refuse), pytest.raises(RuntimeError):
        atomic_write_bytes(tmp_path / "c.txt", b"4")
    assert not (tmp_path / "c.txt").exists() and not list(tmp_path.glob(".*.tmp"))
