"""The command handlers that compute and write an output folder: pave, joint, analyze, paper, trajectory.

Each ``run_*`` function backs one sub-command of :mod:`intervalkin.app.cli`: it
reads the options, calls the library (:mod:`intervalkin.pipeline` and the layers
below), writes the output folder through :mod:`intervalkin.app.output`, prints
the short table on stdout (progress goes to stderr) and returns the exit status
0.  Bad input raises :class:`~intervalkin.core.errors.IntervalkinError`, which the
command line turns into one line on stderr and status 2.  Nothing here proves
anything: every claim printed or written comes from the library's results.
"""

from __future__ import annotations

import json
import re
import sys
import time
from contextlib import nullcontext
from pathlib import Path

from intervalkin.app.animation import write_trajectory
from intervalkin.app.export import paving_columns, write_npz, write_vtu_paving
from intervalkin.app.figures import render_all, render_joint
from intervalkin.app.options import check_barrier_faces, check_joint_depth, geometry_from_option
from intervalkin.app.output import (
    OutputFolder,
    npz_bytes,
    write_analysis_certificates,
    write_chain,
    write_region_files,
)
from intervalkin.app.progress import Stages
from intervalkin.app.report import write_report
from intervalkin.app.report_html import write_report_html
from intervalkin.app.summary import (
    add_barrier_certificates,
    chain_table,
    joint_summary,
    joint_table,
    pave_summary,
    pave_table,
)
from intervalkin.app.table1 import TABLE1_RHO
from intervalkin.core.errors import IntervalkinError
from intervalkin.core.files import atomic_write_bytes, write_json
from intervalkin.core.geometry import Geometry, default_geometry
from intervalkin.paving.adjacency import shares_face
from intervalkin.paving.budget import check_depth
from intervalkin.paving.labels import Label
from intervalkin.paving.predicates import pave_workspace
from intervalkin.pipeline import Analysis, analyse, check_chain_depth, pave_joint_space
from intervalkin.space.aspect import aspect_components
from intervalkin.space.trajectory import check_request, trajectory

__all__ = ['GEOMETRY_FILE', 'run_pave', 'run_joint', 'run_analyze', 'run_trajectory']

#: The geometry of a run, as the exact TOML it was read from (``label --from`` reads it back).
GEOMETRY_FILE = "geometry.toml"


def _begin(folder: OutputFolder, geometry: Geometry) -> None:
    """The first files of a run: its geometry, and a summary.json that says the run has not completed."""
    atomic_write_bytes(folder.root / GEOMETRY_FILE, geometry.to_toml().encode())
    write_json(folder.root / "summary.json", {"complete": False, "command": folder.command,
                                              "geometry": geometry.name})


def _end(folder: OutputFolder, summary: dict) -> None:
    """The last write of a run: the manifest marked complete, then summary.json with ``"complete": true``."""
    summary["files"] = sorted(set(summary.get("files", [])) | {GEOMETRY_FILE})
    folder.finish()
    summary["complete"] = True
    write_json(folder.root / "summary.json", summary)


def run_pave(geometry_path, depth, out, figures: bool = True, progress: bool = True, force: bool = False,
             quiet: bool = False) -> int:
    """``intervalkin pave``: W, the det A sign and the aspects at ``depth``, written into ``out``.

    Validates ``depth`` (integer 1..MAX_DEPTH, memory estimate against
    MemAvailable) and the output folder before any work.
    """
    depth = check_depth(depth)
    geometry = geometry_from_option(geometry_path)
    folder = OutputFolder.open(out, force, "pave")  # refused before the paving, not after
    out = folder.root
    st = Stages(quiet=quiet or not progress)
    with folder.recording():
        _begin(folder, geometry)
        t0 = time.perf_counter()
        st.start(f"workspace paving (depth {depth})")
        paving = pave_workspace(geometry, depth, progress=st.levels())
        st.done()
        t1 = time.perf_counter()
        edges = shares_face(paving.level, paving.ijk, paving.depth)
        aspect, info = aspect_components(paving, edges)
        t2 = time.perf_counter()
        st.start("writing pavings (npz, VTK)")
        write_npz(out / "pavings" / "workspace.npz", paving, aspect)
        cols = paving_columns(paving, aspect)
        write_vtu_paving(out / "pavings" / "workspace.vtu", paving,
                         {k: cols[k] for k in ("in_workspace", "det_sign", "aspect", "depth")},
                         mask=paving.labels["W"] != Label.OUTSIDE)
        st.done()
        t3 = time.perf_counter()
        st.start("figures")
        fig_files = render_all(paving, out / "figures", base=geometry.base) if figures else []
        st.done()
        t4 = time.perf_counter()
        timings = {"paving": t1 - t0, "components": t2 - t1, "export": t3 - t2, "figures": t4 - t3, "total": t4 - t0}
        summary = {"complete": False, **pave_summary(paving, info, timings)}
        summary["geometry"] = geometry.name
        summary["files"] = ["pavings/workspace.npz", "pavings/workspace.vtu"] + [f"figures/{f.name}" for f in fig_files]
        _end(folder, summary)
    if not quiet:
        sys.stdout.write(pave_table(summary) + "\n")
    return 0


def run_joint(geometry_path, depth: int, out, force: bool = False, quiet: bool = False, figures: bool = True) -> int:
    """``intervalkin joint``: the enclosure of g(S), the certified cells and their table."""
    depth = check_joint_depth(depth)
    geometry = geometry_from_option(geometry_path)
    folder = OutputFolder.open(out, force, "joint")
    out = folder.root
    st = Stages(quiet=quiet)
    ds = min(depth + 2, 10)
    with folder.recording():
        _begin(folder, geometry)
        jp = pave_joint_space(geometry, ds, depth, progress=st)
        atomic_write_bytes(out / "pavings" / "joint.npz", npz_bytes(jp.columns()))
        files = ["pavings/joint.npz"]
        if figures:
            st.start("figures")
            files += [f"figures/{f.name}" for f in render_joint(jp, out / "figures")]
            st.done()
        summary = {"complete": False, "geometry": geometry.name, "singular_depth": ds, "joint": joint_summary(jp),
                   "timings_seconds": st.timings, "files": files}
        _end(folder, summary)
    if not quiet:
        sys.stdout.write(joint_table(jp) + "\n")
    return 0


def run_analyze(geometry_path, depth: int, out, force: bool = False, quiet: bool = False, as_json: bool = False,
                figures: bool = True, certificates: bool = True, paper: bool = False,
                refine_to: int | None = None, barrier_faces: int | None = None, retract: bool = False) -> int:
    """``intervalkin analyze`` (and ``paper`` when paper=True): the whole chain into one folder.
    ``barrier_faces``: the pattern barriers' face budget (None: the default); ``retract``: also retract the joint
    paving's open layer (:func:`~intervalkin.pipeline.analyse`)."""
    geometry = default_geometry() if paper else geometry_from_option(geometry_path)
    check_chain_depth(depth, refine_to)  # before the output folder is made
    if barrier_faces is not None:
        check_barrier_faces(barrier_faces)
    folder = OutputFolder.open(out, force, "paper" if paper else "analyze")
    out = folder.root
    st = Stages(quiet=quiet or as_json)
    with folder.recording():
        _begin(folder, geometry)
        early: dict = {}

        def table1_paths(regions, joint, files):
            paths = _table1_paths(geometry, regions, joint, st)
            st.start("certified trajectories between Table 1's solutions 2, 3, 6")
            early["trajectories"] = _paper_trajectories(geometry, regions, joint, out, files, paths)
            st.done()

        def beside(regions, joint):  # needs the regions, not the joint cells: done while those are paved
            early["files"] = write_region_files(geometry, regions, joint, out, figures, st)
            if paper:
                table1_paths(regions, joint, early["files"])

        # with refine_to the regions may be paved again after the joint cells: then everything is written after
        a = analyse(geometry, depth, progress=st, refine_to=refine_to,
                    while_waiting=beside if refine_to is None else None, retract=retract)
        summary = write_chain(a, out, figures=figures, stages=st, written=early.get("files"))
        trajs = []
        if paper:  # before the certificates, which re-check these paths
            if "trajectories" not in early:
                table1_paths(a.regions, a.joint, summary["files"])
            summary["trajectories"], trajs = early["trajectories"]
        if certificates:
            st.start("certificates")
            summary["files"] += write_analysis_certificates(a, out, trajectories=trajs, barrier_faces=barrier_faces)
            if (out / "certificates" / "joint_separation.json").is_file():
                barriers = json.loads((out / "certificates" / "joint_separation.json").read_text(encoding="utf-8"))
                add_barrier_certificates(summary, barriers["claims"])
            st.done()
        if paper:
            st.start("paper report")
            summary["timings_seconds"] = {**summary["timings_seconds"], **st.timings,
                                          "total": time.perf_counter() - st.t0}
            summary["files"].append(write_report(a, summary, out, st.timings))
            summary["files"].append(write_report_html(a, summary, out))
            st.done()
        summary["timings_seconds"] = {**summary["timings_seconds"], **st.timings,
                                      "total": time.perf_counter() - st.t0}
        _end(folder, summary)
    if as_json:
        sys.stdout.write(json.dumps(summary) + "\n")
    elif not quiet:
        sys.stdout.write(chain_table(summary) + f"\nwritten to {out}/ in {summary['timings_seconds']['total']:.1f} s\n")
    return 0


def _table1_paths(geometry, regions, joint, st: Stages) -> list[tuple[int, int, object]]:
    """Certified non-singular paths between Table 1's solutions 2, 3 and 6 (paper section 3.2, Fig. 13):
    (i, j, the :class:`~intervalkin.space.trajectory.Trajectory` or the error that stopped it)."""
    out = []
    for i, j in st.iterate(((2, 3), (2, 6), (3, 6)), "trajectories"):
        try:
            out.append((i, j, trajectory(geometry, TABLE1_RHO, i, j, analysis=regions, joint=joint)))
        except IntervalkinError as exc:
            out.append((i, j, exc))
    return out


def _paper_trajectories(geometry, regions, joint, out: Path, files: list[str], paths) -> tuple[list[dict], list]:
    """Write the Table 1 paths (their files appended to ``files``); their report entries (one per pair,
    failures included) and the :class:`~intervalkin.space.trajectory.Trajectory` objects found (for the
    certificates)."""
    done, found = [], []
    for i, j, tr in paths:
        if isinstance(tr, IntervalkinError):
            done.append({"from": i, "to": j, "certified": False, "reason": str(tr)})
            continue
        folder = out / "trajectories" / f"{i}-{j}"
        for path in write_trajectory(tr, geometry, folder, paving=regions.paving, joint=joint):
            files.append(str(Path(path).relative_to(out)))
        doc = tr.to_json()
        doc["summary"] = tr.summary()
        doc["folder"] = f"trajectories/{i}-{j}"
        done.append(doc)
        found.append(tr)
    return done, found


#: The parameters of :func:`~intervalkin.space.trajectory.trajectory` and the flags that set them.
_TRAJECTORY_FLAGS = {"i_from": "--from", "i_to": "--to"}


def _check_trajectory_request(geometry, rho, i_from: int, i_to: int) -> None:
    """``check_request``, its message naming the command's flags where the library names parameters."""
    try:
        check_request(geometry, rho, i_from, i_to)
    except IntervalkinError as exc:
        text = re.sub(r"\b(i_from|i_to)\b", lambda m: _TRAJECTORY_FLAGS[m.group(1)], str(exc))
        raise type(exc)(text) from None


def run_trajectory(geometry_path, rho, i_from: int, i_to: int, depth: int = 7, out=None,
                   as_json: bool = False, quiet: bool = False, force: bool = False) -> int:
    """``intervalkin trajectory``: the chain at ``depth``, then a certified path between two solutions.

    The request, the depth and the output folder are checked first (solutions of
    different aspects are refused at once, before any paving).
    """
    geometry = geometry_from_option(geometry_path)
    _check_trajectory_request(geometry, rho, i_from, i_to)
    check_chain_depth(depth)
    folder = None if out is None else OutputFolder.open(out, force, "trajectory")
    st = Stages(quiet=quiet or as_json)
    # no path found (NoPathError) leaves no folder behind: recording() removes what the run made
    with folder.recording() if folder is not None else nullcontext():
        a = analyse(geometry, depth, progress=st)
        st.start("certified path")
        traj = trajectory(geometry, rho, i_from, i_to, analysis=a.regions, joint=a.joint)
        st.done()
        if folder is not None:
            atomic_write_bytes(folder.root / GEOMETRY_FILE, geometry.to_toml().encode())
            write_trajectory(traj, geometry, folder.root, paving=a.regions.paving, joint=a.joint)
            folder.finish()
    if as_json:
        sys.stdout.write(json.dumps(traj.to_json()) + "\n")
    else:
        sys.stdout.write(traj.summary() + "\n")
    return 0
