"""The output folder of a run: its safety rules, the pavings and figures, the certificates.

Layout (README "Output files")::

    DIR/.intervalkin-output      marks a folder intervalkin may write into again
    DIR/summary.json             counts with their status, volumes, cells, timings, files
    DIR/pavings/workspace.npz    one row per workspace box (format: intervalkin.app.export)
    DIR/pavings/workspace.vtu    the basic-region boxes and the singular layer, for ParaView
    DIR/pavings/joint.npz        one row per joint-space voxel
    DIR/figures/*.png            views and slices
    DIR/certificates/            the claims, re-checked by ``intervalkin verify``

A folder is written into only when it is new, empty, an earlier intervalkin
output, or ``--force`` is given; every file is written atomically
(:mod:`intervalkin.core.files`).
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from intervalkin.app.export import paving_columns, write_npz, write_vtu_paving
from intervalkin.app.figures import render_all, render_joint, render_regions
from intervalkin.app.progress import Stages
from intervalkin.app.summary import chain_summary
from intervalkin.app.table1 import TABLE1_RHO
from intervalkin.core.errors import InputError
from intervalkin.core.files import atomic_write_bytes, write_json
from intervalkin.paving.labels import Label
from intervalkin.pipeline import Analysis
from intervalkin.solve.dkp import parse_joint_vector, solve

__all__ = ['MARKER', 'writable_folder', 'prepare_output_dir', 'write_chain', 'npz_bytes', 'write_analysis_certificates']

#: The file that marks an intervalkin output folder.
MARKER = ".intervalkin-output"


def writable_folder(out) -> Path:
    """Create ``out`` (and its parents) and prove it writable, or refuse it in one line naming --out."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out: {str(out)!r} exists and is not a folder")
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / f".{MARKER}.probe"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as exc:
        raise InputError(f"--out: cannot write to {str(out)!r} ({exc.strerror or exc})") from None
    return out


def prepare_output_dir(out, force: bool) -> Path:
    """Create ``out`` or accept it when empty / an earlier intervalkin output; refuse otherwise; mark it."""
    out = Path(out)
    if out.is_dir() and any(out.iterdir()) and not (out / MARKER).exists() and not force:
        raise InputError(f"--out: {str(out)!r} is not empty and not an intervalkin output (use --force to write there)")
    out = writable_folder(out)
    try:
        for stale in out.rglob(".*.tmp"):  # left by a run that was killed outright
            stale.unlink()
    except OSError as exc:
        raise InputError(f"--out: cannot clean {str(out)!r} ({exc.strerror or exc})") from None
    atomic_write_bytes(out / MARKER, b"intervalkin output folder\n")
    return out


def write_chain(a: Analysis, out: Path, figures: bool = True, stages: Stages | None = None) -> dict:
    """Write pavings (npz, VTK), figures and summary.json of an analysis; returns the summary."""
    st = stages or Stages(quiet=True)
    ra = a.regions
    p = ra.paving
    st.start("writing pavings (npz, VTK)")
    extra = {"basic_region": ra.region.astype(np.int32), "uniqueness_domain": ra.domain.astype(np.int32)}
    write_npz(out / "pavings" / "workspace.npz", p, ra.aspect, extra)
    cols = paving_columns(p, ra.aspect, extra)
    write_vtu_paving(out / "pavings" / "workspace.vtu", p,
                     {k: cols[k] for k in ("in_workspace", "det_sign", "aspect", "basic_region", "uniqueness_domain",
                                           "depth")},
                     # a viewable file: the basic regions and the singular layer (the npz holds every box)
                     mask=(ra.region >= 0) | ((p.labels["W"] == Label.INSIDE) & (p.labels["det_positive"] == Label.BOUNDARY)))
    jc = a.joint.columns()
    atomic_write_bytes(out / "pavings" / "joint.npz", npz_bytes(jc))
    st.done()
    files = ["pavings/workspace.npz", "pavings/workspace.vtu", "pavings/joint.npz"]
    if figures:
        st.start("figures")
        base = a.geometry.base
        figs = (render_all(p, out / "figures", base=base) + render_joint(a.joint, out / "figures")
                + render_regions(ra, out / "figures", base=base))
        files += [f"figures/{f.name}" for f in figs]
        st.done()
    summary = chain_summary(a)
    summary["timings_seconds"] = {**a.timings, **st.timings}
    summary["files"] = files
    write_json(out / "summary.json", summary)
    return summary


def npz_bytes(cols: dict) -> bytes:
    """A compressed npz file of named columns, as bytes (for an atomic write)."""
    buf = io.BytesIO()
    np.savez_compressed(buf, **cols)
    return buf.getvalue()


def write_analysis_certificates(a: Analysis, out: Path, trajectories=()) -> list[str]:
    """Write ``out/certificates`` for an analysis; returns the file names relative to ``out``.

    On the paper's manipulator the certified solve of Table 1 is certified too;
    ``trajectories`` (:class:`~intervalkin.space.trajectory.Trajectory` objects) become
    ``trajectory`` claims (the paper run passes its three Table 1 paths).
    """
    dkp_results = []
    if a.geometry.name == "Wenger-Chablat 1997":
        dkp_results.append(solve(a.geometry, parse_joint_vector(a.geometry, TABLE1_RHO)))
    paths = a.write_certificates(out / "certificates", dkp_results=dkp_results, trajectories=trajectories)
    return [f"certificates/{Path(p).name}" for p in paths]
