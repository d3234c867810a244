"""Benchmark: time of one certified direct-kinematics solve (not a test).

Draws ~200 seeded random joint vectors (4 decimals) inside the joint limits of the
paper's manipulator (or of --geometry FILE), solves each with
:func:`intervalkin.solve.dkp.solve` and prints the median and percentiles of the wall
time, the solution counts, how many solves were proved complete, the precision
used and the widest enclosure.

    python benchmarks/bench_dkp.py [--n 200] [--seed 1997] [--geometry FILE]
"""

from __future__ import annotations

import argparse
import time
from collections import Counter
from fractions import Fraction

import numpy as np

from intervalkin.solve.dkp import solve
from intervalkin.app.options import geometry_from_option


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=200)
    ap.add_argument("--seed", type=int, default=1997)
    ap.add_argument("--geometry", default=None)
    args = ap.parse_args()
    g = geometry_from_option(args.geometry)
    rng = np.random.default_rng(args.seed)
    lo = np.array([float(v) for v in g.rho_min])
    hi = np.array([float(v) for v in g.rho_max])
    vectors = [[Fraction(f"{v:.4f}") for v in np.clip(rng.uniform(lo, hi), lo, hi)] for _ in range(args.n)]
    solve(g, vectors[0])  # warm the caches (constants, basis polynomials)
    times, counts, precs = [], Counter(), Counter()
    complete, widest = 0, 0.0
    t_all = time.perf_counter()
    for rho in vectors:
        t = time.perf_counter()
        r = solve(g, rho)
        times.append(time.perf_counter() - t)
        counts[r.count] += 1
        precs[r.precision] += 1
        complete += r.complete
        widest = max([widest] + [s.width for s in r.solutions if s.status == "unique"])
    total = time.perf_counter() - t_all
    ms = np.array(times) * 1e3
    print(f"geometry: {g.name}; {args.n} joint vectors (seed {args.seed})")
    print(f"time per certified solve (ms): median {np.median(ms):.2f}  p10 {np.percentile(ms, 10):.2f}  "
          f"p90 {np.percentile(ms, 90):.2f}  p99 {np.percentile(ms, 99):.2f}  max {ms.max():.2f}")
    print(f"total {total:.2f} s; complete {complete}/{args.n}; solution counts {dict(sorted(counts.items()))}; "
          f"precision used {dict(sorted(precs.items()))}")
    print(f"widest unique enclosure: {widest:.2e}")


if __name__ == "__main__":
    main()
