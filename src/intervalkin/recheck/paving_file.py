"""Every INSIDE/OUTSIDE label of an output folder's ``pavings/workspace.npz``, re-proved: :func:`recheck_folder`.

The file (columns documented in :mod:`intervalkin.app.export`) holds one row per
workspace box: ``lo``, ``hi`` (n, 3) bounds in (x, y, phi), and the signed labels
``in_workspace`` (1 in W, -1 outside W, 0 undecided) and ``det_sign`` (1 det A
> 0, -1 det A < 0, 0 undecided or not evaluated).  Each nonzero label is a
claim on the whole box; :func:`recheck_paving` re-proves all of them:

1. by the recheck's own outward-rounded evaluation, bisected a bounded number
   of times (:func:`~intervalkin.recheck.bisect.confirm_labels`);
2. the few still open by the arb checker
   (:func:`~intervalkin.checker.labels.box_label_proved`), at most
   :data:`ARB_FALLBACK_MAX` of them within :data:`ARB_SECONDS`.

A label is reported as confirmed, refuted (its opposite is proved on part of
the box: the label is wrong) or not confirmed (neither proof succeeded).  The
geometry is the one the certificates state (``certificates/index.json``), else
the output's ``geometry.toml``.  A file that is missing columns, holds values
outside the format or cannot be read raises
:class:`~intervalkin.core.errors.CertificateFormatError` with a one-line message.
"""

from __future__ import annotations

import decimal
import json
import time
import tomllib
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from intervalkin.checker.folder import CheckResult
from intervalkin.checker.labels import box_label_proved
from intervalkin.core.errors import CertificateFormatError, GeometryError
from intervalkin.core.geometry import Geometry, parse_geometry
from intervalkin.recheck.bisect import CONFIRMED, NOT_CONFIRMED, REFUTED, confirm_labels
from intervalkin.recheck.model import constants

__all__ = ['PAVING', 'KIND', 'ARB_FALLBACK_MAX', 'ARB_SECONDS', 'LABELS', 'WorkspaceLabels', 'RecheckReport',
           'read_workspace_labels', 'find_paving', 'folder_geometry', 'recheck_paving', 'recheck_folder']

#: Where an output folder keeps its workspace paving.
PAVING = Path("pavings") / "workspace.npz"
#: The kind of the result line ``verify`` prints for it.
KIND = "box_labels_all"
#: Labels left open by the vectorised pass that are handed to arb, at most, and the seconds they may take in
#: all (a file of wrong labels must not make ``verify`` slow: past either limit the rest stay not confirmed).
ARB_FALLBACK_MAX = 500
ARB_SECONDS = 20.0
#: npz column -> (the checker's label name, its INSIDE and OUTSIDE values 2 and 1 for the npz's 1 and -1).
LABELS = {"in_workspace": "W", "det_sign": "det_positive"}


@dataclass(frozen=True)
class WorkspaceLabels:
    """The columns of a workspace paving that carry claims: boxes and the two signed labels."""

    lo: np.ndarray
    hi: np.ndarray
    labels: dict[str, np.ndarray]


@dataclass(frozen=True)
class RecheckReport:
    """Counts of a full re-check (labels, not boxes: a box carries up to two) and its seconds, reading excluded.

    ``first_refuted`` and ``first_open`` name one wrong and one unproved label (row, column, value), if any.
    """

    boxes: int
    checked: int
    by_intervals: int
    by_arb: int
    refuted: int
    not_confirmed: int
    seconds: float
    first_refuted: tuple[int, str, int] | None = None
    first_open: tuple[int, str, int] | None = None

    @property
    def confirmed(self) -> int:
        return self.by_intervals + self.by_arb

    @property
    def verified(self) -> bool:
        """True when every INSIDE/OUTSIDE label was re-proved."""
        return self.refuted == 0 and self.not_confirmed == 0


def read_workspace_labels(path: str | Path) -> WorkspaceLabels:
    """Read and validate ``lo``, ``hi``, ``in_workspace``, ``det_sign`` of a workspace npz.

    Raises :class:`CertificateFormatError` (one line naming the file and the
    column) when the file cannot be read as an npz, a column is missing, has the
    wrong shape or kind, a bound is not finite, lo > hi, or a label is not -1, 0, 1.
    """
    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as z:
            missing = [c for c in ("lo", "hi", *LABELS) if c not in z.files]
            if missing:
                raise CertificateFormatError(f"{path}: missing column(s) {', '.join(missing)}")
            cols = {c: z[c] for c in ("lo", "hi", *LABELS)}
    except CertificateFormatError:
        raise
    except FileNotFoundError:
        raise CertificateFormatError(f"{path}: missing") from None
    except (OSError, ValueError, EOFError, zipfile.BadZipFile, KeyError) as exc:
        raise CertificateFormatError(f"{path}: not a readable npz file ({type(exc).__name__}: {exc})") from None
    lo, hi = cols["lo"], cols["hi"]
    for c in ("lo", "hi"):
        a = cols[c]
        if a.dtype.kind != "f" or a.ndim != 2 or a.shape[1] != 3:
            raise CertificateFormatError(f"{path}: {c}: expected floats of shape (n, 3), got {a.dtype} {a.shape}")
    if lo.shape != hi.shape:
        raise CertificateFormatError(f"{path}: lo and hi differ in shape ({lo.shape} and {hi.shape})")
    lo, hi = lo.astype(np.float64), hi.astype(np.float64)
    if not (np.isfinite(lo).all() and np.isfinite(hi).all()):
        raise CertificateFormatError(f"{path}: lo, hi: every bound must be finite")
    if (lo > hi).any():
        row = int(np.flatnonzero((lo > hi).any(axis=1))[0])
        raise CertificateFormatError(f"{path}: box {row}: lo > hi")
    labels = {}
    for c in LABELS:
        a = cols[c]
        if a.dtype.kind not in "iu" or a.shape != (len(lo),):
            raise CertificateFormatError(f"{path}: {c}: expected integers of shape ({len(lo)},), got {a.dtype} {a.shape}")
        bad = ~np.isin(a, (-1, 0, 1))
        if bad.any():
            row = int(np.flatnonzero(bad)[0])
            raise CertificateFormatError(f"{path}: {c}: box {row} has {int(a[row])}; allowed -1, 0, 1")
        labels[c] = a.astype(np.int8)
    return WorkspaceLabels(lo, hi, labels)


def find_paving(folder: str | Path) -> Path | None:
    """The workspace npz of an output folder, given the folder or its ``certificates/``; None when absent."""
    root = Path(folder)
    if (root / PAVING).is_file():
        return root / PAVING
    if root.name == "certificates" and (root.parent / PAVING).is_file():
        return root.parent / PAVING
    return None


def folder_geometry(paving: Path) -> Geometry:
    """The geometry of the output folder holding ``paving``: the certificates' index, else geometry.toml."""
    out = paving.parent.parent
    index, toml_file = out / "certificates" / "index.json", out / "geometry.toml"
    try:
        if index.is_file():
            text = json.loads(index.read_text(encoding="utf-8")).get("geometry_toml")
            where = index
        else:
            text, where = toml_file.read_text(encoding="utf-8"), toml_file
        if not isinstance(text, str):
            raise CertificateFormatError(f"{where}: no geometry_toml text")
        return parse_geometry(tomllib.loads(text, parse_float=decimal.Decimal), source=str(where))
    except FileNotFoundError:
        raise CertificateFormatError(f"{out}: neither certificates/index.json nor geometry.toml") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError, tomllib.TOMLDecodeError, GeometryError) as exc:
        raise CertificateFormatError(f"{out}: cannot read the geometry ({exc})") from None


def recheck_paving(geometry: Geometry, w: WorkspaceLabels) -> RecheckReport:
    """Re-prove every nonzero label of ``w``; see the module docstring for the steps."""
    t0 = time.perf_counter()
    k = constants(geometry)
    checked = by_intervals = by_arb = refuted = open_ = 0
    first_refuted = first_open = None
    budget, deadline = ARB_FALLBACK_MAX, None
    for column, name in LABELS.items():
        values = w.labels[column]
        rows = np.flatnonzero(values != 0)
        status = confirm_labels(k, w.lo[rows], w.hi[rows], column, values[rows])
        checked += len(rows)
        by_intervals += int((status == CONFIRMED).sum())
        for j in rows[status == NOT_CONFIRMED]:
            v = int(values[j])
            ok = False
            deadline = deadline or time.perf_counter() + ARB_SECONDS
            if budget > 0 and time.perf_counter() < deadline:
                budget -= 1
                box = [(float(w.lo[j, a]), float(w.hi[j, a])) for a in range(3)]
                ok = bool(box_label_proved(geometry, box, name, 2 if v == 1 else 1))
            if ok:
                by_arb += 1
            else:
                open_ += 1
                first_open = first_open or (int(j), column, v)
        wrong = rows[status == REFUTED]
        refuted += len(wrong)
        if len(wrong) and first_refuted is None:
            first_refuted = (int(wrong[0]), column, int(values[wrong[0]]))
    return RecheckReport(len(w.lo), checked, by_intervals, by_arb, refuted, open_,
                         time.perf_counter() - t0, first_refuted, first_open)


def _meaning(column: str, value: int) -> str:
    if column == "in_workspace":
        return "in W" if value == 1 else "outside W"
    return "det A > 0" if value == 1 else "det A < 0"


def recheck_folder(folder: str | Path) -> CheckResult | None:
    """The ``box_labels_all`` verdict on the workspace paving of an output folder; None when it has none.

    ``folder`` is the folder given to ``intervalkin verify``: an output folder or
    its ``certificates/``.  Raises :class:`CertificateFormatError` when the npz
    or the geometry is malformed.
    """
    paving = find_paving(folder)
    if paving is None:
        return None
    t0 = time.perf_counter()
    w = read_workspace_labels(paving)
    r = recheck_paving(folder_geometry(paving), w)
    seconds = time.perf_counter() - t0  # reading the file included
    name = PAVING.as_posix()
    counts = (f"{r.checked} INSIDE/OUTSIDE labels (W and the sign of det A) of all {r.boxes} boxes: "
              f"{r.by_intervals} re-proved by outward-rounded interval evaluation, {r.by_arb} in arb")
    if r.verified:
        return CheckResult(name, "all", KIND, True, f"{counts}; every label re-proved ({seconds:.1f} s)")
    if r.refuted:
        row, column, v = r.first_refuted
        why = (f"{r.refuted} label(s) are WRONG, the first box {row}: {column} = {v} ({_meaning(column, v)}) "
               f"but the opposite is proved on part of the box")
    else:
        row, column, v = r.first_open
        why = f"{r.not_confirmed} label(s) not re-proved, the first box {row}: {column} = {v} ({_meaning(column, v)})"
    return CheckResult(name, "all", KIND, False, f"{why}; {counts} ({seconds:.1f} s)")
