"""The boundary of a region of closed joint boxes: where it runs, which barrier boxes cover it, which boxes meet.

Used by both kinds of separation claims (:mod:`intervalkin.recheck.separation_file`).  A path of the open
joint box that leaves the region S crosses, in general position, an open cell of some plane x_a = v that
holds a face of a box of S: the plane cut by every rectangle edge met there, a cell that S reaches from one
side only.  :func:`uncovered_boundary` lists the cells of that kind that no barrier box covers, comparing
the joint limits exactly; :func:`face_pairs` finds the boxes of S whose intersection has dimension 2 or 3,
where a pattern barrier's relations must agree.  Numbers are binary64 read from the files: exact comparisons.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from intervalkin.checker.parse import Refused
from intervalkin.core.geometry import Geometry

__all__ = ["uncovered_boundary", "require_covered", "face_pairs"]

#: Region boxes taken as one run when looking for the pairs that share a face, and (run box, candidate) pairs
#: compared at once (about 100 MB of temporaries).
_CHUNK = 512
_CELLS = 1 << 22


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


def require_covered(r_lo: np.ndarray, r_hi: np.ndarray, b_lo: np.ndarray, b_hi: np.ndarray,
                     geometry: Geometry) -> None:
    """Refuse unless the region's boundary inside the open joint box lies on the barrier boxes."""
    missing, first = uncovered_boundary(r_lo, r_hi, b_lo, b_hi, geometry)
    if missing:
        ax, v, centre = first
        raise Refused(f"{missing} cells of the region's boundary lie on no barrier box, the first on rho_{ax + 1} = "
                      f"{v} around {centre}")


def face_pairs(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every pair i < j of closed boxes whose intersection has dimension 2 or 3 (a shared piece of face, or an
    overlap): exact float comparisons, sorted by i then j.

    The boxes are taken in runs of :data:`_CHUNK` consecutive ones in the order of their lower x end; a box
    meeting one of a run has lo_x <= the run's largest hi_x and hi_x >= its smallest lo_x, a necessary condition
    tested first in one dimension, so the full test compares each run with a slab of the boxes, not all of
    them (a region of 67 000 boxes: seconds and megabytes instead of minutes and 13 GB)."""
    n = lo.shape[0]
    order = np.argsort(lo[:, 0], kind="stable")
    out_i, out_j = [], []
    for s in range(0, n, _CHUNK):
        rows = order[s:s + _CHUNK]
        cand = np.flatnonzero((lo[:, 0] <= hi[rows, 0].max()) & (hi[:, 0] >= lo[rows, 0].min()))
        step = max(1, _CELLS // rows.size)
        for t in range(0, cand.size, step):
            c = cand[t:t + step]
            ext_lo = np.maximum(lo[rows, None, :], lo[None, c, :])
            ext_hi = np.minimum(hi[rows, None, :], hi[None, c, :])
            meet = np.all(ext_lo <= ext_hi, axis=2) & ((ext_lo < ext_hi).sum(axis=2) >= 2)
            a, b = np.nonzero(meet)
            i, j = rows[a], c[b]
            keep = i < j
            out_i.append(i[keep])
            out_j.append(j[keep])
    i = np.concatenate(out_i) if out_i else np.zeros(0, dtype=np.int64)
    j = np.concatenate(out_j) if out_j else np.zeros(0, dtype=np.int64)
    at = np.lexsort((j, i))
    return i[at], j[at]
