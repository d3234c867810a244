"""Progress: tqdm bars for paving levels, fractions and loops; silent with --quiet or off a terminal."""

from __future__ import annotations

import io

from intervalkin.app.progress import Stages, shows_progress
from intervalkin.pipeline import ProgressEvent


class _Terminal(io.StringIO):
    """A stream that says it is a terminal."""

    def isatty(self) -> bool:
        return True


def _feed(st: Stages) -> None:
    st(ProgressEvent("singular layer (depth 4)", "start", 0.0))
    for level in range(5):
        st(ProgressEvent("singular layer (depth 4)", "level", 0.1,
                         {"level": level, "depth": 4, "boxes": 1000 * (level + 1), "split": 10}))
    st(ProgressEvent("singular layer (depth 4)", "done", 0.5))
    st(ProgressEvent("joint space", "start", 0.0))
    for k in range(1, 5):
        st(ProgressEvent("joint space", "fraction", 0.1, fraction=k / 4, detail="certified solves per cell"))
    st(ProgressEvent("joint space", "done", 0.4))
    st.start("trajectories")
    assert list(st.iterate([(2, 3), (2, 6), (3, 6)], "trajectories")) == [(2, 3), (2, 6), (3, 6)]
    st.done()


def test_bars_on_a_terminal():
    stream = _Terminal()
    st = Stages(stream=stream)
    assert st.show
    _feed(st)
    text = stream.getvalue()
    assert "singular layer (depth 4)" in text and "joint space" in text and "trajectories" in text
    assert "paving" in text and "5,000 boxes" in text  # the last level's bar
    assert "certified solves per cell" in text and "100%" in text
    assert "trajectories:" in text and "/3 [" in text  # the loop's bar (tqdm throttles its redraws)
    assert set(st.timings) == {"singular layer (depth 4)", "joint space", "trajectories"}


def test_quiet_and_non_terminal_streams_get_nothing_but_timings_are_kept():
    for st in (Stages(quiet=True, stream=_Terminal()), Stages(stream=io.StringIO())):
        assert not st.show and st.levels() is None
        _feed(st)
        assert st.stream.getvalue() == ""
        assert set(st.timings) == {"singular layer (depth 4)", "joint space", "trajectories"}


def test_shows_progress_survives_odd_streams():
    class Closed(io.StringIO):
        def isatty(self):
            raise ValueError("I/O operation on closed file")

    assert shows_progress(_Terminal(), quiet=False) and not shows_progress(_Terminal(), quiet=True)
    assert not shows_progress(Closed(), quiet=False) and not shows_progress(object(), quiet=False)
