"""Distinct rows of a table of numbers, compared bit for bit, in linear time.

A paving hands the same work to many boxes (a parent's live cells go to all eight
children, and four of them share rho_1), so a kernel that depends on a few columns
only can evaluate each distinct row once and gather the result.  :func:`distinct_rows`
finds them with a hash table instead of a sort: O(m) passes over the columns.

Equality is bitwise (``-0.0`` and ``0.0`` are different rows, a NaN equals itself), so
a row and its representative give bit-identical results under any float function.
The hash only places rows in buckets: every row is then compared, column by column,
with the row that holds its bucket, and rows that collided are hashed again with
another salt.  So the answer never depends on the hash being good, only the time.
"""

from __future__ import annotations

import numpy as np

__all__ = ["distinct_rows", "ramp"]

#: Multiplier of the hash (the 64-bit golden ratio, odd) and the shift that folds high bits down.
_MIX = np.uint64(0x9E3779B97F4A7C15)
_FOLD = np.uint64(29)
#: Hash table sizes (log2): at least twice the rows, within these bounds.
_MIN_BITS, _MAX_BITS = 10, 22
#: Rows hashed and compared together.
_PIECE = 1 << 19


def _bits_of(part: np.ndarray) -> np.ndarray:
    """The part as uint64 bit patterns, shape (m, c): a view of 8-byte numbers, so no float comparison anywhere."""
    p = np.asarray(part)
    if p.dtype.itemsize != 8 or p.dtype.kind not in "fiu":
        p = p.astype(np.int64)
    p = p.view(np.uint64)  # also for a strided column: the item size does not change
    return p[:, None] if p.ndim == 1 else p


def _hash(parts: list[np.ndarray], salt: int) -> np.ndarray:
    h = np.full(len(parts[0]), np.uint64(salt), dtype=np.uint64)
    tmp = np.empty_like(h)
    for p in parts:
        for j in range(p.shape[1]):  # h = mix(h) ^ column, then spread over all bits
            np.right_shift(h, _FOLD, out=tmp)
            h ^= tmp
            h ^= p[:, j]
            h *= _MIX
    np.right_shift(h, _FOLD, out=tmp)
    h ^= tmp
    return h


def distinct_rows(parts: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """(rep, inv) for the rows of the table made of ``parts``, each (m,) or (m, c) (floats or integers).

    ``rep`` (k,) int64: one row of each distinct value (increasing row numbers); ``inv`` (m,)
    int64: row i is bitwise equal, in every column, to row ``rep[inv[i]]``.

    >>> a = np.array([1.0, 2.0, 1.0, -0.0, 0.0]); b = np.array([5, 6, 5, 7, 7])
    >>> rep, inv = distinct_rows([a, b])
    >>> len(rep), bool(inv[0] == inv[2]), bool(inv[3] != inv[4])  # -0.0 is not 0.0, bit for bit
    (4, True, True)
    """
    parts = [_bits_of(p) for p in parts]
    m = len(parts[0])
    if m == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    rep = np.empty(m, dtype=np.int64)
    todo, salt = None, 0  # None: all rows
    while todo is None or todo.size:
        sub = parts if todo is None else [p[todo] for p in parts]
        size = m if todo is None else todo.size
        bits = min(_MAX_BITS, max(_MIN_BITS, int(size).bit_length() + 1))
        shift = np.uint64(64 - bits)
        table = np.empty(1 << bits, dtype=np.int32 if size < 2**31 else np.int64)  # half the cache misses
        # pieces of _PIECE rows: the temporaries stay small enough for malloc to recycle (a block
        # above its mmap threshold is mapped, and page-faulted, afresh each time); the hash is
        # computed twice rather than stored
        for s in range(0, size, _PIECE):
            table[_hash([p[s:s + _PIECE] for p in sub], salt) >> shift] = np.arange(s, min(s + _PIECE, size))
        left = []
        for s in range(0, size, _PIECE):
            piece = [p[s:s + _PIECE] for p in sub]
            held = table[_hash(piece, salt) >> shift].astype(np.int64)  # the row that holds the bucket (any one)
            same = np.ones(len(held), dtype=bool)
            for p, whole in zip(piece, sub):
                q = whole[held]  # whole rows at once: one cache line per row
                for j in range(p.shape[1]):
                    same &= q[:, j] == p[:, j]
            rows = np.arange(s, s + len(held))
            if todo is None:
                rep[rows[same]] = held[same]
            else:
                rep[todo[rows[same]]] = todo[held[same]]
            left.append(rows[~same] if todo is None else todo[rows[~same]])
        todo = np.concatenate(left)  # these met another value in their bucket: hash them again
        salt = (salt + int(_MIX)) % 2**64
    first = np.flatnonzero(rep == np.arange(m))
    pos = np.empty(m, dtype=np.int64)
    pos[first] = np.arange(first.size)
    return first, pos[rep]


def ramp(lengths: np.ndarray) -> np.ndarray:
    """0, 1, ..., len - 1 for each length in turn: the offsets inside runs laid end to end."""
    lengths = np.asarray(lengths, dtype=np.int64)
    starts = np.repeat(np.cumsum(lengths) - lengths, lengths)
    return np.arange(int(lengths.sum()), dtype=np.int64) - starts
