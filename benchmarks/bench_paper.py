"""Benchmark of the paper run as a user types it: ``intervalkin paper``, then ``intervalkin verify``.

Prints the wall time of each command, the peak memory of the largest process (the run forks a
joint-paving process and workers; each is counted apart, as the operating system does), the CPU
time of all of them, the stage times the run wrote into ``summary.json``, and the targets of
issue 14 (the whole paper run in 120 s and 4 GiB on two cores) beside them.

    python benchmarks/bench_paper.py [--out DIR] [--keep] [--retraction]

The run has two processes busy for most of its length (the joint paving beside the regions), so
its wall time follows its CPU time: about (CPU of the joint process) / 2 + (work after the join).
A script that prints figures, not a test: targets live here, not in timed tests.
"""

from __future__ import annotations

import argparse
import json
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: Issue 14's targets for the whole paper run on two cores.
TARGET_SECONDS = 120.0
TARGET_GIB = 4.0


def _timed(cmd: list[str]) -> tuple[float, float, float, int]:
    """(wall s, CPU s of the command's processes, peak RSS GiB of its largest process, exit code)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    code = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE).returncode
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    # ru_maxrss of the children is the largest over all of them so far (KiB on Linux): a later command
    # that stays smaller reports the earlier peak, so the paper run is measured first
    return wall, cpu, after.ru_maxrss / 2**20, code


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", help="output folder (default: a temporary one)")
    ap.add_argument("--keep", action="store_true", help="keep the temporary output folder")
    ap.add_argument("--retraction", action="store_true",
                    help="run `intervalkin paper --retraction` (the open layer's retraction, off by default)")
    args = ap.parse_args()
    scratch = Path(tempfile.mkdtemp(prefix="bench-paper-")) if args.out is None else None
    out = Path(args.out) if args.out else scratch / "paper"
    exe = [sys.executable, "-m", "intervalkin"]
    wall, cpu, gib, code = _timed(exe + ["paper", "--out", str(out), "--force", "--quiet"]
                                  + (["--retraction"] if args.retraction else []))
    if code != 0:
        sys.exit(f"intervalkin paper failed (exit {code})")
    v_wall, v_cpu, _, v_code = _timed(exe + ["verify", str(out)])
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    print(f"intervalkin paper : {wall:7.1f} s wall, {cpu:7.1f} s CPU, largest process {gib:.2f} GiB "
          f"(targets {TARGET_SECONDS:.0f} s, {TARGET_GIB:.0f} GiB: "
          f"{'met' if wall <= TARGET_SECONDS and gib <= TARGET_GIB else 'not met'})")
    print(f"intervalkin verify: {v_wall:7.1f} s wall, {v_cpu:7.1f} s CPU, "
          f"{'every claim re-proved' if v_code == 0 else f'exit {v_code}: some claim did not re-prove'}")
    print("stages of the paper run (summary.json, seconds; the joint paving runs beside the first ones):")
    for name, seconds in summary.get("timings_seconds", {}).items():
        print(f"  {seconds:7.1f}  {name}")
    if scratch is not None and not args.keep:
        shutil.rmtree(scratch, ignore_errors=True)
    elif scratch is not None:
        print(f"output kept in {out}")


if __name__ == "__main__":
    main()
