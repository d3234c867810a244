"""VTK exports through meshio, read back and compared with the pavings they came from.

Comparisons are made on the paving's fine lattice: every exported cuboid holds only boxes
of its own field values, every box that should be exported is covered exactly once, and
fields that say nothing (constant over the file) are left out.
"""

from __future__ import annotations

import math

import meshio
import numpy as np
import pytest

from intervalkin.app.boxes import fine_bounds, joint_boxes
from intervalkin.app.export import paving_columns
from intervalkin.app.vtk_export import (
    read_vtu,
    workspace_fields,
    write_exports,
    write_joint_vtu,
    write_region_surfaces,
    write_vtu_paving,
    write_workspace_vtu,
)
from intervalkin.core.errors import InputError
from intervalkin.core.geometry import default_geometry
from intervalkin.paving.labels import Label
from intervalkin.paving.predicates import pave_workspace
from intervalkin.space.aspect import aspect_components

from .shared import chain

DEG = 180.0 / math.pi


@pytest.fixture(scope="module")
def paving4():
    p = pave_workspace(default_geometry(), 4)
    aspect, _ = aspect_components(p)
    return p, aspect


@pytest.fixture(scope="module")
def chain6():
    return chain(6)


def _cells_on_lattice(mesh, domain, depth, scale):
    """Integer bounds (n, 3) of each hexahedron of ``mesh`` on the fine lattice of a paving."""
    pts = mesh.points.astype(np.float64) / np.asarray(scale)
    conn = mesh.cells_dict["hexahedron"]
    dom = np.asarray(domain, dtype=np.float64)
    step = (dom[:, 1] - dom[:, 0]) / (1 << depth)
    k = (pts - dom[:, 0]) / step
    assert np.allclose(k, np.round(k), atol=1e-3), "corners off the paving's lattice"
    k = np.round(k).astype(np.int64)
    return k[conn].min(axis=1), k[conn].max(axis=1)


def _painted(lo, hi, values, n):
    """(n, n, n) grid of the index of the cuboid covering each fine cell, -1 if none; asserts no overlap."""
    grid = np.full((n, n, n), -1, dtype=np.int64)
    for i, (a, b) in enumerate(zip(lo, hi)):
        block = grid[a[0]:b[0], a[1]:b[1], a[2]:b[2]]
        assert np.all(block == -1), "two exported cells overlap"
        block[...] = i
    return grid


def test_workspace_vtu_holds_every_certified_box_with_its_labels(tmp_path, chain6):
    """Read back with meshio: hexahedra, only informative fields, phi in degrees, and on the paving's lattice
    every box certified in W lies in exactly one cell carrying the box's own field values.

    Would catch a merge across different labels, a missing or extra box, a constant field left in
    (in_workspace), a field lost, or phi left in radians.
    """
    ra = chain6.regions
    p = ra.paving
    path = write_workspace_vtu(tmp_path / "workspace.vtu", ra)
    mesh = read_vtu(path)
    assert list(mesh.cells_dict) == ["hexahedron"]
    fields = workspace_fields(ra)
    w_in = p.labels["W"] == Label.INSIDE
    varying = {k for k, v in fields.items() if len(np.unique(np.asarray(v)[w_in])) > 1}
    assert set(mesh.cell_data) == varying and "in_workspace" not in mesh.cell_data
    assert {"basic_region", "uniqueness_domain", "aspect", "cell", "count"} <= varying
    assert np.isclose(mesh.field_data["phi_axis_degrees"][0], DEG)
    z = mesh.points[:, 2]
    assert z.min() >= -180.0 - 1e-3 and z.max() <= 180.0 + 1e-3 and z.max() - z.min() > 300

    lo, hi = _cells_on_lattice(mesh, p.domain, p.depth, (1.0, 1.0, DEG))
    grid = _painted(lo, hi, None, 1 << p.depth)
    blo, bhi = fine_bounds(p.level, p.ijk, p.depth)
    covered = np.zeros(grid.shape, dtype=bool)
    for b in np.flatnonzero(w_in):
        block = grid[blo[b, 0]:bhi[b, 0], blo[b, 1]:bhi[b, 1], blo[b, 2]:bhi[b, 2]]
        cells = np.unique(block)
        assert cells.min() >= 0, "a certified box of W is not exported"
        for name in varying:
            assert np.all(mesh.cell_data[name][0][cells] == fields[name][b]), name
        covered[blo[b, 0]:bhi[b, 0], blo[b, 1]:bhi[b, 1], blo[b, 2]:bhi[b, 2]] = True
    assert not np.any((grid >= 0) & ~covered), "a cell covers a box that is not certified in W"
    assert len(lo) < np.count_nonzero(w_in)  # merged: fewer cells than boxes


def test_constant_fields_are_dropped_and_phi_scaled_as_asked(tmp_path, paving4):
    p, aspect = paving4
    cols = paving_columns(p, aspect)
    inside = p.labels["W"] == Label.INSIDE
    path = write_vtu_paving(tmp_path / "w.vtu", p, {k: cols[k] for k in ("in_workspace", "aspect")}, mask=inside,
                            phi_unit="rad")
    mesh = meshio.read(path)
    assert "in_workspace" not in mesh.cell_data and "aspect" in mesh.cell_data
    assert mesh.field_data["constant_in_workspace"][0] == 1
    assert mesh.field_data["phi_axis_radians"][0] == 1.0
    assert np.abs(mesh.points[:, 2]).max() <= math.pi + 1e-6
    path = write_vtu_paving(tmp_path / "w10.vtu", p, {"aspect": cols["aspect"]}, mask=inside, phi_unit=10.0)
    assert meshio.read(path).field_data["phi_axis_radians_x_10"][0] == 10.0
    with pytest.raises(InputError, match="phi_unit"):
        write_vtu_paving(tmp_path / "bad.vtu", p, {"aspect": cols["aspect"]}, phi_unit="grad")
    assert not (tmp_path / "bad.vtu").exists()


def test_joint_vtu_holds_every_cell_voxel_with_its_count(tmp_path, chain6):
    """joint.vtu read back: cell, count, n_wa1, n_wa2 of every voxel of a certified cell, nothing else."""
    path = write_joint_vtu(tmp_path / "joint.vtu", chain6.joint)
    mesh = read_vtu(path)
    jb = joint_boxes(chain6.joint)
    cols = jb.columns
    lo, hi = _cells_on_lattice(mesh, jb.domain, jb.depth, (1.0, 1.0, 1.0))
    grid = _painted(lo, hi, None, 1 << jb.depth)
    cell_of = grid[jb.lo[:, 0], jb.lo[:, 1], jb.lo[:, 2]]  # one voxel per row (uniform grid)
    assert np.array_equal(cell_of >= 0, cols["cell"] >= 0)
    sel = cell_of >= 0
    for name in ("cell", "count", "n_wa1", "n_wa2"):
        if name in mesh.cell_data:
            assert np.array_equal(mesh.cell_data[name][0][cell_of[sel]], cols[name][sel]), name
    assert {"cell", "count"} <= set(mesh.cell_data)


def test_region_surfaces_one_file_per_region(tmp_path, chain6):
    """One closed triangle surface per region with boxes, carrying its id, inside the region's bounding box."""
    ra = chain6.regions
    files = write_region_surfaces(tmp_path / "surfaces", ra)
    with_boxes = [r.id for r in ra.regions if r.n_boxes > 0]
    assert sorted(f.name for f in files) == [f"basic_region_{i:02d}.vtu" for i in with_boxes]
    p = ra.paving
    pad = (p.domain[:, 1] - p.domain[:, 0]) / (1 << 7) * np.array([1, 1, DEG]) + 1e-6
    for f, rid in zip(sorted(files), sorted(with_boxes)):
        m = meshio.read(f)
        assert list(m.cells_dict) == ["triangle"] and np.all(m.cell_data["basic_region"][0] == rid)
        box = ra.region == rid
        lo = p.lo[box].min(axis=0) * np.array([1, 1, DEG]) - pad
        hi = p.hi[box].max(axis=0) * np.array([1, 1, DEG]) + pad
        assert np.all(m.points >= lo) and np.all(m.points <= hi)
    stl = write_region_surfaces(tmp_path / "stl", ra, file_format="stl")
    for f in stl:  # binary STL: 80-byte header, triangle count, 50 bytes per triangle
        data = f.read_bytes()
        n = int(np.frombuffer(data[80:84], "<u4")[0])
        assert n > 0 and len(data) == 84 + 50 * n


def test_write_exports_lists_what_it_wrote(tmp_path, chain6):
    files = write_exports(chain6, tmp_path)
    assert files[:2] == ["pavings/workspace.vtu", "pavings/joint.vtu"]
    assert all((tmp_path / f).is_file() for f in files)
    assert not [q for q in tmp_path.rglob("*") if q.name.endswith(".tmp")]
