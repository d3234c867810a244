"""The pairs of region boxes whose intersection is 2- or 3-dimensional, found by a sweep along x, against the
definition checked pair by pair."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import intervalkin.recheck.region_boundary as rb


def _brute(lo, hi):
    out = []
    for i in range(lo.shape[0]):
        for j in range(i + 1, lo.shape[0]):
            e_lo, e_hi = np.maximum(lo[i], lo[j]), np.minimum(hi[i], hi[j])
            if np.all(e_lo <= e_hi) and int(np.sum(e_lo < e_hi)) >= 2:
                out.append((i, j))
    return out


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 90), st.sampled_from([1, 3, 7, 512]))
def test_face_pairs_are_those_of_the_definition(seed, n, chunk):
    """Boxes on a coarse grid of coordinates (so that faces, edges and corners touch often, and some boxes repeat
    or are flat), in runs of 1, 3, 7 or 512: the same pairs as the pair-by-pair test, in (i, j) order.  The slab's
    conditions made strict (boxes touching across a plane x = v dropped) or the candidates past the first piece
    left out would lose pairs."""
    rng = np.random.default_rng(seed)
    a = rng.integers(0, 6, (n, 3)).astype(float)
    b = a + rng.integers(0, 3, (n, 3))
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    old = rb._CHUNK, rb._CELLS
    try:
        rb._CHUNK, rb._CELLS = chunk, 5
        i, j = rb.face_pairs(lo, hi)
    finally:
        rb._CHUNK, rb._CELLS = old
    assert list(zip(i.tolist(), j.tolist())) == _brute(lo, hi)
