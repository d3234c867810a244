"""Atomic file writing: the one way intervalkin puts a file on disk.

A writer fills a temporary file in the destination folder, flushes it to the
disk, gives it the permissions a plain ``open`` would (``0o666`` less the
umask) and moves it in place with :func:`os.replace`, which is atomic within a
file system.  A reader (or a second run) therefore sees either the old file or
the complete new one, never a half-written file; on any error the temporary
file is removed and the destination is left as it was.

Every output of the package goes through here: pavings (npz, VTK), JSON
summaries, certificate files, reports, figures and the trajectory animation.
"""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path
from typing import IO, Any, Callable

__all__ = ['atomic_write', 'atomic_write_bytes', 'write_json']


def atomic_write(path, write: Callable[[IO[bytes]], Any]) -> Path:
    """Create ``path`` (and its folder) from ``write(f)``, ``f`` a binary file object; atomic.

    Returns the path written.  Whatever ``write`` raises propagates, after the
    temporary file is removed.
    """
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
    """Write ``data`` to ``path`` atomically; returns the path."""
    return atomic_write(path, lambda f: f.write(data))


def write_json(path, obj, indent: int = 2) -> Path:
    """Write ``obj`` as JSON (``indent`` spaces, trailing newline, no NaN), atomically; returns the path."""
    data = (json.dumps(obj, indent=indent, allow_nan=False) + "\n").encode()
    return atomic_write_bytes(path, data)
