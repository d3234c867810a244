"""Count barriers re-proved from an output folder: ``certificates/joint_separation.json`` and ``.npz``.

Each claim says that the witness of one joint cell and the witnesses of the other cells of its
signature (count, n_wa1, n_wa2) lie in different components of the joint box Q minus g(S).  Its
evidence is a *region* S (closed boxes, rows of the npz) and a *barrier* (closed boxes, usually
face rectangles).  :func:`check_separation` proves, from the files and the geometry alone:

1. every witness's solution list is complete, with the declared count and split, and all declare
   the claim's signature (the arb checker, :func:`intervalkin.checker.claims.run_check`);
2. no point of any barrier box has exactly c solutions, c the signature's count
   (:func:`~intervalkin.recheck.count_range.count_ranges`);
3. the boundary of S inside the open joint box is covered by the barrier: on every plane
   x_a = v that holds a face of a box of S, with v strictly between the joint limits of axis a,
   the plane is cut into open cells by every rectangle edge met there; a cell that S reaches from
   one side only must lie in some barrier box (:func:`uncovered_boundary`);
4. the cell's witness lies in the interior of a box of S, every other witness outside S.

A path of Q minus g(S) from the first witness to another keeps c solutions
(lemma-constant-count-off-gS.md); pushed into general position inside the open joint box, it
leaves S through the open cell of some plane, which the barrier covers: a point with c solutions
on a barrier box, against 2.  The argument is ``proofs/lemma-count-barrier.md``.

Numbers read from the npz are binary64, hence exact rationals; the joint limits are compared
exactly (as Fractions), witnesses are exact rationals enclosed by floats one ulp apart.
"""

from __future__ import annotations

import json
import time
import zipfile
from fractions import Fraction
from pathlib import Path

import numpy as np

from intervalkin.checker.claims import MALFORMED, run_check
from intervalkin.checker.folder import CheckResult
from intervalkin.checker.parse import Refused
from intervalkin.core.errors import CertificateFormatError
from intervalkin.core.geometry import Geometry
from intervalkin.core.workers import Workers, default_workers
from intervalkin.recheck.arith import fraction_enclosure
from intervalkin.recheck.count_range import count_ranges, supported
from intervalkin.recheck.paving_file import folder_geometry

__all__ = ["CLAIMS", "ARRAYS", "KIND", "uncovered_boundary", "check_separation", "recheck_separations"]

#: Where an output folder keeps the separation claims and their boxes.
CLAIMS = Path("certificates") / "joint_separation.json"
ARRAYS = Path("certificates") / "joint_separation.npz"
#: The kind of the result lines ``verify`` prints for them.
KIND = "joint_separation"
#: Barrier boxes worth sending to a second process at once.
MIN_PART = 400
_COLUMNS = ("region_lo", "region_hi", "region_claim", "barrier_lo", "barrier_hi", "barrier_claim")


def _cover(u: np.ndarray, w: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(len(u) - 1, len(w) - 1) bool: the open grid cells (u_i, u_i+1) x (w_j, w_j+1) inside some closed
    rectangle [lo, hi] (rows: u then w); u and w sorted, holding every rectangle end."""
    grid = np.zeros((u.size, w.size), dtype=np.int64)
    i0, i1 = np.searchsorted(u, lo[:, 0]), np.searchsorted(u, hi[:, 0])
    j0, j1 = np.searchsorted(w, lo[:, 1]), np.searchsorted(w, hi[:, 1])
    np.add.at(grid, (i0, j0), 1)
    np.add.at(grid, (i1, j0), -1)
    np.add.at(grid, (i0, j1), -1)
    np.add.at(grid, (i1, j1), 1)
    return grid.cumsum(axis=0).cumsum(axis=1)[:-1, :-1] > 0


def uncovered_boundary(region_lo: np.ndarray, region_hi: np.ndarray, barrier_lo: np.ndarray,
                       barrier_hi: np.ndarray, geometry: Geometry) -> tuple[int, tuple | None]:
    """(number of open plane cells on the boundary of the region, inside the open joint box, that no barrier
    box covers; (axis, plane, cell centre) of the first one, or None)."""
    missing, first = 0, None
    for ax in range(3):
        rest = [k for k in range(3) if k != ax]
        lim_lo, lim_hi = Fraction(geometry.rho_min[ax]), Fraction(geometry.rho_max[ax])
        planes = np.unique(np.concatenate([region_lo[:, ax], region_hi[:, ax]]))
        for v in planes:
            if not lim_lo < Fraction(float(v)) < lim_hi:
                continue  # a path in the open joint box never reaches this plane
            below = (region_lo[:, ax] < v) & (v <= region_hi[:, ax])
            above = (region_lo[:, ax] <= v) & (v < region_hi[:, ax])
            wall = (barrier_lo[:, ax] <= v) & (v <= barrier_hi[:, ax])
            lo = np.concatenate([region_lo[below | above][:, rest], barrier_lo[wall][:, rest]])
            hi = np.concatenate([region_hi[below | above][:, rest], barrier_hi[wall][:, rest]])
            u, w = np.unique(np.r_[lo[:, 0], hi[:, 0]]), np.unique(np.r_[lo[:, 1], hi[:, 1]])
            if u.size < 2 or w.size < 2:
                continue
            side_b = _cover(u, w, region_lo[below][:, rest], region_hi[below][:, rest])
            side_a = _cover(u, w, region_lo[above][:, rest], region_hi[above][:, rest])
            walled = _cover(u, w, barrier_lo[wall][:, rest], barrier_hi[wall][:, rest])
            bad = (side_b ^ side_a) & ~walled
            if bad.any():
                missing += int(bad.sum())
                if first is None:
                    i, j = np.argwhere(bad)[0]
                    first = (ax, float(v), (float((u[i] + u[i + 1]) / 2), float((w[j] + w[j + 1]) / 2)))
    return missing, first


def _witness(geometry: Geometry, obj, what: str) -> tuple[tuple[Fraction, ...], tuple[int, int, int]]:
    """The witness point and its (count, n_wa1, n_wa2), its complete solution list re-proved in arb."""
    if not isinstance(obj, dict):
        raise Refused(f"{what}: expected an object")
    try:
        _, facts = run_check(geometry, "joint_cell", dict(obj, id="witness"), 128)
    except MALFORMED as exc:
        raise Refused(f"{what}: malformed ({exc})") from None
    except Refused as exc:
        raise Refused(f"{what}: {exc}") from None
    q = tuple(Fraction(str(v)) for v in obj["witness"])
    return q, (int(facts["n"]), int(facts["n_wa1"]), int(facts["n_wa2"]))


def _enclose(q: tuple[Fraction, ...]) -> tuple[np.ndarray, np.ndarray]:
    pairs = [fraction_enclosure(v) for v in q]
    return np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs])


def check_separation(geometry: Geometry, claim: dict, region: tuple[np.ndarray, np.ndarray],
                     barrier: tuple[np.ndarray, np.ndarray], workers: Workers | None = None) -> tuple[str, dict]:
    """Re-prove one claim (module docstring); (statement, facts) or :class:`Refused`.  ``workers`` may share
    the count ranges of the barrier boxes between processes (the same verdict)."""
    sig = claim.get("signature")
    if not (isinstance(sig, list) and len(sig) == 3 and all(isinstance(v, int) and 0 <= v <= 6 for v in sig)):
        raise Refused(f"signature: expected [count, n_wa1, n_wa2], got {sig!r}")
    sig = tuple(sig)
    others = claim.get("others")
    if not isinstance(others, list) or not others:
        raise Refused("others: expected a non-empty list of witnesses")
    r_lo, r_hi = region
    b_lo, b_hi = barrier
    for name, (lo, hi) in (("region", region), ("barrier", barrier)):
        if lo.size == 0 and name == "region":
            raise Refused("the region holds no box")
        if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) and np.all(lo <= hi) and np.all(lo > 0)):
            raise Refused(f"{name}: boxes need finite bounds with 0 < lo <= hi")
    if not supported(geometry):
        raise Refused("count ranges are refused for this geometry (|p_i| = |A_i - A_1| on legs 2 and 3)")
    x, got = _witness(geometry, claim.get("witness"), "witness")
    if got != sig:
        raise Refused(f"witness: its solutions give {got}, not the claimed signature {sig}")
    x_lo, x_hi = _enclose(x)
    if not all(Fraction(geometry.rho_min[a]) < x[a] < Fraction(geometry.rho_max[a]) for a in range(3)):
        raise Refused("the witness is not strictly inside the joint limits")
    if not np.any(np.all((r_lo < x_lo) & (x_hi < r_hi), axis=1)):
        raise Refused("the witness is not inside a box of the region")
    cells = []
    for k, other in enumerate(others):
        y, got = _witness(geometry, other, f"others[{k}]")
        if got != sig:
            raise Refused(f"others[{k}]: its solutions give {got}, not the claimed signature {sig}")
        y_lo, y_hi = _enclose(y)
        if np.any(np.all((r_lo <= y_hi) & (y_lo <= r_hi), axis=1)):
            raise Refused(f"others[{k}]: its witness may lie in the region")
        cells.append(other.get("cell"))
    free = (count_ranges(geometry, b_lo, b_hi, workers=workers).excludes(sig[0]) if b_lo.size
            else np.zeros(0, dtype=bool))
    if not free.all():
        i = int(np.flatnonzero(~free)[0])
        raise Refused(f"{int((~free).sum())} barrier boxes not proved free of {sig[0]} solutions, the first "
                      f"[{b_lo[i].tolist()}, {b_hi[i].tolist()}]")
    missing, first = uncovered_boundary(r_lo, r_hi, b_lo, b_hi, geometry)
    if missing:
        ax, v, centre = first
        raise Refused(f"{missing} cells of the region's boundary lie on no barrier box, the first on rho_{ax + 1} = "
                      f"{v} around {centre}")
    facts = {"signature": sig, "cell": claim.get("cell"), "others": cells}
    return (f"cell {claim.get('cell')} and cells {', '.join(map(str, cells))} ({sig[0]} solutions) lie in different "
            f"components of the joint box minus g(S): {len(r_lo)} region boxes, their boundary covered by "
            f"{len(b_lo)} boxes with no point of {sig[0]} solutions"), facts


def _read(folder: Path) -> tuple[dict, dict[str, np.ndarray]]:
    try:
        doc = json.loads((folder / CLAIMS).read_text(encoding="utf-8"))
        with np.load(folder / ARRAYS, allow_pickle=False) as z:
            arrays = {k: np.asarray(z[k]) for k in _COLUMNS}
    except FileNotFoundError as exc:
        raise CertificateFormatError(f"{folder}: {exc.filename} missing beside {CLAIMS}") from None
    except KeyError as exc:
        raise CertificateFormatError(f"{folder / ARRAYS}: column {exc} missing") from None
    except (OSError, ValueError, zipfile.BadZipFile, json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise CertificateFormatError(f"{folder}: cannot read the separation certificate ({exc})") from None
    if not isinstance(doc, dict) or not isinstance(doc.get("claims"), list):
        raise CertificateFormatError(f"{folder / CLAIMS}: claims: expected a list")
    for k in ("region_lo", "region_hi", "barrier_lo", "barrier_hi"):
        if arrays[k].dtype != np.float64 or arrays[k].ndim != 2 or arrays[k].shape[1:] != (3,):
            raise CertificateFormatError(f"{folder / ARRAYS}: {k} must be float64 of shape (n, 3)")
    for k in ("region_claim", "barrier_claim"):
        if arrays[k].dtype.kind != "i" or arrays[k].shape != arrays[k.replace("claim", "lo")].shape[:1]:
            raise CertificateFormatError(f"{folder / ARRAYS}: {k} must be integers, one per box")
    return doc, arrays


def recheck_separations(folder: str | Path) -> list[CheckResult]:
    """One verdict per separation claim of the output folder (given as the folder or its ``certificates/``);
    [] when it has none.  Raises :class:`CertificateFormatError` for unreadable or malformed files."""
    root = Path(folder)
    if root.name == "certificates" and not (root / CLAIMS).is_file():
        root = root.parent
    if not (root / CLAIMS).is_file():
        return []
    doc, arrays = _read(root)
    geometry = folder_geometry(root / "pavings" / "workspace.npz")
    out = []
    with Workers(default_workers(), min_items=MIN_PART) as workers:
        for j, claim in enumerate(doc["claims"]):
            out.append(_one(geometry, j, claim, arrays, workers))
    return out


def _one(geometry: Geometry, j: int, claim, arrays: dict, workers: Workers) -> CheckResult:
    """The verdict on claim ``j`` of the file (its boxes: the npz rows tagged ``j``)."""
    t0 = time.perf_counter()
    name = str(claim.get("id", f"#{j}")) if isinstance(claim, dict) else f"#{j}"
    try:
        if not isinstance(claim, dict) or claim.get("region") != j:
            raise Refused(f"claim {j}: expected an object whose region is {j}")
        rows, walls = arrays["region_claim"] == j, arrays["barrier_claim"] == j
        msg, _ = check_separation(geometry, claim, (arrays["region_lo"][rows], arrays["region_hi"][rows]),
                                  (arrays["barrier_lo"][walls], arrays["barrier_hi"][walls]), workers)
    except Refused as exc:
        return CheckResult(CLAIMS.name, name, KIND, False, str(exc))
    return CheckResult(CLAIMS.name, name, KIND, True, f"{msg} ({time.perf_counter() - t0:.1f} s)")
