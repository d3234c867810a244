"""Pavings as files: the npz columns, VTK hexahedra for ParaView, and readers for both.

Every writer goes through the atomic writer of :mod:`intervalkin.core.files`
(temporary file in the destination folder, then :func:`os.replace`), so a
reader never sees a half-written file.

``pavings/workspace.npz`` (one row per box; x, y, phi with phi in radians):

==================  ==========  ==========================================================
array               dtype       meaning
==================  ==========  ==========================================================
lo, hi              float64     (n, 3) box bounds (x, y, phi)
depth               int64       (n,) octree level of the box (leaf width = domain / 2**depth)
in_workspace        int8        1 certified in W, 0 undecided, -1 certified outside W
det_sign            int8        1 det A > 0 on the box, -1 det A < 0, 0 undecided (or not
                                evaluated: boxes certified outside W)
aspect              int32       component id of the certified aspect box, -1 for none
domain              float64     (3, 2) the paved domain
(extra columns)     any         e.g. ``basic_region``, ``uniqueness_domain`` (n,), added
                                by later stages through ``extra``
==================  ==========  ==========================================================
"""

from __future__ import annotations

import base64
import io
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Mapping

import numpy as np

from intervalkin.core.files import atomic_write, atomic_write_bytes
from intervalkin.paving.labels import signed_labels
from intervalkin.paving.tree import Paving

__all__ = ['NPZ_COLUMNS', 'paving_columns', 'write_npz', 'read_npz', 'write_vtu', 'write_vtu_paving', 'read_vtu', 'write_vtk_legacy']

NPZ_COLUMNS = ("lo", "hi", "depth", "in_workspace", "det_sign", "aspect")


def paving_columns(paving: Paving, aspect: np.ndarray | None = None,
                   extra: Mapping[str, np.ndarray] | None = None) -> dict[str, np.ndarray]:
    """The documented columns of a workspace paving (labels W, det_positive)."""
    n = len(paving)
    cols = {
        "lo": np.ascontiguousarray(paving.lo, dtype=np.float64),
        "hi": np.ascontiguousarray(paving.hi, dtype=np.float64),
        "depth": paving.level.astype(np.int64),
        "in_workspace": signed_labels(paving.labels["W"]),
        "det_sign": signed_labels(paving.labels["det_positive"]),
        "aspect": (np.full(n, -1, np.int32) if aspect is None else np.asarray(aspect, dtype=np.int32)),
    }
    for k, v in (extra or {}).items():
        v = np.asarray(v)
        if k in cols:
            raise ValueError(f"extra column {k!r}: name already used")
        if v.shape[:1] != (n,):
            raise ValueError(f"extra column {k!r}: expected {n} rows, got shape {v.shape}")
        cols[k] = v
    return cols


def write_npz(path, paving: Paving, aspect=None, extra=None) -> Path:
    """Write ``pavings/workspace.npz`` (compressed) with the documented columns plus ``extra``."""
    cols = paving_columns(paving, aspect, extra)
    cols["domain"] = np.asarray(paving.domain, dtype=np.float64)
    return atomic_write(Path(path), lambda f: np.savez_compressed(f, **cols))


def read_npz(path) -> dict[str, np.ndarray]:
    with np.load(path) as z:
        return {k: z[k] for k in z.files}


# --------------------------------------------------------------------------------------
# VTK
# --------------------------------------------------------------------------------------
# hexahedron corner order of VTK (cell type 12): bottom face counter-clockwise, then top
_HEX = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]])


def _hex_points(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    sel = _HEX[None, :, :]
    pts = np.where(sel == 0, lo[:, None, :], hi[:, None, :])
    return pts.reshape(-1, 3)


def _b64(arr: np.ndarray) -> str:
    """Inline binary DataArray payload: base64 of (UInt64 byte count + little-endian data)."""
    data = np.ascontiguousarray(arr).tobytes()
    return base64.b64encode(np.uint64(len(data)).astype("<u8").tobytes() + data).decode("ascii")


def _vtu_bytes(points: np.ndarray, connectivity: np.ndarray, offsets: np.ndarray,
               cell_data: Mapping[str, np.ndarray]) -> bytes:
    """An XML VTK UnstructuredGrid of hexahedra (cell type 12), arrays inline base64, int32 cell data."""
    int_type = {"<i4": "Int32", "<i8": "Int64"}[connectivity.dtype.str]
    n = offsets.size
    out = [
        '<?xml version="1.0"?>\n',
        '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">\n',
        f'<UnstructuredGrid>\n<Piece NumberOfPoints="{len(points)}" NumberOfCells="{n}">\n',
        '<Points>\n<DataArray type="Float64" NumberOfComponents="3" format="binary">\n',
        _b64(np.asarray(points, "<f8")), "\n</DataArray>\n</Points>\n<Cells>\n",
        f'<DataArray type="{int_type}" Name="connectivity" format="binary">\n',
        _b64(connectivity), "\n</DataArray>\n",
        f'<DataArray type="{int_type}" Name="offsets" format="binary">\n',
        _b64(offsets.astype(connectivity.dtype)), "\n</DataArray>\n",
        '<DataArray type="UInt8" Name="types" format="binary">\n',
        _b64(np.full(n, 12, dtype=np.uint8)), "\n</DataArray>\n</Cells>\n<CellData>\n",
    ]
    for name, arr in cell_data.items():
        out.append(f'<DataArray type="Int32" Name="{name}" format="binary">\n')
        out.append(_b64(np.asarray(arr).astype("<i4")))
        out.append("\n</DataArray>\n")
    out.append("</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n")
    return "".join(out).encode()


def write_vtu(path, lo: np.ndarray, hi: np.ndarray, cell_data: Mapping[str, np.ndarray]) -> Path:
    """XML VTK UnstructuredGrid (.vtu) of hexahedra (cell type 12) with int32 cell data.

    Arrays are inline base64 binary (fast to write, opens in ParaView).  Each box
    is its own 8-point hexahedron (points are not shared), which keeps the writer
    one vectorized pass; ParaView's "Clean" filter merges points if wanted.
    """
    n = lo.shape[0]
    pts = _hex_points(np.asarray(lo, "<f8"), np.asarray(hi, "<f8"))
    data = _vtu_bytes(pts, np.arange(8 * n, dtype="<i8"), 8 * np.arange(1, n + 1, dtype="<i8"), cell_data)
    return atomic_write_bytes(path, data)


def write_vtu_paving(path, paving: Paving, cell_data: Mapping[str, np.ndarray], mask=None) -> Path:
    """.vtu of the selected boxes of a paving, hexahedra sharing their corner points.

    Corners are identified by their integer coordinates at the paving's depth,
    so neighbouring boxes share points (about one point per box instead of
    eight) and connectivity is Int32: a file about a quarter of the size of
    :func:`write_vtu`.  Corner coordinates are the same floats as the box bounds.
    """
    sel = np.arange(len(paving)) if mask is None else np.flatnonzero(mask)
    flo, fhi = paving.fine_coordinates()
    flo, fhi = flo[sel], fhi[sel]
    nf = np.int64(1) << paving.depth
    corners = np.stack([np.where(_HEX[None, :, a] == 0, flo[:, None, a], fhi[:, None, a]) for a in range(3)], axis=-1)
    keys = (corners[..., 0] * (nf + 1) + corners[..., 1]) * (nf + 1) + corners[..., 2]
    uniq, inverse = np.unique(keys.ravel(), return_inverse=True)
    k = np.stack([uniq // ((nf + 1) * (nf + 1)), (uniq // (nf + 1)) % (nf + 1), uniq % (nf + 1)], axis=1)
    dom = np.asarray(paving.domain, dtype=np.float64)
    step = np.ldexp(dom[:, 1] - dom[:, 0], -paving.depth)
    pts = np.where(k == nf, dom[:, 1], dom[:, 0] + k * step)
    n = sel.size
    data = _vtu_bytes(pts, inverse.astype("<i4"), 8 * np.arange(1, n + 1, dtype="<i4"),
                      {name: np.asarray(arr)[sel] for name, arr in cell_data.items()})
    return atomic_write_bytes(path, data)


def read_vtu(path) -> dict[str, np.ndarray]:
    """Read back a file written by :func:`write_vtu` (points, cell types, cell data)."""
    dtypes = {"Float64": "<f8", "Int64": "<i8", "UInt8": "u1", "Int32": "<i4"}
    root = ET.parse(path).getroot()
    piece = root.find("UnstructuredGrid/Piece")
    out = {"NumberOfCells": np.int64(piece.get("NumberOfCells")), "NumberOfPoints": np.int64(piece.get("NumberOfPoints"))}
    for da in root.iter("DataArray"):
        raw = base64.b64decode(da.text.strip())
        nbytes = int(np.frombuffer(raw[:8], "<u8")[0])
        arr = np.frombuffer(raw[8:8 + nbytes], dtypes[da.get("type")])
        name = da.get("Name") or "points"
        out[name] = arr.reshape(-1, 3) if name == "points" else arr
    return out


def write_vtk_legacy(path, lo: np.ndarray, hi: np.ndarray, cell_data: Mapping[str, np.ndarray]) -> Path:
    """Legacy ASCII VTK (.vtk) UNSTRUCTURED_GRID of hexahedra with integer cell data."""
    n = lo.shape[0]
    pts = _hex_points(lo, hi)
    out = ["# vtk DataFile Version 3.0\nintervalkin paving\nASCII\nDATASET UNSTRUCTURED_GRID\n"]
    out.append(f"POINTS {8 * n} double\n")
    out.append(_fmt(pts, "%.17g"))
    conn = np.hstack([np.full((n, 1), 8, np.int64), np.arange(8 * n, dtype=np.int64).reshape(n, 8)])
    out.append(f"CELLS {n} {9 * n}\n")
    out.append(_fmt(conn, "%d"))
    out.append(f"CELL_TYPES {n}\n")
    out.append(_fmt(np.full((n, 1), 12, np.int64), "%d"))
    out.append(f"CELL_DATA {n}\n")
    for name, arr in cell_data.items():
        out.append(f"SCALARS {name} int 1\nLOOKUP_TABLE default\n")
        out.append(_fmt(np.asarray(arr).astype(np.int64)[:, None], "%d"))
    return atomic_write_bytes(path, "".join(out).encode())


def _fmt(a: np.ndarray, fmt: str) -> str:
    if a.size == 0:
        return ""
    buf = io.StringIO()
    np.savetxt(buf, a, fmt=fmt)
    return buf.getvalue()
