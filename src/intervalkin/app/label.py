"""``intervalkin label X Y PHI`` and ``intervalkin locate R1 R2 R3``: one question, one answer with its status.

``label`` looks a pose up either in a fresh analysis (``--depth``) or in the
``pavings/workspace.npz`` of an earlier ``analyze`` / ``paper`` output
(``--from DIR``).  Both go through the one pose lookup of
:mod:`intervalkin.space.pose_label` (phi reduced modulo 2 pi, the boxes holding
the pose, the pose itself in arb, a certified path to a labelled box), so both
answer alike.  An earlier output is read with the geometry it was computed for
(its ``geometry.toml``, or the TOML inside its certificates); a folder whose
run did not complete is refused.

The JSON keys of ``label`` are the command's contract: ``pose``, ``boxes``,
``in_workspace`` ("yes", "no", "undecided"), ``aspect``, ``basic_region``,
``uniqueness_domain`` (a value, "undecided" or "none (outside W)"), ``status``,
``why``, ``phi_reduced`` (when phi was reduced) and, when something is
undecided, ``note``.  ``locate`` prints ``rho``, ``cell``, ``count``,
``n_wa1``, ``n_wa2``, ``status`` and ``why``.
"""

from __future__ import annotations

import decimal
import json
import sys
import tomllib
from pathlib import Path
from typing import Sequence

import numpy as np

from intervalkin.app.options import geometry_from_option
from intervalkin.app.output import read_manifest
from intervalkin.app.progress import Stages
from intervalkin.core.errors import GeometryError, InputError
from intervalkin.core.exact import exact_text
from intervalkin.core.geometry import Geometry, load_geometry, parse_geometry
from intervalkin.paving.tree import workspace_paving_domain
from intervalkin.pipeline import analyse, check_chain_depth
from intervalkin.solve.dkp import parse_joint_vector
from intervalkin.space.joint_route import JointGrid
from intervalkin.space.pose_label import LabelledBoxes, PoseLabel, check_pose_domain, label_pose_in, read_pose

__all__ = ['run_label', 'run_locate', 'label_from_npz', 'label_json', 'folder_geometry']

#: The workspace.npz columns a lookup reads.
_COLUMNS = ("lo", "hi", "in_workspace", "det_sign", "basic_region", "uniqueness_domain")


def folder_geometry(folder: Path, option: str | None = None) -> Geometry | None:
    """The geometry an output folder was computed for, or None when the folder does not say.

    Read from ``geometry.toml``, else from the geometry TOML of
    ``certificates/index.json``.  A ``--geometry`` option that names another
    manipulator is refused; without any, the folder's is used.
    """
    geometry = None
    toml = folder / "geometry.toml"
    index = folder / "certificates" / "index.json"
    if toml.is_file():
        geometry = load_geometry(toml)
    elif index.is_file():
        try:
            text = json.loads(index.read_text(encoding="utf-8")).get("geometry_toml")
            geometry = parse_geometry(tomllib.loads(text, parse_float=decimal.Decimal), source=str(index))
        except (OSError, ValueError, AttributeError, TypeError, GeometryError) as exc:
            raise InputError(f"--from: cannot read the geometry of {str(index)!r} ({exc})") from None
    if option is not None:
        given = geometry_from_option(option)
        if geometry is not None and given.to_toml() != geometry.to_toml():
            raise InputError(f"--geometry: {option!r} is not the manipulator {str(folder)!r} was computed for")
        geometry = geometry or given
    return geometry


def label_from_npz(folder: Path, pose: Sequence, geometry_option: str | None = None) -> PoseLabel:
    """Look a pose up in the ``pavings/workspace.npz`` of an earlier ``analyze`` / ``paper`` output."""
    read_pose(pose)  # a bad pose is refused before the folder is read
    folder = Path(folder)
    manifest = read_manifest(folder) if folder.is_dir() else None
    if manifest is not None and manifest.get("complete") is False:
        raise InputError(f"--from: {str(folder)!r} was written by a run that did not complete")
    path = folder / "pavings" / "workspace.npz"
    try:
        with np.load(path) as z:
            cols = {k: z[k] for k in _COLUMNS}
            domain = z["domain"] if "domain" in z.files else np.stack([cols["lo"].min(0), cols["hi"].max(0)], 1)
    except (OSError, KeyError, ValueError) as exc:
        raise InputError(f"--from: cannot read {str(path)!r} ({exc})") from None
    boxes = LabelledBoxes(cols["lo"], cols["hi"], domain, cols["in_workspace"], cols["det_sign"],
                          cols["basic_region"], cols["uniqueness_domain"])
    return label_pose_in(boxes, pose, folder_geometry(folder, geometry_option), _joint_grid(folder))


def _joint_grid(folder: Path) -> JointGrid | None:
    """The joint cells of an earlier output (``pavings/joint.npz``), or None when it has none."""
    path = folder / "pavings" / "joint.npz"
    if not path.is_file():
        return None
    try:
        with np.load(path) as z:
            return JointGrid.of_columns(z["lo"], z["hi"], z["cell"])
    except (OSError, KeyError, ValueError) as exc:
        raise InputError(f"--from: cannot read {str(path)!r} ({exc})") from None


def label_json(label: PoseLabel, pose_text: Sequence[str]) -> dict:
    """The command's JSON object for a label (keys and values as documented above)."""
    outside = label.in_workspace is False

    def value(v):
        return "none (outside W)" if outside else ("undecided" if v is None else v)

    res = {"pose": list(pose_text), "boxes": label.boxes,
           "in_workspace": {True: "yes", False: "no", None: "undecided"}[label.in_workspace],
           "aspect": value(label.aspect), "basic_region": value(label.basic_region),
           "uniqueness_domain": value(label.uniqueness_domain), "status": label.status.value, "why": label.why}
    if label.phi_reduced is not None:
        lo, hi = label.phi_reduced
        res["phi_reduced"] = repr(float((lo + hi) / 2))  # approximate: the reduced angle is irrational
    if label.status.value != "certified":
        res["note"] = label.why
    return res


def run_label(geometry_path, pose, depth: int, source=None, as_json: bool = False) -> int:
    """``intervalkin label X Y PHI``: certified aspect, basic region and uniqueness domain of a pose."""
    read_pose(list(pose))  # a bad pose is refused before any work
    if source is not None:
        label = label_from_npz(Path(source), list(pose), geometry_path)
    else:
        geometry = geometry_from_option(geometry_path)
        check_chain_depth(depth)
        check_pose_domain(read_pose(list(pose)), workspace_paving_domain(geometry))  # before the analysis
        label = analyse(geometry, depth, progress=Stages(quiet=as_json)).label(list(pose))
    res = label_json(label, [str(v) for v in pose])
    if as_json:
        sys.stdout.write(json.dumps(res) + "\n")
    else:
        for k in ("in_workspace", "aspect", "basic_region", "uniqueness_domain", "phi_reduced", "status", "why"):
            if k in res:
                sys.stdout.write(f"{k:<18} {res[k]}\n")
    return 0


def run_locate(geometry_path, rho, depth: int, as_json: bool = False) -> int:
    """``intervalkin locate R1 R2 R3``: the joint cell of a joint vector and its certified number of solutions."""
    geometry = geometry_from_option(geometry_path)
    q = parse_joint_vector(geometry, list(rho))  # outside the joint limits: refused before any work
    check_chain_depth(depth)
    loc = analyse(geometry, depth, progress=Stages(quiet=as_json)).locate(list(q))
    res = {"rho": [exact_text(v) for v in loc.rho], "cell": loc.cell, "count": loc.count, "n_wa1": loc.n_wa1,
           "n_wa2": loc.n_wa2, "status": loc.status.value, "why": loc.why}
    if as_json:
        sys.stdout.write(json.dumps(res) + "\n")
    else:
        for k, v in res.items():
            sys.stdout.write(f"{k:<8} {'undecided' if v is None else v}\n")
    return 0
