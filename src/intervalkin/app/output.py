"""The output folder of a run: its safety rules and manifest, the pavings and figures, the certificates.

Layout (README "Output files")::

    DIR/.intervalkin-output      the manifest: the files this run wrote, and whether it completed
    DIR/summary.json             counts with their status, volumes, cells, timings, files, "complete"
    DIR/pavings/workspace.npz    one row per workspace box (format: intervalkin.app.export)
    DIR/pavings/workspace.vtu    the certified workspace boxes (merged), for ParaView (intervalkin.app.vtk_export)
    DIR/pavings/joint.vtu        the joint cells, for ParaView; DIR/pavings/surfaces/ the region surfaces
    DIR/pavings/joint.npz        one row per joint-space voxel (the grid off the enclosure of g(S))
    DIR/pavings/joint_cells.npz  one row per box of the direct joint paving (issue 13): lo, hi, level,
                                 cell, count, n_wa1, n_wa2
    DIR/figures/*.png            one figure (or more) per octree figure of the paper
    DIR/report.html              (paper) report.md with rotatable 3-D views
    DIR/certificates/            the claims, re-checked by ``intervalkin verify``

Rules (:class:`OutputFolder`): a folder is written into only when it is new or
empty, or ``--force`` is given.  A run owns the files it writes and lists each
of them in the manifest *before* it appears (every file goes through
:mod:`intervalkin.core.files`, which reports each destination), so even a
killed run leaves no file its manifest does not name.  A forced re-run into
an earlier output first removes the files that output owned (never anything
else), so no stale file survives.  The manifest and summary.json say
``"complete": false`` until the run has written everything.
"""

from __future__ import annotations

import io
import json
import os
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

import numpy as np

from intervalkin.app.export import write_npz
from intervalkin.app.figures import render_chain_figures
from intervalkin.app.progress import Stages
from intervalkin.app.summary import chain_summary
from intervalkin.app.table1 import TABLE1_RHO
from intervalkin.app.vtk_export import write_region_exports
from intervalkin.core.errors import InputError, IntervalkinError
from intervalkin.core.files import atomic_write_bytes, watching_writes, write_json, write_npz_columns
from intervalkin.core.version import __version__
from intervalkin.pipeline import Analysis
from intervalkin.solve.dkp import parse_joint_vector, solve

__all__ = ['MARKER', 'MANIFEST_FORMAT', 'OutputFolder', 'read_manifest', 'writable_folder', 'prepare_output_dir',
           'write_region_files', 'write_chain', 'npz_bytes', 'write_analysis_certificates']

#: The manifest file that marks an intervalkin output folder.
MARKER = ".intervalkin-output"
#: The ``format`` field of the manifest.
MANIFEST_FORMAT = "intervalkin-output"
#: What an output written before manifests existed (a plain-text marker) owned: the documented layout.
_LEGACY_LAYOUT = ("summary.json", "report.md", "report.html", "trajectory.json", "trajectory_animation.gif",
                  "pavings", "figures", "certificates", "trajectories", "trajectory_frames")


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


def read_manifest(folder) -> dict | None:
    """The manifest of an output folder: None when there is none; a legacy marker reads as ``{"legacy": True}``."""
    path = Path(folder) / MARKER
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        return None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{str(path)!r}: cannot read the output manifest ({exc})") from None
    try:
        doc = json.loads(text)
    except json.JSONDecodeError:
        doc = None
    if not isinstance(doc, dict) or doc.get("format") != MANIFEST_FORMAT:
        return {"legacy": True}
    files = doc.get("files")
    if not isinstance(files, list) or not all(isinstance(f, str) for f in files):
        raise InputError(f"{str(path)!r}: files: expected a list of relative paths")
    return doc


def _owned_paths(root: Path, manifest: dict) -> list[Path]:
    """The files an earlier run owned, each checked to lie inside ``root`` (a manifest is data, not trusted)."""
    if manifest.get("legacy"):
        found = []
        for name in _LEGACY_LAYOUT:
            p = root / name
            found += [q for q in p.rglob("*") if not q.is_dir()] if p.is_dir() and not p.is_symlink() else [p]
        return found
    top = root.resolve()
    out = []
    for rel in manifest["files"]:
        p = root / rel
        if Path(rel).is_absolute() or ".." in Path(rel).parts or not p.parent.resolve().is_relative_to(top):
            raise InputError(f"{str(root / MARKER)!r}: the manifest names {rel!r}, outside the folder")
        out.append(p)
    return out


def _remove_files(root: Path, paths) -> None:
    """Remove ``paths`` (files or links; missing ones are skipped), then the folders they leave empty."""
    folders = set()
    for p in paths:
        if p.is_symlink() or p.is_file():
            p.unlink()
        folders.update(q for q in p.parents if q != root and q.is_relative_to(root))
    for d in sorted(folders, key=lambda q: len(q.parts), reverse=True):
        try:
            d.rmdir()  # only when empty: a folder holding anything else stays
        except OSError:
            pass


class OutputFolder:
    """The folder one run writes: checked and cleaned before the run, its manifest kept during it.

    Use :meth:`open` before any file is written, then write inside
    :meth:`recording`; :meth:`finish` marks the manifest complete.
    """

    def __init__(self, root: Path, command: str, created: bool):
        self.root = root
        self.command = command
        self.created = created
        self.files: set[str] = set()
        self.complete = False
        self.started = time.strftime("%Y-%m-%dT%H:%M:%S%z")

    @classmethod
    def open(cls, out, force: bool, command: str) -> "OutputFolder":
        """Check ``out`` (one line naming --out when refused), remove what an earlier run owned, start the manifest.

        Refused: a path that is not a writable folder, and a non-empty folder
        without ``force``.  With ``force``, a foreign folder keeps its files
        (ours are added beside them); an earlier output loses the files its
        manifest lists.
        """
        root = Path(out)
        existed = root.exists()
        if root.is_dir() and not force and any(root.iterdir()):
            kind = "an earlier intervalkin output" if (root / MARKER).exists() else "not an intervalkin output"
            raise InputError(f"--out: {str(root)!r} is not empty ({kind}); use --force to write there")
        manifest = read_manifest(root) if root.is_dir() else None
        root = writable_folder(root)
        try:
            if manifest is not None:  # an earlier output: its files, and the temporary files of a killed run
                _remove_files(root, _owned_paths(root, manifest) + list(root.rglob(".*.tmp")))
        except OSError as exc:
            raise InputError(f"--out: cannot clean {str(root)!r} ({exc.strerror or exc})") from None
        folder = cls(root, command, created=not existed)
        folder.write_manifest()
        return folder

    def manifest(self) -> dict:
        """The manifest document: what wrote the folder, whether it completed, the files it owns."""
        return {"format": MANIFEST_FORMAT, "version": 1, "tool": {"name": "intervalkin", "version": __version__},
                "command": self.command, "started": self.started, "complete": self.complete,
                "files": sorted(self.files)}

    def write_manifest(self) -> None:
        write_json(self.root / MARKER, self.manifest())

    def _record(self, path: Path) -> None:
        try:
            rel = Path(os.path.abspath(path)).relative_to(os.path.abspath(self.root))
        except ValueError:
            return  # written elsewhere: not part of this folder
        if rel.as_posix() == MARKER or rel.as_posix() in self.files:
            return
        self.files.add(rel.as_posix())
        self.write_manifest()  # before the file appears: a killed run leaves no unlisted file

    @contextmanager
    def recording(self) -> Iterator["OutputFolder"]:
        """Record every file written inside the block; on a user error, remove them (no file left behind)."""
        try:
            with watching_writes(self._record):
                yield self
        except IntervalkinError:
            self.discard()
            raise

    def discard(self) -> None:
        """Remove what this run wrote, and the folder itself when this run created it and it is left empty."""
        _remove_files(self.root, [self.root / f for f in self.files] + [self.root / MARKER])
        self.files.clear()
        if self.created:
            try:
                self.root.rmdir()
            except OSError:
                pass

    def finish(self) -> None:
        """Mark the manifest complete (the command then writes its final summary.json)."""
        self.complete = True
        self.write_manifest()


def prepare_output_dir(out, force: bool, command: str = "intervalkin") -> Path:
    """Check and clean ``out`` as :meth:`OutputFolder.open` does; returns the folder (no recording)."""
    return OutputFolder.open(out, force, command).root


def write_region_files(geometry, regions, joint, out: Path, figures: bool = True,
                       stages: Stages | None = None) -> list[str]:
    """Write what needs no joint cells: the workspace and joint-enclosure pavings (npz, VTK) and the figures.

    Returns the files written, relative to ``out``.  The chain commands call it while the joint
    paving still runs in its second process (:func:`intervalkin.pipeline.analyse`, ``while_waiting``).
    """
    st = stages or Stages(quiet=True)
    st.start("writing pavings (npz, VTK)")
    extra = {"basic_region": regions.region.astype(np.int32), "uniqueness_domain": regions.domain.astype(np.int32)}
    write_npz(out / "pavings" / "workspace.npz", regions.paving, regions.aspect, extra)
    atomic_write_bytes(out / "pavings" / "joint.npz", npz_bytes(joint.columns()))
    files = ["pavings/workspace.npz", "pavings/joint.npz", *write_region_exports(regions, joint, out)]
    st.done()
    if figures:
        st.start("figures")
        files += [f"figures/{f.name}" for f in render_chain_figures(geometry, regions, joint, out / "figures")]
        st.done()
    return files


def write_chain(a: Analysis, out: Path, figures: bool = True, stages: Stages | None = None,
                written: list[str] | None = None) -> dict:
    """Write pavings (npz, VTK), figures and summary.json of an analysis; returns the summary.

    ``written``: the files :func:`write_region_files` already wrote for these regions (not written again).
    """
    st = stages or Stages(quiet=True)
    files = list(written) if written is not None else write_region_files(a.geometry, a.regions, a.joint, out,
                                                                          figures, st)
    st.start("writing the joint cells (npz)")
    atomic_write_bytes(out / "pavings" / "joint_cells.npz", npz_bytes(a.cells.columns()))
    st.done()
    files.append("pavings/joint_cells.npz")
    summary = {"complete": False, **chain_summary(a)}
    summary["timings_seconds"] = {**a.timings, **st.timings}
    summary["files"] = files
    write_json(out / "summary.json", summary)
    return summary


def npz_bytes(cols: dict) -> bytes:
    """A compressed npz file of named columns, as bytes (for an atomic write)."""
    buf = io.BytesIO()
    write_npz_columns(buf, cols)
    return buf.getvalue()


def write_analysis_certificates(a: Analysis, out: Path, trajectories=(), barrier_faces: int | None = None) -> list[str]:
    """Write ``out/certificates`` for an analysis; returns the file names relative to ``out``.

    On the paper's manipulator the certified solve of Table 1 is certified too;
    ``trajectories`` (:class:`~intervalkin.space.trajectory.Trajectory` objects) become
    ``trajectory`` claims (the paper run passes its three Table 1 paths).
    """
    dkp_results = []
    if a.geometry.name == "Wenger-Chablat 1997":
        dkp_results.append(solve(a.geometry, parse_joint_vector(a.geometry, TABLE1_RHO)))
    paths = a.write_certificates(out / "certificates", dkp_results=dkp_results, trajectories=trajectories,
                                 barrier_faces=barrier_faces)
    return [f"certificates/{Path(p).name}" for p in paths]
