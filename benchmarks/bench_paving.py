"""Benchmark of the workspace paving (a script, not a test).

    python benchmarks/bench_paving.py [--max-depth 8] [--with-9] [--codac-max-depth 6] [--no-codac]

Per depth: boxes evaluated, boxes/s, wall time, peak memory (tracemalloc for numpy
buffers, plus ru_maxrss of the process), inside / undecided volumes of W and of each
aspect, number of components, and inner-volume ratios against a seeded Monte Carlo
estimate of the true volumes.  Codac 2 (``pip install codac``) paves the same sets
in a SEPARATE process (importing codac switches the process to upward rounding):
phi is rescaled so that all axes have width 64 and Codac's bisection of the largest
side reproduces the octree resolution 64 / 2**depth on every axis.
"""

from __future__ import annotations

import argparse
import json
import math
import resource
import subprocess
import sys
import time
import tracemalloc

import numpy as np

from intervalkin.core.geometry import default_geometry
from intervalkin.kinematics.formulas import approx_det_a, approx_inverse_kinematics
from intervalkin.paving.adjacency import shares_face
from intervalkin.space.aspect import aspect_components
from intervalkin.paving.predicates import pave_workspace

CODAC_SCRIPT = r'''
import sys, time, json, math
from codac import *
depth = int(sys.argv[1]); which = sys.argv[2]
p3x, p3y, l2 = float(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
a2x, a3y = 15.91, 10.0
k = 2 * math.pi / 64.0
x = VectorVar(3)
phi = k * x[2]
c, s = cos(phi), sin(phi)
r2x, r2y = l2 * c, l2 * s
r3x, r3y = p3x * c - p3y * s, p3x * s + p3y * c
X, Y = x[0], x[1]
rho = AnalyticFunction([x], vec(sqr(X) + sqr(Y), sqr(X + r2x - a2x) + sqr(Y + r2y), sqr(X + r3x) + sqr(Y + r3y - a3y)))
w2 = r2x * Y - r2y * (X - a2x)
w3 = r3x * (Y - a3y) - r3y * X
d2x, d2y = r2x - a2x, r2y
d3x, d3y = r3x, r3y - a3y
det = AnalyticFunction([x], X * (d2y * w3 - w2 * d3y) - Y * (d2x * w3 - w2 * d3x))
sW = SepInverse(rho, IntervalVector([[100, 1024], [100, 1024], [100, 1024]]))
sep = {"W": sW, "WA1": SepInter(sW, SepInverse(det, Interval(0, oo))), "WA2": SepInter(sW, SepInverse(det, Interval(-oo, 0)))}[which]
x0 = IntervalVector([[-32, 32], [-32, 32], [-32, 32]])
eps = 64.0 / 2 ** depth * 1.01
t = time.perf_counter()
p = pave(x0, sep, eps)
el = time.perf_counter() - t
def vol(boxes):
    return sum(b[0].diam() * b[1].diam() * b[2].diam() * k for b in boxes)
inner = p.boxes(PavingInOut.inner); bound = p.boxes(PavingInOut.bound)
out = {"seconds": el, "inner_volume": vol(inner), "boundary_volume": vol(bound), "inner_boxes": len(inner), "boundary_boxes": len(bound)}
try:
    cs = p.connected_subsets(PavingInOut.inner)
    out["components_all"] = len(cs)
except Exception as e:
    out["components_all"] = str(e)
print(json.dumps(out))
'''


def monte_carlo(geometry, n=4_000_000, seed=12345):
    """Float (not certified) estimates of vol(W), vol(WA1), vol(WA2): the reference."""
    rng = np.random.default_rng(seed)
    dom = np.array([[-32, 32], [-32, 32], [-math.pi, math.pi]])
    V = float(np.prod(dom[:, 1] - dom[:, 0]))
    acc = np.zeros(3)
    chunk = 1_000_000
    for _ in range(n // chunk):
        X = rng.uniform(dom[:, 0], dom[:, 1], (chunk, 3))
        rho = approx_inverse_kinematics(geometry, X)
        w = np.all((rho >= 10) & (rho <= 32), axis=1)
        d = approx_det_a(geometry, X)
        acc += [w.sum(), (w & (d > 0)).sum(), (w & (d < 0)).sum()]
    est = acc / n * V
    return dict(zip(("W", "WA1", "WA2"), est.tolist()))


def run_ours(geometry, depth):
    tracemalloc.start()
    t = time.perf_counter()
    p = pave_workspace(geometry, depth)
    t_pave = time.perf_counter() - t
    edges = shares_face(p.level, p.ijk, p.depth)
    aspect, info = aspect_components(p, edges)
    wall = time.perf_counter() - t
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    evaluated = sum(s["boxes"] for s in p.stats)
    row = {
        "depth": depth,
        "boxes_evaluated": evaluated,
        "leaves": len(p),
        "boxes_per_s": evaluated / t_pave,
        "paving_s": t_pave,
        "wall_s": wall,
        "peak_traced_MiB": peak / 2**20,
        "maxrss_MiB": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
    }
    for name in ("W", "WA1", "WA2"):
        v = p.volume_by_label(name)
        row[f"{name}_in"] = v["inside"]
        row[f"{name}_und"] = v["boundary"]
    row["comp_WA1"] = sum(1 for d in info if d["sign"] > 0)
    row["comp_WA2"] = sum(1 for d in info if d["sign"] < 0)
    row["comp_big"] = sum(1 for d in info if d["volume"] > 100)
    return row


def run_codac(geometry, depth, timeout):
    out = {}
    args = [str(float(geometry.p3x)), str(float(geometry.p3y)), str(float(geometry.l2))]
    for which in ("W", "WA1", "WA2"):
        try:
            r = subprocess.run([sys.executable, "-c", CODAC_SCRIPT, str(depth), which] + args,
                               capture_output=True, text=True, timeout=timeout)
            out[which] = json.loads(r.stdout.strip().splitlines()[-1]) if r.returncode == 0 else {"error": r.stderr[-300:]}
        except subprocess.TimeoutExpired:
            out[which] = {"error": f"timeout {timeout} s"}
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--min-depth", type=int, default=4)
    ap.add_argument("--max-depth", type=int, default=8)
    ap.add_argument("--with-9", action="store_true", help="also depth 9")
    ap.add_argument("--codac-max-depth", type=int, default=6)
    ap.add_argument("--codac-timeout", type=float, default=600)
    ap.add_argument("--no-codac", action="store_true")
    ap.add_argument("--json", metavar="FILE")
    a = ap.parse_args()
    g = default_geometry()
    mc = monte_carlo(g)
    print("Monte Carlo reference volumes (4e6 samples, float, seed 12345): "
          + ", ".join(f"{k} {v:.1f}" for k, v in mc.items()))
    depths = list(range(a.min_depth, a.max_depth + 1)) + ([9] if a.with_9 and a.max_depth < 9 else [])
    rows = []
    hdr = (f"{'d':>2} {'evaluated':>10} {'boxes/s':>9} {'wall s':>7} {'peakMiB':>8} {'rssMiB':>7} "
           f"{'W in%':>6} {'W und':>8} {'WA1 in%':>7} {'WA1 und':>8} {'WA2 in%':>7} {'WA2 und':>8} {'comp+':>5} {'comp-':>5}")
    print(hdr)
    for d in depths:
        r = run_ours(g, d)
        for k in ("W", "WA1", "WA2"):
            r[f"{k}_ratio"] = r[f"{k}_in"] / mc[k]
        rows.append(r)
        print(f"{d:>2} {r['boxes_evaluated']:>10} {r['boxes_per_s']:>9.0f} {r['wall_s']:>7.2f} {r['peak_traced_MiB']:>8.0f} "
              f"{r['maxrss_MiB']:>7.0f} {100 * r['W_ratio']:>6.1f} {r['W_und']:>8.1f} {100 * r['WA1_ratio']:>7.1f} "
              f"{r['WA1_und']:>8.1f} {100 * r['WA2_ratio']:>7.1f} {r['WA2_und']:>8.1f} {r['comp_WA1']:>5} {r['comp_WA2']:>5}", flush=True)
    codac = {}
    if not a.no_codac:
        print("\nCodac 2 (separate process, SepInverse + SepInter, pave with eps = 64/2**d on rescaled axes)")
        print(f"{'d':>2} {'set':>4} {'codac s':>8} {'ours s':>7} {'ratio':>6} {'codac in':>9} {'ours in':>8} "
              f"{'codac und':>9} {'ours und':>8} {'codac comp':>10} {'ours comp':>9}")
        for r in rows:
            d = r["depth"]
            if d > a.codac_max_depth:
                continue
            c = run_codac(g, d, a.codac_timeout)
            codac[d] = c
            total = sum(c[k].get("seconds", float("nan")) for k in c)
            for k in ("W", "WA1", "WA2"):
                ck = c[k]
                if "error" in ck:
                    print(f"{d:>2} {k:>4} {ck['error']}")
                    continue
                ours_comp = {"W": "-", "WA1": r["comp_WA1"], "WA2": r["comp_WA2"]}[k]
                print(f"{d:>2} {k:>4} {ck['seconds']:>8.2f} {'':>7} {'':>6} {ck['inner_volume']:>9.1f} {r[k + '_in']:>8.1f} "
                      f"{ck['boundary_volume']:>9.1f} {r[k + '_und']:>8.1f} {str(ck['components_all']):>10} {str(ours_comp):>9}")
            print(f"{d:>2} {'all':>4} {total:>8.2f} {r['paving_s']:>7.2f} {total / r['paving_s']:>6.0f}x  (W + aspects, ours in one pass)")
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"monte_carlo": mc, "ours": rows, "codac": codac}, f, indent=1)


if __name__ == "__main__":
    main()
