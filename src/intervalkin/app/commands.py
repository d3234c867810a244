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
from pathlib import Path

import numpy as np

from intervalkin.app.animation import write_trajectory
from intervalkin.app.export import paving_columns, write_npz, write_vtu_paving
from intervalkin.app.figures import render_all, render_joint
from intervalkin.app.options import geometry_from_option
from intervalkin.app.output import (
    MARKER,
    _npz_bytes,
    _write_certificates,
    prepare_output_dir,
    write_chain,
)
from intervalkin.app.progress import ProgressBar, Stages
from intervalkin.app.report import write_report
from intervalkin.app.summary import (
    _table,
    chain_table,
    joint_summary,
    joint_table,
    pave_summary,
)
from intervalkin.app.table1 import TABLE1_RHO
from intervalkin.core.errors import InputError, IntervalkinError
from intervalkin.core.files import atomic_write_bytes, write_json
from intervalkin.core.geometry import default_geometry
from intervalkin.paving.adjacency import shares_face
from intervalkin.paving.budget import check_depth
from intervalkin.paving.labels import Label
from intervalkin.paving.predicates import pave_workspace
from intervalkin.pipeline import (
    Analysis,
    _singular_and_joint,
    analyse,
    check_chain_depth,
)
from intervalkin.space.aspect import aspect_components
from intervalkin.space.basic_region import label_pose
from intervalkin.space.trajectory import check_request, trajectory

__all__ = ['run_pave', 'run_analyze']


def run_pave(geometry_path, depth, out, figures: bool = True, progress: bool = True) -> int:
    """Pave W, det A sign and the aspects at ``depth`` and write everything into ``out``.

    Validates ``depth`` (integer 1..MAX_DEPTH, memory estimate against
    MemAvailable) before any work; returns the exit status 0.
    """

    depth = check_depth(depth)
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out: {str(out)!r} exists and is not a folder")
    geometry = geometry_from_option(geometry_path)
    t0 = time.perf_counter()
    paving = pave_workspace(geometry, depth, progress=ProgressBar() if progress else None)
    t1 = time.perf_counter()
    edges = shares_face(paving.level, paving.ijk, paving.depth)
    aspect, info = aspect_components(paving, edges)
    t2 = time.perf_counter()
    write_npz(out / "pavings" / "workspace.npz", paving, aspect)
    cols = paving_columns(paving, aspect)
    write_vtu_paving(out / "pavings" / "workspace.vtu", paving,
                     {k: cols[k] for k in ("in_workspace", "det_sign", "aspect", "depth")},
                     mask=paving.labels["W"] != Label.OUTSIDE)
    t3 = time.perf_counter()
    fig_files = []
    if figures:

        fig_files = render_all(paving, out / "figures", base=geometry.base)
    t4 = time.perf_counter()
    timings = {"paving": t1 - t0, "components": t2 - t1, "export": t3 - t2, "figures": t4 - t3, "total": t4 - t0}
    summary = pave_summary(paving, info, timings)
    summary["geometry"] = geometry.name
    summary["files"] = ["pavings/workspace.npz", "pavings/workspace.vtu"] + [f"figures/{f.name}" for f in fig_files]
    write_json(out / "summary.json", summary)
    sys.stdout.write(_table(summary) + "\n")
    return 0


def run_analyze(geometry_path, depth: int, out, force: bool = False, quiet: bool = False, as_json: bool = False,
                figures: bool = True, certificates: bool = True, paper: bool = False,
                refine_to: int | None = None) -> int:
    """``intervalkin analyze`` (and ``paper`` when paper=True): the whole chain into one folder."""
    import json


    geometry = default_geometry() if paper else geometry_from_option(geometry_path)
    check_chain_depth(depth)
    out = prepare_output_dir(out, force)
    st = Stages(quiet=quiet)
    a = analyse(geometry, depth, st, refine_to=refine_to)
    summary = write_chain(a, out, figures=figures, stages=st)
    trajs = []
    if paper:  # before the certificates, which re-check these paths
        st.start("certified trajectories between Table 1's solutions 2, 3, 6")
        summary["trajectories"], trajs = _paper_trajectories(a, out, summary["files"])
        st.done()
    if certificates:
        st.start("certificates")
        cert_files = _write_certificates(a, out, trajectories=trajs)
        st.done()
        summary["files"] += cert_files
    if paper:
        st.start("paper report")

        summary["timings_seconds"] = {**summary["timings_seconds"], **st.timings,
                                      "total": time.perf_counter() - st.t0}

        summary["files"].append(write_report(a, summary, out, st.timings))
        st.done()
    summary["timings_seconds"] = {**summary["timings_seconds"], **st.timings,
                                  "total": time.perf_counter() - st.t0}

    write_json(out / "summary.json", summary)
    if as_json:
        sys.stdout.write(json.dumps(summary) + "\n")
    elif not quiet:
        sys.stdout.write(chain_table(summary) + f"\nwritten to {out}/ in {summary['timings_seconds']['total']:.1f} s\n")
    return 0


def run_joint(geometry_path, depth: int, out, force: bool = False, quiet: bool = False, figures: bool = True) -> int:
    """``intervalkin joint``: the enclosure of g(S), the certified cells and their table."""

    if isinstance(depth, bool) or not isinstance(depth, int) or not 2 <= depth <= 8:
        raise InputError(f"--depth: expected an integer in 2..8 (voxels per axis 2**depth), got {depth!r}")
    geometry = geometry_from_option(geometry_path)
    out = prepare_output_dir(out, force)
    st = Stages(quiet=quiet)
    ds = min(depth + 2, 10)
    check_depth(ds)
    _, jp = _singular_and_joint(geometry, ds, depth, st)
    atomic_write_bytes(out / "pavings" / "joint.npz", _npz_bytes(jp.columns()))
    files = ["pavings/joint.npz"]
    if figures:
        st.start("figures")

        files += [f"figures/{f.name}" for f in render_joint(jp, out / "figures")]
        st.done()
    summary = {"geometry": geometry.name, "singular_depth": ds, "joint": joint_summary(jp),
               "timings_seconds": st.timings, "files": files}
    write_json(out / "summary.json", summary)
    if not quiet:
        sys.stdout.write(joint_table(jp) + "\n")
    return 0


def run_label(geometry_path, pose, depth: int, source=None, as_json: bool = False) -> int:
    """``intervalkin label X Y PHI``: certified aspect, basic region and uniqueness domain of a pose."""
    import json
    from fractions import Fraction


    try:
        exact = [Fraction(str(v)) for v in pose]
    except (ValueError, ZeroDivisionError):
        raise InputError(f"pose: expected three numbers X Y PHI, got {' '.join(map(str, pose))}") from None
    if source is not None:
        res = _label_from_npz(Path(source), exact)
        res["pose"] = [str(v) for v in pose]
    else:
        geometry = geometry_from_option(geometry_path)

        a = analyse(geometry, depth)
        res = label_pose(a.regions, [str(v) for v in pose])
    if res["aspect"] in ("WA1", "WA2") and res["basic_region"] == "undecided":
        res["note"] = ("certified inside the aspect, but the box holding the pose may meet a characteristic "
                       "surface (its image meets the enclosure of g(S)), or its sheet is not identified; "
                       "a deeper --depth may decide it")
    elif res["in_workspace"] == "undecided":
        res["note"] = "the box holding the pose is on the undecided layer of W or of det A = 0"
    if as_json:
        sys.stdout.write(json.dumps(res) + "\n")
    else:
        for k in ("in_workspace", "aspect", "basic_region", "uniqueness_domain", "note"):
            if k not in res:
                continue
            sys.stdout.write(f"{k:<18} {res[k]}\n")
    return 0


def _label_from_npz(folder: Path, exact) -> dict:
    """Look a pose up in the workspace.npz of an earlier ``analyze`` / ``paper`` output."""
    from fractions import Fraction

    path = folder / "pavings" / "workspace.npz"
    try:
        with np.load(path) as z:
            cols = {k: z[k] for k in ("lo", "hi", "in_workspace", "det_sign", "basic_region", "uniqueness_domain")}
    except (OSError, KeyError, ValueError) as exc:
        raise InputError(f"--from: cannot read {str(path)!r} ({exc})") from None
    xf = np.array([float(v) for v in exact])
    near = np.flatnonzero(np.all((cols["lo"] <= xf + 1e-9) & (xf - 1e-9 <= cols["hi"]), axis=1))
    hit = [i for i in near if all(Fraction(float(cols["lo"][i, j])) <= exact[j] <= Fraction(float(cols["hi"][i, j]))
                                  for j in range(3))]
    res = {"pose": [str(v) for v in exact], "boxes": len(hit), "in_workspace": "undecided", "aspect": "undecided",
           "basic_region": "undecided", "uniqueness_domain": "undecided"}
    for i in hit:
        w = int(cols["in_workspace"][i])
        if w != 0:
            res["in_workspace"] = "yes" if w > 0 else "no"
        if w > 0 and cols["det_sign"][i] != 0:
            res["aspect"] = "WA1" if cols["det_sign"][i] > 0 else "WA2"
        if cols["basic_region"][i] >= 0:
            res["basic_region"] = int(cols["basic_region"][i])
        if cols["uniqueness_domain"][i] >= 0:
            res["uniqueness_domain"] = int(cols["uniqueness_domain"][i])
    if res["in_workspace"] == "no":
        res["aspect"] = res["basic_region"] = res["uniqueness_domain"] = "none (outside W)"
    return res


def _paper_trajectories(a: Analysis, out: Path, files: list[str]) -> tuple[list[dict], list]:
    """Certified non-singular paths between Table 1's solutions 2, 3 and 6 (paper section 3.2, Fig. 13).

    Returns the report entries (one per pair, failures included) and the
    :class:`~intervalkin.space.trajectory.Trajectory` objects found (for the certificates).
    """

    done, found = [], []
    for i, j in ((2, 3), (2, 6), (3, 6)):
        try:
            tr = trajectory(a.geometry, TABLE1_RHO, i, j, analysis=a.regions, joint=a.joint)
        except IntervalkinError as exc:
            done.append({"from": i, "to": j, "certified": False, "reason": str(exc)})
            continue
        folder = out / "trajectories" / f"{i}-{j}"
        for path in write_trajectory(tr, a.geometry, folder, paving=a.regions.paving, joint=a.joint):
            files.append(str(Path(path).relative_to(out)))
        doc = tr.to_json()
        doc["summary"] = tr.summary()
        doc["folder"] = f"trajectories/{i}-{j}"
        done.append(doc)
        found.append(tr)
    return done, found


def run_trajectory(geometry_path, rho, i_from: int, i_to: int, depth: int = 7, out=None,
                   as_json: bool = False, quiet: bool = False) -> int:
    """``intervalkin trajectory``: the chain at ``depth``, then a certified path between two solutions.

    The request is checked first (solutions of different aspects are refused at
    once, before any paving).
    """
    import json


    geometry = geometry_from_option(geometry_path)
    check_request(geometry, rho, i_from, i_to)
    check_chain_depth(depth)
    if out is not None:
        out = prepare_output_dir(out, force=True) if Path(out).is_dir() and (Path(out) / MARKER).exists() \
            else prepare_output_dir(out, force=False)
    st = Stages(quiet=quiet or as_json)
    a = analyse(geometry, depth, st)
    st.start("certified path")
    traj = trajectory(geometry, rho, i_from, i_to, analysis=a.regions, joint=a.joint)
    st.done()
    if out is not None:
        write_trajectory(traj, geometry, out, paving=a.regions.paving, joint=a.joint)
    if as_json:
        sys.stdout.write(json.dumps(traj.to_json()) + "\n")
    else:
        sys.stdout.write(traj.summary() + "\n")
    return 0
