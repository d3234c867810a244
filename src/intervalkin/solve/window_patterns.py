"""Patterns of pair windows: which of the 2**k statuses of a leaf's k pair windows a way keeps.

A pair window (:mod:`intervalkin.solve.window_fold`) holds no root or two at each point of its leaf.  A PATTERN
fixes that status for each of the leaf's live pair windows (1: two roots, 0: none).  With u = min over the window
of s f (s the window's end sign), the window is empty where u > 0 and holds its two roots where u < 0, and along a
way u moves, wherever it can vanish, with a proved sign (+1, -1) or the window is STEADY (it keeps its status
whatever the way).  A way keeps the pattern when no empty window's u falls and no full window's u rises there
(proofs/lemma-joint-retraction.md, "Retraction" and "Cusp patterns").  Pure functions over sign arrays: what is
certified is the signs handed in.
"""

from __future__ import annotations

import numpy as np

from intervalkin.solve.window_fold import STEADY

__all__ = ["patterns", "pattern_keeps", "curved_keeps"]


def patterns(k: int):
    """The 2**k patterns of k pair windows: (k,) int64, 1 where the window holds its two roots."""
    for pattern in range(1 << k):
        yield np.array([(pattern >> i) & 1 for i in range(k)], dtype=np.int64)


def pattern_keeps(signs: np.ndarray, real: np.ndarray) -> np.ndarray:
    """(m, c) bool from the signs (m, k, c) of the pattern's k windows along c ways: the ways along which no u
    falls where its window is empty and none rises where it holds its two roots (or the window is STEADY)."""
    return ((signs * (1 - 2 * real)[None, :, None] == 1) | (signs == STEADY)).all(axis=1)


def curved_keeps(drive: np.ndarray, signs: np.ndarray, faces: np.ndarray, steady: np.ndarray,
                 real: np.ndarray) -> np.ndarray:
    """(m, ways, 6): the faces ``faces`` (m, ways, 6) of curved ways, r' = d (u - q v) times a positive factor with
    d = ``drive`` (m, ways), that keep the pattern ``real`` (k,) too.  ``signs`` (m, k, ways): the sign of
    s (D_u f - q D_v f) proved on each window's critical pieces for every q of the way, so u moves with d times
    it; ``steady`` (m, k, 1): the windows that keep their status along any way.  A way with d = 0 is not
    proved and has no faces."""
    d = drive.astype(np.int64)
    moves = np.where(steady, STEADY, d[:, None, :] * signs)
    return faces & (pattern_keeps(moves, real) | (d == 0))[..., None]
