"""npz and JSON files: the documented columns (a contract), round trips, atomic replacement."""

from __future__ import annotations

import io
import json
import os
import zipfile

import numpy as np
import pytest

from intervalkin.app.export import NPZ_COLUMNS, paving_columns, read_npz, write_npz
from intervalkin.core.files import NPZ_LEVEL, write_json, write_npz_columns
from intervalkin.core.geometry import default_geometry
from intervalkin.paving.labels import Label
from intervalkin.paving.predicates import pave_workspace
from intervalkin.space.aspect import aspect_components


@pytest.fixture(scope="module")
def paving4():
    p = pave_workspace(default_geometry(), 4)
    aspect, _ = aspect_components(p)
    return p, aspect


def test_npz_columns_read_back_as_written():
    """The npz writer (zlib level NPZ_LEVEL instead of numpy's default) gives what numpy.load reads: every dtype and
    shape the pavings use, empty columns and 0-d ones, each member deflated; an object column is refused."""
    cols = {"lo": np.random.default_rng(1).normal(size=(500, 3)), "label": np.arange(500, dtype=np.int8) % 3,
            "ok": np.arange(500) % 2 == 0, "ids": np.arange(500, dtype=np.int64) << 40, "none": np.zeros((0, 3)),
            "domain": np.array([[10.0, 32.0]] * 3), "depth": np.int64(7)}
    buf = io.BytesIO()
    write_npz_columns(buf, cols)
    back = np.load(io.BytesIO(buf.getvalue()))
    assert sorted(back.files) == sorted(cols)
    for k, v in cols.items():
        assert back[k].dtype == np.asarray(v).dtype and np.array_equal(back[k], v), k
    with zipfile.ZipFile(io.BytesIO(buf.getvalue())) as z:
        assert all(i.compress_type == zipfile.ZIP_DEFLATED for i in z.infolist()) and NPZ_LEVEL == 1
    with pytest.raises(ValueError):
        write_npz_columns(io.BytesIO(), {"bad": np.array([{"a": 1}], dtype=object)})


def test_npz_round_trip(tmp_path, paving4):
    p, aspect = paving4
    extra = {"basic_region": np.arange(len(p), dtype=np.int32) % 7}
    path = write_npz(tmp_path / "pavings" / "workspace.npz", p, aspect, extra)
    z = read_npz(path)
    for k in NPZ_COLUMNS + ("basic_region", "domain"):
        assert k in z
    n = len(p)
    assert z["lo"].shape == (n, 3) and z["lo"].dtype == np.float64
    assert z["hi"].shape == (n, 3) and z["hi"].dtype == np.float64
    assert z["depth"].shape == (n,) and np.issubdtype(z["depth"].dtype, np.integer)
    assert z["in_workspace"].dtype == np.int8 and z["det_sign"].dtype == np.int8
    assert z["aspect"].dtype == np.int32
    assert np.array_equal(z["lo"], p.lo) and np.array_equal(z["hi"], p.hi)
    assert np.array_equal(z["in_workspace"] == 1, p.labels["W"] == Label.INSIDE)
    assert np.array_equal(z["in_workspace"] == -1, p.labels["W"] == Label.OUTSIDE)
    assert np.array_equal(z["det_sign"] == 1, p.labels["det_positive"] == Label.INSIDE)
    assert np.array_equal(z["det_sign"] == -1, p.labels["det_positive"] == Label.OUTSIDE)
    assert np.array_equal(z["aspect"], aspect)
    assert set(np.unique(z["in_workspace"]).tolist()) <= {-1, 0, 1}
    # aspect ids only on boxes certified in W with a certified sign
    a = z["aspect"] >= 0
    assert np.all(z["in_workspace"][a] == 1) and np.all(z["det_sign"][a] != 0)
    assert np.array_equal(z["basic_region"], extra["basic_region"])
    assert sorted(os.listdir(tmp_path / "pavings")) == ["workspace.npz"]  # no temp file left


def test_extra_column_checked(paving4):
    p, _ = paving4
    with pytest.raises(ValueError, match="rows"):
        paving_columns(p, None, {"uniqueness_domain": np.zeros(3)})
    with pytest.raises(ValueError, match="already"):
        paving_columns(p, None, {"aspect": np.zeros(len(p))})


def test_json_atomic(tmp_path):
    path = tmp_path / "summary.json"
    path.write_text("old")
    write_json(path, {"a": 1, "b": [1.5, 2]})
    assert json.loads(path.read_text()) == {"a": 1, "b": [1.5, 2]}
    with pytest.raises(ValueError):
        write_json(path, {"a": float("nan")})
    assert json.loads(path.read_text()) == {"a": 1, "b": [1.5, 2]}  # failed write left the old file
    assert os.listdir(tmp_path) == ["summary.json"]
