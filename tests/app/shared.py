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


@functools.lru_cache(maxsize=None)
def chain(depth: int):
    """``intervalkin.analyse(depth=depth)`` (depth 6: about 2 s, 16 basic regions, 7 uniqueness domains)."""
    return intervalkin.analyse(depth=depth)


@functools.lru_cache(maxsize=None)
def paper_folder(depth: int = 6) -> tuple[Path, dict]:
    """An output folder of the chain at ``depth`` with every figure, export and both reports; (folder, summary).

    Written with the same calls as the paper command: the figures, the VTK exports, report.md,
    then report.html.  Removed when the test process ends.
    """
    out = Path(tempfile.mkdtemp(prefix="intervalkin-paper-"))
    atexit.register(shutil.rmtree, out, ignore_errors=True)
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
