"""Work cut into parts on worker processes gives the answer of one process, in order."""

from __future__ import annotations

import os

import numpy as np
import pytest

from intervalkin.core import workers as workers_module
from intervalkin.core.geometry import default_geometry
from intervalkin.core.workers import Beside, Workers, owned_rows
from intervalkin.space.joint_paving import pave_joint_space


def _square_and_pid(x: np.ndarray) -> tuple[np.ndarray, int]:
    return x * x, os.getpid()


def test_parts_cover_the_items_once():
    w = Workers(3, min_items=10)
    for n in (0, 1, 9, 10, 11, 1000):
        parts = w.parts(n)
        covered = np.concatenate([np.arange(a, b) for a, b in parts]) if parts else np.zeros(0)
        assert np.array_equal(covered, np.arange(n))
        assert (len(parts) > 1) == (n >= 10)


def test_owned_rows_follow_the_owners():
    owner = np.array([0, 0, 1, 3, 3, 3, 4])
    assert owned_rows(owner, [(0, 2), (2, 4), (4, 5)]) == [(0, 3), (3, 6), (6, 7)]


def test_run_keeps_the_order_and_uses_a_second_process():
    x = np.arange(40000, dtype=np.float64)
    with Workers(2) as w:
        parts = w.parts(len(x))
        out = w.run(_square_and_pid, [(x[a:b],) for a, b in parts])
    assert len(out) == len(parts) > 1
    assert np.array_equal(np.concatenate([o for o, _ in out]), x * x)
    assert out[0][1] == os.getpid() and any(pid != os.getpid() for _, pid in out)


def _fails(message: str) -> None:
    raise KeyError(message)


def test_beside_computes_in_a_second_process_and_passes_errors_on(monkeypatch):
    x = np.arange(1000.0)
    with Beside(_square_and_pid, x) as side:
        square, pid = side.result()
        assert side.result()[1] == pid  # asked twice: the same answer, not a second wait
    assert np.array_equal(square, x * x)
    assert pid != os.getpid()
    with Beside(_fails, "no such cell") as side, pytest.raises(KeyError, match="no such cell"):
        side.result()
    # where no second process may run, the call is made here, when its result is asked for
    monkeypatch.setattr(workers_module, "default_workers", lambda: 1)
    with Beside(_square_and_pid, x) as side:
        assert side.result()[1] == os.getpid()


def _sleep(seconds: float) -> None:
    import time
    time.sleep(seconds)


def test_a_second_process_stopped_at_once_ends_and_never_runs_this_one(monkeypatch):
    """The command line turns SIGTERM into SystemExit.  A second process stopped right after its fork, before it
    runs its own code, must end there: not raise that exit in its copy of this process's stack and go on with
    this process's work (here: this loop, which would then run twice), and not hold the caller in a join."""
    import signal
    import time

    def exit_on_term(signum, frame):
        raise SystemExit(128 + signum)

    previous = signal.signal(signal.SIGTERM, exit_on_term)
    me = os.getpid()
    try:
        t0 = time.perf_counter()
        for _ in range(30):
            with Beside(_sleep, 60.0) as side:
                pid = side._proc.pid
            assert os.getpid() == me  # a child that escaped into this loop would fail here, in its own copy
            with pytest.raises(ProcessLookupError):
                os.kill(pid, 0)  # ended and reaped
        assert time.perf_counter() - t0 < 60
    finally:
        signal.signal(signal.SIGTERM, previous)


def test_bad_worker_counts_are_refused():
    for bad in (0, -1, True, 1.5):
        with pytest.raises(ValueError):
            Workers(bad)


def test_joint_paving_is_the_same_with_two_workers(monkeypatch):
    # small parts, so a depth-4 paving really is cut: every column must be identical, bit for bit
    monkeypatch.setattr(workers_module, "MIN_PARALLEL_ITEMS", 64)
    g = default_geometry()
    one = pave_joint_space(g, 4, model_levels=1, face_levels=0, workers=1)
    two = pave_joint_space(g, 4, model_levels=1, face_levels=0, workers=2)
    a, b = one.columns(), two.columns()
    assert a.keys() == b.keys()
    for k in a:
        assert np.array_equal(a[k], b[k], equal_nan=True), k
    assert [c.signature for c in one.cells] == [c.signature for c in two.cells]
    assert np.array_equal(one.pieces.edges, two.pieces.edges)
    assert np.array_equal(one.piece_signatures.signature, two.piece_signatures.signature)
