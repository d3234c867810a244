"""Tri-state labels of boxes as bit flags: OUTSIDE = 1, INSIDE = 2, BOUNDARY = 3.

A label is the set of answers a sound evaluation still allows (bit 1: the predicate
may fail somewhere in the box, bit 2: it may hold somewhere).  Two sound labels of
the same predicate combine by ``&`` (keep what both allow; 0 would mean that two
sound evaluations contradict each other, which is asserted against); children are
merged into a parent by ``|``.  A conjunction of two DIFFERENT predicates is
:func:`and_labels` (OUTSIDE if either fails everywhere, INSIDE only if both hold
everywhere), and :func:`not_label` swaps INSIDE and OUTSIDE.
"""

from __future__ import annotations

import enum

import numpy as np

__all__ = ['Label', 'and_labels', 'not_label', 'signed_labels']


class Label(enum.IntEnum):
    """Tri-state certified answer of a predicate over a box (bit flags)."""

    CONTRADICTION = 0
    OUTSIDE = 1
    INSIDE = 2
    BOUNDARY = 3


def and_labels(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Conjunction of two DIFFERENT predicates: OUTSIDE if either is, INSIDE only if both are.

    >>> and_labels(np.array([1, 2, 2, 3], np.uint8), np.array([3, 2, 3, 3], np.uint8))
    array([1, 2, 3, 3], dtype=uint8)
    """
    a = np.asarray(a, dtype=np.uint8)
    b = np.asarray(b, dtype=np.uint8)
    out = np.full(np.broadcast_shapes(a.shape, b.shape), Label.BOUNDARY, dtype=np.uint8)
    out[(a == Label.INSIDE) & (b == Label.INSIDE)] = Label.INSIDE
    out[(a == Label.OUTSIDE) | (b == Label.OUTSIDE)] = Label.OUTSIDE
    return out


def not_label(a: np.ndarray) -> np.ndarray:
    """Negation: INSIDE <-> OUTSIDE, BOUNDARY stays (swap the two flag bits)."""
    a = np.asarray(a, dtype=np.uint8)
    return (((a & 1) << 1) | ((a & 2) >> 1)).astype(np.uint8)


def signed_labels(a: np.ndarray) -> np.ndarray:
    """Label -> int8 as the output files write it: INSIDE 1, BOUNDARY 0, OUTSIDE -1.

    >>> signed_labels(np.array([1, 2, 3], np.uint8))
    array([-1,  1,  0], dtype=int8)
    """
    a = np.asarray(a)
    out = np.zeros(a.shape, dtype=np.int8)
    out[a == Label.INSIDE] = 1
    out[a == Label.OUTSIDE] = -1
    return out
