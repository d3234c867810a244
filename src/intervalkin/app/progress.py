"""The whole workspace chain for one geometry, writing one output folder.

``run_pave`` (the ``intervalkin pave`` command) paves W, the sign of det A and the
aspects, finds the aspects as connected components, and writes::

    DIR/pavings/workspace.npz    boxes and labels (format: intervalkin.app.export)
    DIR/pavings/workspace.vtu    the same as a VTK unstructured grid of hexahedra
    DIR/figures/*.png            3-D views and phi-slices
    DIR/summary.json             counts, volumes, components, timings, what is certified
"""

from __future__ import annotations

import sys
import time

__all__ = ['ProgressBar']


class ProgressBar:
    """A plain text bar on stderr, one update per paving level."""

    def __init__(self, stream=None, width: int = 30):
        self.stream = stream if stream is not None else sys.stderr
        self.width = width
        self.t0 = time.perf_counter()

    def __call__(self, st: dict) -> None:
        done = (st["level"] + 1) / (st["depth"] + 1)
        n = int(round(done * self.width))
        self.stream.write(
            f"\rpaving [{'#' * n}{'.' * (self.width - n)}] level {st['level']}/{st['depth']}"
            f"  {st['boxes']:>9,d} boxes  {time.perf_counter() - self.t0:6.1f} s"
        )
        if st["level"] == st["depth"] or st["split"] == 0:
            self.stream.write("\n")
        self.stream.flush()


class Stages:
    """Stage names and timings on stderr (silent when quiet)."""

    def __init__(self, quiet: bool = False, stream=None):
        self.quiet = quiet
        self.stream = stream if stream is not None else sys.stderr
        self.t0 = time.perf_counter()
        self.timings: dict[str, float] = {}
        self._name = None
        self._start = 0.0

    def start(self, name: str) -> None:
        self._name, self._start = name, time.perf_counter()
        if not self.quiet:
            self.stream.write(f"[{time.perf_counter() - self.t0:6.1f} s] {name} ...\n")
            self.stream.flush()

    def done(self) -> None:
        self.timings[self._name] = time.perf_counter() - self._start

    def bar(self):
        return None if self.quiet else ProgressBar(self.stream)
