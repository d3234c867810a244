"""Worker processes for vectorised work that splits into independent parts.

The joint paving spends most of its time in kernels that treat each box (or each
point) on its own: the clear-box search, the local models, the side tests.  Cut
into parts, such work gives the same arrays whichever process computes each part,
so a second core can take a part while this process computes another, and the
answer is bit-for-bit the one of a single process.

:class:`Workers` owns the extra processes.  They are started on the first call
large enough to pay for them (forked where the platform can: no re-import, and
no need for a ``__main__`` guard in the caller's script), and stopped when the
``with`` block ends.  With one
worker, or for small calls, everything runs here, in order.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
from concurrent.futures import ProcessPoolExecutor
from typing import Any, Callable, Sequence

import numpy as np
from threadpoolctl import threadpool_limits

__all__ = ["Workers", "Beside", "default_workers", "owned_rows", "one_blas_thread", "MIN_PARALLEL_ITEMS"]

#: Calls on fewer items than this run in this process (a part must outweigh the cost of shipping it).
MIN_PARALLEL_ITEMS = 20000
#: Parts per process of a large call: small enough that the last ones balance the load.
PARTS_PER_PROCESS = 4


def default_workers() -> int:
    """Processes to use by default: two when the machine has two cores or more, one inside a daemonic
    process (such as a Dask worker, which may not start children)."""
    if multiprocessing.current_process().daemon:
        return 1
    return 2 if (os.cpu_count() or 1) > 1 else 1


def owned_rows(owner, parts: Sequence[tuple[int, int]]) -> list[tuple[int, int]]:
    """For rows sorted by ``owner`` (an int array), the row range of each owner range [start, stop)."""
    owner = np.asarray(owner)
    return [(int(np.searchsorted(owner, a, "left")), int(np.searchsorted(owner, b, "left"))) for a, b in parts]


def one_blas_thread():
    """A context in which BLAS runs on one thread.  The kernels here multiply many tiny matrices; a BLAS
    thread pool beside a second busy process spins for a core it does not get (measured: the window models
    of the default paving took 27 to 78 s with the default pool, 18 s with one thread)."""
    return threadpool_limits(limits=1, user_api="blas")


def _limited(fn: Callable[..., Any], args: tuple) -> Any:
    with one_blas_thread():
        return fn(*args)


def _context():
    # fork where there is one: a spawned interpreter would re-run the caller's main script, which breaks
    # every script without a __main__ guard; the forked worker shares this process's pages until it writes
    methods = multiprocessing.get_all_start_methods()
    return multiprocessing.get_context("fork" if "fork" in methods else "spawn")


class Workers:
    """Up to ``count`` processes: this one and ``count - 1`` started on demand.

    Use as a context manager; :meth:`parts` cuts n items into contiguous ranges and
    :meth:`run` computes one call per range, the first here and the others in the
    workers, and returns the results in order.  ``fn`` must be a module-level function
    and its arguments picklable.
    """

    def __init__(self, count: int = 1, min_items: int | None = None):
        if isinstance(count, bool) or not isinstance(count, int) or count < 1:
            raise ValueError(f"workers: expected a positive integer, got {count!r}")
        self.count = count
        self.min_items = min_items
        self._pool: ProcessPoolExecutor | None = None

    def __enter__(self) -> "Workers":
        return self

    def start(self) -> "Workers":
        """Start the workers now (a forked worker then shares only what this process holds so far)."""
        if self.count > 1 and self._pool is None:
            self._pool = ProcessPoolExecutor(max_workers=self.count - 1, mp_context=_context())
            for f in [self._pool.submit(os.getpid) for _ in range(self.count - 1)]:
                f.result()
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None

    def parts(self, n: int, least: int | None = None) -> list[tuple[int, int]]:
        """Contiguous ranges [start, stop) covering range(n): :data:`PARTS_PER_PROCESS` per process (parts no
        smaller than half the threshold), or one when n is below the threshold or there is one process.
        ``least``: the threshold for this call (default: the pool's ``min_items``, else MIN_PARALLEL_ITEMS)."""
        if least is None:
            least = MIN_PARALLEL_ITEMS if self.min_items is None else self.min_items
        k = 1 if self.count == 1 or n < least else max(2, min(PARTS_PER_PROCESS * self.count, 2 * n // max(least, 1)))
        cuts = [n * i // k for i in range(k + 1)]
        return [(cuts[i], cuts[i + 1]) for i in range(k)]

    def run(self, fn: Callable[..., Any], calls: Sequence[tuple]) -> list:
        """[fn(*args) for args in calls], in order, computed by this process and the workers at once.

        Every call but the first is queued for the workers; this process computes the first,
        then takes back, from the end, the queued calls no worker has started, so neither
        side waits long for the other whatever the calls cost.
        """
        if len(calls) <= 1 or self.count == 1:
            return [fn(*args) for args in calls]
        self.start()
        futures = [self._pool.submit(_limited, fn, args) for args in calls[1:]]
        out: list = [None] * len(calls)
        try:
            out[0] = _limited(fn, calls[0])
            for i in range(len(futures), 0, -1):
                if futures[i - 1].cancel():  # not started by a worker: computed here
                    out[i] = _limited(fn, calls[i])
            for i, f in enumerate(futures, start=1):
                if not f.cancelled():
                    out[i] = f.result()
            return out
        except BaseException:
            for f in futures:
                f.cancel()
            raise


class Beside:
    """``fn(*args)`` computed in a second process while this one goes on; :meth:`result` waits for it.

    For independent stages that are each serial: the second core takes one while this process does the
    others.  The process is forked, so ``fn`` and its arguments (a paving of a million boxes) are shared,
    not pickled; only the result comes back through a pipe.  It is daemonic (it dies with this process),
    so ``fn`` runs there on one process (:func:`default_workers` is 1).  Where no second process may be
    started (one core, a daemonic caller, no fork), ``fn`` runs here, at the first call of :meth:`result`.
    An exception of ``fn`` is raised by :meth:`result` either way.  Use as a context manager: leaving the
    block stops the process if it still runs.
    """

    def __init__(self, fn: Callable[..., Any], *args: Any):
        self._fn, self._args = fn, args
        self._proc = None
        self._recv = None
        self._got: tuple[bool, Any] | None = None
        if default_workers() > 1 and "fork" in multiprocessing.get_all_start_methods():
            ctx = multiprocessing.get_context("fork")
            self._recv, send = ctx.Pipe(duplex=False)
            self._proc = ctx.Process(target=_send_result, args=(send, fn, args), daemon=True)
            with _sigterm_blocked():  # the child unblocks it once it runs its own code (_send_result)
                self._proc.start()
            send.close()

    def __enter__(self) -> "Beside":
        return self

    def __exit__(self, *exc) -> None:
        if self._proc is not None:
            if self._proc.is_alive():
                self._proc.terminate()
                self._proc.join(EXIT_WAIT)
                if self._proc.is_alive():  # a child that ignored SIGTERM must not hold this process forever
                    self._proc.kill()
            self._proc.join()
            self._recv.close()
            self._proc = None

    def result(self) -> Any:
        if self._proc is None:
            return self._fn(*self._args)
        if self._got is None:
            try:
                self._got = self._recv.recv()
            except EOFError:
                self._proc.join()
                raise RuntimeError(f"the second process computing {self._fn.__name__} ended without a result "
                                   f"(exit code {self._proc.exitcode})") from None
        ok, value = self._got
        if not ok:
            raise value
        return value


#: Seconds a stopped second process is given to end before it is killed.
EXIT_WAIT = 5.0


@contextlib.contextmanager
def _sigterm_blocked():
    """SIGTERM held pending in this thread meanwhile.  A child forked here inherits the blocked signal: a SIGTERM
    sent right after the fork, before the child runs :func:`_send_result`, would otherwise run this process's
    handler (the command line's raises SystemExit) in the copy of this process's stack, and the child would go
    on with the parent's work (a test runner's loop, the parent's clean-up of its temporary files)."""
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGTERM})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _send_result(send, fn: Callable[..., Any], args: tuple) -> None:
    if hasattr(signal, "pthread_sigmask"):
        # this process's own code from here: SIGTERM ends it (a pending one now), whatever handler the parent had
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGTERM})
    try:
        out = (True, _limited(fn, args))
    except BaseException as exc:  # sent back whole, to be raised by the caller
        out = (False, exc)
    try:
        send.send(out)
    except Exception as exc:  # an unpicklable exception: its text still reaches the caller
        send.send((False, RuntimeError(f"{type(out[1]).__name__}: {out[1]} ({exc})")))
    send.close()
