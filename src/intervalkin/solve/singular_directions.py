"""The sign of D_e f at the double roots of f, read from the singular poses instead of the elimination.

Why
---
The retraction (:mod:`intervalkin.space.joint_retraction`) needs, on each critical piece [lo, hi] of a window over a
joint box R, the sign of D_e f = sum_l e_l 2 rho_l df/dr_l at the double roots of f (a window's count changes only
through one).  The forms of :mod:`~intervalkin.solve.root_directions` read it through the elimination, whose
gradient in r shrinks like D near a zero of D: there they leave most pieces unsigned at any box size.  The
singular poses themselves are not degenerate there.  This module reads the same sign from them.

The identity
------------
Let z(phi; r) = N / D be the Cramer solution of the two linear equations F_2 - F_1 = F_3 - F_1 = 0 and
G(phi; r) = F_1(z, phi; r), so that f = D^2 G (:mod:`intervalkin.kinematics.sextic`) and F(z, phi; r) = G (1, 1, 1)
along the curve.  Differentiating in r along dr and taking the product with the left null vector w of
A = dF/dX at a singular pose (w^T A = 0, with dF/dr = -I):

    -w . dr = (D_dr G) (w_1 + w_2 + w_3).

With u_l = B_l - A_l, w = (u_2 x u_3, u_3 x u_1, u_1 x u_2) is such a vector (the identity
(b x c) a + (c x a) b + (a x b) c = 0 for plane vectors kills the first two columns, det A = 0 the third), and
w_1 + w_2 + w_3 = (u_2 - u_1) x (u_3 - u_1) = D / 4, since m_i = 2 (u_i - u_1).  At a double root phi* of f with
D(phi*) != 0 the pose (z, phi*) is singular (f = f' = 0 there gives A dX/dphi = 0 with dX/dphi != 0), so with
dr = 2 rho e:

    D_e f = D^2 D_e G = -8 D sum_l e_l rho_l w_l      at every double root of f where D != 0.

No division by D is left: the sign is sign(D) times the opposite of sign(sum_l e_l rho_l w_l), and w is
enclosed over pose boxes holding every singular pose with phi in the piece and rho in R: the live torus cells of
the clear-box search (:mod:`intervalkin.solve.joint_box`) started on the piece's phi range alone (every singular
pose with rho(X) in R lies in one of them).  When no cell is live the piece holds no
singular pose, hence (with D of one sign) no double root of f.

The same curve gives f'': differentiating F(X(phi; r); r) = G (1, 1, 1) in phi and multiplying by w, G' = det A / D
along the curve, so at a double root f'' = D^2 G'' = D (grad det A . k), k = (dz/dphi, 1) the kernel of A there.
The cusp sides' straight ways need sigma D_e f with sigma the sign of f'' (:mod:`~intervalkin.solve.window_cusp`):
that is -sign(grad det A . k) sign(sum_l e_l rho_l w_l), in which D cancels (``fold=True``).

Each live cell holds some of those poses, so a sign that every cell of a piece proves holds at all of them.

Without D
---------
Whether the pair of roots meeting at a double root dies or is born along e is a property of the pose: at a singular
pose where A has rank 2, with left null vector y and kernel vector kappa, the direct kinematics has two solutions
nearby on the side where y . (r - r*) has the sign of y . H[kappa, kappa], H[kappa, kappa]_l the second derivative of
rho_l^2 along kappa, and none on the other.  So the pair only dies along e where y . E and y . H have opposite signs
(E = 2 rho e), which is the sign of f'' D_e f where D != 0: -sign(y . E) sign(y . H), with no D at all
(:func:`fold_signs`).  It serves the pieces where D has no sign (beside its zeros) and the cells where w is too small
to sign: next to a zero of D the singular poses have their three legs nearly parallel, where every u_a x u_b, so w,
vanishes, and y is then taken as the product of the other pairs of A's columns.

What is certified: both outputs, from outward-rounded intervals (proofs/lemma-singular-directions.md, statements 4 to
6).
"""

from __future__ import annotations

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import PI_HI, Interval, integer_combinations, sign_label
from intervalkin.kinematics.constants import constants
from intervalkin.kinematics.enclosures import det_a_gradient_interval, jacobian_interval
from intervalkin.solve.joint_box import THETA_CELLS, live_cells, pose_boxes
from intervalkin.solve.window_split import denominator_enclosure

__all__ = ["singular_direction_signs", "singular_pose_cells", "curvature_signs", "denominator_signs", "fold_signs",
           "CELL_ROUNDS"]

#: Bisection rounds of the torus cells on a piece's phi range (each halves theta or phi, whichever moves the pose
#: more).  On the paper's paving, of the pieces the other forms leave open, 22 %, 36 % and 40 % are proved to hold
#: no singular pose with 6, 8 and 10 rounds, for 0.8, 1.1 and 2.1 s per 20 000 pieces.
CELL_ROUNDS = 8
#: A piece with more live cells than this after a round stops bisecting them.
MAX_CELLS = 64
#: Pieces searched together (THETA_CELLS cells each at the start): large calls keep the per-round overhead of
#: live_cells small.
_BLOCK = 1 << 16
#: Pieces whose cells' direction signs are taken together (a few thousand cells x 62 directions stay in cache).
_SIGN_PIECES = 1024


def singular_pose_cells(geometry: Geometry, boxes: np.ndarray, owner: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                        rounds: int = CELL_ROUNDS) -> tuple[np.ndarray, np.ndarray]:
    """((k,) int64 increasing, the piece of each cell; (k, 3, 2) its pose box): boxes that together hold every
    singular pose X with phi in [lo, hi] and rho(X) in R = boxes[owner] (the live cells of
    :func:`~intervalkin.solve.joint_box.live_cells` started on theta in [-pi, pi] and phi in the piece).  A piece
    with no cell holds no singular pose (proved).  Pieces lie in [-PI_HI, PI_HI], as a window's do."""
    boxes = np.asarray(boxes, dtype=np.float64)
    m = len(owner)
    t = np.linspace(-PI_HI, PI_HI, THETA_CELLS + 1)
    t[0], t[-1] = -PI_HI, PI_HI
    got_piece, got_pose = [np.zeros(0, dtype=np.int64)], [np.zeros((0, 3, 2))]
    for a in range(0, m, _BLOCK):
        part = np.arange(a, min(a + _BLOCK, m))
        n = part.size
        cells = np.column_stack([np.tile(t[:-1], n), np.tile(t[1:], n),
                                 np.repeat(lo[part], THETA_CELLS), np.repeat(hi[part], THETA_CELLS)])
        joint = boxes[owner[part]]
        live_owner, live = live_cells(geometry, joint, np.repeat(np.arange(n), THETA_CELLS), cells, rounds=rounds,
                                      max_cells=MAX_CELLS)
        got_piece.append(part[live_owner])
        got_pose.append(pose_boxes(geometry, joint[live_owner, 0, :], live))
    return np.concatenate(got_piece), np.concatenate(got_pose)


def denominator_signs(geometry: Geometry, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(m,) int8: the proved sign of D(phi) = d_0 + d_1 cos phi + d_2 sin phi over [lo, hi], 0 where not proved
    (:func:`~intervalkin.solve.window_split.denominator_enclosure`, which keeps pieces next to a zero of D signed)."""
    return sign_label(denominator_enclosure(geometry, lo, hi)).astype(np.int8)


def singular_direction_signs(geometry: Geometry, boxes: np.ndarray, owner: np.ndarray, lo: np.ndarray,
                             hi: np.ndarray, directions: np.ndarray, fold: bool = False,
                             curvature: np.ndarray | None = None, gap: bool = False,
                             rounds: int = CELL_ROUNDS) -> tuple[np.ndarray, np.ndarray]:
    """((m, c) int8, the sign of D_e f at every double root of f in R^2 x [lo, hi], R = boxes[owner], for each
    integer direction e (c, 3) in rho with entries in -2..2, 0 where not proved; (m,) bool, pieces proved to hold
    no double root of f).  ``fold``: the sign of f'' D_e f instead, with f'' != 0 proved at those double roots.

    Only pieces on which D has a proved sign get either (the identities of the module docstring need D != 0, and
    where D vanishes f has double roots that are not singular).  There, at the singular poses of each live cell,
    D_e f has the sign -sign(D) sign(sum_l e_l rho_l w_l), rho over R and w over the cell's pose box, and
    f'' D_e f the sign -sign(grad det A . k) sign(sum_l e_l rho_l w_l), k the kernel of A with k_phi = 1; the
    piece's sign is the one every cell proves.  A piece with no live cell is quiet.  ``curvature`` (m,) int8: the sign
    of f'' at the piece's double roots where the caller knows it (0 elsewhere); with ``fold`` it stands for the cells'
    own there.

    What those leave open in a cell is read without D (:func:`fold_signs`, module docstring "Without D"): with
    ``fold`` the sign of f'' D_e f itself, otherwise that sign times ``curvature``.  ``gap``: every piece is searched,
    also those where D has no sign; the double roots of f at a zero phi_D of D (on the plane s(phi_D; r) = 0, where
    two poses share the orientation phi_D) are then not covered, and a quiet piece holds none but those: the caller
    must keep its paths off that plane (the retraction's nodes of boxes cut at phi_D do)."""
    boxes = np.asarray(boxes, dtype=np.float64)
    directions = np.asarray(directions, dtype=np.int64)
    if directions.size and np.abs(directions).max() > 2:
        raise ValueError("singular_direction_signs: direction entries must lie in -2..2 (their products are exact)")
    m = len(owner)
    signs = np.zeros((m, len(directions)), dtype=np.int8)
    quiet = np.zeros(m, dtype=bool)
    d_sign = denominator_signs(geometry, lo, hi)
    rows = np.arange(m) if gap else np.flatnonzero(d_sign != 0)
    if not rows.size:
        return signs, quiet
    cell_of, poses = singular_pose_cells(geometry, boxes, owner[rows], lo[rows], hi[rows], rounds)
    quiet[rows[np.bincount(cell_of, minlength=rows.size) == 0]] = True
    if not cell_of.size:
        return signs, quiet
    A = jacobian_interval(geometry, poses)  # row l is 2 (u_lx, u_ly, r_l x u_l): these u give 4 w, same signs
    rho = boxes[owner[rows[cell_of]]]
    terms = []
    for l in range(3):
        i, j = (l + 1) % 3, (l + 2) % 3
        w = A[:, i, 0] * A[:, j, 1] - A[:, i, 1] * A[:, j, 0]
        terms.append(w * Interval(rho[:, l, 0], rho[:, l, 1]))
    t_lo, t_hi = np.column_stack([x.lo for x in terms]), np.column_stack([x.hi for x in terms])
    factor = d_sign[rows[cell_of]]
    known = np.zeros(m, dtype=np.int8) if curvature is None else np.asarray(curvature, dtype=np.int8)
    # what the signs without D are multiplied by: 1 for f'' D_e f, else the sign of f'' at the piece's double roots
    to_out = np.ones(cell_of.size, dtype=np.int8) if fold else known[rows[cell_of]]
    if fold:  # sign(f'') sign(D) at the double roots: from the piece where proved, else from the cells' poses
        cell_known = known[rows[cell_of]] * factor
        factor = np.where(cell_known != 0, cell_known, curvature_signs(geometry, poses, A)).astype(np.int8)
    start = np.flatnonzero(np.r_[True, cell_of[1:] != cell_of[:-1]])
    bounds = np.r_[start, cell_of.size]
    for a in range(0, start.size, _SIGN_PIECES):  # runs of whole pieces whose (cells, directions) arrays stay in cache
        b = min(a + _SIGN_PIECES, start.size)
        c = slice(bounds[a], bounds[b])
        combined = integer_combinations(t_lo[c], t_hi[c], directions)
        per_cell = (-sign_label(combined) * factor[c][:, None]).astype(np.int8)
        # what w leaves open (D not signed, or w near 0 where the legs are nearly parallel): the signs without D
        open_ = np.flatnonzero((per_cell == 0).any(axis=1) & (to_out[c] != 0))
        if open_.size:
            cells = np.arange(bounds[a], bounds[b])[open_]
            own = fold_signs(geometry, poses[cells], A[cells], rho[cells], directions,
                             along=sign_label(combined[open_])) * to_out[cells][:, None]
            per_cell[open_] = np.where(per_cell[open_] != 0, per_cell[open_], own)
        # each cell holds some of the piece's singular poses: the piece has a sign where every cell proves the same one
        at = start[a:b] - bounds[a]
        low, high = np.minimum.reduceat(per_cell, at, axis=0), np.maximum.reduceat(per_cell, at, axis=0)
        signs[rows[cell_of[start[a:b]]]] = np.where(low == high, low, 0)
    return signs, quiet


def _cross3(a: list[Interval], b: list[Interval]) -> list[Interval]:
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def fold_signs(geometry: Geometry, poses: np.ndarray, A: Interval, rho: np.ndarray,
               directions: np.ndarray, along: np.ndarray | None = None) -> np.ndarray:
    """(k, c) int8: at every singular pose of each pose box (k, 3, 2), with its joint vector in rho (k, 3, 2), the
    proved sign of f'' D_e f for each integer direction e (c, 3) in rho: +1 where moving along e only lets the pair of
    roots meeting there die, -1 only be born, 0 not proved.  Read from the pose alone, without D (module docstring,
    "Without D"): -sign(y . E) sign(y . H[kappa, kappa]), y a left null vector of A, kappa a kernel vector,
    E = 2 rho e and H[kappa, kappa]_l the second derivative of rho_l^2 along kappa.  ``along`` (k, c): the proved
    signs of y . E for y = 4 w (the product of A's first two columns), when the caller has them.

    y is, per cell, the product of two of A's columns with the sharpest enclosure (4 w, the first two, vanishes where
    the legs are parallel); kappa each product of two rows in turn, until y . H is signed."""
    k = constants(geometry)
    poses = np.asarray(poses, dtype=np.float64)
    phi = Interval(poses[:, 2, 0], poses[:, 2, 1])
    rows = [[A[:, l, j] for j in range(3)] for l in range(3)]
    cols = [[A[:, l, j] for l in range(3)] for j in range(3)]
    half_u = [(rows[l][0] * 0.5, rows[l][1] * 0.5) for l in range(3)]  # u_l: row l of A is 2 (u_lx, u_ly, .)
    zero = Interval.point(np.zeros(len(poses)))
    plat = [(zero, zero)]  # B_1 is the pose's point: no platform offset
    for i in (1, 2):
        a = phi + k.alpha_iv[i]
        plat.append((k.radius_iv[i] * a.cos(), k.radius_iv[i] * a.sin()))
    # H[kappa, kappa]_l = 2 |d u_l / d kappa|^2 - 2 kappa_phi^2 u_l . r_l, for kappa the product of each two rows
    hessians = []
    for c, d in ((0, 1), (1, 2), (2, 0)):
        kx, ky, kp = _cross3(rows[c], rows[d])
        kp2 = kp.sqr()
        h = []
        for l in range(3):
            px, py = plat[l]
            vx, vy = kx - kp * py, ky + kp * px
            h.append((vx.sqr() + vy.sqr() - kp2 * (half_u[l][0] * px + half_u[l][1] * py)) * 2.0)
        hessians.append(h)
    # y: per cell the product of two of A's columns whose enclosure is the sharpest (the first, 4 w, vanishes where
    # the legs are parallel); any nonzero one is a left null vector at the cell's singular poses
    ys = [_cross3(cols[a], cols[b]) for a, b in ((0, 1), (0, 2), (1, 2))]
    sharp = np.stack([sum(np.abs(v.mid()) for v in y) / (sum(v.width() for v in y) + 1e-300) for y in ys], axis=1)
    pick = np.argmax(sharp, axis=1)
    out = np.zeros((len(poses), len(directions)), dtype=np.int8)
    for choice, y in enumerate(ys):
        at = np.flatnonzero(pick == choice)
        if not at.size:
            continue
        yc = [v[at] for v in y]
        curve = np.zeros(at.size, dtype=np.int8)
        for h in hessians:
            dot = yc[0] * h[0][at] + yc[1] * h[1][at] + yc[2] * h[2][at]
            curve = np.where(curve != 0, curve, sign_label(dot)).astype(np.int8)
        if along is not None and choice == 0:
            signs = along[at]
        else:
            t = [yc[l] * Interval(rho[at, l, 0], rho[at, l, 1]) for l in range(3)]
            signs = sign_label(integer_combinations(np.column_stack([v.lo for v in t]),
                                                    np.column_stack([v.hi for v in t]), directions))
        out[at] = -signs * curve[:, None]
    return out


def curvature_signs(geometry: Geometry, poses: np.ndarray, A: Interval | None = None) -> np.ndarray:
    """(k,) int8: the proved sign of grad det A . k over each pose box, k the kernel vector of A with k_phi = 1 at its
    singular poses (0 where not proved), which is sign(D) sign(f'') at a double root of f there.

    k is taken as row_a x row_b of A (a kernel vector wherever those rows are independent and A is singular) divided
    by its phi entry 4 u_a x u_b; the pair (a, b) is the first of the three whose product is signed."""
    if A is None:
        A = jacobian_interval(geometry, poses)
    grad = det_a_gradient_interval(geometry, poses)
    out = np.zeros(len(poses), dtype=np.int8)
    for a, b in ((0, 1), (1, 2), (2, 0)):
        kx, ky, kp = _cross3([A[:, a, j] for j in range(3)], [A[:, b, j] for j in range(3)])
        dot = grad[:, 0] * kx + grad[:, 1] * ky + grad[:, 2] * kp
        got = sign_label(dot) * sign_label(kp)
        out = np.where(out != 0, out, got).astype(np.int8)
    return out
