"""Forward-backward (HC4-revise) contractors for the joint limits and the sign of det A, over arrays of boxes.

A contractor takes boxes B (rows of ``lo``, ``hi``, each (n, 3): x, y, phi) and a
constraint c, and returns boxes C subset of B with

    every point of B that satisfies c lies in C            (proofs/lemma-contractor.md),

or says that no point of B satisfies c (``empty``).  It never drops a solution; it may
keep points that are not solutions.  Two constraint families:

* a joint limit, rho_i^2 in [t_lo, t_hi] (a limit itself, or the half-lines
  rho_i^2 <= rho_min_i^2 and rho_i^2 >= rho_max_i^2 where a limit fails), written as
  (x + P)^2 + (y + R)^2 + T in [t_lo, t_hi] with P, R, T intervals
  (:class:`~intervalkin.kinematics.enclosures.LegForms`): the natural form (P, R enclose
  c_i over [phi], T = 0), then the centred form in phi (P, R at phi_m, T = s (phi - phi_m)
  with s in the slope enclosure), which also contracts phi;
* the sign of det A, det A in [0, +inf) or (-inf, 0], by the mean-value form in the three
  variables: det A(p) in det A(m) + sum_j G_j (p_j - m_j) with G the enclosure of grad det A
  over the box (:func:`~intervalkin.kinematics.enclosures.det_a_gradient_interval`).

Each revise is one forward pass (the enclosure of every node of the expression) and one
backward pass (each node intersected with what its parent and siblings allow: for a
sum, the parent minus the siblings; for a square, the two-sided square root; for a
product with an interval factor free of zero, the quotient).  Every operation is the
outward-rounded :class:`~intervalkin.core.interval.Interval` arithmetic, so each
backward enclosure holds the exact projection of the solution set.  All of it is
numpy over the rows: no Python loop per box.

Certified: :func:`contract_leg` and :func:`contract_det` keep every solution of B
(``tests/paving/test_contract.py::test_contractors_keep_every_solution``).
"""

from __future__ import annotations

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import Interval
from intervalkin.kinematics.enclosures import det_a_gradient_interval, det_a_interval, rho_sq_leg_forms

__all__ = ['contract_leg', 'contract_det']


def _meet(a: Interval, b: Interval) -> tuple[Interval, np.ndarray]:
    """The intersection of two intervals and where it is certainly empty.

    A NaN bound of ``b`` (an undefined backward step) contracts nothing (fmax / fmin skip
    it); a NaN never makes a row empty, and :func:`_guard` restores boxes left with one.
    Empty rows keep a's bounds, so later steps compute on valid numbers.
    """
    lo = np.fmax(a.lo, b.lo)
    hi = np.fmin(a.hi, b.hi)
    empty = lo > hi
    return Interval(np.where(empty, a.lo, lo), np.where(empty, a.hi, hi)), empty


def _sqr_preimage(u: Interval, w: Interval) -> tuple[Interval, np.ndarray]:
    """Hull of {v in u : v^2 in w}: u met with [-sqrt(w_hi), -sqrt(w_lo)] and with [sqrt(w_lo), sqrt(w_hi)]."""
    s = Interval(np.maximum(w.lo, 0.0), np.maximum(w.hi, 0.0)).sqrt()  # outward-rounded roots
    plo, phi_ = np.maximum(u.lo, s.lo), np.minimum(u.hi, s.hi)
    nlo, nhi = np.maximum(u.lo, -s.hi), np.minimum(u.hi, -s.lo)
    p_empty, n_empty = plo > phi_, nlo > nhi
    lo = np.where(n_empty, plo, nlo)
    hi = np.where(p_empty, nhi, phi_)
    empty = p_empty & n_empty
    return Interval(np.where(empty, u.lo, lo), np.where(empty, u.hi, hi)), empty


def _revise_squares(x: Interval, y: Interval, p: Interval, r: Interval, t: Interval, target: Interval):
    """HC4-revise of (x + p)^2 + (y + r)^2 + t in target: contracted (x, y, t) and the empty rows.

    p, r, t are intervals of existentially quantified quantities: a point (x, y) survives
    if SOME values in p, r, t satisfy the constraint.
    """
    u, v = x + p, y + r
    u2, v2 = u.sqr(), v.sqr()
    s, empty = _meet(u2 + v2 + t, target)
    u2, e = _meet(u2, s - v2 - t)
    empty |= e
    v2, e = _meet(v2, s - u2 - t)
    empty |= e
    t, e = _meet(t, s - u2 - v2)
    empty |= e
    u, e = _sqr_preimage(u, u2)
    empty |= e
    v, e = _sqr_preimage(v, v2)
    empty |= e
    x, e = _meet(x, u - p)
    empty |= e
    y, e = _meet(y, v - r)
    return x, y, t, empty | e


def _guard(lo0, hi0, lo, hi, empty):
    """Rows with a NaN bound (or outside their box) get their box back and are not empty: no claim."""
    bad = ~np.all((lo0 <= lo) & (lo <= hi) & (hi <= hi0), axis=1) & ~empty
    bad |= np.isnan(lo).any(axis=1) | np.isnan(hi).any(axis=1)
    lo[bad], hi[bad] = lo0[bad], hi0[bad]
    return lo, hi, empty & ~bad


def _axis(lo: np.ndarray, hi: np.ndarray, j: int) -> Interval:
    return Interval(lo[:, j], hi[:, j])


def _store(lo, hi, j, iv: Interval, live: np.ndarray) -> None:
    lo[live, j] = iv.lo[live]
    hi[live, j] = iv.hi[live]


def contract_leg(geometry: Geometry, lo: np.ndarray, hi: np.ndarray, leg: int,
                 target: tuple[float, float], rounds: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Contract boxes under rho_leg^2 in [target_lo, target_hi] (floats, +-inf allowed).

    Parameters
    ----------
    lo, hi : ndarray (n, 3), the boxes (x, y, phi).
    leg : 0, 1 or 2.
    target : the closed range allowed for rho_leg^2; pass an outward enclosure of the
        exact set (e.g. ``(-inf, rho_min_sq_iv.hi)`` for "rho^2 <= rho_min^2").
    rounds : how many times the natural then the centred revise are applied.

    Returns (lo', hi', empty): the contracted boxes (each inside its box) and the rows
    where no point satisfies the constraint (their bounds are then those given).
    Certified: every point of a box with rho_leg^2 in the target lies in the contracted box.
    """
    lo0, hi0 = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    lo, hi = lo0.copy(), hi0.copy()
    n = len(lo)
    empty = np.zeros(n, dtype=bool)
    tgt = Interval(np.float64(target[0]), np.float64(target[1]))
    zero = Interval.point(np.zeros(n))
    for _ in range(rounds):
        f = rho_sq_leg_forms(geometry, np.stack([lo, hi], axis=-1), leg)
        x, y, _, e = _revise_squares(_axis(lo, hi, 0), _axis(lo, hi, 1), f.cx, f.cy, zero, tgt)
        empty |= e
        _store(lo, hi, 0, x, ~empty)
        _store(lo, hi, 1, y, ~empty)
        if leg == 0:  # no phi in rho_1: the natural revise is the whole story
            break
        f = rho_sq_leg_forms(geometry, np.stack([lo, hi], axis=-1), leg)
        d = _axis(lo, hi, 2) - f.phi_mid
        x, y, t, e = _revise_squares(_axis(lo, hi, 0), _axis(lo, hi, 1), f.cx_mid, f.cy_mid, f.slope * d, tgt)
        empty |= e
        d, e = _meet(d, t / f.slope)  # slope free of zero: phi - phi_m = t / slope; else no contraction
        empty |= e
        phi, e = _meet(_axis(lo, hi, 2), d + f.phi_mid)
        empty |= e
        live = ~empty
        _store(lo, hi, 0, x, live)
        _store(lo, hi, 1, y, live)
        _store(lo, hi, 2, phi, live)
    return _guard(lo0, hi0, lo, hi, empty)


def contract_det(geometry: Geometry, lo: np.ndarray, hi: np.ndarray,
                 sign: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Contract boxes under det A >= 0 (``sign`` = +1) or det A <= 0 (``sign`` = -1).

    Mean-value form at a float point m of each box: det A(p) = det A(m) + sum_j g_j (p_j - m_j)
    with g in the enclosure G of grad det A over the box; forward: the sum; backward:
    each term meets (the target minus the others), and p_j - m_j meets term_j / G_j.
    Returns (lo', hi', empty) as :func:`contract_leg`.  Certified: every point of a box
    where det A has the asked (weak) sign lies in the contracted box.
    """
    lo0, hi0 = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    lo, hi = lo0.copy(), hi0.copy()
    boxes = np.stack([lo, hi], axis=-1)
    m = Interval(lo, hi).mid()
    fm = det_a_interval(geometry, np.stack([m, m], axis=-1))
    grad = det_a_gradient_interval(geometry, boxes)
    d = [_axis(lo, hi, j) - m[:, j] for j in range(3)]
    terms = [grad[:, j] * d[j] for j in range(3)]
    t_lo, t_hi = (0.0, np.inf) if sign > 0 else (-np.inf, 0.0)
    target = Interval(np.float64(t_lo), np.float64(t_hi))
    s, empty = _meet(fm + terms[0] + terms[1] + terms[2], target)
    for j in range(3):
        others = [terms[i] for i in range(3) if i != j]
        terms[j], e = _meet(terms[j], s - fm - others[0] - others[1])
        empty |= e
        dj, e = _meet(d[j], terms[j] / grad[:, j])
        empty |= e
        axis, e = _meet(_axis(lo, hi, j), dj + m[:, j])
        empty |= e
        _store(lo, hi, j, axis, ~empty)
    return _guard(lo0, hi0, lo, hi, empty)
