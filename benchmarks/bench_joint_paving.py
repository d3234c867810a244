"""Benchmark of the direct joint-space paving (a script, not a test).

    python benchmarks/bench_joint_paving.py [--depths 6 7] [--geometry FILE] [--samples 2000] [--no-fold]
        [--model-levels 1] [--face-levels 3] [--workers 1] [--windows] [--separations [--zones]]

Per depth: boxes, wall time, peak memory (resident set of this process; and, sampled
every 0.2 s, the largest sum over this process and its workers of the memory each holds
alone, psutil's USS: what the run costs the machine), the share of
the joint box's volume in boxes certified off g(S), the cells (count: number), the
basic regions they imply (the sum of the cells' counts, Theorem 1), and the agreement
of the paving with independent certified solves at random joint vectors: labelled
(the vector lies in a cell, or in a piece of a fold box placed by the side test),
agreeing (the cell's count and aspect split equal the solve's) and wrong (must be 0:
a wrong label is a soundness bug).  Local models are on by default (``--no-fold``: the
clear-box test alone): the boxes cleared by Krawczyk exclusion, the fold boxes, the fold
pieces joined to no cell and the fragments are printed.  With two depths or more, the
cells of each depth are compared with the first's, witness by witness.

Issue 13's targets: >= 99 % of the volume certified, random vectors labelled and
agreeing >= 99 %, 0 wrong, <= 60 s and <= 2 GiB at the default settings on 2 cores.
"""

from __future__ import annotations

import argparse
import resource
import threading
import time
from collections import Counter
from fractions import Fraction

import numpy as np
import psutil

from intervalkin.core.geometry import default_geometry, load_geometry
from intervalkin.solve.dkp import solve
from intervalkin.space.joint_paving import DEFAULT_JOINT_DEPTH, JOIN_LEVELS, joint_domain, pave_joint_space
from intervalkin.space.joint_separation import separated_cells
from intervalkin.space.joint_topology import refine_separations


class _MemoryWatch:
    """The largest sum, sampled, of the unique set sizes (USS) of this process and its children."""

    def __init__(self, every: float = 0.2):
        self.peak, self.every, self._stop = 0, every, threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        me = psutil.Process()
        while not self._stop.is_set():
            total = 0
            for p in [me] + me.children(recursive=True):
                try:
                    total += p.memory_full_info().uss
                except psutil.Error:  # a worker that just ended
                    pass
            self.peak = max(self.peak, total)
            self._stop.wait(self.every)

    def stop(self) -> int:
        self._stop.set()
        self._thread.join()
        return self.peak


def _agreement(geometry, jp, samples: int, seed: int) -> tuple[int, int, int, int]:
    dom = joint_domain(geometry)
    rng = np.random.default_rng(seed)
    q = dom[:, 0] + rng.random((samples, 3)) * (dom[:, 1] - dom[:, 0])
    sig = jp.signature_of(q, geometry)
    labelled = agree = wrong = 0
    for v, label in zip(q, sig):
        if label[0] < 0:
            continue
        labelled += 1
        res = solve(geometry, [Fraction(float(x)) for x in v])
        if not res.complete:
            continue
        n1 = sum(1 for s in res.solutions if s.aspect == "WA1")
        if (res.count, n1, res.count - n1) == tuple(int(x) for x in label):
            agree += 1
        else:
            wrong += 1
    return samples, labelled, agree, wrong


def _compare(geometry, a, b) -> str:
    """Whether paving b has the cells of paving a: same signatures, each witness of a in a cell of b of its signature."""
    same = sorted(c.signature for c in a.cells) == sorted(c.signature for c in b.cells)
    by_id = {c.id: c for c in b.cells}
    hits = set()
    for c in a.cells:
        cid = int(b.cell_of(np.array([[float(v) for v in c.witness]]), geometry)[0])
        if cid in by_id and by_id[cid].signature == c.signature:
            hits.add(cid)
    ok = same and len(hits) == len(a.cells)
    return (f"against the first depth: {'the same cells' if ok else 'DIFFERENT cells'} (signatures "
            f"{'equal' if same else 'differ'}, {len(hits)} of {len(a.cells)} witnesses in distinct cells of their signature)")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--depths", type=int, nargs="+", default=[DEFAULT_JOINT_DEPTH])
    ap.add_argument("--geometry", default=None)
    ap.add_argument("--samples", type=int, default=1000, help="random joint vectors checked by certified solves")
    ap.add_argument("--no-fold", action="store_true", help="no local models: the clear-box test alone")
    ap.add_argument("--model-levels", type=int, default=None, help="levels of local refinement (default: the library's)")
    ap.add_argument("--face-levels", type=int, default=None,
                    help="further levels for undecided boxes on the faces (default: the library's)")
    ap.add_argument("--windows", action="store_true",
                    help="window models for the leaves with no fold model (as analyze and paper do)")
    ap.add_argument("--workers", type=int, default=None, help="processes (default: the library's, two on 2 cores)")
    ap.add_argument("--zones", action="store_true",
                    help="with --separations: pave again, finer between cells still joined (space.joint_topology)")
    ap.add_argument("--separations", action="store_true",
                    help="the separations of cells of one signature, and the basic regions they prove (with --windows)")
    args = ap.parse_args()
    g = default_geometry() if args.geometry is None else load_geometry(args.geometry)
    print(f"{'depth':>5} {'boxes':>9} {'seconds':>8} {'peak MB':>8} {'all MB':>7} {'certified':>9} {'regions':>7} "
          f"{'labelled':>8} {'agree':>6} {'wrong':>5}   cells (count: number)")
    first = None
    extra = {} if args.model_levels is None else {"model_levels": args.model_levels}
    if args.face_levels is not None:
        extra["face_levels"] = args.face_levels
    if args.workers is not None:
        extra["workers"] = args.workers
    if args.windows:
        extra["windows"] = True
    for depth in args.depths:
        watch = _MemoryWatch()
        t0 = time.perf_counter()
        jp = pave_joint_space(g, depth, fold=not args.no_fold, **extra)
        dt = time.perf_counter() - t0
        every = watch.stop() / 2**20
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        n, labelled, agree, wrong = _agreement(g, jp, args.samples, seed=depth)
        kinds = Counter(c.count for c in jp.cells)
        cells = ", ".join(f"{k}: {kinds[k]}" for k in sorted(kinds))
        print(f"{depth:>5} {len(jp.paving):>9} {dt:>8.1f} {peak:>8.0f} {every:>7.0f} {100 * jp.certified_share():>8.1f}% "
              f"{sum(c.count for c in jp.cells):>7} {100 * labelled / n:>7.1f}% {100 * agree / n:>5.1f}% {wrong:>5}   {cells}",
              flush=True)
        if jp.fold_stats:
            fs = jp.fold_stats
            print(f"       cleared by exclusion {fs['void_boxes']} boxes (volume {fs['void_volume']:.0f}); fold boxes "
                  f"{fs['fold_boxes']} ({fs['seconds']:.1f} s for their pieces); pieces joined to no cell: "
                  f"{fs['unjoined_piece_groups']} groups, volume {fs['unjoined_piece_volume']:.2f}; fragments "
                  f"{len(jp.fragments)} (volume {sum(c.volume for c in jp.fragments):.3f})", flush=True)
        if jp.fold_stats and "windows" in jp.fold_stats:
            w = jp.fold_stats["windows"]
            print(f"       window models: {w['leaves_modelled']} of {w['leaves_tried']} leaves without a fold model "
                  f"(volume {w['volume_modelled']:.1f} of {w['volume_tried']:.1f}); {w['pair_windows']} pair and "
                  f"{w['triple_windows']} triple windows; {w['seconds']:.1f} s", flush=True)
            if "window_folds" in w:
                print(f"       window pieces: {w['window_clear']} window-clear leaves and {w['window_folds']} window "
                      f"folds (volume {w['volume_pieced']:.1f}), proved pieces joined to the cells", flush=True)
        print("       undecided volume per stage: " + ", ".join(
            f"{st['stage']} {st['level']}: {st['undecided_volume']['clear']:.0f}" for st in jp.paving.stats), flush=True)
        print("       cells: " + "; ".join(f"{c.count} ({c.n_wa1}+{c.n_wa2}) vol {c.volume:.2f} at "
                                          f"({', '.join(f'{float(v):.2f}' for v in c.witness)})" for c in jp.cells))
        if args.separations:
            t1 = time.perf_counter()
            sep = separated_cells(jp, g)
            print("       separations (" + f"{time.perf_counter() - t1:.1f} s): " + "; ".join(
                f"{sig[0]} solutions " + " | ".join(",".join(map(str, grp)) for grp in groups)
                for sig, groups in sorted(sep.groups.items()))
                + f"; at least {sep.components_at_least()} components and {sep.basic_regions_at_least()} basic regions; "
                f"{sep.pattern_nodes} pattern nodes, {sep.refuted_contacts} refuted contacts, "
                f"{sep.leaves_modelled} leaves modelled", flush=True)
            if args.zones and sep.between.size:
                t1 = time.perf_counter()
                jp, sep = refine_separations(g, jp, sep, depth, JOIN_LEVELS, fold=not args.no_fold, **extra)
                print(f"       zone passes ({time.perf_counter() - t1:.1f} s, paving and separations again): "
                      + "; ".join(f"{z['boxes']} boxes of the uniform level (volume {z['volume']:.2f}) split "
                                  f"{z['levels']} more times: at least {z['components_at_least']} components, "
                                  f"{'kept' if z['kept'] else 'not kept'}" for z in sep.zone_passes)
                      + f"; at least {sep.basic_regions_at_least()} basic regions", flush=True)
        if first is None:
            first = jp
        else:
            print("       " + _compare(g, first, jp), flush=True)
    print("peak MB is the process's maximum resident set so far (it includes the earlier depths); all MB the "
          "largest sampled sum of the memory held alone by this process and its workers during that depth's paving.")


if __name__ == "__main__":
    main()
