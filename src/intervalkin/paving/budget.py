"""Octree pavings of the workspace domain: subdivision, tri-state labels, face adjacency.

A paving is a set of axis-aligned boxes (x, y, phi) that tile a domain.  Each box
is stored twice, consistently:

* as integer coordinates ``(level, i, j, k)``: at ``level`` the domain is cut into
  ``2**level`` slices per axis and the box is slice ``(i, j, k)``;
* as float bounds ``lo``, ``hi`` of shape (n, 3), computed from the integers by one
  formula (``lo = domain_lo + i * (width * 2**-level)``), so that two boxes that
  share a face share it bit for bit, whatever their levels.

Depth d means leaf width = domain width / 2**d on every axis.  Only undecided boxes
are split, level by level, with numpy over all boxes of a level (no Python loop
per box).

Labels are ``uint8`` arrays of :class:`Label` flags: OUTSIDE = 1 (the predicate
fails at every point of the box), INSIDE = 2 (it holds at every point),
BOUNDARY = 3 (not decided).  ``a & b`` keeps the sharper of two sound labels of the
same predicate; 0 would mean a contradiction, i.e. an unsound evaluation, and is
asserted against.

The phi axis is periodic.  The phi range of the domain is widened outward to
[-PI_HI, PI_HI] (PI_HI is the float just above pi), so the boxes cover every angle
and the two boxes on either side of the seam overlap (by ~1e-16) modulo 2 pi:
their union is connected, which is what the seam adjacency claims.

Face adjacency (``shares_face``): two boxes are adjacent when they share a 2-D
piece of a face (a common edge or corner is not enough).  In an x-phi section
(faces are drawn as edges)::

      phi = +pi  +---------+----+----+      ^ phi
                 |         | b  | c  |      |
                 |    a    +----+----+      +--> x
                 |         | d  | e  |
                 +----+----+----+----+      a-b, a-d, a-f, a-g: share a face piece
                 | f  | g  |         |      d-h, e-h, g-h, j-h: share a face piece
                 +----+----+    h    |      a-h, d-g: a corner only, NOT adjacent
                 | i  | j  |         |
      phi = -pi  +----+----+---------+
                 seam: phi = +pi is phi = -pi, so the top faces of a, b, c touch
                 the bottom faces of i, j, h: a-i, a-j, b-h, c-h are adjacent too.

All adjacency pairs are computed in bulk from the integer coordinates: along an
axis, a "+" face and a "-" face on the same plane overlap in 2-D exactly when one
dyadic square contains the other, so each face looks up its ancestors' keys
(one sorted search per level).
"""

from __future__ import annotations

import math

import numpy as np

from intervalkin.core.errors import InputError, ResourceError

__all__ = ['MAX_DEPTH', 'estimate_memory_bytes', 'available_memory_bytes', 'check_depth']

#: Deepest octree accepted (leaf width 64 / 2**11 ~ 0.03 in x, y); memory is checked too.
MAX_DEPTH = 11


# --------------------------------------------------------------------------------------
# Memory
# --------------------------------------------------------------------------------------
#: Calibrated on the paper's manipulator (benchmarks/bench_paving.py): boxes evaluated
#: at the deepest level ~ _LEAF_FACTOR * 4**depth; the estimate takes twice as many.
_LEAF_FACTOR = 14.0
#: Peak bytes per box of the deepest level during evaluation (temporaries included).
_BYTES_PER_BOX = 600.0
_BYTES_BASE = 150e6


def estimate_memory_bytes(depth: int) -> float:
    """A generous estimate of the peak memory of a workspace paving at ``depth``.

    The undecided layer is a surface, so the boxes of the deepest level grow like
    4**depth; the constants come from measured runs with a safety factor of ~1.5.
    """
    n = 1.5 * _LEAF_FACTOR * 4.0 ** depth
    return _BYTES_BASE + _BYTES_PER_BOX * n


def available_memory_bytes() -> float:
    """MemAvailable from /proc/meminfo (bytes); +inf when it cannot be read."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0
    except OSError:
        pass
    return math.inf


def check_depth(depth, max_depth: int = MAX_DEPTH) -> int:
    """Validate a depth before any work: an integer in 1..max_depth whose memory fits.

    Raises :class:`InputError` (not an integer, out of range) or
    :class:`ResourceError` (the estimate exceeds MemAvailable), one line each.
    """
    if isinstance(depth, bool) or not isinstance(depth, (int, np.integer)):
        raise InputError(f"depth: expected an integer in 1..{max_depth}, got {depth!r}")
    depth = int(depth)
    if not 1 <= depth <= max_depth:
        raise InputError(f"depth: expected an integer in 1..{max_depth}, got {depth}")
    need = estimate_memory_bytes(depth)
    have = available_memory_bytes()
    if need > have:
        raise ResourceError(
            f"depth {depth}: estimated memory {need / 2**30:.1f} GiB exceeds available {have / 2**30:.1f} GiB; use a smaller depth"
        )
    return depth
