"""``intervalkin verify`` on an output folder re-checks every box label of ``pavings/workspace.npz``.

A small output folder is built as ``analyze`` lays it out: ``certificates/``
(written by ``write_certificates``) and ``pavings/workspace.npz`` (written by
``write_npz``) of a depth-5 paving.  Would fail if the new result line were
missing, if a mutated label (W INSIDE -> OUTSIDE, a flipped det A sign) passed,
or if a malformed npz crashed ``verify`` instead of giving one line.
"""

from __future__ import annotations

import shutil
import time
import zipfile

import numpy as np
import pytest

from intervalkin.app.cli import main
from intervalkin.app.export import write_npz
from intervalkin.certify.writer import write_certificates
from intervalkin.core.errors import CertificateFormatError
from intervalkin.paving.predicates import pave_workspace
from intervalkin.pipeline import verify
from intervalkin.recheck import KIND, paving_file, read_workspace_labels, recheck_folder, recheck_paving


@pytest.fixture(scope="module")
def output(tmp_path_factory, paper_geometry):
    out = tmp_path_factory.mktemp("out")
    p = pave_workspace(paper_geometry, 5)
    write_certificates(out / "certificates", paper_geometry, paving=p, box_sample=20)
    write_npz(out / "pavings" / "workspace.npz", p)
    return out


def _copy(src, tmp_path):
    d = tmp_path / "o"
    shutil.copytree(src, d)
    return d


def _rewrite(folder, **changes):
    """Rewrite the folder's npz with some columns replaced (None: dropped)."""
    path = folder / "pavings" / "workspace.npz"
    with np.load(path) as z:
        cols = {k: z[k] for k in z.files}
    for k, v in changes.items():
        if v is None:
            cols.pop(k)
        else:
            cols[k] = v
    np.savez_compressed(path, **cols)


def test_verify_adds_one_verified_line_for_all_boxes(output, capsys):
    report = verify(output)
    last = report.results[-1]
    assert last.kind == KIND and last.verified, last.message
    assert sum(r.kind == KIND for r in report.results) == 1
    assert main(["verify", str(output)]) == 0
    out, _ = capsys.readouterr()
    assert f"({KIND}): " in out and "every label re-proved" in out
    # the certificates folder itself also finds the paving beside it
    assert recheck_folder(output / "certificates").verified


def test_the_count_is_every_nonzero_label(output, paper_geometry):
    w = read_workspace_labels(output / "pavings" / "workspace.npz")
    r = recheck_paving(paper_geometry, w)
    n = int((w.labels["in_workspace"] != 0).sum() + (w.labels["det_sign"] != 0).sum())
    assert r.checked == n and r.confirmed == n and r.boxes == len(w.lo) and r.verified


def test_a_certificate_folder_alone_gets_no_extra_line(output, tmp_path):
    d = tmp_path / "c"
    shutil.copytree(output / "certificates", d)
    assert all(r.kind != KIND for r in verify(d).results)


@pytest.mark.parametrize("column", ["in_workspace", "det_sign"])
def test_a_flipped_inside_label_fails_verify(output, tmp_path, capsys, column):
    d = _copy(output, tmp_path)
    with np.load(d / "pavings" / "workspace.npz") as z:
        labels = z[column].copy()
    row = int(np.flatnonzero(labels == 1)[len(np.flatnonzero(labels == 1)) // 2])
    labels[row] = -1
    _rewrite(d, **{column: labels})
    result = recheck_folder(d)
    assert not result.verified and "WRONG" in result.message and f"box {row}" in result.message
    assert main(["verify", str(d)]) == 2
    out, err = capsys.readouterr()
    assert f"FAILED: pavings/workspace.npz#all ({KIND})" in out and "1 FAILED" in err


def test_an_undecided_box_claimed_inside_fails(output, tmp_path, monkeypatch):
    """Thousands of open labels: the arb fallback stops at its time limit and the result fails."""
    monkeypatch.setattr(paving_file, "ARB_SECONDS", 1.0)
    d = _copy(output, tmp_path)
    with np.load(d / "pavings" / "workspace.npz") as z:
        labels = z["in_workspace"].copy()
    labels[labels == 0] = 1
    _rewrite(d, in_workspace=labels)
    t0 = time.perf_counter()
    result = recheck_folder(d)
    assert not result.verified and "WRONG" in result.message
    assert time.perf_counter() - t0 < 10


@pytest.mark.parametrize("case", [
    "garbage", "no-det-column", "labels-float", "label-value", "nan-bound", "lo-above-hi", "lo-shape",
])
def test_a_malformed_npz_is_one_line_not_a_traceback(output, tmp_path, capsys, case):
    d = _copy(output, tmp_path)
    path = d / "pavings" / "workspace.npz"
    with np.load(path) as z:
        lo, labels = z["lo"].copy(), z["in_workspace"].copy()
    if case == "garbage":
        path.write_bytes(b"PK\x03\x04 not a zip at all")
    elif case == "no-det-column":
        _rewrite(d, det_sign=None)
    elif case == "labels-float":
        _rewrite(d, in_workspace=labels.astype(float))
    elif case == "label-value":
        labels[3] = 2
        _rewrite(d, in_workspace=labels)
    elif case == "nan-bound":
        lo[5, 1] = np.nan
        _rewrite(d, lo=lo)
    elif case == "lo-above-hi":
        lo[7, 0] = 1e3
        _rewrite(d, lo=lo)
    elif case == "lo-shape":
        _rewrite(d, lo=lo[:, :2])
    with pytest.raises(CertificateFormatError):
        recheck_folder(d)
    assert main(["verify", str(d)]) == 2
    out, err = capsys.readouterr()
    assert err.count("\n") == 1 and err.startswith("intervalkin: error: ") and "workspace.npz" in err
    assert "Traceback" not in out + err


def test_npz_reader_refuses_a_pickled_object_column(tmp_path):
    path = tmp_path / "w.npz"
    np.savez(path, lo=np.zeros((1, 3)), hi=np.ones((1, 3)), in_workspace=np.array([object()], dtype=object),
             det_sign=np.zeros(1, np.int8))
    with pytest.raises(CertificateFormatError):
        read_workspace_labels(path)
    assert zipfile.is_zipfile(path)
