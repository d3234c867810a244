"""VTK files for ParaView, written by meshio: labelled boxes, joint cells, region surfaces.

* ``pavings/workspace.vtu``: the boxes certified inside W as hexahedra, with
  the fields ``aspect`` (component of certified aspect boxes), ``det_sign``
  (1 WA1, -1 WA2, 0 the singular layer), ``basic_region``, ``uniqueness_domain``,
  ``cell`` and ``count`` (the joint cell under the region and its certified
  number of solutions); -1 means none.  Neighbouring boxes with equal fields are
  merged into one cuboid (:func:`~intervalkin.app.boxes.merge_boxes`; the union is
  unchanged), corners are shared, arrays are zlib-compressed.
* ``pavings/joint.vtu``: the joint-space boxes of certified cells, with ``cell``,
  ``count``, ``n_wa1`` and ``n_wa2``, merged the same way.
* ``pavings/surfaces/basic_region_NN.vtu``: the boundary surface of each basic
  region (marching cubes on a label grid, :mod:`intervalkin.app.surfaces`), triangles
  carrying the region's fields: light files to colour and combine in ParaView.

phi is scaled (degrees by default; ``phi_unit``): the field-data array
``phi_axis_<unit>`` holds the factor from radians, so that a reader knows the
unit.  A field that is constant over the exported cells says nothing about them:
it is dropped, and its value kept as field data ``constant_<name>``.

meshio is imported when a file is written, so importing this module stays light.
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path
from typing import Mapping

import numpy as np

from intervalkin.app.boxes import fine_bounds, joint_boxes, lattice_points, merge_boxes, rasterise
from intervalkin.app.surfaces import grid_geometry, label_surfaces
from intervalkin.app.units import phi_factor, phi_unit_name
from intervalkin.core.files import atomic_write
from intervalkin.paving.labels import Label, signed_labels
from intervalkin.paving.tree import Paving
from intervalkin.space.basic_region import RegionAnalysis

__all__ = ["write_vtu_paving", "workspace_fields", "write_workspace_vtu", "write_joint_vtu",
           "write_region_surfaces", "write_exports", "write_region_exports", "read_vtu", "SURFACE_BITS"]

#: Grid of the region surfaces: 2**7 cells per axis (x, y steps of 0.5, phi steps of 2.8 deg).
SURFACE_BITS = 7


def write_mesh(path, mesh, file_format: str = "vtu") -> Path:
    """Write a meshio mesh atomically (meshio writes a named file; it is then moved in place).

    meshio 5.3 reads the field data of a .vtu but does not write it: it is added here as a
    ``<FieldData>`` element of ASCII arrays, which ParaView and :func:`read_vtu` read.
    """
    import meshio

    path = Path(path)
    field_data = dict(mesh.field_data)
    mesh.field_data = {}
    with tempfile.TemporaryDirectory() as scratch:
        tmp = Path(scratch) / f"mesh.{file_format}"
        # STL is written binary (meshio's default is ASCII, five times larger)
        meshio.write(tmp, mesh, file_format=file_format, **({"binary": True} if file_format == "stl" else {}))
        if file_format == "vtu" and field_data:
            _insert_field_data(tmp, field_data)
        with open(tmp, "rb") as src:
            return atomic_write(path, lambda f: shutil.copyfileobj(src, f))


def _insert_field_data(path: Path, field_data: Mapping[str, np.ndarray]) -> None:
    """Put a ``<FieldData>`` block of ASCII arrays at the start of the ``<UnstructuredGrid>`` of a .vtu."""
    arrays = []
    for name, v in field_data.items():
        v = np.atleast_1d(np.asarray(v))
        kind = "Float64" if np.issubdtype(v.dtype, np.floating) else "Int64"
        text = " ".join(repr(float(x)) if kind == "Float64" else str(int(x)) for x in v)
        arrays.append(f'<DataArray type="{kind}" Name="{name}" NumberOfTuples="{v.size}" format="ascii">'
                      f"{text}</DataArray>\n")
    data = path.read_bytes()
    tag = b"<UnstructuredGrid>\n"
    at = data.index(tag) + len(tag)
    path.write_bytes(data[:at] + ("<FieldData>\n" + "".join(arrays) + "</FieldData>\n").encode() + data[at:])


def read_vtu(path):
    """Read a VTK file back (a :class:`meshio.Mesh`: points, cells, cell_data, field_data)."""
    import meshio

    return meshio.read(path)


def _smallest_int(a: np.ndarray) -> np.ndarray:
    """The values in the smallest signed integer type that holds them (smaller files)."""
    for t in (np.int8, np.int16, np.int32):
        info = np.iinfo(t)
        if a.size == 0 or (a.min() >= info.min and a.max() <= info.max):
            return a.astype(t)
    return a.astype(np.int64)


def _split_constant(fields: Mapping[str, np.ndarray]) -> tuple[dict, dict]:
    """(fields that vary over the cells, {name: value} of the constant ones)."""
    kept, constant = {}, {}
    for name, v in fields.items():
        v = np.asarray(v)
        if v.size and np.all(v == v[0]):
            constant[name] = v[0]
        else:
            kept[name] = v
    return kept, constant


def _hexahedra(lo, hi, depth: int, domain, fields: Mapping[str, np.ndarray], scale, field_data: dict):
    """A meshio mesh of merged integer boxes carrying integer ``fields`` (constant ones dropped)."""
    import meshio

    kept, constant = _split_constant(fields)
    names = list(kept)
    # one integer per distinct row of fields (mixed radix): a 1-D unique is much faster than a row unique
    code = np.zeros(len(lo), dtype=np.int64)
    for k in names:
        v = np.asarray(kept[k], dtype=np.int64)
        if v.size == 0:  # no box at all (a shallow run): an empty mesh
            continue
        code = code * (int(v.max() - v.min()) + 1) + (v - v.min())
    _, first, key = np.unique(code, return_index=True, return_inverse=True)
    m_lo, m_hi, m_key = merge_boxes(lo, hi, key.reshape(-1))
    points, conn = lattice_points(m_lo, m_hi, depth, domain)
    points = (points * np.asarray(scale, dtype=np.float64)).astype(np.float32)  # ParaView draws in float32
    cell_data = {k: [_smallest_int(np.asarray(kept[k])[first][m_key])] for k in names}
    fd = dict(field_data)
    fd.update({f"constant_{k}": np.array([v]) for k, v in constant.items()})
    return meshio.Mesh(points, [("hexahedron", conn)], cell_data=cell_data, field_data=fd)


def _phi_field_data(phi_unit) -> tuple[np.ndarray, dict]:
    factor = phi_factor(phi_unit)
    name = "phi_axis_" + phi_unit_name(phi_unit).replace(" ", "_")
    return np.array([1.0, 1.0, factor]), {name: np.array([factor])}


def write_vtu_paving(path, paving: Paving, cell_data: Mapping[str, np.ndarray], mask=None,
                     phi_unit="deg") -> Path:
    """.vtu of the selected boxes of a workspace paving (merged, constant fields dropped, phi scaled)."""
    sel = np.arange(len(paving)) if mask is None else np.asarray(mask)
    lo, hi = fine_bounds(paving.level[sel], paving.ijk[sel], paving.depth)
    scale, fd = _phi_field_data(phi_unit)
    fields = {k: np.asarray(v)[sel] for k, v in cell_data.items()}
    return write_mesh(path, _hexahedra(lo, hi, paving.depth, paving.domain, fields, scale, fd))


def workspace_fields(regions: RegionAnalysis) -> dict[str, np.ndarray]:
    """Per box of the regions paving: aspect, det_sign, basic_region, uniqueness_domain, cell, count."""
    p = regions.paving
    r = regions.region
    per_region = np.array([(x.cell, x.cell_count) for x in regions.regions] + [(-1, -1)], dtype=np.int64)
    return {
        "aspect": regions.aspect,
        "det_sign": signed_labels(p.labels["det_positive"]),
        "basic_region": r,
        "uniqueness_domain": regions.domain,
        "cell": per_region[r, 0],  # r = -1 picks the (-1, -1) row
        "count": per_region[r, 1],
    }


def write_workspace_vtu(path, regions: RegionAnalysis, phi_unit="deg") -> Path:
    """``workspace.vtu``: every box certified inside W, with :func:`workspace_fields`."""
    p = regions.paving
    return write_vtu_paving(path, p, workspace_fields(regions), mask=p.labels["W"] == Label.INSIDE,
                            phi_unit=phi_unit)


def write_joint_vtu(path, joint) -> Path:
    """``joint.vtu``: the boxes of certified joint cells, with cell, count, n_wa1, n_wa2 (merged)."""
    jb = joint_boxes(joint)
    cols = jb.columns
    sel = cols["cell"] >= 0
    fields = {k: cols[k][sel] for k in ("cell", "count", "n_wa1", "n_wa2")}
    mesh = _hexahedra(jb.lo[sel], jb.hi[sel], jb.depth, jb.domain, fields, (1.0, 1.0, 1.0), {})
    return write_mesh(path, mesh)


def write_region_surfaces(folder, regions: RegionAnalysis, phi_unit="deg", bits: int = SURFACE_BITS,
                          file_format: str = "vtu") -> list[Path]:
    """One boundary surface per basic region with certified boxes: ``basic_region_NN.<file_format>``.

    Triangles carry the region's fields (basic_region, uniqueness_domain, det_sign, cell, count)
    in VTU; ``file_format="stl"`` writes bare triangles for other tools.  phi scaled as the VTU.
    """
    import meshio

    p = regions.paving
    b = min(bits, p.depth)
    scale, fd = _phi_field_data(phi_unit)
    origin, spacing = grid_geometry(p.domain, b, scale)
    lo, hi = fine_bounds(p.level, p.ijk, p.depth)
    sel = regions.region >= 0
    grid = rasterise(lo[sel], hi[sel], regions.region[sel], p.depth, b)
    ids = [r.id for r in regions.regions if r.n_boxes > 0]
    surfaces = label_surfaces(grid, ids, origin, spacing)
    fields = workspace_fields(regions)
    written = []
    for rid in ids:
        s = surfaces[rid]
        if s.is_empty():
            continue
        box = np.flatnonzero(regions.region == rid)[0]
        data = {k: [np.full(s.n_faces, v[box], dtype=np.int32)] for k, v in fields.items() if k != "aspect"}
        mesh = meshio.Mesh(s.vertices.astype(np.float32), [("triangle", s.faces)],
                           cell_data=data if file_format == "vtu" else {},
                           field_data=fd if file_format == "vtu" else {})
        written.append(write_mesh(Path(folder) / f"basic_region_{rid:02d}.{file_format}", mesh, file_format))
    return written


def write_exports(analysis, out, phi_unit="deg") -> list[str]:
    """The ParaView files of an analysis under ``out``: workspace.vtu, joint.vtu and the region surfaces.

    Returns the paths written, relative to ``out`` (for summary.json's file list).
    """
    return write_region_exports(analysis.regions, analysis.joint, out, phi_unit)


def write_region_exports(regions, joint, out, phi_unit="deg") -> list[str]:
    """:func:`write_exports` from the regions and the joint enclosure (the joint cells are not drawn)."""
    out = Path(out)
    paths = [write_workspace_vtu(out / "pavings" / "workspace.vtu", regions, phi_unit),
             write_joint_vtu(out / "pavings" / "joint.vtu", joint)]
    paths += write_region_surfaces(out / "pavings" / "surfaces", regions, phi_unit)
    return [str(Path(p).relative_to(out)) for p in paths]
