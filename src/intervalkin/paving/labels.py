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
