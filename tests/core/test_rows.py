"""distinct_rows: bitwise row identity found by hashing, checked against a sort-based reference."""

from __future__ import annotations

import numpy as np

import intervalkin.core.rows as rows_module
from intervalkin.core.rows import distinct_rows


def _check(parts, rep, inv):
    table = np.concatenate([np.asarray(p).reshape(len(p), -1).view(np.uint64) for p in parts], axis=1)
    assert np.array_equal(table[rep][inv], table), "a row maps to a representative that differs from it"
    assert len(np.unique(table[rep], axis=0)) == len(rep), "two representatives are equal"
    assert np.all(np.diff(rep) > 0)


def test_rows_of_floats_and_integers():
    rng = np.random.default_rng(3)
    cells = rng.choice(np.array([-0.0, 0.0, 0.5, np.pi, np.nan, -np.inf]), size=(5000, 4))
    owner = rng.integers(0, 7, 5000)
    rep, inv = distinct_rows([owner, cells])
    _check([owner, cells], rep, inv)


def test_collisions_are_resolved(monkeypatch):
    """With a table of 2**10 buckets for ~4000 distinct rows, most rows share a bucket with
    another value: each is compared, hashed again, and still mapped exactly."""
    monkeypatch.setattr(rows_module, "_MAX_BITS", 10)
    a = np.arange(4000, dtype=np.float64).repeat(3)
    rep, inv = distinct_rows([a, -a])
    _check([a, -a], rep, inv)
    assert len(rep) == 4000


def test_empty_table():
    rep, inv = distinct_rows([np.zeros(0), np.zeros((0, 2))])
    assert rep.size == 0 and inv.size == 0
