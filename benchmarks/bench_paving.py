"""Benchmark of the workspace paving against Codac 2, in one run (a script, not a test).

    python benchmarks/bench_paving.py [--depths 5 6 7 8 9] [--refine 0 1] [--codac-depth 6] [--no-codac] [--json F]

Per depth and per mode (``grid``: the octree alone; ``contract+r``: its undecided leaves cut
by the contractors with r bisect-and-cut rounds, :mod:`intervalkin.paving.contracted`): boxes
(grid leaves, contracted parts), seconds (paving, contraction), peak memory (the ru_maxrss
of a fresh process per row), inner volumes of W, WA1 and WA2 as fractions of seeded Monte
Carlo volumes, and the undecided volume.  Codac 2 (the optional ``bench`` extra:
``pip install codac``; never a dependency of the library) paves the same three sets with
``SepInverse`` (+ ``SepInter`` for the aspects) in SEPARATE processes (importing codac
switches the process to upward rounding): phi is rescaled so that all axes have width 64 and
bisection down to 64 / 2**d reproduces the octree resolution of depth d.  The last lines
compare: the first of our rows whose inner volumes reach Codac's for all three sets, and its
time as a fraction of Codac's.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SETS = ("W", "WA1", "WA2")

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
import resource
print(json.dumps({"seconds": el, "inner_volume": vol(inner), "boundary_volume": vol(bound),
                  "inner_boxes": len(inner), "boundary_boxes": len(bound),
                  "maxrss_MiB": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
'''

OURS_SCRIPT = r'''
import json, resource, sys, time
from intervalkin.core.geometry import default_geometry
from intervalkin.paving.predicates import contract_paving, pave_workspace
depth, refine = int(sys.argv[1]), int(sys.argv[2])
g = default_geometry()
pave_workspace(g, 3, contract=refine >= 0)  # warm-up: imports, constant caches
t = time.perf_counter()
p = pave_workspace(g, depth)
t_pave = time.perf_counter() - t
row = {"depth": depth, "refine": refine, "leaves": len(p), "evaluated": sum(s["boxes"] for s in p.stats),
       "paving_s": t_pave, "contract_s": 0.0, "parts": 0}
if refine >= 0:
    t = time.perf_counter()
    p.parts.update(contract_paving(g, p, refine))
    row["contract_s"] = time.perf_counter() - t
    row["parts"] = sum(len(v) for v in p.parts.values())
row["seconds"] = row["paving_s"] + row["contract_s"]
for name in ("W", "WA1", "WA2"):
    v = p.volume_by_label(name, contracted=refine >= 0)
    row[name + "_in"], row[name + "_und"] = v["inside"], v["boundary"]
row["maxrss_MiB"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps(row))
'''


def monte_carlo(n: int = 4_000_000, seed: int = 12345) -> dict[str, float]:
    """Float (not certified) estimates of vol(W), vol(WA1), vol(WA2): the reference."""
    from intervalkin.core.geometry import default_geometry
    from intervalkin.kinematics.formulas import approx_det_a, approx_inverse_kinematics

    g = default_geometry()
    rng = np.random.default_rng(seed)
    dom = np.array([[-32, 32], [-32, 32], [-math.pi, math.pi]])
    vol = float(np.prod(dom[:, 1] - dom[:, 0]))
    acc = np.zeros(3)
    chunk = 1_000_000
    for _ in range(n // chunk):
        X = rng.uniform(dom[:, 0], dom[:, 1], (chunk, 3))
        rho = approx_inverse_kinematics(g, X)
        w = np.all((rho >= 10) & (rho <= 32), axis=1)
        d = approx_det_a(g, X)
        acc += [w.sum(), (w & (d > 0)).sum(), (w & (d < 0)).sum()]
    return dict(zip(SETS, (acc / n * vol).tolist()))


def _child(code: str, args: list[str], timeout: float) -> dict:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([os.path.join(HERE, "..", "src"), os.environ.get("PYTHONPATH", "")]))
    try:
        r = subprocess.run([sys.executable, "-c", code] + args, capture_output=True, text=True, timeout=timeout, env=env)
    except subprocess.TimeoutExpired:
        return {"error": f"timeout {timeout} s"}
    if r.returncode != 0:
        return {"error": r.stderr.strip().splitlines()[-1] if r.stderr.strip() else f"exit {r.returncode}"}
    return json.loads(r.stdout.strip().splitlines()[-1])


def run_codac(depth: int, timeout: float) -> dict:
    from intervalkin.core.geometry import default_geometry

    g = default_geometry()
    args = [str(depth), "", str(float(g.p3x)), str(float(g.p3y)), str(float(g.l2))]
    out = {}
    for which in SETS:
        args[1] = which
        out[which] = _child(CODAC_SCRIPT, args, timeout)
    ok = all("seconds" in out[k] for k in SETS)
    out["seconds"] = sum(out[k]["seconds"] for k in SETS) if ok else float("nan")
    out["maxrss_MiB"] = max(out[k].get("maxrss_MiB", 0) for k in SETS)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--depths", type=int, nargs="+", default=[5, 6, 7, 8, 9])
    ap.add_argument("--refine", type=int, nargs="+", default=[0, 1],
                    help="bisect-and-cut rounds of the contracted modes (-1 alone: grid only)")
    ap.add_argument("--refine-max-depth", type=int, default=7,
                    help="no bisect-and-cut rounds above this depth (a grid level is cheaper at equal gain)")
    ap.add_argument("--codac-depth", type=int, default=6)
    ap.add_argument("--codac-timeout", type=float, default=900)
    ap.add_argument("--no-codac", action="store_true")
    ap.add_argument("--timeout", type=float, default=600)
    ap.add_argument("--json", metavar="FILE")
    a = ap.parse_args()

    mc = monte_carlo()
    print("Monte Carlo volumes (4e6 float samples, seed 12345): " + ", ".join(f"{k} {v:.1f}" for k, v in mc.items()))
    print(f"cores: {os.cpu_count()}; each row in a fresh process (peak memory = its max RSS)\n")
    hdr = (f"{'d':>2} {'mode':>10} {'leaves':>9} {'parts':>9} {'pave s':>7} {'cut s':>6} {'total s':>7} {'MiB':>6} "
           + " ".join(f"{k + ' in%':>7} {k + ' und':>8}" for k in SETS))
    print(hdr, flush=True)
    rows = []
    for d in a.depths:
        for r in sorted(set([-1] + [r for r in a.refine if r <= 0 or d <= a.refine_max_depth])):
            row = _child(OURS_SCRIPT, [str(d), str(r)], a.timeout)
            row.setdefault("depth", d)
            row["mode"] = "grid" if r < 0 else f"contract+{r}"
            rows.append(row)
            if "error" in row:
                print(f"{d:>2} {row['mode']:>10} {row['error']}", flush=True)
                continue
            print(f"{d:>2} {row['mode']:>10} {row['leaves']:>9} {row['parts']:>9} {row['paving_s']:>7.2f} "
                  f"{row['contract_s']:>6.2f} {row['seconds']:>7.2f} {row['maxrss_MiB']:>6.0f} "
                  + " ".join(f"{100 * row[k + '_in'] / mc[k]:>7.1f} {row[k + '_und']:>8.1f}" for k in SETS), flush=True)
    codac = None
    if not a.no_codac:
        codac = run_codac(a.codac_depth, a.codac_timeout)
        print(f"\nCodac 2, depth {a.codac_depth} (SepInverse / SepInter, separate processes)")
        for k in SETS:
            c = codac[k]
            if "error" in c:
                print(f"  {k:>3}: {c['error']}")
            else:
                print(f"  {k:>3}: {c['seconds']:7.2f} s  inner {100 * c['inner_volume'] / mc[k]:5.1f} %  "
                      f"undecided {c['boundary_volume']:8.1f}  boxes {c['inner_boxes'] + c['boundary_boxes']}  "
                      f"{c['maxrss_MiB']:.0f} MiB")
        if math.isfinite(codac["seconds"]):
            print(f"  all: {codac['seconds']:7.2f} s (W + both aspects, three pavings)\n")
            print("Ours against Codac: inner volume ratio per set, time ratio (Codac s / ours s)")
            first = None
            for row in rows:
                if "error" in row:
                    continue
                ratios = [row[k + "_in"] / codac[k]["inner_volume"] for k in SETS]
                speed = codac["seconds"] / row["seconds"]
                ok = all(x >= 1 for x in ratios)
                print(f"{row['depth']:>2} {row['mode']:>10}  " + "  ".join(f"{k} {x:5.3f}" for k, x in zip(SETS, ratios))
                      + f"   {speed:7.1f}x faster" + ("   >= Codac on all three" if ok else ""))
                if ok and (first is None or row["seconds"] < first["seconds"]):
                    first = row
            if first is not None:
                print(f"\nFastest row at or above Codac's inner volume on W, WA1 and WA2: depth {first['depth']} "
                      f"{first['mode']}, {first['seconds']:.2f} s = 1/{codac['seconds'] / first['seconds']:.0f} of Codac's "
                      f"{codac['seconds']:.1f} s")
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"monte_carlo": mc, "ours": rows, "codac": codac, "cores": os.cpu_count()}, f, indent=1)


if __name__ == "__main__":
    main()
