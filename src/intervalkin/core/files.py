"""Atomic file writing: the one way intervalkin puts a file on disk.

A writer fills a temporary file in the destination folder, flushes it to the
disk, gives it the permissions a plain ``open`` would (``0o666`` less the
umask) and moves it in place with :func:`os.replace`, which is atomic within a
file system.  A reader (or a second run) therefore sees either the old file or
the complete new one, never a half-written file; on any error the temporary
file is removed and the destination is left as it was.

Every output of the package goes through here: pavings (npz, VTK), JSON
summaries, certificate files, reports, figures and the trajectory animation.
So this is also where a command learns which files it wrote: inside
:func:`watching_writes`, every destination is reported to a callback just
before it is moved in place (the output folder's manifest is kept that way,
and a file is listed before it exists, never after: an interrupted run leaves
no unlisted file behind).
"""

from __future__ import annotations

import json
import os
import tempfile
import zipfile
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any, Callable, Iterator

import numpy as np

__all__ = ['atomic_write', 'atomic_write_bytes', 'write_json', 'watching_writes', 'write_npz_columns', 'NPZ_LEVEL']

#: zlib level of the npz files: 1 writes the pavings about four times faster than numpy's ``savez_compressed``
#: (level 6), for files about a fifth larger (the paper run's workspace paving: 4.0 s -> 0.9 s, 16 -> 20 MB).
NPZ_LEVEL = 1

#: Callbacks told of each destination before it is replaced (see :func:`watching_writes`).
_watchers: list[Callable[[Path], None]] = []


@contextmanager
def watching_writes(callback: Callable[[Path], None]) -> Iterator[None]:
    """Within the ``with`` block, call ``callback(path)`` for every file :func:`atomic_write` is about to create.

    The call comes after the data are on disk under the temporary name and
    before the rename, so a callback that records ``path`` records it before the
    file appears.  If the callback raises, the write is abandoned (the
    temporary file is removed) and the exception propagates.
    """
    _watchers.append(callback)
    try:
        yield
    finally:
        _watchers.remove(callback)


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
        for watch in list(_watchers):
            watch(path)
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


def write_npz_columns(fh: IO[bytes], cols: dict) -> None:
    """Named arrays into an open binary file as a compressed npz (one ``name.npy`` member each, what
    :func:`numpy.load` reads), deflated at :data:`NPZ_LEVEL`; no pickled objects."""
    with zipfile.ZipFile(fh, "w", compression=zipfile.ZIP_DEFLATED, compresslevel=NPZ_LEVEL) as z:
        for name, value in cols.items():
            with z.open(f"{name}.npy", "w", force_zip64=True) as member:
                np.lib.format.write_array(member, np.asanyarray(value), allow_pickle=False)
