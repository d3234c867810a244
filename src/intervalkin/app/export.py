"""Pavings as npz files: the documented columns, and their reader (the VTK files: :mod:`intervalkin.app.vtk_export`).

Every writer goes through the atomic writer of :mod:`intervalkin.core.files`
(temporary file in the destination folder, then :func:`os.replace`), so a
reader never sees a half-written file.  The columns below are a contract: they
do not change when the VTK exports do.

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

from pathlib import Path
from typing import Mapping

import numpy as np

# the VTK writers live in vtk_export (meshio); the command handlers import them from here
from intervalkin.app.vtk_export import read_vtu, write_vtu_paving
from intervalkin.core.files import atomic_write, write_npz_columns
from intervalkin.paving.labels import signed_labels
from intervalkin.paving.tree import Paving

__all__ = ['NPZ_COLUMNS', 'paving_columns', 'write_npz', 'read_npz', 'write_vtu_paving', 'read_vtu']

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
    return atomic_write(Path(path), lambda f: write_npz_columns(f, cols))


def read_npz(path) -> dict[str, np.ndarray]:
    """Every array of an npz file written by :func:`write_npz` (or ``joint.npz``), by name."""
    with np.load(path) as z:
        return {k: z[k] for k in z.files}
