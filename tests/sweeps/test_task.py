"""One design on a worker: a failure is a result, and analyse runs inside a daemonic process."""

from __future__ import annotations

import dataclasses
import multiprocessing

import intervalkin.pipeline as pipeline
from intervalkin.core.geometry import default_geometry
from intervalkin.sweeps.task import count_from_json, run_design


def _without_timings(value):
    """The count with its wall-clock entries removed: two runs agree on everything but the time."""
    if isinstance(value, dict):
        return {k: _without_timings(v) for k, v in value.items() if k != "seconds"}
    return value


def test_a_failed_design_is_a_result_with_its_error_not_an_exception():
    out = run_design("[base\n", {"depth": 4})
    assert out["status"] == "failed" and out["error"].startswith("TOMLDecodeError") and "\n" not in out["error"]
    out = run_design(default_geometry().to_toml(), {"depth": 99})
    assert out["status"] == "failed" and "depth: expected an integer in 3..9, got 99" in out["error"]


def test_a_design_carries_the_counts_of_its_analysis():
    out = run_design(default_geometry().to_toml(), {"depth": 4, "refine_to": None})
    assert out["status"] == "ok" and out["depth"] == 4
    counts = pipeline.analyse(default_geometry(), depth=4).counts()
    for name in ("aspects", "basic_regions", "uniqueness_domains"):
        got, want = count_from_json(out["counts"][name]), getattr(counts, name)
        assert dataclasses.replace(got, undecided=_without_timings(got.undecided)) == dataclasses.replace(
            want, undecided=_without_timings(want.undecided))
    cells = count_from_json(out["counts"]["joint_cells"])
    assert cells.lower <= cells.found and not cells.exact


def _analyse_in_child(queue):
    try:
        a = pipeline.analyse(depth=4)
        queue.put(("ok", a.counts().aspects.found))
    except BaseException as exc:  # noqa: BLE001 - reported to the parent
        queue.put(("failed", f"{type(exc).__name__}: {exc}"))


def test_analyse_runs_in_a_daemonic_process_where_a_second_process_is_not_allowed(monkeypatch):
    # a Dask worker is a daemonic process: it may not start the joint paving's second process
    monkeypatch.setattr(pipeline, "PARALLEL_JOINT_DEPTH", 3)  # so that depth 4 would use it
    ctx = multiprocessing.get_context("fork")
    queue = ctx.Queue()
    child = ctx.Process(target=_analyse_in_child, args=(queue,), daemon=True)
    child.start()
    status, value = queue.get(timeout=120)
    child.join(10)
    assert (status, value) == ("ok", 2), value
