"""Progress on stderr for the command line: stage lines with times, and a bar per paving level.

The library never prints; :func:`intervalkin.pipeline.analyse` reports its stages
to a callback.  :class:`Stages` is that callback for the ``intervalkin`` command
(it also times the command's own stages: writing files, figures, certificates),
and :class:`ProgressBar` draws one paver's levels.
"""

from __future__ import annotations

import sys
import time
from typing import Mapping

from intervalkin.pipeline import ProgressEvent

__all__ = ['ProgressBar', 'Stages']


class ProgressBar:
    """A plain text bar on stderr, one update per paving level."""

    def __init__(self, stream=None, width: int = 30):
        self.stream = stream if stream is not None else sys.stderr
        self.width = width
        self.t0 = time.perf_counter()

    def __call__(self, st: Mapping) -> None:
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
    """Stage names and timings on stderr (silent when quiet); a progress callback for the library."""

    def __init__(self, quiet: bool = False, stream=None):
        self.quiet = quiet
        self.stream = stream if stream is not None else sys.stderr
        self.t0 = time.perf_counter()
        self.timings: dict[str, float] = {}
        self._name = None
        self._start = 0.0
        self._bar: ProgressBar | None = None

    def start(self, name: str) -> None:
        self._name, self._start = name, time.perf_counter()
        self._bar = None if self.quiet else ProgressBar(self.stream)
        if not self.quiet:
            self.stream.write(f"[{time.perf_counter() - self.t0:6.1f} s] {name} ...\n")
            self.stream.flush()

    def done(self) -> None:
        self.timings[self._name] = time.perf_counter() - self._start

    def __call__(self, event: ProgressEvent) -> None:
        """Follow a library run: a line per stage, a bar per paving."""
        if event.kind == "start":
            self.start(event.stage)
        elif event.kind == "level" and self._bar is not None and event.level is not None:
            self._bar(event.level)
        elif event.kind == "done":
            self.done()
