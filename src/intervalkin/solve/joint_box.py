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
"""

from __future__ import annotations

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import PI_HI, Interval
from intervalkin.kinematics.constants import constants
from intervalkin.kinematics.enclosures import det_a_interval, rho_sq_interval

__all__ = ["Cells", "initial_cells", "live_cells", "clear_boxes", "ROUNDS", "MAX_CELLS"]

#: Cells of the theta circle and of the phi circle at the start.
THETA_CELLS = 16
PHI_CELLS = 24
#: Rounds of bisection per call (a paving calls once per level: the cells also shrink with the boxes).
ROUNDS = 2
#: A box with more live cells than this after a round stops bisecting them (it straddles g(S)).
MAX_CELLS = 64
#: Cells evaluated together (memory).
_CHUNK = 65536

#: (owner (m,), cells (m, 4) rows [theta_lo, theta_hi, phi_lo, phi_hi]).
Cells = tuple[np.ndarray, np.ndarray]


def _discard(geometry: Geometry, rho_sq: Interval, rho1: Interval, cells: np.ndarray) -> np.ndarray:
    """Which cells (m, 4) [theta_lo, theta_hi, phi_lo, phi_hi] hold no singular pose with rho in the box."""
    k = constants(geometry)
    theta = Interval(cells[:, 0], cells[:, 1])
    x = rho1 * theta.cos() + k.ax_iv[0]
    y = rho1 * theta.sin() + k.ay_iv[0]
    boxes = np.stack([np.stack([x.lo, x.hi], -1), np.stack([y.lo, y.hi], -1), cells[:, 2:4]], axis=1)
    e = rho_sq_interval(geometry, boxes)
    out = np.zeros(len(cells), dtype=bool)
    for j in (1, 2):
        out |= (e.hi[:, j] < rho_sq.lo[:, j]) | (e.lo[:, j] > rho_sq.hi[:, j])
    live = np.flatnonzero(~out)
    if live.size:
        det = det_a_interval(geometry, boxes[live])
        out[live] = (det.lo > 0) | (det.hi < 0)
    return out


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
    """
    owner = np.asarray(owner, dtype=np.int64)
    n = len(joint_boxes)
    if owner.size == 0:
        return owner, np.asarray(cells, dtype=np.float64).reshape(0, 4)
    rho = Interval(joint_boxes[:, :, 0], joint_boxes[:, :, 1])
    rho_sq = rho.sqr()
    k = constants(geometry)
    reach = float(np.max(k.radius_iv.hi)) + 1.0  # how far a platform point moves per radian of phi, roughly
    done_o, done_c = [], []
    for round_ in range(rounds + 1):
        gone = np.zeros(owner.size, dtype=bool)
        for s in range(0, owner.size, _CHUNK):
            b = owner[s:s + _CHUNK]
            gone[s:s + _CHUNK] = _discard(geometry, rho_sq[b], rho[b][:, 0], cells[s:s + _CHUNK])
        owner, cells = owner[~gone], cells[~gone]
        stop = np.bincount(owner, minlength=n)[owner] > max_cells
        if round_ == rounds:
            stop[:] = True
        done_o.append(owner[stop])
        done_c.append(cells[stop])
        owner, cells = owner[~stop], cells[~stop]
        if owner.size == 0:
            break
        # bisect where the pose moves most: rho_1 d(theta) against the platform's reach d(phi)
        rows = np.arange(len(cells))
        by_theta = rho.hi[owner, 0] * (cells[:, 1] - cells[:, 0]) >= reach * (cells[:, 3] - cells[:, 2])
        a = np.where(by_theta, 0, 2)
        mid = 0.5 * cells[rows, a] + 0.5 * cells[rows, a + 1]
        left, right = cells.copy(), cells.copy()
        left[rows, a + 1] = mid
        right[rows, a] = mid
        owner = np.concatenate([owner, owner])
        cells = np.concatenate([left, right])
    o, c = np.concatenate(done_o), np.concatenate(done_c)
    order = np.argsort(o, kind="stable")
    return o[order], c[order]


def clear_boxes(geometry: Geometry, boxes: np.ndarray, rounds: int = 6) -> np.ndarray:
    """(n,) bool: True where the joint box is PROVED clear (off g(S)); False means undecided.

    boxes : (n, 3, 2) of [rho_lo, rho_hi] with rho > 0.  A one-shot test (no parent
    to inherit from), so it bisects more rounds than one paving level does.
    """
    boxes = np.asarray(boxes, dtype=np.float64)
    owner, cells = initial_cells(len(boxes))
    owner, _ = live_cells(geometry, boxes, owner, cells, rounds=rounds)
    return np.bincount(owner, minlength=len(boxes)) == 0
