"""Joint boxes proved off g(S): a search for singular poses on the circle of leg 1.

The claim
---------
A box R of joint vectors is *clear* when no singular pose X (det A(X) = 0) has
rho(X) in R.  Then R does not meet g(S), so on R (connected) the number of
direct-kinematic solutions and their split between the aspects are constant
(proofs/lemma-constant-count-off-gS.md), and one certified solve anywhere in R
gives them for all of R.

The search
----------
Every pose with rho(X) in R has B1 = (x, y) on the circle of leg 1 about A1,

    (x, y) = A1 + rho_1 (cos theta, sin theta),   rho_1 in R_1,

so the pose boxes  [x] x [y] x Phi,  [x] = a_1x + R_1 cos(Theta),
[y] = a_1y + R_1 sin(Theta),  built from a cover of the torus (theta, phi) by cells
Theta x Phi contain every candidate pose.  A cell is discarded when

* rho_2^2 or rho_3^2 over its pose box misses R_2^2 or R_3^2 (no pose of the cell
  has its joint vector in R), or
* det A over its pose box has a proved sign (no singular pose in the cell),

with the certified enclosures of :mod:`intervalkin.kinematics.enclosures`.  Cells
that stay are bisected (theta or phi, whichever moves the pose more) a few times.
R is clear when every cell is discarded (proofs/lemma-clear-joint-box.md).

Nothing is eliminated: the circle of leg 1 is parametrised, not solved, so the
test has no blind spot where an elimination degenerates (the reduced equation in
phi alone has a double root wherever two solutions share one orientation, which
is not a singularity).

Inheritance: a cell discarded for R is discarded for every sub-box of R (the
enclosures over a sub-box are subsets), so a paving hands a box's live cells to
its children and re-tests only those.

Sharing: the pose box of a cell depends on R_1 and the cell only, so the enclosures
are computed once per distinct (R_1, cell) (:func:`intervalkin.core.rows.distinct_rows`,
bitwise) and compared with each box's R_2, R_3: the same floats as one evaluation per
box, so the same cells are discarded.
"""

from __future__ import annotations

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import PI_HI, Interval
from intervalkin.core.rows import distinct_rows
from intervalkin.kinematics.constants import constants
from intervalkin.kinematics.enclosures import det_a_interval, rho_sq_leg_interval

__all__ = ["Cells", "initial_cells", "live_cells", "pose_boxes", "clear_boxes", "ROUNDS", "MAX_CELLS"]

#: Cells of the theta circle and of the phi circle at the start.
THETA_CELLS = 16
PHI_CELLS = 24
#: Rounds of bisection per call (a paving calls once per level: the cells also shrink with the boxes).
ROUNDS = 2
#: A box with more live cells than this after a round stops bisecting them (it straddles g(S)).
MAX_CELLS = 64
#: Pose boxes evaluated together.  Measured (depth-7 keys, ordered by phi): 0.99, 0.82, 0.72 and
#: 0.85 us per box at 8000, 16000, 32000 and 48000: small chunks repeat the per-phi-range work,
#: large ones outgrow the caches with the temporaries of the interval kernels.
_CHUNK = 32000
#: Rows compared together with their keys' enclosures (8 MB per gathered float array).
_ROWS = 1 << 20

#: (owner (m,), cells (m, 4) rows [theta_lo, theta_hi, phi_lo, phi_hi]).
Cells = tuple[np.ndarray, np.ndarray]


def pose_boxes(geometry: Geometry, rho1: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """Pose boxes (m, 3, 2) [x] x [y] x Phi of cells (m, 4) with leg 1 in rho1 (m, 2): every pose of the cell."""
    k = constants(geometry)
    r1 = Interval(rho1[:, 0], rho1[:, 1])
    theta = Interval(cells[:, 0], cells[:, 1])
    x = r1 * theta.cos() + k.ax_iv[0]
    y = r1 * theta.sin() + k.ay_iv[0]
    return np.stack([np.stack([x.lo, x.hi], -1), np.stack([y.lo, y.hi], -1), cells[:, 2:4]], axis=1)


def _det_signed(geometry: Geometry, boxes: np.ndarray) -> np.ndarray:
    """(m,) bool: det A has a proved sign over the box (no singular pose in it)."""
    det = det_a_interval(geometry, boxes)
    return (det.lo > 0) | (det.hi < 0)


def initial_cells(n: int, theta_cells: int = THETA_CELLS, phi_cells: int = PHI_CELLS) -> Cells:
    """(owner, cells): a grid of theta x phi cells covering the torus, for each of n joint boxes.

    cells (m, 4) rows [theta_lo, theta_hi, phi_lo, phi_hi]; the outer cuts are -PI_HI
    and PI_HI on both axes, so the cells cover the whole torus.
    """
    t = np.linspace(-PI_HI, PI_HI, theta_cells + 1)
    p = np.linspace(-PI_HI, PI_HI, phi_cells + 1)
    t[0], t[-1], p[0], p[-1] = -PI_HI, PI_HI, -PI_HI, PI_HI
    T, P = np.meshgrid(np.arange(theta_cells), np.arange(phi_cells), indexing="ij")
    grid = np.stack([t[T.ravel()], t[T.ravel() + 1], p[P.ravel()], p[P.ravel() + 1]], axis=1)
    return np.repeat(np.arange(n), len(grid)), np.tile(grid, (n, 1))


def live_cells(geometry: Geometry, joint_boxes: np.ndarray, owner: np.ndarray, cells: np.ndarray,
               rounds: int = ROUNDS, max_cells: int = MAX_CELLS) -> Cells:
    """The cells (owner, cells) that may hold a singular pose with its joint vector in the owner's box.

    Parameters
    ----------
    joint_boxes : (n, 3, 2) boxes of (rho_1, rho_2, rho_3), rho > 0.
    owner, cells : (m,) and (m, 4): theta x phi cells, each of box ``owner`` (sorted by owner).

    Returns
    -------
    (owner, cells) of the sub-cells NOT discarded, sorted by owner.  Every point of an
    input cell lies in a discarded sub-cell or in a returned one, so a box none of whose
    cells is returned holds no joint vector of a singular pose: it does not meet g(S).
    Cells are bisected up to ``rounds`` times; a box with more than ``max_cells`` live
    cells after a round stops being bisected (its cells are returned as they are).

    Cost: the enclosures depend on the pose box alone, i.e. on the cell and R_1, and a
    paving hands one parent's cells to eight children, four of which share R_1 (and many
    boxes share R_1 and cells across parents: ~29 rows per distinct pose box at depth 7).
    So each distinct (R_1, cell), a *key*, is evaluated once, bit for bit as for any of its
    rows, and only the comparison with R_2, R_3 is made per row.  A key's two halves are
    the keys of its rows' halves, so keys are found once, before the first round.
    """
    owner = np.asarray(owner, dtype=np.int64)
    n = len(joint_boxes)
    cells = np.asarray(cells, dtype=np.float64).reshape(-1, 4)
    if owner.size == 0:
        return owner, cells
    jb = np.asarray(joint_boxes, dtype=np.float64)
    rho = Interval(jb[:, :, 0], jb[:, :, 1])
    rho_sq = rho.sqr()
    bounds = [np.ascontiguousarray(v) for j in (1, 2) for v in (rho_sq.lo[:, j], rho_sq.hi[:, j])]
    k = constants(geometry)
    reach = float(np.max(k.radius_iv.hi)) + 1.0  # how far a platform point moves per radian of phi, roughly
    r1_rep, r1_of = distinct_rows([jb[:, 0, 0], jb[:, 0, 1]])
    first, key = distinct_rows([r1_of[owner], cells])
    key_rho1, key_cells, key = _by_phi(jb[owner[first], 0, :], cells[first], key)
    del first, cells
    done_o, done_c = [], []
    for round_ in range(rounds + 1):
        boxes, enclosures = _key_rho_sq(geometry, key_rho1, key_cells)
        gone = _rows_missed(owner, key, enclosures, bounds)
        gone |= _key_det_signed(geometry, boxes, key[~gone])[key]
        owner, key = owner[~gone], key[~gone]
        stop = np.bincount(owner, minlength=n)[owner] > max_cells
        if round_ == rounds:
            stop[:] = True
        done_o.append(owner[stop])
        done_c.append(key_cells[key[stop]])
        owner, key = owner[~stop], key[~stop]
        if owner.size == 0:
            break
        key_rho1, key_cells, key = _by_phi(*_bisect(key_rho1, key_cells, key, reach))
        owner = np.concatenate([owner, owner])
    o, c = np.concatenate(done_o), np.concatenate(done_c)
    order = np.argsort(o, kind="stable")
    return o[order], c[order]


def _key_rho_sq(geometry: Geometry, rho1: np.ndarray, cells: np.ndarray) -> tuple[np.ndarray, list[np.ndarray]]:
    """(pose boxes (K, 3, 2), [lo_2, hi_2, lo_3, hi_3]): each key's pose box and the bounds (K,) of
    its enclosures of rho_2^2 and rho_3^2 (:func:`~intervalkin.kinematics.enclosures.rho_sq_leg_interval`;
    leg 1 is not needed: B1 is on its circle by construction)."""
    boxes = np.empty((len(cells), 3, 2))
    bounds = [np.empty(len(cells)) for _ in range(4)]
    for s in range(0, len(cells), _CHUNK):
        boxes[s:s + _CHUNK] = b = pose_boxes(geometry, rho1[s:s + _CHUNK], cells[s:s + _CHUNK])
        for leg, lo, hi in ((1, *bounds[:2]), (2, *bounds[2:])):
            e = rho_sq_leg_interval(geometry, b, leg)
            lo[s:s + _CHUNK], hi[s:s + _CHUNK] = e.lo, e.hi
    return boxes, bounds


def _rows_missed(owner: np.ndarray, key: np.ndarray, e: list[np.ndarray], bounds: list[np.ndarray]) -> np.ndarray:
    """(m,) bool: the key's enclosure of rho_2^2 or rho_3^2 misses the owner's R_2^2 or R_3^2.

    By pieces of _ROWS rows: the gathered temporaries stay small enough for malloc to recycle
    them (a larger block is mapped afresh each time, and page faults cost more than the gathers)."""
    out = np.empty(owner.size, dtype=bool)
    lo2, hi2, lo3, hi3 = e
    b2l, b2h, b3l, b3h = bounds
    for s in range(0, owner.size, _ROWS):
        o, k = owner[s:s + _ROWS], key[s:s + _ROWS]
        out[s:s + _ROWS] = (hi2[k] < b2l[o]) | (lo2[k] > b2h[o]) | (hi3[k] < b3l[o]) | (lo3[k] > b3h[o])
    return out


def _key_det_signed(geometry: Geometry, boxes: np.ndarray, used: np.ndarray) -> np.ndarray:
    """(K,) bool: det A has a proved sign over the pose box of the key; evaluated for the keys in ``used`` only."""
    out = np.zeros(len(boxes), dtype=bool)
    mark = out.copy()
    mark[used] = True
    todo = np.flatnonzero(mark)
    for s in range(0, todo.size, _CHUNK):
        t = todo[s:s + _CHUNK]
        out[t] = _det_signed(geometry, boxes[t])
    return out


def _by_phi(rho1: np.ndarray, cells: np.ndarray, key: np.ndarray):
    """The keys in order of phi_lo (and the rows' keys renumbered): a chunk of keys then spans few
    phi ranges, and the enclosures work out their phi-dependent parts once per range and chunk."""
    order = np.argsort(cells[:, 2], kind="stable")
    rank = np.empty_like(order)
    rank[order] = np.arange(order.size)
    return rho1[order], cells[order], rank[key]


def _bisect(rho1: np.ndarray, cells: np.ndarray, key: np.ndarray, reach: float):
    """Halve the keys the rows use (theta or phi, whichever moves the pose more: rho_1 d(theta)
    against the platform's reach d(phi)); returns the new keys and the rows' keys, left halves first."""
    mark = np.zeros(len(cells), dtype=bool)
    mark[key] = True
    used = np.flatnonzero(mark)
    pos = np.cumsum(mark) - 1
    rho1, cells = rho1[used], cells[used]
    rows = np.arange(len(cells))
    by_theta = rho1[:, 1] * (cells[:, 1] - cells[:, 0]) >= reach * (cells[:, 3] - cells[:, 2])
    a = np.where(by_theta, 0, 2)
    mid = 0.5 * cells[rows, a] + 0.5 * cells[rows, a + 1]
    left, right = cells.copy(), cells.copy()
    left[rows, a + 1] = mid
    right[rows, a] = mid
    p = pos[key]
    return np.concatenate([rho1, rho1]), np.concatenate([left, right]), np.concatenate([p, p + len(used)])


def clear_boxes(geometry: Geometry, boxes: np.ndarray, rounds: int = 6) -> np.ndarray:
    """(n,) bool: True where the joint box is PROVED clear (off g(S)); False means undecided.

    boxes : (n, 3, 2) of [rho_lo, rho_hi] with rho > 0.  A one-shot test (no parent
    to inherit from), so it bisects more rounds than one paving level does.
    """
    boxes = np.asarray(boxes, dtype=np.float64)
    owner, cells = initial_cells(len(boxes))
    owner, _ = live_cells(geometry, boxes, owner, cells, rounds=rounds)
    return np.bincount(owner, minlength=len(boxes)) == 0
