"""Retraction directions of workspace boxes into an aspect: the local step of the aspect count's upper bound.

Fix a sign s (+1 for WA1, -1 for WA2) and let S = {X : f_j(X) >= 0 for the six
joint-limit constraints, s det A(X) > 0}, with

    f_{2i-1} = rho_i^2 - rho_min_i^2,   f_{2i} = rho_max_i^2 - rho_i^2   (i = 1, 2, 3).

A box b and a direction e satisfy the RETRACTION condition when every constraint
is, on the whole closed box, either certified satisfied (f_j >= 0, s det A > 0)
or certified nondecreasing along e (D_e f_j >= 0, D_e (s det A) >= 0).  Then a
point X of S in b moves along e, inside S, until it reaches a face of b whose
outward normal has a positive component along e (an EXIT face):
proofs/lemma-aspect-retraction.md.

:func:`classify_boxes` labels boxes for one sign, in bulk:

* OUT: no point of S in the box (a leg certified beyond a limit, or det A
  certified of sign -s on the whole box), or, where several constraint surfaces
  pass near the box and none of them alone excludes it, a combination
  sum_j w_j f_j with integer weights w_j >= 0 certified < 0 on the box (then at
  every point some f_j with w_j > 0 is negative: the point is not in S);
* IN: the box lies in S (every constraint certified satisfied);
* otherwise, the candidate directions e for which the retraction condition is
  certified: the fixed directions :data:`DIRECTIONS` and two directions built per
  box from the midpoint gradients of its undecided constraints (their sum, and
  the least-norm e with g_j . e = 1 for each normalised gradient), rounded to a
  finer integer grid (:data:`FINE_GRID`).

Directions are integer triples (a, b, c) standing for e = (a, b, c / PHI_DIVISOR):
exact numbers, so that the certificate and the checker use the very e the library
certified.  Certified: every directional derivative is enclosed with outward
rounding (:class:`~intervalkin.core.interval.Interval`) from the gradient
enclosures of :mod:`intervalkin.kinematics.enclosures` (rows of the Jacobian A for
rho_i^2, :func:`~intervalkin.kinematics.enclosures.det_a_gradient_interval` for
det A); OUT and IN are the comparisons of :mod:`intervalkin.paving.predicates`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import Interval
from intervalkin.kinematics.constants import constants
from intervalkin.kinematics.formulas import approx_det_a, approx_rho_sq
from intervalkin.kinematics.enclosures import (
    det_a_gradient_interval,
    det_a_interval,
    jacobian_interval,
    rho_sq_interval,
)

__all__ = ["PHI_DIVISOR", "GRID", "FINE_GRID", "WEIGHT_GRID", "DIRECTIONS", "BoxRetraction", "exit_faces",
           "classify_boxes", "shared_direction", "shared_directions", "constraint_values", "approx_free_of_aspect"]

#: e = (a, b, c / PHI_DIVISOR): a turn of the platform moves its points about 20 times further than
#: a unit shift, so the phi component is scaled down to balance the gradients.
PHI_DIVISOR = 16
#: On coarse boxes every decision (a bound's sign) is taken only when it holds with a margin of MARGIN
#: times the enclosure's width: a box decided narrowly by the library's tight forms is split instead, so that the
#: checker's plainer arb forms decide its few children at once (soundness does not depend on it).
MARGIN = 0.05
#: Boxes of this level and deeper are decided without a margin (the checker's forms are tight enough there).
MARGIN_LEVEL = 8
#: Largest |component| of a fixed direction.
GRID = 16
#: Largest |component| of a direction built per box or per cluster (its components are rounded to this grid).
#: Finer than GRID: where three constraint surfaces meet with nearly dependent gradients the valid directions
#: form a cone a few hundredths of a radian wide, which may hold no point of the coarse grid.
FINE_GRID = 256
#: Smallest positive weight of a combination of constraints proving a box OUT (weights are integers, exact,
#: below 2**40; the gradients of rho_i^2 and det A differ by orders of magnitude, so the largest may be far above).
WEIGHT_GRID = 256


def _fixed_directions() -> np.ndarray:
    """The six axis directions first (one exit face each), then the diagonals with several phi weights."""
    out = [(a * GRID if k == 0 else 0, a * GRID if k == 1 else 0, a * GRID if k == 2 else 0)
           for k in range(3) for a in (1, -1)]
    for a in (-1, 0, 1):
        for b in (-1, 0, 1):
            for c in (-1, 0, 1):
                if (a, b) == (0, 0) or (a, b, c).count(0) == 2:
                    continue
                weights = (GRID,) if c == 0 else (GRID, 4, 1)
                out += [(a * GRID, b * GRID, c * w) for w in weights]
    return np.array(out, dtype=np.int64)


#: Fixed candidate directions (m, 3), integer triples (a, b, c): e = (a, b, c / PHI_DIVISOR).
DIRECTIONS = _fixed_directions()


def exit_faces(directions: np.ndarray) -> np.ndarray:
    """Exit faces of directions (..., 3) -> bool (..., 6): face 2k is the -axis-k face, 2k + 1 the +axis-k face."""
    d = np.asarray(directions)
    out = np.zeros(d.shape[:-1] + (6,), dtype=bool)
    for k in range(3):
        out[..., 2 * k] = d[..., k] < 0
        out[..., 2 * k + 1] = d[..., k] > 0
    return out


@dataclass(frozen=True, eq=False)
class BoxRetraction:
    """Labels of n boxes for one sign of det A.

    ``out`` (n,): no point of the aspect's set S in the box; ``inside`` (n,): the box lies in S;
    ``weights`` (n, 7) int: on an OUT box proved by a combination, its weights w_j >= 0 on the seven
    constraints (sum_j w_j f_j < 0 on the box), else 0;
    ``ok`` (n, m + 2): the retraction condition is certified along candidate direction j (the fixed
    :data:`DIRECTIONS` first, then the two per-box directions ``custom`` (n, 2, 3)); rows of ``out``
    and ``inside`` boxes are all False (an IN box needs no condition: every direction retracts it).
    """

    out: np.ndarray
    inside: np.ndarray
    ok: np.ndarray
    custom: np.ndarray
    weights: np.ndarray


def _to_grid(v: np.ndarray) -> np.ndarray:
    """Real directions (..., 3) in scaled coordinates -> integer triples, largest component FINE_GRID."""
    s = np.max(np.abs(v), axis=-1, keepdims=True)
    s = np.where(s > 0, s, 1.0)
    return np.rint(v / s * FINE_GRID).astype(np.int64)


def _custom_directions(grads: np.ndarray, active: np.ndarray) -> np.ndarray:
    """Two directions per box from midpoint gradients (n, c, 3) of the active constraints (n, c).

    In coordinates (x, y, PHI_DIVISOR phi) the gradient is (g_x, g_y, g_phi / PHI_DIVISOR); each
    active one is normalised; the candidates are their sum and the least-norm solution of
    g_j . e = 1 over the active j (pseudo-inverse; floats: the certification comes after).
    """
    g = grads * np.array([1.0, 1.0, 1.0 / PHI_DIVISOR])
    norm = np.linalg.norm(g, axis=-1, keepdims=True)
    g = np.where(active[..., None] & (norm > 0), g / np.where(norm > 0, norm, 1.0), 0.0)
    bisector = g.sum(axis=1)
    rhs = active.astype(np.float64)[..., None]
    least = (np.linalg.pinv(g) @ rhs)[..., 0]
    return np.stack([_to_grid(bisector), _to_grid(least)], axis=1)


def _slopes(grad: Interval, dirs: np.ndarray) -> Interval:
    """Enclosure of D_e f = sum_k e_k df/dx_k for gradients (n, 3) and directions (n, m, 3) or (m, 3)."""
    e = dirs.astype(np.float64) * np.array([1.0, 1.0, 1.0 / PHI_DIVISOR])  # exact: integers over a power of 2
    g = Interval(grad.lo[:, None, :], grad.hi[:, None, :])
    p = g * (e if e.ndim == 3 else e[None])
    return p[..., 0] + p[..., 1] + p[..., 2]


def _constraints(geometry: Geometry, boxes: np.ndarray, sign: int):
    """(out, inside, open (n, 7)) and a function giving the gradient enclosures of the 7 constraints on rows."""
    k = constants(geometry)
    r = rho_sq_interval(geometry, boxes)
    sd = det_a_interval(geometry, boxes) * float(sign)
    mu = margins(boxes)
    rm, dm = mu[:, None] * (r.hi - r.lo), mu * (sd.hi - sd.lo)  # the margins asked of every decision
    low_open = ~(r.lo - rm >= k.rho_min_sq_iv.hi)   # rho_i^2 >= rho_min_i^2 not certified (with the margin)
    high_open = ~(r.hi + rm <= k.rho_max_sq_iv.lo)  # rho_i^2 <= rho_max_i^2 likewise
    out = np.any((r.hi + rm < k.rho_min_sq_iv.lo) | (r.lo - rm > k.rho_max_sq_iv.hi), axis=1) | (sd.hi + dm < 0)
    opened = np.concatenate([low_open, high_open, ~(sd.lo - dm > 0)[:, None]], axis=1)
    inside = ~out & ~np.any(opened, axis=1)

    def gradients(idx: np.ndarray) -> list[Interval]:
        b = boxes[idx]
        jac = jacobian_interval(geometry, b)
        rows = [Interval(jac.lo[:, i, :], jac.hi[:, i, :]) for i in range(3)]
        return rows + [-g for g in rows] + [det_a_gradient_interval(geometry, b) * float(sign)]

    return out, inside, opened, gradients, mu


def _midpoints(grads: list[Interval]) -> np.ndarray:
    return np.nan_to_num(np.stack([0.5 * (g.lo + g.hi) for g in grads], axis=1))


def margins(boxes: np.ndarray) -> np.ndarray:
    """The margin asked of the decisions on each box: MARGIN above level MARGIN_LEVEL (phi width), else 0."""
    return np.where(boxes[:, 2, 1] - boxes[:, 2, 0] > 1.5 * 2 * np.pi / 2.0**MARGIN_LEVEL, MARGIN, 0.0)


def _certified(grads: list[Interval], opened: np.ndarray, dirs: np.ndarray, mu: np.ndarray) -> np.ndarray:
    """(n, m): every open constraint has D_e f >= 0 certified on the box, for dirs (m, 3) or (n, m, 3)."""
    good = np.ones((opened.shape[0],) + dirs.shape[-2:-1], dtype=bool)
    for j, g in enumerate(grads):
        sl = _slopes(g, dirs)
        good &= ~opened[:, j, None] | (sl.lo - mu[:, None] * (sl.hi - sl.lo) >= 0)
    return good & np.any(dirs != 0, axis=-1)


def classify_boxes(geometry: Geometry, boxes: np.ndarray, sign: int) -> BoxRetraction:
    """OUT, IN and the certified retraction directions of boxes (n, 3, 2) for the aspect of ``sign``.

    A constraint is OPEN on a box when it is not certified satisfied there; a direction is
    certified when each open constraint has a directional derivative certified >= 0 on the
    whole box.  Cost: the enclosures of rho_i^2 and det A on every box, and the Jacobian and
    grad det A on the boxes that are neither OUT nor IN.
    """
    out, inside, opened, gradients, mu = _constraints(geometry, boxes, sign)
    n, nd = len(boxes), len(DIRECTIONS)
    ok = np.zeros((n, nd + 2), dtype=bool)
    custom = np.zeros((n, 2, 3), dtype=np.int64)
    weights = np.zeros((n, 7), dtype=np.int64)
    idx = np.flatnonzero(~out & ~inside)
    if idx.size == 0:
        return BoxRetraction(out, inside, ok, custom, weights)
    grads = gradients(idx)
    own = _custom_directions(_midpoints(grads), opened[idx])
    ok[idx, :nd] = _certified(grads, opened[idx], DIRECTIONS, mu[idx])
    ok[idx, nd:] = _certified(grads, opened[idx], own, mu[idx])
    custom[idx] = own
    stuck = ~np.any(ok[idx], axis=1) & (opened[idx].sum(axis=1) >= 2)
    if np.any(stuck):
        rows = idx[stuck]
        w, proved = _combination_out(geometry, boxes[rows], sign, opened[rows],
                                     [Interval(g.lo[stuck], g.hi[stuck]) for g in grads], mu[rows])
        out[rows[proved]] = True
        ok[rows[proved]] = False
        weights[rows[proved]] = w[proved]
    return BoxRetraction(out, inside, ok, custom, weights)


def shared_directions(geometry: Geometry, boxes: np.ndarray, sign: int,
                      cluster: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`shared_direction` for every cluster at once: ``cluster`` (n,) ids 0..c-1 -> (e (c, 3), ok (n,))."""
    n = len(boxes)
    nc = int(cluster.max()) + 1 if n else 0
    e = np.zeros((nc, 3), dtype=np.int64)
    ok = np.zeros(n, dtype=bool)
    out, inside, opened, gradients, mu = _constraints(geometry, boxes, sign)
    idx = np.flatnonzero(~out & ~inside)
    if idx.size == 0:
        return e, ok
    grads = gradients(idx)
    g = _midpoints(grads) * np.array([1.0, 1.0, 1.0 / PHI_DIVISOR])
    norm = np.linalg.norm(g, axis=-1, keepdims=True)
    g = np.where(opened[idx][..., None] & (norm > 0), g / np.where(norm > 0, norm, 1.0), 0.0)
    sums = np.zeros((nc, 7, 3))
    np.add.at(sums, cluster[idx], g)
    used = np.zeros((nc, 7), dtype=np.int64)
    np.add.at(used, cluster[idx], opened[idx].astype(np.int64))
    for c in np.flatnonzero(np.any(used > 0, axis=1)):
        mean = sums[c][used[c] > 0]
        mean /= np.maximum(np.linalg.norm(mean, axis=-1, keepdims=True), 1e-300)
        e[c] = _to_grid(np.linalg.pinv(mean) @ np.ones(len(mean)))
    ok[idx] = _certified(grads, opened[idx], e[cluster[idx]][:, None, :], mu[idx])[:, 0]
    return e, ok


def constraint_values(geometry: Geometry, boxes: np.ndarray, sign: int) -> Interval:
    """Enclosures (n, 7) of the seven constraints f_j over boxes (n, 3, 2), in the order of the module docstring."""
    k = constants(geometry)
    r = rho_sq_interval(geometry, boxes)
    sd = det_a_interval(geometry, boxes) * float(sign)
    low, high = r - k.rho_min_sq_iv, k.rho_max_sq_iv - r
    return Interval(np.concatenate([low.lo, high.lo, sd.lo[:, None]], axis=1),
                    np.concatenate([low.hi, high.hi, sd.hi[:, None]], axis=1))


def _combination_out(geometry: Geometry, boxes: np.ndarray, sign: int, opened: np.ndarray, grads: list[Interval],
                     mu: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Integer weights w (n, 7) >= 0 on the open constraints, and where sum_j w_j f_j < 0 is certified (n,).

    Where the gradients of the open constraints are nearly dependent with nonnegative weights (two or
    three constraint surfaces nearly tangent, S pinched away), the combination is nearly constant
    over a small box, and its sign is decided by a centred form: F(m) + sum_k [dF/dx_k](B) ([B_k] - m_k),
    m the box's midpoint (float), F(m) enclosed on the point box [m, m].  The weights minimise
    |sum_j v_j g_j| over sum_j v_j = 1 (g_j the scaled, normalised midpoint gradients; floats),
    kept when nonnegative and rounded to integers (exact); the certification comes after.
    """
    n = len(boxes)
    scale = np.array([1.0, 1.0, 1.0 / PHI_DIVISOR])
    g = _midpoints(grads) * scale  # (n, 7, 3)
    norm = np.linalg.norm(g, axis=-1)
    use = opened & (norm > 0)
    gn = np.where(use[..., None], g / np.where(norm > 0, norm, 1.0)[..., None], 0.0)
    h = gn @ np.swapaxes(gn, 1, 2) + np.where(use, 1e-9, 1e9)[:, None, :] * np.eye(7)[None]
    v = np.linalg.solve(h, np.ones((n, 7, 1)))[..., 0]
    v = np.where(use, v, 0.0)
    v /= np.where(np.abs(v.sum(axis=1, keepdims=True)) > 0, v.sum(axis=1, keepdims=True), 1.0)
    lam = np.where(use, v / np.where(norm > 0, norm, 1.0), 0.0)
    good = np.all(lam >= -1e-12, axis=1) & (np.count_nonzero(lam > 0, axis=1) >= 2)
    lam = np.where(lam > 1e-9 * np.max(lam, axis=1, keepdims=True), lam, 0.0)
    least = np.min(np.where(lam > 0, lam, np.inf), axis=1, keepdims=True)
    w = np.rint(lam / np.where(np.isfinite(least), least, 1.0) * WEIGHT_GRID)
    good &= np.all(w < 2.0**40, axis=1)
    w = np.where(good[:, None], w, 0).astype(np.int64)
    proved = np.zeros(n, dtype=bool)
    rows = np.flatnonzero(np.any(w > 0, axis=1))
    if rows.size == 0:
        return w, proved
    b = boxes[rows]
    m = 0.5 * (b[:, :, 0] + b[:, :, 1])
    wf = w[rows].astype(np.float64)  # exact: small integers
    at_m = constraint_values(geometry, np.stack([m, m], axis=-1), sign)
    total = Interval(np.zeros(rows.size), np.zeros(rows.size))
    for j in range(7):
        total = total + Interval(at_m.lo[:, j], at_m.hi[:, j]) * wf[:, j]
    for k in range(3):
        dk = Interval(np.zeros(rows.size), np.zeros(rows.size))
        for j in range(7):
            dk = dk + Interval(grads[j].lo[rows, k], grads[j].hi[rows, k]) * wf[:, j]
        total = total + dk * (Interval(b[:, k, 0], b[:, k, 1]) - Interval(m[:, k], m[:, k]))
    proved[rows] = np.nan_to_num(total.hi + mu[rows] * (total.hi - total.lo), nan=1.0) < 0
    return w, proved


def shared_direction(geometry: Geometry, boxes: np.ndarray, sign: int) -> tuple[np.ndarray, np.ndarray]:
    """One direction for a cluster of boxes (n, 3, 2), and where it is certified (n,) bool.

    Near a corner of the aspect (three constraint surfaces meeting) the valid directions form
    a narrow cone, and directions chosen box by box may send neighbours at each other.  One
    direction for the whole cluster cannot: every step then moves forward along it.  It is the
    least-norm solution of g_j . e = 1 over the open constraints, g_j their normalised midpoint
    gradients averaged over the cluster.
    """
    out, inside, opened, gradients, mu = _constraints(geometry, boxes, sign)
    idx = np.flatnonzero(~out & ~inside)
    ok = np.zeros(len(boxes), dtype=bool)
    if idx.size == 0:
        return np.zeros(3, dtype=np.int64), ok
    grads = gradients(idx)
    g = _midpoints(grads) * np.array([1.0, 1.0, 1.0 / PHI_DIVISOR])
    norm = np.linalg.norm(g, axis=-1, keepdims=True)
    g = np.where(opened[idx][..., None] & (norm > 0), g / np.where(norm > 0, norm, 1.0), 0.0)
    used = np.any(opened[idx], axis=0)
    mean = g.sum(axis=0)[used]
    mean /= np.maximum(np.linalg.norm(mean, axis=-1, keepdims=True), 1e-300)
    e = _to_grid(np.linalg.pinv(mean) @ np.ones(int(used.sum())))
    ok[idx] = _certified(grads, opened[idx], e[None, :], mu[idx])[:, 0]
    return e, ok


def approx_free_of_aspect(geometry: Geometry, boxes: np.ndarray, sign: int, points: int = 5) -> np.ndarray:
    """Float screen, NOT certified: True where none of points**3 grid points of a box (n, 3, 2) lies in S.

    Used only to choose which boxes to refine (where OUT boxes may cut two groups of sinks apart);
    never a label.  Cost: points**3 float evaluations per box.
    """
    lo2 = np.array([float(v) ** 2 for v in geometry.rho_min])
    hi2 = np.array([float(v) ** 2 for v in geometry.rho_max])
    t = np.linspace(0.0, 1.0, points)
    grid = np.stack(np.meshgrid(t, t, t, indexing="ij"), axis=-1).reshape(-1, 3)
    free = np.ones(len(boxes), dtype=bool)
    for start in range(0, len(boxes), 4096):
        b = boxes[start:start + 4096]
        p = b[:, None, :, 0] + grid[None] * (b[:, None, :, 1] - b[:, None, :, 0])
        r = approx_rho_sq(geometry, p)
        ins = np.all((r >= lo2) & (r <= hi2), axis=-1) & (sign * approx_det_a(geometry, p) > 0)
        free[start:start + 4096] = ~np.any(ins, axis=1)
    return free
