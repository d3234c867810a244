"""Command-line options shared by several sub-commands: ``--geometry FILE``."""

from __future__ import annotations

from pathlib import Path

from intervalkin.core.geometry import Geometry, default_geometry, load_geometry


def geometry_from_option(path: str | Path | None) -> Geometry:
    """The geometry named on the command line, or the paper's default when None."""
    return default_geometry() if path is None else load_geometry(path)
