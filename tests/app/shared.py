"""Results shared by the tests of the figures, exports and reports, computed once per test process.

Fixtures of one test module are not shared with another without a conftest; these cached
functions are: the chain at a small depth, and an output folder written the way
``intervalkin paper`` writes it (figures, ParaView exports, report.md, report.html).
"""

from __future__ import annotations

import atexit
import functools
import shutil
import tempfile
from pathlib import Path

import numpy as np

import intervalkin
from intervalkin.app.export import write_npz
from intervalkin.app.figures import render_paper_figures
from intervalkin.app.report import write_report
from intervalkin.app.report_html import write_report_html
from intervalkin.app.summary import chain_summary
from intervalkin.app.vtk_export import write_exports

from ..conftest import shared_root, shared_value


@functools.lru_cache(maxsize=None)
def chain(depth: int):
    """``intervalkin.analyse(depth=depth)`` (depth 6: about 17 s on one core, 16 basic regions, 7 uniqueness
    domains), made once a run: five test files read it, on either worker (tests/conftest.py: shared_value)."""
    return shared_value(f"analysis-depth-{depth}", lambda: intervalkin.analyse(depth=depth))


@functools.lru_cache(maxsize=None)
def paper_folder(depth: int = 6) -> tuple[Path, dict]:
    """An output folder of the chain at ``depth`` with every figure, export and both reports; (folder, summary).

    Written with the same calls as the paper command: the figures, the VTK exports, report.md,
    then report.html.  Written once a run (two test files read it, on either worker) in a folder that outlives
    the worker that wrote it: the run's shared temporary folder under xdist, else one removed at exit.
    Read it only."""
    return shared_value(f"paper-folder-depth-{depth}", lambda: _write_paper_folder(depth))


def _write_paper_folder(depth: int) -> tuple[Path, dict]:
    root = shared_root()
    if root is None:
        out = Path(tempfile.mkdtemp(prefix="intervalkin-paper-"))
        atexit.register(shutil.rmtree, out, ignore_errors=True)
    else:
        out = Path(tempfile.mkdtemp(prefix="intervalkin-paper-", dir=root))
    a = chain(depth)
    ra = a.regions
    write_npz(out / "pavings" / "workspace.npz", ra.paving, ra.aspect,
              {"basic_region": ra.region.astype(np.int32), "uniqueness_domain": ra.domain.astype(np.int32)})
    files = ["pavings/workspace.npz"] + write_exports(a, out)
    files += [f"figures/{p.name}" for p in render_paper_figures(a, out / "figures")]
    summary = chain_summary(a)
    summary["timings_seconds"] = dict(a.timings)
    summary["files"] = files
    files.append(write_report(a, summary, out, {}))
    files.append(write_report_html(a, summary, out))
    return out, summary
