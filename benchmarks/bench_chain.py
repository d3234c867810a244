"""Benchmark of the whole chain (singular layer -> joint cells -> regions -> uniqueness domains).

Prints, per depth, the time of each stage, the peak memory (each depth runs in
its own process, so the figure is that depth's own), the joint-space undecided
share, the undecided volume left in W and in each aspect, the volume of the
characteristic layer, and the counts with their certified lower bounds.

    python benchmarks/bench_chain.py                 # depths 5..8
    python benchmarks/bench_chain.py --depths 6 7 8 9 [--geometry FILE]

A script that prints figures, not a test: targets live here, not in timed tests.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time


def one(depth: int, geometry_path: str | None) -> dict:
    from intervalkin.app.options import geometry_from_option
    from intervalkin.app.summary import chain_summary
    from intervalkin.pipeline import analyse

    g = geometry_from_option(geometry_path)
    t0 = time.perf_counter()
    a = analyse(g, depth)
    total = time.perf_counter() - t0
    s = chain_summary(a)
    return {
        "depth": depth,
        "seconds": total,
        "stages": {k.split(" (")[0].split(":")[0]: v for k, v in a.timings.items()},
        "peak_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        "joint_undecided_share": s["joint"]["undecided_share"],
        "undecided": s["undecided_volume"],
        "characteristic_layer": s["characteristic_layer_volume"],
        "boxes": len(a.regions.paving),
        "basic_regions": [s["basic_regions"]["count"], s["basic_regions"]["lower_bound"]],
        "uniqueness_domains": [s["uniqueness_domains"]["count"], s["uniqueness_domains"]["lower_bound"]],
        "consistent": s["basic_regions"]["consistent_with_proposition_1"],
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--depths", type=int, nargs="+", default=[5, 6, 7, 8])
    ap.add_argument("--geometry")
    ap.add_argument("--one", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one is not None:
        print(json.dumps(one(args.one, args.geometry)))
        return
    rows = []
    print(f"{'d':>2} {'total s':>8} {'sing s':>7} {'joint s':>8} {'regions s':>9} {'peak MiB':>9} {'boxes':>9} "
          f"{'jointUnd':>8} {'W und':>8} {'WA1 und':>8} {'WA2 und':>8} {'Sc layer':>9} {'regions':>8} {'domains':>8}")
    for d in args.depths:
        cmd = [sys.executable, __file__, "--one", str(d)] + (["--geometry", args.geometry] if args.geometry else [])
        r = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
        rows.append(r)
        st = list(r["stages"].values())
        print(f"{d:>2} {r['seconds']:>8.1f} {st[0]:>7.1f} {st[1]:>8.1f} {st[2]:>9.1f} {r['peak_mib']:>9.0f} "
              f"{r['boxes']:>9,d} {100 * r['joint_undecided_share']:>7.1f}% {r['undecided']['W']:>8.1f} "
              f"{r['undecided']['WA1']:>8.1f} {r['undecided']['WA2']:>8.1f} {r['characteristic_layer']:>9.1f} "
              f"{r['basic_regions'][0]:>3}>={r['basic_regions'][1]:<3} {r['uniqueness_domains'][0]:>3}>={r['uniqueness_domains'][1]:<3}")
    print("regions / domains: found >= certified lower bound; volumes in x * y * phi units")


if __name__ == "__main__":
    main()
