"""``intervalkin label X Y PHI``: the certified labels of one pose, printed as a table or JSON.

The pose is looked up either in a fresh analysis (``--depth``) or in the
``pavings/workspace.npz`` of an earlier ``analyze`` / ``paper`` output
(``--from DIR``).  Both go through the one pose lookup of
:mod:`intervalkin.space.pose_label` (an exact test of the pose against the box
bounds), so both answer alike.  The JSON keys are the command's contract:
``pose``, ``boxes``, ``in_workspace`` ("yes", "no", "undecided"), ``aspect``,
``basic_region``, ``uniqueness_domain`` (a value, "undecided" or
"none (outside W)") and, when something is undecided, ``note``.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Sequence

import numpy as np

from intervalkin.app.options import geometry_from_option
from intervalkin.core.errors import InputError
from intervalkin.pipeline import analyse
from intervalkin.space.pose_label import (
    PoseLabel,
    boxes_holding,
    label_from_boxes,
    read_pose,
)

__all__ = ['run_label', 'label_from_npz', 'label_json']

#: The workspace.npz columns a lookup reads.
_COLUMNS = ("lo", "hi", "in_workspace", "det_sign", "basic_region", "uniqueness_domain")


def label_from_npz(folder: Path, pose: Sequence) -> PoseLabel:
    """Look a pose up in the ``pavings/workspace.npz`` of an earlier ``analyze`` / ``paper`` output."""
    exact = read_pose(pose)
    path = Path(folder) / "pavings" / "workspace.npz"
    try:
        with np.load(path) as z:
            cols = {k: z[k] for k in _COLUMNS}
    except (OSError, KeyError, ValueError) as exc:
        raise InputError(f"--from: cannot read {str(path)!r} ({exc})") from None
    idx = boxes_holding(cols["lo"], cols["hi"], exact)
    return label_from_boxes(exact, cols["in_workspace"][idx], cols["det_sign"][idx], cols["basic_region"][idx],
                            cols["uniqueness_domain"][idx])


def label_json(label: PoseLabel, pose_text: Sequence[str]) -> dict:
    """The command's JSON object for a label (keys and values as documented above)."""
    outside = label.in_workspace is False

    def value(v):
        return "none (outside W)" if outside else ("undecided" if v is None else v)

    res = {"pose": list(pose_text), "boxes": label.boxes,
           "in_workspace": {True: "yes", False: "no", None: "undecided"}[label.in_workspace],
           "aspect": value(label.aspect), "basic_region": value(label.basic_region),
           "uniqueness_domain": value(label.uniqueness_domain)}
    if label.aspect is not None and label.basic_region is None:
        res["note"] = ("certified inside the aspect, but the box holding the pose may meet a characteristic "
                       "surface (its image meets the enclosure of g(S)), or its sheet is not identified; "
                       "a deeper --depth may decide it")
    elif label.in_workspace is None:
        res["note"] = "the box holding the pose is on the undecided layer of W or of det A = 0"
    return res


def run_label(geometry_path, pose, depth: int, source=None, as_json: bool = False) -> int:
    """``intervalkin label X Y PHI``: certified aspect, basic region and uniqueness domain of a pose."""
    exact = read_pose(list(pose))  # a bad pose is refused before any work
    if source is not None:
        label = label_from_npz(Path(source), exact)
    else:
        label = analyse(geometry_from_option(geometry_path), depth).label(exact)
    res = label_json(label, [str(v) for v in pose])
    if as_json:
        sys.stdout.write(json.dumps(res) + "\n")
    else:
        for k in ("in_workspace", "aspect", "basic_region", "uniqueness_domain", "note"):
            if k in res:
                sys.stdout.write(f"{k:<18} {res[k]}\n")
    return 0
