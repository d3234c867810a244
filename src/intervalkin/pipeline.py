"""The whole analysis of one manipulator as one library call, with typed, certified results.

:func:`analyse` runs the chain of DESIGN.md section 5 for a geometry:

1. the singular layer: workspace boxes (depth + 1) covering every singular point of W;
2. joint space: the outer enclosure of g(S) built from their images, and the cells of
   certified solution count (2**min(depth - 1, 7) voxels per axis); and the joint box
   paved directly (:mod:`intervalkin.space.joint_paving`, the same depth, adaptive),
   whose cells carry the count of basic regions;
3. the regions paving (depth): W, the sign of det A, the aspects, the boxes certified off
   the characteristic surfaces; their pieces, sheets and basic regions, the distinctness
   witnesses;
4. the uniqueness domains.

It returns an :class:`Analysis`: the joint cells, the regions, the counts with their certified
bounds (:class:`~intervalkin.core.status.Count`), :meth:`Analysis.label` (a pose) and
:meth:`Analysis.locate` (a joint vector), each answered with a
:class:`~intervalkin.core.status.Status`.  :func:`verify` re-checks a certificate folder with the
independent checker.  Nothing here prints: stages go to an optional ``progress`` callback as
:class:`ProgressEvent` objects; bad arguments raise :class:`~intervalkin.core.errors.InputError`.
"""

from __future__ import annotations

import contextlib
import dataclasses
import multiprocessing
import os
import time
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import Any, Callable, Iterator, Mapping, Sequence

import numpy as np

from intervalkin.certify.writer import write_certificates
from intervalkin.checker import INDEX, CheckResult, verify_directory
from intervalkin.core.errors import InputError
from intervalkin.core.exact import fraction_bounds
from intervalkin.core.geometry import Geometry, default_geometry
from intervalkin.core.status import Status
from intervalkin.core.workers import Beside
from intervalkin.paving.budget import check_depth
from intervalkin.recheck import recheck_folder, recheck_separations
from intervalkin.solve import dkp
from intervalkin.space.aspect_topology import AspectTopology, prove_aspects
from intervalkin.space.basic_region import (
    RegionAnalysis,
    RegionCounts,
    analyse_regions,
    label_pose,
)
from intervalkin.space.joint_cells import regions_from_cells
from intervalkin.space.joint_closure import Closure
from intervalkin.space.joint_paving import DEFAULT_JOINT_DEPTH, FACE_LEVELS, JOIN_LEVELS, MODEL_LEVELS, JointSpacePaving
from intervalkin.space.joint_separation import Separation
from intervalkin.space.joint_space import JointPaving, joint_paving
from intervalkin.space.joint_topology import pave_joint_topology
from intervalkin.space.pose_label import PoseLabel
from intervalkin.space.singular_surface import pave_singular_layer

__all__ = ["DEFAULT_DEPTH", "MAX_CHAIN_DEPTH", "ProgressEvent", "RefinementStep", "JointLocation", "Analysis",
           "VerifyReport", "check_chain_depth", "chain_depths", "pave_joint_space", "analyse", "verify"]

#: Workspace depth of the default run (about a minute on two cores).
DEFAULT_DEPTH = 8
#: Deepest workspace depth of the chain (its singular layer is paved one level deeper).
MAX_CHAIN_DEPTH = 9
#: From this joint depth on, the direct joint paving runs in a second process, beside the
#: regions paving (they are independent; the default run has two cores to use), unless the
#: caller is a daemonic process (a Dask worker of a sweep), which may not start children.
PARALLEL_JOINT_DEPTH = 6


@dataclass(frozen=True)
class ProgressEvent:
    """One step of a running analysis, for a progress display: ``kind`` is ``"start"``, ``"level"`` (one
    paving level done; ``level`` holds the paver's statistics: level, depth, boxes, split, seconds),
    ``"fraction"`` (a stage without levels says how much of its work is done: ``fraction`` in [0, 1],
    ``detail`` names the work) or ``"done"``; ``stage`` names the stage (the key of its time in
    :attr:`Analysis.timings`); ``seconds`` is the time since the stage started."""

    stage: str
    kind: str
    seconds: float
    level: Mapping[str, Any] | None = None
    fraction: float | None = None
    detail: str = ""


ProgressCallback = Callable[[ProgressEvent], None]


@dataclass(frozen=True)
class RefinementStep:
    """One depth of the regions paving: whether Proposition 1 was seen in full there.

    ``stopped`` says why the refinement stopped at this depth ("" when it went on).
    """

    depth: int
    consistent: bool
    basic_regions: int
    stopped: str = ""

    def to_json(self) -> dict:
        doc: dict = {"depth": self.depth, "consistent": self.consistent, "basic_regions": self.basic_regions}
        if self.stopped:
            doc["stopped"] = self.stopped
        return doc


@dataclass(frozen=True)
class JointLocation:
    """Where a joint vector lies in joint space, and its certified number of solutions.

    ``cell`` is the joint cell holding ``rho`` (None on the undecided layer, which may
    meet g(S)); ``count``, ``n_wa1`` and ``n_wa2`` are the certified numbers of
    solutions in all, with det A > 0 and with det A < 0 (None when not certified).
    ``status`` is CERTIFIED or UNDECIDED; ``why`` says what certified the count.
    """

    rho: tuple[Fraction, Fraction, Fraction]
    cell: int | None
    count: int | None
    n_wa1: int | None
    n_wa2: int | None
    status: Status
    why: str


@dataclass(frozen=True, eq=False)
class Analysis:
    """The definition sets of one manipulator, as certified pavings and counts.

    Attributes
    ----------
    geometry : the manipulator analysed.
    depth, singular_depth, joint_depth : the regions paving's depth, the singular
        layer's depth, and the joint grid's (2**joint_depth voxels per axis).
    joint : the joint-space grid: enclosure of g(S) by images of workspace boxes, cells with
        certified counts (the regions paving finds its sheets through it).
    cells : the joint box paved directly (boxes proved off g(S), adaptive), its cells with
        certified counts: the basic regions are counted over these, every cell included.
    regions : aspects, pieces, basic regions, witnesses, uniqueness domains, per box and in all.
    timings : seconds per stage, keyed by the stage names of the progress events.
    refinement : each depth the regions paving was tried at, and why it stopped.
    aspect_topology : the covers proving each sign's part of W connected (the aspects' upper bound).
    closure, separation : what is proved of the cells' topology: the cells that are whole components
        (:func:`~intervalkin.space.joint_closure.closed_cells`) and the cells of one signature that are
        different components (:func:`~intervalkin.space.joint_separation.separated_cells`); library proofs,
        not yet in the certificates.
    """

    geometry: Geometry
    depth: int
    singular_depth: int
    joint_depth: int
    joint: JointPaving
    cells: JointSpacePaving
    regions: RegionAnalysis
    timings: Mapping[str, float]
    refinement: tuple[RefinementStep, ...]
    aspect_topology: AspectTopology | None = None
    closure: Closure | None = None
    separation: Separation | None = None

    @property
    def n_singular_boxes(self) -> int:
        """Number of workspace boxes whose images make the enclosure of g(S)."""
        return self.joint.n_singular_boxes

    def counts(self) -> RegionCounts:
        """Aspects, basic regions and uniqueness domains, each a :class:`~intervalkin.core.status.Count`.

        The basic regions are counted over every cell of the direct joint paving
        (:func:`~intervalkin.space.joint_cells.regions_from_cells`), not over the cells
        that happen to receive certified workspace boxes.
        """
        counts = self.regions.counts()
        aspects = counts.aspects if self.aspect_topology is None else self.aspect_topology.count(counts.aspects)
        return dataclasses.replace(counts, aspects=aspects,
                                   basic_regions=regions_from_cells(self.cells.cells, counts.basic_regions.lower,
                                                                                    self.cells.open_places()))

    def label(self, pose: Sequence, refine: bool = True) -> PoseLabel:
        """Certified aspect, basic region and uniqueness domain of a pose (x, y, phi), read exactly.

        phi is reduced modulo 2 pi; a pose outside the paved domain raises InputError; where the
        paving leaves a label open, the pose itself and (``refine``, up to a few seconds) a
        certified path to a labelled box decide it (:mod:`intervalkin.space.pose_label`).
        """
        return label_pose(self.regions, pose, self.geometry, self.joint, refine)

    def locate(self, rho: Sequence) -> JointLocation:
        """The joint cell of a joint vector and its certified count and aspect split.

        A vector in a solved cell takes the cell's count (certified at every point of
        the cell).  Elsewhere (the undecided layer, an unsolved cell) the count comes
        from a certified solve at ``rho`` itself, or is UNDECIDED when that solve
        cannot be completed (``rho`` on or very near g(S)).
        """
        q = dkp.parse_joint_vector(self.geometry, rho)
        cid = self.joint.cell_at(q)
        if cid >= 0 and self.joint.cells[cid].count >= 0:
            c = self.joint.cells[cid]
            return JointLocation(q, cid, c.count, c.n_wa1, c.n_wa2, Status.CERTIFIED,
                                 f"rho lies in joint cell {cid}, certified off g(S); the certified solve at the "
                                 "cell's witness gives the count at every point of the cell")
        where = (f"rho lies in joint cell {cid}, whose solve was not completed" if cid >= 0 else
                 "rho lies on the undecided layer of the joint grid (it may be near g(S))")
        cell = cid if cid >= 0 else None
        direct = int(self.cells.cell_of(np.array([[fraction_bounds(v) for v in q]]))[0])
        found = next((c for c in self.cells.cells if c.id == direct and c.count >= 0), None)
        if found is not None:
            return JointLocation(q, cell, found.count, found.n_wa1, found.n_wa2, Status.CERTIFIED,
                                 f"{where}; it lies in cell {direct} of the direct joint paving, whose boxes are "
                                 "proved off g(S): the certified solve at that cell's witness gives its count")
        res = dkp.solve(self.geometry, q)
        if res.complete and all(s.status == "unique" and s.det_sign != 0 for s in res.solutions):
            n1 = sum(1 for s in res.solutions if s.det_sign > 0)
            return JointLocation(q, cell, res.count, n1, res.count - n1, Status.CERTIFIED,
                                 f"{where}; a certified solve at rho itself gives its count")
        return JointLocation(q, cell, None, None, None, Status.UNDECIDED,
                             f"{where}; the solve at rho was not completed ({res.completeness_reason})")

    def write_certificates(self, folder: str | Path, dkp_results: Sequence[dkp.DkpResult] = (),
                           trajectories: Sequence = (), barrier_faces: int | None = None) -> list[Path]:
        """Write the certificate folder of this analysis (and of extra solves and paths); return its files.

        ``barrier_faces``: faces the pattern barriers may range (None: the default budget).
        :func:`verify` re-proves every claim from the files alone.
        """
        return write_certificates(folder, self.geometry, dkp_results=dkp_results, joint=self.joint,
                                  regions=self.regions, trajectories=trajectories, counts=self.counts(),
                                  aspect_topology=self.aspect_topology, joint_cells=self.cells,
                                  barrier_faces=barrier_faces)


@dataclass(frozen=True)
class VerifyReport:
    """The independent checker's verdicts on one certificate folder, one per claim."""

    folder: Path
    results: tuple[CheckResult, ...]

    @property
    def verified(self) -> bool:
        """True when the folder holds claims and every one of them was re-proved."""
        return bool(self.results) and all(r.verified for r in self.results)

    @property
    def failed(self) -> tuple[CheckResult, ...]:
        """The claims that were not re-proved."""
        return tuple(r for r in self.results if not r.verified)


def check_chain_depth(depth, refine_to=None) -> int:
    """A depth for the chain: an integer in 3..MAX_CHAIN_DEPTH whose singular layer fits in memory.

    ``refine_to``, when given, must be an integer in depth..MAX_CHAIN_DEPTH.
    Raises :class:`~intervalkin.core.errors.InputError` naming the parameter.
    """
    if isinstance(depth, bool) or not isinstance(depth, int) or not 3 <= depth <= MAX_CHAIN_DEPTH:
        raise InputError(f"depth: expected an integer in 3..{MAX_CHAIN_DEPTH}, got {depth!r}")
    if refine_to is not None and (isinstance(refine_to, bool) or not isinstance(refine_to, int)
                                  or not depth <= refine_to <= MAX_CHAIN_DEPTH):
        raise InputError(f"refine_to: expected an integer in {depth}..{MAX_CHAIN_DEPTH}, got {refine_to!r}")
    check_depth(depth + 1)
    return depth


def chain_depths(depth: int) -> tuple[int, int, int]:
    """(workspace depth, singular-layer depth, joint depth) for a chain depth."""
    return depth, depth + 1, min(depth - 1, 7)


class _Stages:
    """Times the stages of a run and reports them to the progress callback."""

    def __init__(self, progress: ProgressCallback | None):
        self.progress = progress
        self.timings: dict[str, float] = {}

    @contextmanager
    def stage(self, name: str) -> Iterator[Callable[[dict], None] | None]:
        """Time one stage; yields the per-level callback for a paver (None without a progress callback)."""
        t0 = time.perf_counter()
        report = self.progress
        if report is not None:
            report(ProgressEvent(name, "start", 0.0))
        levels = None if report is None else (
            lambda st: report(ProgressEvent(name, "level", time.perf_counter() - t0, dict(st))))
        yield levels
        self.timings[name] = time.perf_counter() - t0
        if report is not None:
            report(ProgressEvent(name, "done", self.timings[name]))

    def fractions(self, name: str) -> Callable[[str, float], None] | None:
        """A ``(detail, fraction)`` callback reporting "fraction" events of stage ``name`` (None without a callback)."""
        report = self.progress
        if report is None:
            return None
        t0 = time.perf_counter()
        return lambda detail, done: report(ProgressEvent(name, "fraction", time.perf_counter() - t0,
                                                         fraction=float(done), detail=detail))


def _joint_space(geometry: Geometry, singular_depth: int, joint_depth: int, stages: _Stages) -> JointPaving:
    with stages.stage(f"singular layer (depth {singular_depth})") as levels:
        singular = pave_singular_layer(geometry, singular_depth, progress=levels)
    name = f"joint space: enclosure of g(S) and certified cells (2^{joint_depth} voxels per axis)"
    with stages.stage(name):
        return joint_paving(geometry, singular, joint_depth, progress=stages.fractions(name))


def pave_joint_space(geometry: Geometry | None = None, singular_depth: int = DEFAULT_DEPTH + 1,
                     joint_depth: int = 7, progress: ProgressCallback | None = None) -> JointPaving:
    """The singular layer at ``singular_depth`` and the joint cells on 2**joint_depth voxels per axis.

    The joint-space half of :func:`analyse`, on its own: every cell's count and aspect
    split is certified by one solve; the marked voxels may meet g(S).
    """
    geometry = default_geometry() if geometry is None else geometry
    check_depth(singular_depth)
    return _joint_space(geometry, singular_depth, joint_depth, _Stages(progress))


def analyse(geometry: Geometry | None = None, depth: int = DEFAULT_DEPTH, progress: ProgressCallback | None = None,
            refine_to: int | None = None, while_waiting: Callable[[RegionAnalysis, JointPaving], None] | None = None,
            retract: bool = False) -> Analysis:
    """Run the chain geometry -> singular layer -> joint cells -> regions -> uniqueness domains.

    Parameters
    ----------
    geometry : the manipulator; the paper's (Wenger & Chablat 1997) when None.
    depth : octree depth of the regions paving, 3..MAX_CHAIN_DEPTH (:func:`chain_depths` gives the other
        stages'; below the default the joint paving is a preview: one level of local refinement, no face level).
    progress : called with a :class:`ProgressEvent` at the start and end of each stage and after each level.
    refine_to : while Proposition 1 is not seen in full (a sheet of a counted cell holds no certified box),
        pave the regions one level deeper, up to this depth (only undecided boxes are split).
    while_waiting : work needing the regions and the joint enclosure, not the joint cells (the chain commands'
        pavings and figures, the paper run's trajectories), done while the joint paving runs in its second process.
    retract : also retract the joint paving's open layer towards its cells (``cells.retraction``); off by default,
        since it closes on no geometry yet (:func:`~intervalkin.space.joint_topology.pave_joint_topology`).

    Raises :class:`~intervalkin.core.errors.InputError` on a bad depth and
    :class:`~intervalkin.core.errors.ResourceError` when the run would not fit in memory.
    """
    geometry = default_geometry() if geometry is None else geometry
    check_chain_depth(depth, refine_to)
    dw, ds, dj = chain_depths(depth)
    stages = _Stages(progress)
    joint = _joint_space(geometry, ds, dj, stages)
    full = dj - 1 >= DEFAULT_JOINT_DEPTH  # below it a preview: one local level, no window models (separations need them)
    levels = {"model_levels": MODEL_LEVELS if full else 1, "face_levels": FACE_LEVELS if full else 0, "windows": full}
    name = (f"joint space paved directly (depth {dj - 1}, local models{', window models' if full else ''}, "
            f"{levels['model_levels']} + {levels['face_levels']} levels of local and face refinement, {JOIN_LEVELS} join levels; "
            f"closed cells, separations{', retraction' if retract else ''})")
    with contextlib.ExitStack() as side:
        future = None
        daemonic = multiprocessing.current_process().daemon
        if dj >= PARALLEL_JOINT_DEPTH and (os.cpu_count() or 1) > 1 and not daemonic:
            # the two pavings are independent: the joint one runs in a second process beside the regions
            # (not from a daemonic process, such as a Dask worker, which may not have children: in-process there)
            pool = side.enter_context(ProcessPoolExecutor(max_workers=1, mp_context=multiprocessing.get_context("fork")))
            future = pool.submit(pave_joint_topology, geometry, dj - 1, JOIN_LEVELS, retract=retract, **levels)
        else:
            with stages.stage(name) as report:
                cells, closure, separation = pave_joint_topology(geometry, dj - 1, JOIN_LEVELS, progress=report,
                                                                retract=retract, **levels)
        with stages.stage(f"workspace, aspects, characteristic surfaces, basic regions (depth {dw})") as levels:
            regions = analyse_regions(geometry, joint, dw, progress=levels)
        with stages.stage("aspects: covers proving each sign of det A connected"):
            topology = prove_aspects(geometry)
        if while_waiting is not None:
            with stages.stage("work beside the joint paving (files of the regions, trajectories)"):
                while_waiting(regions, joint)  # the main process would idle while the joint paving runs
        if future is not None:
            with stages.stage(name + ", in a second process: waiting for it"):
                cells, closure, separation = future.result()
    history = [RefinementStep(dw, regions.consistent, len(regions.regions))]
    while refine_to is not None and not regions.consistent and dw < refine_to:
        dw += 1
        with stages.stage(f"refining where Proposition 1 is not yet seen in full: regions at depth {dw}") as levels:
            regions = analyse_regions(geometry, joint, dw, progress=levels)
        history.append(RefinementStep(dw, regions.consistent, len(regions.regions)))
    if regions.consistent:
        stopped = "consistent: every sheet above every counted cell holds certified boxes"
    elif refine_to is None:
        stopped = "not consistent at this depth; no refinement asked"
    else:
        stopped = f"limit reached (depth {dw}) before consistency"
    history[-1] = dataclasses.replace(history[-1], stopped=stopped)
    return Analysis(geometry, dw, ds, dj, joint, cells, regions, dict(stages.timings), tuple(history), topology,
                    closure, separation)


def verify(path: str | Path) -> VerifyReport:
    """Re-prove every claim of a certificate folder with the independent checker (arb only).

    ``path`` is the certificate folder or an output folder holding ``certificates/``; with
    ``pavings/workspace.npz`` beside them, one more result (``box_labels_all``) re-proves every
    INSIDE/OUTSIDE box label of that paving (:mod:`intervalkin.recheck`), not only the sample.
    Raises :class:`~intervalkin.core.errors.InputError` (a ``CertificateFormatError``) when the
    folder, its index or the npz is malformed; a claim that does not re-prove is a failed
    result, not an error.
    """
    root = Path(path)
    folder = root / "certificates" if (root / "certificates" / INDEX).is_file() else root
    # the separation claims (a serial pattern check among them) are re-proved in a second process meanwhile
    with Beside(recheck_separations, root) as side:
        results = tuple(verify_directory(folder))
        everything = recheck_folder(root)
        barriers = tuple(side.result())
    return VerifyReport(folder, results + barriers + (() if everything is None else (everything,)))
