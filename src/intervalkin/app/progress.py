"""Progress on stderr for the command line: a line per stage, and tqdm bars inside the long ones.

The library never prints; :func:`intervalkin.pipeline.analyse` reports its stages
to a callback (:class:`~intervalkin.pipeline.ProgressEvent`).  :class:`Stages`
is that callback for the ``intervalkin`` command.  It also times the command's
own stages (writing files, figures, certificates, trajectories), which is why
it exists even when nothing is shown: the timings go into summary.json.

What is shown, and where: a line ``[  12.3 s] stage ...`` when a stage starts,
a bar per paving (one step per octree level, with the number of boxes), a bar
for stages that report a fraction done (the certified solves of the joint
cells) and a bar over the items of a loop the command runs itself
(:meth:`Stages.iterate`).  Nothing at all is written with ``--quiet``, or when
stderr is not a terminal (a log file or a pipe gets no carriage-return bars).
"""

from __future__ import annotations

import sys
import time
from typing import IO, Callable, Iterable, Iterator, Mapping, TypeVar

from tqdm import tqdm

from intervalkin.pipeline import ProgressEvent

__all__ = ['Stages', 'shows_progress']

T = TypeVar("T")


def shows_progress(stream: IO[str], quiet: bool) -> bool:
    """True when progress should be drawn on ``stream``: not quiet, and the stream is a terminal."""
    if quiet:
        return False
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):  # a closed or fake stream
        return False


class Stages:
    """Stage timings, and their display on stderr when it is a terminal; a progress callback for the library.

    Parameters
    ----------
    quiet : show nothing (the timings are still kept).
    stream : where to draw (default ``sys.stderr``).
    show : force the display on or off (default: :func:`shows_progress`); tests use it.
    """

    def __init__(self, quiet: bool = False, stream: IO[str] | None = None, show: bool | None = None):
        self.stream = stream if stream is not None else sys.stderr
        self.show = shows_progress(self.stream, quiet) if show is None else show
        self.t0 = time.perf_counter()
        self.timings: dict[str, float] = {}
        self._name: str | None = None
        self._start = 0.0
        self._bar: tqdm | None = None

    # -- stages ---------------------------------------------------------------------------
    def start(self, name: str) -> None:
        """A stage begins: its line on the display, its clock started."""
        self._close_bar()
        self._name, self._start = name, time.perf_counter()
        if self.show:
            tqdm.write(f"[{time.perf_counter() - self.t0:6.1f} s] {name}", file=self.stream)

    def done(self) -> None:
        """The current stage ends: its time is kept under its name."""
        self._close_bar()
        if self._name is not None:  # once: a library stage may end after sub-stages the caller timed inside it
            self.timings[self._name] = time.perf_counter() - self._start
            self._name = None

    # -- bars -------------------------------------------------------------------------------
    def _close_bar(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def _new_bar(self, total: float, unit: str, desc: str, bar_format: str | None = None) -> tqdm:
        self._close_bar()
        self._bar = tqdm(total=total, unit=unit, desc=desc, file=self.stream, leave=False, dynamic_ncols=True,
                         bar_format=bar_format, disable=not self.show)
        return self._bar

    def level(self, stats: Mapping) -> None:
        """One octree level of a paving done (``stats``: level, depth, boxes, split)."""
        if not self.show:
            return
        bar = self._bar
        if bar is None or getattr(bar, "unit", "") != "level":
            bar = self._new_bar(int(stats["depth"]) + 1, "level", "paving")
        bar.n = int(stats["level"]) + 1
        bar.set_postfix_str(f"{int(stats['boxes']):,} boxes", refresh=True)
        if stats["level"] >= stats["depth"] or stats.get("split", 1) == 0:
            self._close_bar()

    def levels(self) -> Callable[[Mapping], None] | None:
        """The per-level callback to give a paver (None when nothing is shown: the paver then skips it)."""
        return self.level if self.show else None

    def fraction(self, done: float, what: str = "") -> None:
        """A stage reports the fraction of its work done, in [0, 1]."""
        if not self.show:
            return
        bar = self._bar
        if bar is None or getattr(bar, "unit", "") != "%":
            bar = self._new_bar(100.0, "%", what or "working",
                                bar_format="{desc}: {percentage:3.0f}%|{bar}| [{elapsed}<{remaining}]")
        bar.n = max(0.0, min(100.0, 100.0 * float(done)))
        bar.refresh()

    def iterate(self, items: Iterable[T], desc: str, total: int | None = None) -> Iterator[T]:
        """Iterate over ``items`` with a bar (one step per item) while the display is on."""
        bar = self._new_bar(total if total is not None else len(items), "item", desc)  # type: ignore[arg-type]
        for item in items:
            yield item
            bar.update(1)
        self._close_bar()

    # -- the library's callback ----------------------------------------------------------------
    def __call__(self, event: ProgressEvent) -> None:
        """Follow a library run: a line per stage, a bar per paving or per counted piece of work."""
        if event.kind == "start":
            self.start(event.stage)
        elif event.kind == "level" and event.level is not None:
            self.level(event.level)
        elif event.kind == "fraction" and event.fraction is not None:
            self.fraction(event.fraction, event.detail or event.stage)
        elif event.kind == "done":
            self.done()
