"""Joint space: an outer enclosure of g(S) and the cells of constant solution count.

Mathematics (DESIGN.md section 5; proofs/lemma-constant-count-off-gS.md).  The
inverse kinematics g is proper (|B1 - A1| = rho_1 bounds the pose) and a local
diffeomorphism off the type-2 surface S, so on every connected set of joint
space that does not meet g(S) the number of real direct-kinematic solutions,
and the number in each aspect, is constant.  Hence:

1. Outer enclosure of g(S) inside the joint box: the union of the interval
   images g(b) of the workspace boxes b that may hold a singular point of W
   (det A undecided and not certainly outside W).  Every singular X with g(X) in
   the joint box is in W, so lies in such a box.
2. A uniform grid of N = 2**depth voxels per axis over prod_i [rho_min_i,
   rho_max_i] (voxel edges at the exact rationals rho_min_i + k h_i).  A voxel is
   *marked* when it may meet one of the boxes of step 1 (a conservative overlap
   test with a margin that absorbs the float rounding of the index computation);
   an unmarked voxel is certified off g(S).  Marking uses a 3-D difference array
   (one ``np.add.at`` per corner) and prefix sums; the prefix sums also answer
   "does this joint-space box meet a marked voxel" in O(1) per box.
3. Cells: face-connected components of the unmarked voxels.  A cell is
   connected and off g(S), so ONE certified direct-kinematics solve at one exact
   point of it certifies its count and aspect split for every point of every
   voxel of the cell (closed voxels included).

What is NOT certified: two cells with the same count may be parts of one true
component of (joint box minus g(S)) joined through the marked layer; cells with
different counts are certainly different.  Cells whose solve could not be
completed (or that were not solved because of the solve budget) keep count -1.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from fractions import Fraction
from typing import Callable, Sequence

import numpy as np

from intervalkin.core.errors import InputError
from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import Interval
from intervalkin.paving.adjacency import component_labels, grow_labels
from intervalkin.solve.dkp import solve
from intervalkin.space.singular_surface import singular_image

__all__ = ['JointCell', 'JointPaving', 'joint_paving']

#: Margin, in voxel units, added on both sides of every marked range: the float
#: index (r - rho_min) / h is within a few ulps of the exact ratio, far below it.
_INDEX_MARGIN = 1e-9


@dataclass(frozen=True)
class JointCell:
    """A face-connected set of voxels certified off g(S), with its certified count.

    ``count``, ``n_wa1``, ``n_wa2`` are -1 when the cell's solve was not completed.
    ``witness`` is the exact joint vector (Fractions) that was solved.
    """

    id: int
    n_voxels: int
    volume: float
    share: float
    count: int
    n_wa1: int
    n_wa2: int
    witness: tuple[Fraction, Fraction, Fraction] | None
    complete: bool

    def to_json(self) -> dict:
        return {
            "id": self.id,
            "count": self.count,
            "n_wa1": self.n_wa1,
            "n_wa2": self.n_wa2,
            "voxels": self.n_voxels,
            "volume": self.volume,
            "share": self.share,
            "witness": None if self.witness is None else [str(float(v)) for v in self.witness],
            "witness_exact": None if self.witness is None else [f"{v.numerator}/{v.denominator}" for v in self.witness],
            "certified": self.complete,
        }


@dataclass(frozen=True, eq=False)
class JointPaving:
    """The joint-space grid: marked voxels (may meet g(S)) and certified cells.

    Attributes
    ----------
    depth : voxels per axis N = 2**depth.
    rho_min, step : exact Fractions per leg; voxel k of leg i is
        [rho_min_i + k step_i, rho_min_i + (k + 1) step_i].
    marked : bool (N, N, N), True where the voxel may meet g(S).
    prefix : int64 (N+1, N+1, N+1), summed-area table of ``marked``.
    cell : int32 (N, N, N), cell id, -1 on marked voxels.
    cells : the cells, by id.
    n_singular_boxes : number of workspace boxes whose images make the enclosure.
    joinable : pairs of cells of equal count that the undecided layer may join
        (their nearest-cell shares of the marked voxels touch): not certified different.
    """

    geometry: Geometry
    depth: int
    rho_min: tuple[Fraction, Fraction, Fraction]
    step: tuple[Fraction, Fraction, Fraction]
    marked: np.ndarray
    prefix: np.ndarray
    cell: np.ndarray
    cells: tuple[JointCell, ...]
    n_singular_boxes: int
    seconds: float
    joinable: tuple[tuple[int, int], ...] = ()

    @property
    def n(self) -> int:
        """Voxels per axis, 2**depth."""
        return 1 << self.depth

    def approx_grid(self) -> tuple[np.ndarray, np.ndarray]:
        """rho_min and the voxel step as floats (3,) each: for index guesses and plots, never a proof."""
        return np.array([float(v) for v in self.rho_min]), np.array([float(v) for v in self.step])

    def voxel_centre(self, idx) -> tuple[Fraction, Fraction, Fraction]:
        """The exact centre rho_min + (k + 1/2) step of the voxel with indices ``idx`` (3 ints)."""
        return _voxel_centre(self.rho_min, self.step, idx)

    def voxel_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Float bounds (N^3, 3) of every voxel, C order, rounded outward."""
        n = self.n
        idx = np.indices((n, n, n)).reshape(3, -1).T
        lo = np.empty(idx.shape)
        hi = np.empty(idx.shape)
        for i in range(3):
            edges = Interval.from_exact(self.rho_min[i] + k * self.step[i] for k in range(n + 1))
            lo[:, i] = edges.lo[idx[:, i]]
            hi[:, i] = edges.hi[idx[:, i] + 1]
        return lo, hi

    def index_ranges(self, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Inclusive voxel index ranges (m, 3) of joint boxes [lo, hi] (m, 3), conservative.

        Returns (ilo, ihi, inside) where ``inside`` is False for boxes that miss
        the joint box entirely (their ranges are then meaningless).
        """
        n = self.n
        r0, h = self.approx_grid()
        tlo = (lo - r0) / h
        thi = (hi - r0) / h
        inside = np.all((thi >= -_INDEX_MARGIN) & (tlo <= n + _INDEX_MARGIN), axis=1)
        ilo = np.clip(np.floor(tlo - _INDEX_MARGIN), 0, n - 1).astype(np.int64)
        ihi = np.clip(np.floor(thi + _INDEX_MARGIN), 0, n - 1).astype(np.int64)
        return ilo, ihi, inside

    def meets_marked(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """For joint boxes (m, 3): True where the box may meet g(S) (or leaves the joint box).

        False is certified: the box lies in the joint box and meets no marked voxel.
        """
        ilo, ihi, inside = self.index_ranges(lo, hi)
        n = self.n
        r0, h = self.approx_grid()
        within = np.all((lo >= r0) & (hi <= r0 + n * h), axis=1)
        total = _range_sum(self.prefix, ilo, ihi)
        return ~(inside & within) | (total > 0)

    def cell_of_boxes(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """Cell id of each joint box (m, 3) that lies in unmarked voxels, else -1.

        When the index range of a box holds no marked voxel, it is a rectangular
        block of unmarked voxels, face-connected, so all in one cell.
        """
        ilo, _, _ = self.index_ranges(lo, hi)
        clear = ~self.meets_marked(lo, hi)
        out = np.full(lo.shape[0], -1, dtype=np.int32)
        out[clear] = self.cell[ilo[clear, 0], ilo[clear, 1], ilo[clear, 2]]
        return out

    def cell_at(self, rho: Sequence[Fraction]) -> int:
        """Cell id of an exact joint vector, or -1 (marked voxel or outside)."""
        idx = []
        for i in range(3):
            t = (Fraction(rho[i]) - self.rho_min[i]) / self.step[i]
            k = int(t // 1)
            if t == k and k == self.n:
                k -= 1
            if not 0 <= k < self.n:
                return -1
            idx.append(k)
        return int(self.cell[tuple(idx)])

    def columns(self) -> dict[str, np.ndarray]:
        """The npz columns: lo, hi (rho), cell, count, n_wa1, n_wa2 (-1 undecided)."""
        lo, hi = self.voxel_bounds()
        cell = self.cell.reshape(-1)
        table = np.array([(c.count, c.n_wa1, c.n_wa2) for c in self.cells], dtype=np.int32).reshape(-1, 3)
        vals = np.full((cell.size, 3), -1, dtype=np.int32)
        has = cell >= 0
        vals[has] = table[cell[has]]
        return {
            "lo": lo,
            "hi": hi,
            "cell": cell.astype(np.int32),
            "count": vals[:, 0],
            "n_wa1": vals[:, 1],
            "n_wa2": vals[:, 2],
        }

    def volume_by_count(self) -> dict[str, float]:
        """Volume of the certified cells per solution count, and of the undecided voxels."""
        out: dict[str, float] = {}
        for c in self.cells:
            key = str(c.count) if c.count >= 0 else "unsolved"
            out[key] = out.get(key, 0.0) + c.volume
        voxel = float(np.prod([float(s) for s in self.step]))
        out["undecided"] = float(self.marked.sum()) * voxel
        return out


def _voxel_centre(rho_min, step, idx) -> tuple[Fraction, Fraction, Fraction]:
    return tuple(rho_min[i] + (int(idx[i]) + Fraction(1, 2)) * step[i] for i in range(3))  # type: ignore[return-value]


def _range_sum(prefix: np.ndarray, ilo: np.ndarray, ihi: np.ndarray) -> np.ndarray:
    """Sum of a 3-D array over inclusive index boxes, from its summed-area table."""
    a0, b0, c0 = ilo[:, 0], ilo[:, 1], ilo[:, 2]
    a1, b1, c1 = ihi[:, 0] + 1, ihi[:, 1] + 1, ihi[:, 2] + 1
    p = prefix
    return (
        p[a1, b1, c1] - p[a0, b1, c1] - p[a1, b0, c1] - p[a1, b1, c0]
        + p[a0, b0, c1] + p[a0, b1, c0] + p[a1, b0, c0] - p[a0, b0, c0]
    )


def _mark(n: int, ilo: np.ndarray, ihi: np.ndarray) -> np.ndarray:
    """Boolean (n, n, n) grid, True in the union of the inclusive index boxes."""
    diff = np.zeros((n + 1, n + 1, n + 1), dtype=np.int32)
    a0, b0, c0 = ilo.T
    a1, b1, c1 = (ihi + 1).T
    for (a, sa), (b, sb), (c, sc) in (
        ((a0, 1), (b0, 1), (c0, 1)), ((a1, -1), (b0, 1), (c0, 1)),
        ((a0, 1), (b1, -1), (c0, 1)), ((a0, 1), (b0, 1), (c1, -1)),
        ((a1, -1), (b1, -1), (c0, 1)), ((a1, -1), (b0, 1), (c1, -1)),
        ((a0, 1), (b1, -1), (c1, -1)), ((a1, -1), (b1, -1), (c1, -1)),
    ):
        np.add.at(diff, (a, b, c), sa * sb * sc)
    counts = diff.cumsum(0).cumsum(1).cumsum(2)
    return counts[:n, :n, :n] > 0


def _summed_area(marked: np.ndarray) -> np.ndarray:
    n = marked.shape[0]
    p = np.zeros((n + 1, n + 1, n + 1), dtype=np.int64)
    p[1:, 1:, 1:] = marked.astype(np.int64).cumsum(0).cumsum(1).cumsum(2)
    return p


def _grid_edges(shape) -> np.ndarray:
    """Face-adjacent voxel pairs (2, m) of a 3-D grid (C-order indices), no wrap."""
    idx = np.arange(int(np.prod(shape))).reshape(shape)
    edges = []
    for axis in range(3):
        a = np.take(idx, range(shape[axis] - 1), axis=axis).ravel()
        b = np.take(idx, range(1, shape[axis]), axis=axis).ravel()
        edges.append(np.stack([a, b]))
    return np.concatenate(edges, axis=1)


def _grid_components(free: np.ndarray) -> np.ndarray:
    """Face-connected components of the True voxels of a 3-D grid; -1 elsewhere."""

    e = _grid_edges(free.shape)
    flat = free.ravel()
    e = e[:, flat[e[0]] & flat[e[1]]]
    return component_labels(free.size, e, flat).reshape(free.shape)


def _joinable_pairs(cell_grid: np.ndarray, marked: np.ndarray, counts: Sequence[int]) -> tuple[tuple[int, int], ...]:
    """Cells of equal count that the undecided layer may join.

    The marked voxels are shared out to the nearest cell (growth through face
    adjacency); two cells whose shares touch are separated only by a stretch of
    the layer, so they may be one true component of the joint box minus g(S).
    Cells whose shares do not touch are still not PROVED different (the layer is
    an outer enclosure); this is a report of where the doubt is, not a proof.
    """

    e = _grid_edges(cell_grid.shape)
    lab = grow_labels(cell_grid.size, e, cell_grid.ravel(), marked.ravel())
    u, v = e
    m = (lab[u] >= 0) & (lab[v] >= 0) & (lab[u] != lab[v])
    pairs = set()
    for a, b in set(zip(lab[u[m]].tolist(), lab[v[m]].tolist())):
        a, b = min(a, b), max(a, b)
        if counts[a] >= 0 and counts[a] == counts[b]:
            pairs.add((a, b))
    return tuple(sorted(pairs))


def _representative_voxel(cell_grid: np.ndarray, cid: int, rng: np.random.Generator, k: int = 0) -> tuple[int, int, int]:
    """A voxel of cell ``cid``, preferring one far from the cell's border (k-th choice)."""
    vox = np.argwhere(cell_grid == cid)
    if k == 0:
        centre = vox.mean(axis=0)
        return tuple(vox[np.argmin(((vox - centre) ** 2).sum(axis=1))])
    return tuple(vox[rng.integers(len(vox))])


def joint_paving(
    geometry: Geometry,
    singular_boxes: np.ndarray,
    depth: int,
    max_solves: int = 400,
    progress: Callable[[str, float], None] | None = None,
) -> JointPaving:
    """Mark the joint grid with g(singular_boxes) and certify the count of each cell.

    Parameters
    ----------
    singular_boxes : ndarray (m, 3, 2), workspace boxes covering S ∩ W (for
        example the leaves of a workspace paving whose det A sign is undecided
        and that are not certainly outside W).
    depth : voxels per axis 2**depth (1..8).
    max_solves : at most this many certified solves (largest cells first); the
        remaining cells keep count -1 (reported, never guessed).

    Cost: O(m + N^3) array work, plus one certified solve per solved cell.
    """

    if not isinstance(depth, int) or not 1 <= depth <= 8:
        raise InputError(f"joint depth: expected an integer in 1..8, got {depth!r}")
    t0 = time.perf_counter()
    n = 1 << depth
    rho_min = tuple(Fraction(v) for v in geometry.rho_min)
    step = tuple((Fraction(hi) - Fraction(lo)) / n for lo, hi in zip(geometry.rho_min, geometry.rho_max))
    shell = JointPaving(geometry, depth, rho_min, step, np.zeros((n,) * 3, bool),  # type: ignore[arg-type]
                        np.zeros((n + 1,) * 3, np.int64), np.zeros((n,) * 3, np.int32), (), 0, 0.0)
    lo, hi = singular_image(geometry, singular_boxes) if len(singular_boxes) else (np.zeros((0, 3)), np.zeros((0, 3)))
    ilo, ihi, inside = shell.index_ranges(lo, hi)
    marked = _mark(n, ilo[inside], ihi[inside])
    prefix = _summed_area(marked)
    cell_grid = _grid_components(~marked).astype(np.int32)
    if progress:
        progress("joint grid marked", 0.0)

    n_cells = int(cell_grid.max()) + 1 if cell_grid.size else 0
    sizes = np.bincount(cell_grid[cell_grid >= 0].ravel(), minlength=n_cells)
    voxel_volume = float(np.prod([float(s) for s in step]))
    total_volume = voxel_volume * n**3
    rng = np.random.default_rng(0)
    cells = []
    solved = 0
    for cid in range(n_cells):  # one certified solve per cell (ids are by decreasing size)
        count = n1 = n2 = -1
        witness = None
        complete = False
        if solved < max_solves:
            for attempt in range(3):
                vox = _representative_voxel(cell_grid, cid, rng, attempt)
                q = _voxel_centre(rho_min, step, vox)
                res = solve(geometry, q)
                solved += 1
                if res.complete and all(s.status == "unique" and s.det_sign != 0 for s in res.solutions):
                    witness, complete = q, True
                    count = len(res.solutions)
                    n1 = sum(1 for s in res.solutions if s.det_sign > 0)
                    n2 = count - n1
                    break
        if progress:
            progress("certified solves per cell", (cid + 1) / n_cells)
        cells.append(
            JointCell(cid, int(sizes[cid]), sizes[cid] * voxel_volume, sizes[cid] * voxel_volume / total_volume,
                      count, n1, n2, witness, complete)
        )
    joinable = _joinable_pairs(cell_grid, marked, [c.count for c in cells])
    return JointPaving(geometry, depth, rho_min, step, marked, prefix, cell_grid, tuple(cells),  # type: ignore[arg-type]
                       int(len(singular_boxes)), time.perf_counter() - t0, joinable)
