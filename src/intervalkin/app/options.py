"""Command-line options shared by several sub-commands: ``--geometry FILE`` and the depth ranges.

Each sub-command's depth means something different (a workspace octree, a joint
grid, the whole chain), so each has its own range; the ranges live here, once,
so that ``--help`` shows the range each command checks.  Every check runs
before any work and before an output folder is made.
"""

from __future__ import annotations

from pathlib import Path

from intervalkin.core.errors import InputError
from intervalkin.core.geometry import Geometry, default_geometry, load_geometry
from intervalkin.paving.budget import MAX_DEPTH
from intervalkin.pipeline import MAX_CHAIN_DEPTH

__all__ = ['PAVE_DEPTHS', 'JOINT_DEPTHS', 'CHAIN_DEPTHS', 'depth_help', 'check_joint_depth', 'geometry_from_option']

#: ``pave --depth``: workspace octree levels (memory is checked too, by paving.budget).
PAVE_DEPTHS = (1, MAX_DEPTH)
#: ``joint --depth``: 2**N voxels per joint-space axis.
JOINT_DEPTHS = (2, 8)
#: ``analyze``, ``paper``, ``label``, ``trajectory``: depth of the regions paving (pipeline.check_chain_depth).
CHAIN_DEPTHS = (3, MAX_CHAIN_DEPTH)


def depth_help(what: str, depths: tuple[int, int], default: int) -> str:
    """The ``--help`` text of a depth option: what it is, its range and its default."""
    return f"{what}, {depths[0]}..{depths[1]} (default {default})"


#: ``analyze``/``paper --barrier-faces``: faces the pattern barriers may relate in all (certify.separation_claims).
BARRIER_FACES = (0, 4_000_000)


def check_barrier_faces(n) -> int:
    """``--barrier-faces``: an integer in BARRIER_FACES, else :class:`InputError` naming the flag.  The upper end
    keeps a run to hours (about 5 ms per face) and the flood's tables to a few GB."""
    lo, hi = BARRIER_FACES
    if isinstance(n, bool) or not isinstance(n, int) or not lo <= n <= hi:
        raise InputError(f"--barrier-faces: expected an integer in {lo}..{hi} (faces the pattern barriers may "
                         f"relate), got {n!r}")
    return n


def check_joint_depth(depth) -> int:
    """``joint --depth``: an integer in JOINT_DEPTHS, else :class:`InputError` naming the flag."""
    lo, hi = JOINT_DEPTHS
    if isinstance(depth, bool) or not isinstance(depth, int) or not lo <= depth <= hi:
        raise InputError(f"--depth: expected an integer in {lo}..{hi} (voxels per axis 2**depth), got {depth!r}")
    return depth


def geometry_from_option(path: str | Path | None) -> Geometry:
    """The geometry named on the command line, or the paper's default when None."""
    return default_geometry() if path is None else load_geometry(path)
