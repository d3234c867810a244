"""How deep a paving may go: the depth range, and a memory estimate checked before any work.

The undecided boxes of a paving lie along surfaces, so their number grows like
4**depth; :func:`check_depth` refuses a depth whose estimated peak memory exceeds
what the machine has available (MemAvailable), with a one-line error, instead of
letting the run be killed half way.
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
