"""Writers for pavings: npz, JSON and VTK, each atomic.

Every writer writes a temporary file in the destination folder and moves it in
place with :func:`os.replace`, so a reader never sees a half-written file.

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

import json
import os
import tempfile
from pathlib import Path

__all__ = ['atomic_write_bytes', 'write_json']


def _atomic(path: Path, write) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            write(f)
            f.flush()
            os.fsync(f.fileno())
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)  # mkstemp creates 0600; give the usual permissions
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
    return path


def atomic_write_bytes(path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically (temp file in the same folder, then os.replace)."""
    return _atomic(Path(path), lambda f: f.write(data))


def write_json(path, obj) -> Path:
    """Write a JSON document (indented, sorted keys off, trailing newline), atomically."""
    data = (json.dumps(obj, indent=2, allow_nan=False) + "\n").encode()
    return atomic_write_bytes(path, data)
