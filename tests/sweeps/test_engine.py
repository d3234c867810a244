"""The sweep on a real LocalCluster of 2 workers: a worker killed mid-sweep, the cache, the resume.

Six designs around the paper's manipulator (platform scale 0.8..1.2 x rho_max 34 and 40) at
depth 4 (about 2 s each on a quiet machine; the grid of tests/sweeps/shared.py with two of its four rho_max).  The cluster is started once for the
module; the first sweep kills one worker (SIGKILL) while it is analysing a design, and the tests
check that every design still has exactly one result; the later sweeps reuse its cache.
"""

from __future__ import annotations

import dataclasses
import json
import os
import signal
import time
from decimal import Decimal

import pytest
import tomllib

import intervalkin
from intervalkin.sweeps.spec import parse_sweep
from tests.sweeps.shared import GRID as _FULL_GRID

#: six designs: enough for a worker to die with designs still queued, half the twelve's cost
GRID = _FULL_GRID.replace("[34, 36, 38, 40]", "[34, 40]")

distributed = pytest.importorskip("distributed")
dask = pytest.importorskip("dask")



def _spec(text: str):
    return parse_sweep(tomllib.loads(text, parse_float=Decimal))


@pytest.fixture(scope="module")
def cluster():
    # as the sweep's own LocalCluster: without the malloc setting that makes the analysis 4 times slower
    no_trim = {"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}
    with dask.config.set(no_trim):  # read when the nannies are made (a restarted worker gets the same)
        c = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                     silence_logs=40)
    with c, distributed.Client(c) as client:
        yield c, client


@pytest.fixture(scope="module")
def killed_run(cluster, tmp_path_factory):
    """The 6-design sweep, during which one worker busy with a design is killed; (result, cache, killed pid)."""
    c, client = cluster
    cache = tmp_path_factory.mktemp("sweep-cache")
    killed = {}

    def kill_one(event):
        if event.kind != "design" or killed:
            return
        for _ in range(50):  # the scheduler hands the next designs out within milliseconds
            busy = [w for w, keys in client.processing().items() if keys]
            if busy:
                break
            time.sleep(0.1)
        assert busy, "no worker is analysing a design: the sweep cannot be interrupted mid-way"
        pid = client.run(os.getpid, workers=[busy[0]])[busy[0]]
        os.kill(pid, signal.SIGKILL)
        killed.update(pid=pid, at=event.done)

    result = intervalkin.sweep(_spec(GRID), cache=cache, scheduler=c.scheduler_address, progress=kill_one)
    return result, cache, killed


def test_a_worker_killed_mid_sweep_leaves_every_design_exactly_once(killed_run, cluster):
    result, cache, killed = killed_run
    _, client = cluster
    assert killed["at"] == 1  # killed after the first result, with 5 designs to go
    assert killed["pid"] not in client.run(os.getpid).values()  # it died (the nanny started a new one)
    assert sorted(r["design"] for r in result.rows) == list(range(6))
    assert [r["status"] for r in result.rows] == ["ok"] * 6, [r["error"] for r in result.rows]
    assert len(result.computed) == 6 and result.reused == () and result.workers == 2
    files = sorted(p.name for p in cache.iterdir())
    assert files == sorted(f"{r['key']}.json" for r in result.rows)  # one cached result per design, no other file
    doc = json.loads((cache / files[0]).read_text())
    assert doc["key"] == files[0][:-5] and doc["result"]["status"] == "ok"


def test_counts_are_copied_with_their_bounds(killed_run):
    result, _, _ = killed_run
    for r in result.rows:
        for name in ("aspects", "joint_cells", "basic_regions", "uniqueness_domains"):
            assert r[f"{name}_lower"] <= r[f"{name}_found"]
            assert r[f"{name}_exact"] == (r[f"{name}_upper"] is not None and r[f"{name}_upper"] == r[f"{name}_lower"])
        assert r["aspects_lower"] >= 2  # both det A signs are certified; a separation may prove more
        assert 0 <= r["volume_largest_uniqueness_domain"] <= r["volume_W"]
        assert r["seconds"] > 0 and r["memory_mb"] > 0
    table = result.table()
    assert table.num_rows == 6 and table.column("platform.scale").to_pylist()[:2] == [0.8] * 2


def test_a_rerun_does_no_work_and_a_changed_parameter_computes_only_new_designs(killed_run, cluster):
    first, cache, _ = killed_run
    c, _ = cluster
    again = intervalkin.sweep(_spec(GRID), cache=cache, scheduler="tcp://127.0.0.1:1")  # never contacted
    assert again.computed == () and len(again.reused) == 6 and again.workers == 0
    assert [r["cached"] for r in again.rows] == [True] * 6
    assert [r["basic_regions_found"] for r in again.rows] == [r["basic_regions_found"] for r in first.rows]

    changed = intervalkin.sweep(_spec(GRID.replace("[34, 40]", "[32, 40]")), cache=cache,
                                scheduler=c.scheduler_address)
    new = [r["key"] for r in changed.rows if r["limits.rho_max"] == 32]
    assert sorted(changed.computed) == sorted(new) and len(new) == 3
    assert len(changed.reused) == 3
    assert len(list(cache.iterdir())) == 9


def test_degenerate_designs_are_rows_and_do_not_stop_the_others(cluster, tmp_path):
    c, _ = cluster
    spec = _spec('[analysis]\ndepth = 3\n[vary]\n"platform.b1b2" = [17.04, 40]')
    result = intervalkin.sweep(spec, cache=tmp_path, scheduler=c.scheduler_address)
    ok, flat = result.rows
    assert ok["status"] == "ok" and flat["status"] == "degenerate"
    assert "triangle inequality" in flat["error"] and flat["basic_regions_found"] is None
    assert len(result.computed) == 1 and [p.suffix for p in tmp_path.iterdir()] == [".json"]


def test_the_local_cluster_leaves_out_the_malloc_trim_setting_that_slows_the_analysis():
    # with MALLOC_TRIM_THRESHOLD_=65536 (Dask's default for nannies) a depth-6 analysis took 18.7 s instead of 3.3 s
    from intervalkin.sweeps.engine import _Dask

    os.environ["MALLOC_TRIM_THRESHOLD_"] = "65536"  # as an earlier default LocalCluster leaves it in this process
    with _Dask(None, 1, dashboard=True) as dask:
        env = dask.client.run(lambda: (os.environ.get("MALLOC_TRIM_THRESHOLD_"), os.environ.get("OMP_NUM_THREADS")))
        link = dask.link
    assert list(env.values()) == [(None, "1")]
    assert link.startswith("http://") and link.endswith("/status")  # the dashboard the command prints


def test_a_design_whose_analysis_fails_is_a_row_with_its_error_and_is_not_cached(cluster, tmp_path):
    c, _ = cluster
    spec = _spec('[analysis]\ndepth = 3\n[vary]\n"limits.rho_max" = [30, 32]')
    broken = dataclasses.replace(spec.designs[0], geometry_toml="[base\n")  # the worker cannot even read it
    spec = dataclasses.replace(spec, designs=(broken, spec.designs[1]))
    result = intervalkin.sweep(spec, cache=tmp_path, scheduler=c.scheduler_address)
    failed, ok = result.rows
    assert failed["status"] == "failed" and failed["error"].startswith("TOMLDecodeError")
    assert ok["status"] == "ok" and ok["aspects_found"] is not None
    assert [p.name for p in tmp_path.iterdir()] == [f"{ok['key']}.json"]  # the failure is tried again next time
