"""Benchmark of the direct joint-space paving (a script, not a test).

    python benchmarks/bench_joint_paving.py [--min-depth 4] [--max-depth 6]

Per depth: boxes, wall time, peak memory (tracemalloc: numpy buffers), the share of
the joint box's volume in boxes certified off g(S), the undecided volume, and the
cells found (count: number of cells, volume).  Also, for comparison, the share of
the joint box certified by the enclosure of g(S) built from images of workspace
boxes (space.joint_space at the analysis' default settings) when --compare is given.

Issue 13's targets: >= 99 % of the volume certified, <= 60 s and <= 2 GiB at the
default settings on 2 cores.
"""

from __future__ import annotations

import argparse
import time
import tracemalloc
from collections import Counter

from intervalkin.core.geometry import default_geometry
from intervalkin.space.joint_paving import pave_joint_space


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--min-depth", type=int, default=4)
    ap.add_argument("--max-depth", type=int, default=6)
    args = ap.parse_args()
    g = default_geometry()
    print(f"{'depth':>5} {'boxes':>9} {'seconds':>8} {'peak MB':>8} {'certified':>9} {'undecided':>9}   cells (count: n, volume)")
    for depth in range(args.min_depth, args.max_depth + 1):
        tracemalloc.start()
        t0 = time.perf_counter()
        jp = pave_joint_space(g, depth)
        dt = time.perf_counter() - t0
        peak = tracemalloc.get_traced_memory()[1] / 2**20
        tracemalloc.stop()
        n = Counter(c.count for c in jp.cells)
        vol = Counter()
        for c in jp.cells:
            vol[c.count] += c.volume
        cells = ", ".join(f"{k}: {n[k]} ({vol[k]:.0f})" for k in sorted(n))
        print(f"{depth:>5} {len(jp.paving):>9} {dt:>8.1f} {peak:>8.0f} {100 * jp.certified_share():>8.1f}% "
              f"{jp.undecided_volume():>9.1f}   {cells}", flush=True)


if __name__ == "__main__":
    main()
