"""Benchmark of the direct joint-space paving (a script, not a test).

    python benchmarks/bench_joint_paving.py [--depths 5 6 7] [--geometry FILE] [--samples 2000] [--fold] [--face-levels 3]

Per depth: boxes, wall time, peak memory (resident set of this process), the share of
the joint box's volume in boxes certified off g(S), the cells (count: number), the
basic regions they imply (the sum of the cells' counts, Theorem 1), and the agreement
of the paving with independent certified solves at random joint vectors: labelled
(the vector lies in a cell, or in a piece of a fold box placed by the side test),
agreeing (the cell's count and aspect split equal the solve's) and wrong (must be 0:
a wrong label is a soundness bug).  ``--fold`` adds the fold models and prints their
number and the fold pieces joined to no cell.

Issue 13's targets: >= 99 % of the volume certified, random vectors labelled and
agreeing >= 99 %, 0 wrong, <= 60 s and <= 2 GiB at the default settings on 2 cores.
"""

from __future__ import annotations

import argparse
import resource
import time
from collections import Counter
from fractions import Fraction

import numpy as np

from intervalkin.core.geometry import default_geometry, load_geometry
from intervalkin.solve.dkp import solve
from intervalkin.space.joint_paving import DEFAULT_JOINT_DEPTH, joint_domain, pave_joint_space


def _agreement(geometry, jp, samples: int, seed: int) -> tuple[int, int, int, int]:
    dom = joint_domain(geometry)
    rng = np.random.default_rng(seed)
    q = dom[:, 0] + rng.random((samples, 3)) * (dom[:, 1] - dom[:, 0])
    cell = jp.cell_of(q, geometry)
    by_id = {c.id: c for c in jp.cells}
    labelled = agree = wrong = 0
    for v, cid in zip(q, cell):
        if cid < 0:
            continue
        labelled += 1
        res = solve(geometry, [Fraction(float(x)) for x in v])
        if not res.complete:
            continue
        n1 = sum(1 for s in res.solutions if s.aspect == "WA1")
        if (res.count, n1, res.count - n1) == by_id[int(cid)].signature:
            agree += 1
        else:
            wrong += 1
    return samples, labelled, agree, wrong


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--depths", type=int, nargs="+", default=[DEFAULT_JOINT_DEPTH])
    ap.add_argument("--geometry", default=None)
    ap.add_argument("--samples", type=int, default=1000, help="random joint vectors checked by certified solves")
    ap.add_argument("--fold", action="store_true", help="give undecided boxes fold models (solve.fold_model)")
    ap.add_argument("--face-levels", type=int, default=0, help="further levels for undecided boxes on the faces")
    args = ap.parse_args()
    g = default_geometry() if args.geometry is None else load_geometry(args.geometry)
    print(f"{'depth':>5} {'boxes':>9} {'seconds':>8} {'peak MB':>8} {'certified':>9} {'regions':>7} "
          f"{'labelled':>8} {'agree':>6} {'wrong':>5}   cells (count: number)")
    for depth in args.depths:
        t0 = time.perf_counter()
        jp = pave_joint_space(g, depth, fold=args.fold, face_levels=args.face_levels)
        dt = time.perf_counter() - t0
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        n, labelled, agree, wrong = _agreement(g, jp, args.samples, seed=depth)
        kinds = Counter(c.count for c in jp.cells)
        cells = ", ".join(f"{k}: {kinds[k]}" for k in sorted(kinds))
        print(f"{depth:>5} {len(jp.paving):>9} {dt:>8.1f} {peak:>8.0f} {100 * jp.certified_share():>8.1f}% "
              f"{sum(c.count for c in jp.cells):>7} {100 * labelled / n:>7.1f}% {100 * agree / n:>5.1f}% {wrong:>5}   {cells}",
              flush=True)
        if jp.fold_stats:
            print(f"       fold boxes {jp.fold_stats['fold_boxes']} ({jp.fold_stats['seconds']:.1f} s); pieces joined to "
                  f"no cell: {jp.fold_stats['unjoined_piece_groups']} groups, volume "
                  f"{jp.fold_stats['unjoined_piece_volume']:.2f}", flush=True)
        print("       undecided volume per level: " + ", ".join(
            f"{st['level']}: {st['undecided_volume']['clear']:.0f}" for st in jp.paving.stats), flush=True)
    print("peak MB is the process's maximum resident set so far (it includes the earlier depths).")


if __name__ == "__main__":
    main()
