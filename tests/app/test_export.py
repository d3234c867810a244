"""npz / JSON / VTK writers: documented columns, round trips, atomic replacement."""

from __future__ import annotations

import json
import os
import re

import numpy as np
import pytest

from intervalkin.app.export import NPZ_COLUMNS, paving_columns, read_npz, read_vtu, write_npz, write_vtk_legacy, write_vtu
from intervalkin.core.files import write_json
from intervalkin.core.geometry import default_geometry
from intervalkin.paving.labels import Label
from intervalkin.space.aspect import aspect_components
from intervalkin.paving.predicates import pave_workspace


@pytest.fixture(scope="module")
def paving4():
    p = pave_workspace(default_geometry(), 4)
    aspect, _ = aspect_components(p)
    return p, aspect


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


def test_vtu_parses_and_counts_cells(tmp_path, paving4):
    p, aspect = paving4
    cols = paving_columns(p, aspect)
    path = write_vtu(tmp_path / "w.vtu", p.lo, p.hi, {k: cols[k] for k in ("in_workspace", "det_sign", "aspect")})
    g = read_vtu(path)
    n = len(p)
    assert g["NumberOfCells"] == n and g["NumberOfPoints"] == 8 * n
    assert g["types"].shape == (n,) and np.all(g["types"] == 12)
    assert np.array_equal(g["offsets"], 8 * np.arange(1, n + 1))
    assert np.array_equal(g["aspect"], aspect)
    pts = g["points"].reshape(n, 8, 3)
    assert np.array_equal(pts.min(1), p.lo) and np.array_equal(pts.max(1), p.hi)


def test_vtk_legacy_parses(tmp_path, paving4):
    p, aspect = paving4
    sel = slice(0, 50)
    path = write_vtk_legacy(tmp_path / "w.vtk", p.lo[sel], p.hi[sel], {"aspect": aspect[sel]})
    text = path.read_text()
    assert text.startswith("# vtk DataFile Version 3.0")
    m = re.search(r"CELLS (\d+) (\d+)", text)
    assert int(m.group(1)) == 50 and int(m.group(2)) == 450
    types = text.split("CELL_TYPES 50\n")[1].split("CELL_DATA")[0].split()
    assert types == ["12"] * 50
    assert int(re.search(r"POINTS (\d+)", text).group(1)) == 400


def test_json_atomic(tmp_path):
    path = tmp_path / "summary.json"
    path.write_text("old")
    write_json(path, {"a": 1, "b": [1.5, 2]})
    assert json.loads(path.read_text()) == {"a": 1, "b": [1.5, 2]}
    with pytest.raises(ValueError):
        write_json(path, {"a": float("nan")})
    assert json.loads(path.read_text()) == {"a": 1, "b": [1.5, 2]}  # failed write left the old file
    assert os.listdir(tmp_path) == ["summary.json"]


def test_vtu_with_shared_points(tmp_path):
    """Shared corners: fewer points than 8 per box, every cell's corners are its box's corners."""
    from intervalkin.app.export import write_vtu_paving

    g = default_geometry()
    p = pave_workspace(g, 4)
    mask = p.labels["W"] != Label.OUTSIDE
    path = write_vtu_paving(tmp_path / "s.vtu", p, {"depth": p.level}, mask=mask)
    v = read_vtu(path)
    n = int(mask.sum())
    assert v["NumberOfCells"] == n and v["NumberOfPoints"] < 8 * n
    conn = v["connectivity"].reshape(n, 8)
    pts = v["points"][conn]
    sel = np.flatnonzero(mask)
    assert np.array_equal(pts.min(axis=1), p.lo[sel]) and np.array_equal(pts.max(axis=1), p.hi[sel])
    assert np.array_equal(v["depth"], p.level[sel])
