"""``intervalkin sweep FILE --out DIR``: a design sweep on Dask into a resumable output folder.

Layout of DIR::

    DIR/.intervalkin-output     the manifest (command "sweep"): the files it owns, whether it completed
    DIR/sweep.toml              the sweep file of the last run
    DIR/designs/<key>.json      one cached result per design, keyed by the content hash of its
                                exact geometry and settings (the resume and reuse cache)
    DIR/results.csv             the table: one row per design (columns: intervalkin.sweeps.table)
    DIR/results.parquet         the same table, typed
    DIR/plots/counts.png        counts (found, certified lower bound) against the swept parameters
    DIR/plots/volumes.png       volumes against the swept parameters
    DIR/report.md               the best designs by the file's criterion, failures, times
    DIR/summary.json            what this run did: designs, computed, reused, failed, wall time

Folder rules: those of every command that writes a folder (README "Commands"), with one more:
a folder written by an earlier ``sweep`` is taken up again without ``--force``, and its cached
designs are reused (that is the resume).  ``--force`` on such a folder removes the earlier files,
the cache included, and starts afresh.  A sweep file or worker number that is refused is refused
before the folder is touched.
"""

from __future__ import annotations

import json
import sys
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

from tqdm import tqdm

from intervalkin.app.output import MARKER, OutputFolder, read_manifest, writable_folder
from intervalkin.app.progress import shows_progress
from intervalkin.app.sweep_plots import plot_sweep
from intervalkin.core.errors import InputError
from intervalkin.core.files import atomic_write_bytes, watching_writes, write_json
from intervalkin.sweeps.engine import SweepEvent, SweepResult, sweep
from intervalkin.sweeps.spec import load_sweep
from intervalkin.sweeps.table import COUNT_NAMES, csv_bytes, parquet_bytes

__all__ = ["run_sweep", "format_report", "SweepFolder"]


class SweepFolder(OutputFolder):
    """An output folder that a later sweep takes up again (its cache is what makes a sweep resumable).

    Unlike other outputs, files written before a failure are kept: they are cached results.
    """

    @classmethod
    def open(cls, out, force: bool, command: str = "sweep") -> "SweepFolder":
        root = Path(out)
        manifest = read_manifest(root) if root.is_dir() else None
        if force or manifest is None or manifest.get("legacy") or manifest.get("command") != command:
            return super().open(out, force, command)  # type: ignore[return-value]
        root = writable_folder(root)
        for tmp in root.rglob(".*.tmp"):  # a killed run's temporary files (never a finished one)
            tmp.unlink()
        folder = cls(root, command, created=False)
        for rel in manifest["files"]:
            if Path(rel).is_absolute() or ".." in Path(rel).parts:
                raise InputError(f"{str(root / MARKER)!r}: the manifest names {rel!r}, outside the folder")
            if (root / rel).exists():
                folder.files.add(rel)
        folder.write_manifest()  # "complete": false until this run has finished
        return folder

    @contextmanager
    def recording(self) -> Iterator["SweepFolder"]:
        """Record every file written inside the block (none is removed on an error: they are the cache)."""
        with watching_writes(self._record):
            yield self


def _check_workers(workers, scheduler) -> None:
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise InputError(f"--workers: expected a positive integer, got {workers!r}")
    if workers is not None and scheduler is not None:
        raise InputError("--workers: sizes the LocalCluster; with --scheduler the running cluster has its own workers")


class _Bar:
    """The sweep's progress callback for the command line: the cluster line, then a bar over designs."""

    def __init__(self, quiet: bool):
        self.quiet = quiet
        self.bar: tqdm | None = None

    def __call__(self, event: SweepEvent) -> None:
        if event.kind == "start":
            if not self.quiet:
                where = f"dashboard {event.dashboard}" if event.dashboard else "no dashboard"
                sys.stderr.write(f"Dask: {_workers(event.workers)}, {where}; {event.total} designs to analyse\n")
                sys.stderr.flush()
            self.bar = tqdm(total=event.total, unit="design", desc="designs", file=sys.stderr, dynamic_ncols=True,
                            disable=not shows_progress(sys.stderr, self.quiet))
        elif self.bar is not None:
            self.bar.update(1)
            if event.done == event.total:
                self.bar.close()


def _workers(n: int) -> str:
    return f"{n} worker" + ("" if n == 1 else "s")


def _value(v) -> str:
    if v is None:
        return "-"
    return f"{v:.4g}" if isinstance(v, float) else str(v)


def _count(row, name: str) -> str:
    if row.get(f"{name}_found") is None:
        return "-"
    if row[f"{name}_exact"]:
        return f"{row[f'{name}_found']} (exact)"
    return f"{row[f'{name}_found']} (>= {row[f'{name}_lower']})"


def format_report(result: SweepResult, n_best: int = 5) -> str:
    """report.md: the sweep, the best designs by its criterion, the designs not analysed, the times."""
    spec, rows = result.spec, result.rows
    by, order = spec.best_by, spec.best_order
    params = list(spec.parameters)
    ok = [r for r in rows if r["status"] == "ok"]
    lines = [f"# Sweep: {spec.name}", "",
             f"{len(rows)} designs ({', '.join(params)}), analysed at depth {spec.settings.depth}"
             + (f" (refined up to {spec.settings.refine_to})" if spec.settings.refine_to else "")
             + f": {len(ok)} analysed, {sum(r['status'] == 'failed' for r in rows)} failed, "
             f"{sum(r['status'] == 'degenerate' for r in rows)} degenerate; this run computed {len(result.computed)} "
             f"and reused {len(result.reused)} cached results in {result.seconds:.1f} s"
             + (f" on {_workers(result.workers)} of a Dask cluster." if result.workers else "."), "",
             f"## Best designs by `{by}` ({'largest' if order == 'max' else 'smallest'} first)", "",
             "Counts: found at this depth, with the certified lower bound (or exact when proved).", "",
             "| design | " + " | ".join(params)
             + f" | {by} | aspects | joint cells | basic regions | uniqueness domains |",
             "|---" * (len(params) + 6) + "|"]
    for r in result.best(n_best):
        lines.append(f"| {r['design']} | " + " | ".join(_value(r[p]) for p in params) + f" | {_value(r[by])} | "
                     + " | ".join(_count(r, n) for n in COUNT_NAMES) + " |")
    if not ok:
        lines.append("| (no design was analysed) |")
    bad = [r for r in rows if r["status"] != "ok"]
    if bad:
        lines += ["", "## Designs not analysed", ""]
        lines += [f"* design {r['design']} ({', '.join(f'{p} = {_value(r[p])}' for p in params)}): {r['status']}: "
                  f"{r['error']}" for r in bad]
    lines += ["", "Volumes are sums of certified box volumes in (x, y, phi) units, phi in radians; the table is "
              "`results.csv` (and `results.parquet`), the plots are in `plots/`.", ""]
    return "\n".join(lines)


def _table_text(result: SweepResult) -> str:
    rows = result.best(3)
    spec = result.spec
    out = [f"{len(result.rows)} designs: {len(result.computed)} computed, {len(result.reused)} cached, "
           f"{sum(r['status'] == 'failed' for r in result.rows)} failed, "
           f"{sum(r['status'] == 'degenerate' for r in result.rows)} degenerate ({result.seconds:.1f} s)"]
    if rows:
        out.append(f"best by {spec.best_by} ({spec.best_order}):")
        for r in rows:
            out.append(f"  design {r['design']}: " + ", ".join(f"{p} = {_value(r[p])}" for p in spec.parameters)
                       + f"; {spec.best_by} = {_value(r[spec.best_by])}; uniqueness domains "
                       + _count(r, "uniqueness_domains"))
    return "\n".join(out)


def run_sweep(path, out, scheduler: str | None = None, workers: int | None = None, force: bool = False,
              quiet: bool = False, dashboard: bool = True) -> int:
    """``intervalkin sweep``: analyse every design of the sweep file on Dask, write the table, plots and report."""
    spec = load_sweep(path)
    _check_workers(workers, scheduler)
    folder = SweepFolder.open(out, force, "sweep")
    root = folder.root
    t0 = time.perf_counter()
    with folder.recording():
        atomic_write_bytes(root / "sweep.toml", Path(path).read_bytes())
        write_json(root / "summary.json", {"complete": False, "command": "sweep", "sweep": spec.name})
        result = sweep(spec, cache=root / "designs", scheduler=scheduler, workers=workers, progress=_Bar(quiet),
                       dashboard=dashboard)
        params = spec.parameters
        atomic_write_bytes(root / "results.csv", csv_bytes(result.rows, params))
        atomic_write_bytes(root / "results.parquet", parquet_bytes(result.rows, params))
        plots = plot_sweep(result.rows, params, root / "plots", spec.name)
        atomic_write_bytes(root / "report.md", format_report(result).encode())
        summary = {
            "complete": True, "command": "sweep", "sweep": spec.name, "parameters": list(params),
            "settings": spec.settings.to_json(), "designs": len(result.rows),
            "computed": len(result.computed), "reused": len(result.reused),
            "failed": [r["design"] for r in result.rows if r["status"] == "failed"],
            "degenerate": [r["design"] for r in result.rows if r["status"] == "degenerate"],
            "best_by": spec.best_by, "best_order": spec.best_order,
            "best": [r["design"] for r in result.best(5)], "workers": result.workers,
            "seconds": time.perf_counter() - t0,
            "files": ["sweep.toml", "results.csv", "results.parquet", "report.md",
                      *(f"plots/{p.name}" for p in plots)],
        }
        folder.finish()
        write_json(root / "summary.json", json.loads(json.dumps(summary)))
    if not quiet:
        sys.stdout.write(_table_text(result) + f"\nwritten to {root}/\n")
    return 0
