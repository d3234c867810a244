"""One design analysed: the function a Dask worker runs, and the result it sends back.

:func:`run_design` takes the design's geometry as TOML text (exact decimals) and the
settings, runs :func:`intervalkin.analyse` and returns a JSON-able dict: the counts (each
copied from a :class:`~intervalkin.core.status.Count`: found, certified lower and upper
bounds, exact), the volumes, the time and the memory.  It never raises for a failed
analysis: the error comes back as ``status = "failed"`` with one line, so one design cannot
stop the others.  (A worker that dies mid-task is the engine's business: Dask retries the
task elsewhere.)

What the volumes are: float sums of box volumes (a measure of certified boxes, not a
certified bound on the true set, see README "What certified means here").
"""

from __future__ import annotations

import decimal
import threading
import time
from typing import Any

import tomllib

from intervalkin.core.status import Count

__all__ = ["run_design", "count_from_json", "joint_cells_count"]

#: Seconds between two samples of the worker's resident memory.
_SAMPLE = 0.05


def count_from_json(doc: dict) -> Count:
    """A :class:`Count` back from its cached form (its invariants are re-checked)."""
    return Count(doc["found"], doc["lower"], doc["upper"], doc["exact"], doc.get("why", ""), doc.get("undecided") or {})


def _count_json(c: Count) -> dict:
    return {"found": c.found, "lower": c.lower, "upper": c.upper, "exact": c.exact, "why": c.why,
            "undecided": dict(c.undecided)}


def joint_cells_count(analysis) -> Count:
    """The joint cells of the direct joint paving, as a :class:`Count`.

    When the analysis states its own count of joint cells (``counts().joint_cells``), that is
    copied.  Otherwise: found is the number of cells; the certified lower bound is the number of
    distinct certified (count, n_wa1, n_wa2) signatures (cells of different signatures lie in
    different components of the joint box minus g(S)); no upper bound, so never exact.
    """
    own = getattr(analysis.counts(), "joint_cells", None)
    if isinstance(own, Count):
        return own
    cells = analysis.cells.cells
    signatures = {c.signature for c in cells if c.count >= 0}
    return Count(len(cells), len(signatures), None, False,
                 f"{len(cells)} cells of the direct joint paving; the {len(signatures)} distinct certified "
                 "signatures (solutions in all and per aspect) lie in different components of the joint box minus "
                 "g(S); cells of one signature may be one component joined through undecided boxes")


def _volumes(analysis) -> dict[str, float]:
    import numpy as np

    from intervalkin.paving.labels import Label

    ra = analysis.regions
    p = ra.paving
    vol = p.volume()
    dom = np.asarray(ra.domain)
    placed = dom >= 0
    largest = float(np.bincount(dom[placed], weights=vol[placed]).max()) if placed.any() else 0.0
    return {
        "volume_W": float(vol[p.labels["W"] == Label.INSIDE].sum()),
        "volume_WA1": float(vol[p.labels["WA1"] == Label.INSIDE].sum()),
        "volume_WA2": float(vol[p.labels["WA2"] == Label.INSIDE].sum()),
        "volume_largest_uniqueness_domain": largest,
        "volume_undecided": float(vol[p.labels["W"] == Label.BOUNDARY].sum()),
    }


class _PeakMemory:
    """Samples the process's resident memory in a thread; ``peak_mb`` is the largest sample (None without psutil)."""

    def __init__(self) -> None:
        self.peak_mb: float | None = None
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        try:
            import psutil
        except ImportError:  # pragma: no cover - psutil comes with dask.distributed
            return
        self._proc = psutil.Process()
        self.peak_mb = self._proc.memory_info().rss / 2**20
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _run(self) -> None:
        while not self._stop.wait(_SAMPLE):
            self.peak_mb = max(self.peak_mb or 0.0, self._proc.memory_info().rss / 2**20)

    def __enter__(self) -> "_PeakMemory":
        if self._thread is not None:
            self._thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            self.peak_mb = max(self.peak_mb or 0.0, self._proc.memory_info().rss / 2**20)


def run_design(geometry_toml: str, settings: dict) -> dict[str, Any]:
    """Analyse one design; return its counts, volumes, seconds and memory, or ``status = "failed"`` and the error.

    ``settings``: ``{"depth": int, "refine_to": int | None}``.  Counts are copied from the
    analysis (the aspects, basic regions and uniqueness domains from ``Analysis.counts()``,
    the joint cells from :func:`joint_cells_count`); nothing is made exact here.
    """
    t0 = time.perf_counter()
    try:
        from intervalkin.core.geometry import parse_geometry
        from intervalkin.pipeline import analyse

        geometry = parse_geometry(tomllib.loads(geometry_toml, parse_float=decimal.Decimal))
        with _PeakMemory() as mem:
            a = analyse(geometry, depth=settings["depth"], refine_to=settings.get("refine_to"))
            c = a.counts()
            counts = {"aspects": c.aspects, "joint_cells": joint_cells_count(a), "basic_regions": c.basic_regions,
                      "uniqueness_domains": c.uniqueness_domains}
            volumes = _volumes(a)
    except Exception as exc:  # noqa: BLE001 - a design's failure is its result, not the sweep's
        return {"status": "failed", "error": f"{type(exc).__name__}: {exc}".splitlines()[0],
                "seconds": time.perf_counter() - t0}
    return {"status": "ok", "error": "", "counts": {k: _count_json(v) for k, v in counts.items()},
            "volumes": volumes, "seconds": time.perf_counter() - t0, "memory_mb": mem.peak_mb,
            "depth": a.depth}
