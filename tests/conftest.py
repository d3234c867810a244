"""Shared fixtures: the paper's manipulator and a seeded RNG, and the pavings many test files read."""

from __future__ import annotations

import contextlib
import fcntl
import io
import os
import pickle
import tempfile
from pathlib import Path

import numpy as np
import pytest

from intervalkin.core.geometry import default_geometry

DATA = Path(__file__).parent / "data"


#: The temporary folder the xdist workers of this run share (set at the start of each worker's session).
_SHARED_ROOT: list[Path] = []


@pytest.fixture(scope="session", autouse=True)
def _shared_root(tmp_path_factory):
    _SHARED_ROOT[:] = [tmp_path_factory.getbasetemp().parent]


def shared_value(name: str, build):
    """``build()``, computed by one xdist worker of the run and read by the others from a pickle.

    Session fixtures are per worker: a paving read by test files that land on both workers would be
    paved twice (the windowed depth-5 one costs about 30 s).  The first worker to ask builds it under
    an exclusive lock in the run's shared temporary folder; a worker asking later waits for the lock and
    loads the file.  Each worker gets its own copy, so the values stay read-only by convention only.
    Outside xdist (or before the session has started) it is simply built."""
    root = shared_root()
    if root is None:
        return build()
    path = root / f"{name}.pickle"
    with open(root / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if path.is_file():
            return pickle.loads(path.read_bytes())
        value = build()
        part = root / f"{name}.pickle.part"
        part.write_bytes(pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL))
        part.replace(path)  # a worker never reads half a file
        return value


def shared_root() -> Path | None:
    """The folder the xdist workers of this run share; None outside xdist (nothing to share)."""
    if os.environ.get("PYTEST_XDIST_WORKER") is None or not _SHARED_ROOT:
        return None
    return _SHARED_ROOT[0]


@pytest.fixture(scope="session")
def paper_geometry():
    return default_geometry()


@pytest.fixture
def rng():
    return np.random.default_rng(20261121)


def workspace_singular_boxes(geometry, depth: int) -> np.ndarray:
    """Leaves of a workspace paving that may hold a singular point of W (det undecided, not outside W)."""
    from intervalkin.paving.labels import Label
    from intervalkin.paving.predicates import pave_workspace

    p = pave_workspace(geometry, depth)
    sel = (p.labels["W"] != Label.OUTSIDE) & (p.labels["det_positive"] == Label.BOUNDARY)
    return p.boxes[sel]


def small_chain(geometry, workspace_depth: int, joint_depth: int, regions_depth: int | None = None,
                max_solves: int = 400):
    """A small real chain for tests: joint cells from a workspace paving, and (optionally) the regions."""
    from intervalkin.space.joint_space import joint_paving
    from intervalkin.space.basic_region import analyse_regions

    jp = joint_paving(geometry, workspace_singular_boxes(geometry, workspace_depth), joint_depth,
                      max_solves=max_solves)
    if regions_depth is None:
        return jp
    return jp, analyse_regions(geometry, jp, regions_depth)


@pytest.fixture(scope="session")
def regions_chain(paper_geometry):
    """The chain shared by space/test_basic_region.py, space/test_basic_region_properties.py and the depth-7
    test of space/test_trajectory.py (built once, about 8 s): workspace depth 7, joint grid 2**6, regions at
    depth 7.  Read only."""
    return shared_value("regions_chain", lambda: small_chain(paper_geometry, 7, 6, 7, max_solves=200))


@pytest.fixture(scope="session")
def aspect_topology(paper_geometry):
    """The covers proving each sign's part of W connected on the paper's manipulator (about 2 s)."""
    from intervalkin.space.aspect_topology import prove_aspects

    return prove_aspects(paper_geometry)


@pytest.fixture(scope="session")
def fold_paving(paper_geometry):
    """The joint box paved directly with fold models and window models, depth 5 and one join level: the
    source of the ``joint_fold_model`` and ``joint_join`` claims in tests/certify and tests/checker (about
    30 s, read by 17 test files: built once a run)."""
    from intervalkin.space.joint_paving import pave_joint_space

    return shared_value("fold_paving",
                      lambda: pave_joint_space(paper_geometry, 5, 1, fold=True, model_levels=1, windows=True))


@pytest.fixture(scope="session")
def joint_paving_4(paper_geometry):
    """``pave_joint_space(paper_geometry, 4)``, the default options at depth 4: shared by
    space/test_joint_paving.py and app/test_figures.py.  Read only."""
    from intervalkin.space.joint_paving import pave_joint_space

    return pave_joint_space(paper_geometry, 4)


@pytest.fixture(scope="session")
def fold_models_5(paper_geometry):
    """The joint box paved at depth 5 with local models (one model level) and no joins: shared by
    solve/test_fold_model.py (its fold pieces), solve/test_local_model.py (its voided boxes) and
    checker/test_joint_claims.py (its clear groups joined only by fold pieces).  Read only."""
    from intervalkin.space.joint_paving import pave_joint_space

    return shared_value("fold_models_5",
                      lambda: pave_joint_space(paper_geometry, 5, join_levels=0, fold=True, model_levels=1))


SECOND_DESIGN = Path(__file__).parents[1] / "examples" / "second_design_0246.toml"


@pytest.fixture(scope="session")
def second_geometry():
    """examples/second_design_0246.toml: a second manipulator with 0, 2, 4 and 6 solutions (issue 14)."""
    from intervalkin.core.geometry import load_geometry

    return load_geometry(SECOND_DESIGN)


@pytest.fixture(scope="session")
def second_aspect_topology(second_geometry):
    """The covers of the second design's two signs (about 3 s): two components of each sign, 4 aspects."""
    from intervalkin.space.aspect_topology import prove_aspects

    return prove_aspects(second_geometry)


@pytest.fixture(scope="session")
def analyze_depth4(tmp_path_factory) -> Path:
    """``intervalkin analyze --depth 4 --out DIR --quiet --json`` of the paper's manipulator (about 25 s, most of it
    the figures and certificates), written once a run for app/test_output_folder.py, checker/test_consistency.py
    and app/test_commands.py, on either worker; what it printed is in DIR/../stdout.txt.  Read it only: a test
    that changes files copies it first."""
    from intervalkin.app.cli import main

    def build() -> Path:
        out = Path(tempfile.mkdtemp(prefix="analyze-depth4-", dir=shared_root() or tmp_path_factory.getbasetemp()))
        printed = io.StringIO()
        with contextlib.redirect_stdout(printed):
            status = main(["analyze", "--depth", "4", "--out", str(out / "out"), "--quiet", "--json"])
        assert status == 0
        (out / "stdout.txt").write_text(printed.getvalue())
        return out / "out"

    return shared_value("analyze-depth4", build)
