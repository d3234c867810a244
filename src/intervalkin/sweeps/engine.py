"""The sweep: one certified analysis per design as a Dask task, cached by content hash, resumable.

:func:`sweep` expands a sweep file into designs, reads every design already in the cache
(``cache/<key>.json``, ``key`` the content hash of the design's exact geometry and settings,
:func:`~intervalkin.sweeps.spec.design_key`), and sends only the others to Dask: a
``dask.distributed.LocalCluster`` sized to the machine (one single-threaded worker process per
core: the analysis holds the GIL most of the time) or the scheduler at ``scheduler``.  Each
result is written to the cache by this process as soon as it arrives (atomically), so an
interrupted sweep restarts where it stopped and the workers need no shared file system.

Failures stay in the table: a design that is not a manipulator is ``degenerate`` (not
analysed); an analysis that raises is ``failed`` with its error, and so is a task whose
workers died more often than the scheduler allows (``distributed.scheduler.allowed-failures``,
3 by default: a task lost with one dead worker is simply run again elsewhere).  Failed designs
are not cached, so the next run tries them again.  Nothing is certified here beyond what each
analysis certifies; the engine only moves results.
"""

from __future__ import annotations

import json
import logging
import os
import time
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Mapping

from intervalkin.core.errors import InputError
from intervalkin.core.files import write_json
from intervalkin.sweeps.spec import Design, SweepSpec, load_sweep
from intervalkin.sweeps.table import COUNT_NAMES, arrow_table, best_rows, columns
from intervalkin.sweeps.task import count_from_json, run_design

__all__ = ["SweepEvent", "SweepResult", "sweep", "CACHE_FORMAT"]

#: The ``format`` field of a cached design result.
CACHE_FORMAT = "intervalkin-sweep-design"


@dataclass(frozen=True)
class SweepEvent:
    """Progress of a sweep: ``kind`` "start" (the cluster is up: ``workers``, ``dashboard`` link or None,
    ``total`` designs to compute) or "design" (one more result: ``row``; ``done`` of ``total``)."""

    kind: str
    done: int
    total: int
    row: Mapping[str, Any] | None = None
    workers: int = 0
    dashboard: str | None = None


@dataclass(frozen=True, eq=False)
class SweepResult:
    """The results of a sweep: one row per design (see :mod:`intervalkin.sweeps.table` for the columns).

    ``computed`` and ``reused`` are the keys analysed by this run and read from the cache;
    ``seconds`` is the wall time of the run; ``workers`` the number of Dask workers when it
    started (0 when nothing had to be computed).
    """

    spec: SweepSpec
    rows: tuple[Mapping[str, Any], ...]
    computed: tuple[str, ...]
    reused: tuple[str, ...]
    seconds: float
    workers: int
    dashboard: str | None = None

    def table(self):
        """The rows as a ``pyarrow.Table`` (``.to_pandas()`` gives a DataFrame when pandas is installed)."""
        return arrow_table(self.rows, self.spec.parameters)

    def best(self, n: int = 3) -> list[Mapping[str, Any]]:
        """The ``n`` best analysed designs by the sweep file's criterion."""
        return best_rows(self.rows, self.spec.best_by, self.spec.best_order, n)


def _row(spec: SweepSpec, d: Design, result: Mapping[str, Any] | None, cached: bool) -> dict[str, Any]:
    """The table row of a design from its result (None: degenerate); every column is there, None when empty."""
    row: dict[str, Any] = dict.fromkeys(columns(spec.parameters))
    row.update(design=d.index, key=d.key or None)
    row.update({p: float(v) for p, v in zip(spec.parameters, d.values)})
    if result is None:
        row.update(status="degenerate", error=d.degenerate, cached=False)
        return row
    row.update(status=result["status"], error=result.get("error", ""), cached=cached,
               seconds=result.get("seconds"), memory_mb=result.get("memory_mb"))
    for name in COUNT_NAMES if result["status"] == "ok" else ():
        c = count_from_json(result["counts"][name])
        row.update({f"{name}_found": c.found, f"{name}_lower": c.lower, f"{name}_upper": c.upper,
                    f"{name}_exact": c.exact})
    row.update({k: v for k, v in result.get("volumes", {}).items() if k in row})
    return row


def _read_cache(folder: Path | None, key: str) -> dict | None:
    """A cached result of ``key`` (None when absent or not readable as one: it is then computed again)."""
    if folder is None:
        return None
    try:
        doc = json.loads((folder / f"{key}.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(doc, dict) or doc.get("format") != CACHE_FORMAT or doc.get("key") != key:
        return None
    result = doc.get("result")
    if not isinstance(result, dict) or result.get("status") != "ok":
        return None
    try:  # the counts must still be counts (their invariants are re-checked)
        for name in COUNT_NAMES:
            count_from_json(result["counts"][name])
    except (KeyError, TypeError, ValueError):
        return None
    return result


def _write_cache(folder: Path, spec: SweepSpec, d: Design, result: Mapping[str, Any]) -> None:
    write_json(folder / f"{d.key}.json", {
        "format": CACHE_FORMAT, "version": 1, "key": d.key, "settings": spec.settings.to_json(),
        "parameters": dict(zip(spec.parameters, d.values)), "geometry": d.geometry_toml, "result": dict(result)})


class _Dask:
    """A Dask client on a new LocalCluster (closed on exit) or on the scheduler at ``address``."""

    def __init__(self, address: str | None, workers: int | None, dashboard: bool):
        self.address, self.n, self.dashboard = address, workers, dashboard
        self.cluster = self.client = None

    def __enter__(self) -> "_Dask":
        import dask.config
        from dask.distributed import Client, LocalCluster

        if self.address is None:
            n = self.n or os.cpu_count() or 1
            # Dask's nannies start workers with MALLOC_TRIM_THRESHOLD_=65536, which makes glibc hand
            # memory back after every large numpy array: the analysis then runs about 4 times slower
            # (measured: 3.3 s -> 18.7 s at depth 6, mostly system time), so that setting is left out,
            # and taken out of this process's environment, where an earlier nanny may have put it
            # (the workers inherit it, and so does a worker a nanny restarts later).
            no_trim = {"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}
            os.environ.pop("MALLOC_TRIM_THRESHOLD_", None)
            with warnings.catch_warnings(), dask.config.set(no_trim):
                # "port 8787 is in use, using another": the link printed says which
                warnings.simplefilter("ignore", UserWarning)
                self.cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                            dashboard_address=":8787" if self.dashboard else None,
                                            silence_logs=logging.ERROR)
            self.client = Client(self.cluster)
            return self
        try:
            self.client = Client(self.address, timeout="10s")
        except (OSError, ValueError, TimeoutError) as exc:
            raise InputError(f"--scheduler: cannot connect to {self.address!r} ({exc})") from None
        return self

    @property
    def link(self) -> str | None:
        if not self.dashboard:
            return None
        try:
            import bokeh  # noqa: F401 - the dashboard is served only when bokeh is installed
        except ImportError:
            return None
        return self.client.dashboard_link

    def workers(self) -> int:
        return len(self.client.scheduler_info(n_workers=-1)["workers"])

    def __exit__(self, *exc) -> None:
        if self.client is not None:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()


def sweep(spec: SweepSpec | str | Path, cache: str | Path | None = None, scheduler: str | None = None,
          workers: int | None = None, progress: Callable[[SweepEvent], None] | None = None,
          dashboard: bool = True) -> SweepResult:
    """Analyse every design of a sweep (a :class:`SweepSpec` or a sweep file) on Dask; return the table.

    Parameters
    ----------
    cache : folder of the cached results (``<key>.json``); None caches nothing.  Designs found
        there are not computed again; each new result is written there as soon as it arrives.
    scheduler : address of a running Dask scheduler (``tcp://host:8786``); None starts a
        LocalCluster of ``workers`` single-threaded worker processes (default: one per core).
    progress : called with a :class:`SweepEvent` when the cluster is up and after each design.
    dashboard : serve the Dask dashboard of a LocalCluster (its link is in the "start" event).

    Each row's counts are those of :func:`intervalkin.analyse` on the design (certified lower and
    upper bounds, exact or not); failed and degenerate designs are rows with their error.
    Raises :class:`~intervalkin.core.errors.InputError` on a bad file, worker number or scheduler.
    """
    t0 = time.perf_counter()
    spec = spec if isinstance(spec, SweepSpec) else load_sweep(spec)
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise InputError(f"workers: expected a positive integer, got {workers!r}")
    if workers is not None and scheduler is not None:
        raise InputError("workers: the number of workers is the running cluster's when a scheduler is given")
    folder = None if cache is None else Path(cache)
    results: dict[str, dict] = {}
    for d in spec.designs:
        if d.key and d.key not in results and (r := _read_cache(folder, d.key)) is not None:
            results[d.key] = r
    reused = tuple(results)
    todo: dict[str, Design] = {}
    for d in spec.designs:
        if d.key and d.key not in results:
            todo.setdefault(d.key, d)
    n_workers, link = 0, None
    if todo:
        with _Dask(scheduler, workers, dashboard) as dask:
            n_workers, link = dask.workers(), dask.link
            if progress is not None:
                progress(SweepEvent("start", 0, len(todo), workers=n_workers, dashboard=link))
            _run(dask.client, spec, todo, results, folder, progress)
    rows = tuple(_row(spec, d, results.get(d.key) if d.key else None, d.key in reused) for d in spec.designs)
    return SweepResult(spec, rows, tuple(todo), reused, time.perf_counter() - t0, n_workers, link)


def _run(client, spec: SweepSpec, todo: Mapping[str, Design], results: dict[str, dict], folder: Path | None,
         progress: Callable[[SweepEvent], None] | None) -> None:
    """Submit the designs of ``todo``, collect each result as it arrives (cached at once), report progress."""
    from dask.distributed import as_completed

    settings = spec.settings.to_json()
    futures = {client.submit(run_design, d.geometry_toml, settings, key=f"intervalkin-design-{k}"): k
               for k, d in todo.items()}
    retried: set[str] = set()
    try:
        pending = as_completed(futures)
        done = 0
        for fut in pending:
            key = futures[fut]
            try:
                result = fut.result()
            except Exception as exc:  # noqa: BLE001 - e.g. KilledWorker: the design failed, the others go on
                if key not in retried:
                    # run_design returns its own failures: an exception here comes from the cluster (a lost
                    # worker, a broken connection), so the design is submitted once more before it is failed
                    retried.add(key)
                    again = client.submit(run_design, todo[key].geometry_toml, settings,
                                          key=f"intervalkin-design-{key}-retry")
                    futures[again] = key
                    pending.add(again)
                    continue
                result = {"status": "failed", "error": f"{type(exc).__name__}: {exc}".splitlines()[0]}
            done += 1
            results[key] = result
            if result["status"] == "ok" and folder is not None:
                _write_cache(folder, spec, todo[key], result)
            if progress is not None:
                progress(SweepEvent("design", done, len(todo), row=_row(spec, todo[key], result, False)))
    finally:
        client.cancel(list(futures))

