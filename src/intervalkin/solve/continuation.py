"""Certified continuation of direct-kinematic solutions along joint-space paths.

Used by :mod:`intervalkin.space.basic_region` to tell which sheet above a joint cell a piece
of certified boxes lies in (proofs/lemma-sheet-continuation.md).

Parameter Krawczyk test
-----------------------
Along a segment q(t) = q_a + t (q_b - q_a) of joint space (q_a, q_b exact, t a
float) the system is F(X, t)_i = |B_i(X) - A_i|^2 - rho_i(t)^2.  For a box X,
a parameter interval T = [t0, t1], a point m of X, a float matrix Y (inverse of
the float Jacobian at m) and an interval matrix J(X) enclosing dF/dX over X
(independent of t),

    K(X, T) = m - Y F(m, tm) - (T - tm) Y dF/dt(m, T) + (I - Y J(X)) (X - m)

encloses m - Y F(m, t) + (I - Y J(X)) (X - m) for every t in T (mean value in t,
dF_i/dt = -2 rho_i(t) (q_b - q_a)_i).  If K(X, T) lies in the interior of X,
then for EVERY t in T the box X holds exactly one solution x(t), every Jacobian
on X is non-singular (so det A keeps one sign on X) and t -> x(t) is continuous
(proofs/lemma-krawczyk-uniqueness.md applied at each t; closed graph in a
compact box).  Every zero of F(., t1) in X also lies in

    K1 = p - Y F(p, t1) + (I - Y J(X)) (X - p)     (any point p of X),

so K1 n X is a box that holds the solution at t1 (no interior test needed).
All of it is evaluated with :class:`intervalkin.core.interval.Interval` (outward
rounding), vectorized over many tracks at once.

Tracking
--------
A track carries a box Z known to hold the followed solution at q(t).  A step
[t, t1] predicts the solution at t1 in float (tangent + Newton), builds X around
both ends and around Z, and accepts the step when K(X, [t, t1]) is inside X:
the followed solution is then the unique one in X for all of [t, t1], and
Z := K1 n X at t1.  The step doubles on success and halves on failure, with a
floor below which the track gives up (never a guess).

Voxel paths
-----------
Paths run inside one joint cell: between centres of face-adjacent voxels of the
cell (the segment lies in the union of the two closed voxels), in straight runs
along a breadth-first tree of the cell rooted at the cell's witness voxel.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import PI_HI, PI_LO, Interval, round_down, round_up
from intervalkin.kinematics.constants import constants
from intervalkin.kinematics.enclosures import jacobian_interval, rho_sq_interval
from intervalkin.kinematics.formulas import approx_jacobian, approx_rho_sq

#: Steps are halved down to this fraction of the segment, then the track gives up.
MIN_STEP = 2.0**-14
#: Each track may take at most this many steps (accepted or refused).
MAX_STEPS = 400
#: Step box half-width = MARGIN_OWN * |motion| + MARGIN_ALL * (largest scaled motion) per coordinate.
MARGIN_OWN = 0.7
MARGIN_ALL = 0.05
#: Half-width (relative) of the tiny box proved around each step's end point.
TINY = 1e-9


def _step_scale(geometry: Geometry) -> np.ndarray:
    """Length scale of each pose coordinate: 1 for x and y, 1 / (largest platform radius) for phi."""
    k = constants(geometry)
    return np.array([1.0, 1.0, 1.0 / max(float(np.max(k.radius)), 1.0)])


def _sum_last(v: Interval) -> Interval:
    return v[..., 0] + v[..., 1] + v[..., 2]


def _matvec(Y: np.ndarray, v: Interval) -> Interval:
    """Y (m, 3, 3) float times v (m, 3) Interval."""
    return _sum_last(Interval(v.lo[:, None, :], v.hi[:, None, :]) * Y)


def _matmat(Y: np.ndarray, J: Interval) -> Interval:
    """Y (m, 3, 3) float times J (m, 3, 3) Interval."""
    P = Interval(J.lo[:, None, :, :], J.hi[:, None, :, :]) * Y[:, :, :, None]  # (m, i, j, k)
    return P[:, :, 0, :] + P[:, :, 1, :] + P[:, :, 2, :]


def _q_at(qa: Interval, dq: Interval, t) -> Interval:
    """q_a + t (q_b - q_a) for t a float array (m,) or an Interval (m,): Interval (m, 3)."""
    tt = t if isinstance(t, Interval) else Interval.point(np.asarray(t, dtype=np.float64))
    return qa + Interval(tt.lo[:, None], tt.hi[:, None]) * dq


def krawczyk_segment(geometry: Geometry, lo, hi, qa: Interval, qb: Interval, t0, t1, p_end=None,
                     return_ratio: bool = False):
    """Parameter Krawczyk test of boxes [lo, hi] (m, 3) over t in [t0, t1] (m,) each.

    Returns (ok, z_lo, z_hi): ``ok`` (m,) bool is True where the Krawczyk image
    lies in the interior of the box, which proves that for every t in [t0, t1]
    the box holds exactly one solution of F(X, q(t)) = 0, with a non-singular
    Jacobian.  [z_lo, z_hi] is K1 n X at t1 (centred at ``p_end`` when given,
    clipped into the box): it holds every solution in the box at t1, whether
    ``ok`` or not.
    """
    lo = np.asarray(lo, dtype=np.float64)
    hi = np.asarray(hi, dtype=np.float64)
    t0 = np.asarray(t0, dtype=np.float64)
    t1 = np.asarray(t1, dtype=np.float64)
    m = Interval(lo, hi).mid()
    dq = qb - qa
    with np.errstate(all="ignore"):
        A = approx_jacobian(geometry, m)
        good = np.isfinite(A).all(axis=(1, 2)) & (np.abs(np.linalg.det(A)) > 0)
        A[~good] = np.eye(3)
        Y = np.linalg.inv(A)
    good &= np.isfinite(Y).all(axis=(1, 2))
    Y[~good] = 0.0
    tm = 0.5 * t0 + 0.5 * t1
    tm = np.minimum(np.maximum(tm, t0), t1)
    rsq_m = rho_sq_interval(geometry, np.stack([m, m], axis=-1))
    F_m = rsq_m - _q_at(qa, dq, tm).sqr()
    T = Interval(t0, t1)
    dF = _q_at(qa, dq, T) * dq * (-2.0)
    S = T - Interval.point(tm)
    J = jacobian_interval(geometry, np.stack([lo, hi], axis=-1))
    M = Interval.point(np.eye(3)) - _matmat(Y, J)
    box = Interval(lo, hi)
    D = box - m
    YdF = _matvec(Y, dF)
    K = (Interval.point(m) - _matvec(Y, F_m)) - Interval(S.lo[:, None], S.hi[:, None]) * YdF + _matvec(M, D)
    ok = good & np.all((K.lo > lo) & (K.hi < hi), axis=1)
    with np.errstate(all="ignore"):
        ratio = np.max((K.hi - K.lo) / np.maximum(hi - lo, 1e-300), axis=1)
    p = m if p_end is None else np.minimum(np.maximum(np.asarray(p_end, dtype=np.float64), lo), hi)
    F_p = rho_sq_interval(geometry, np.stack([p, p], axis=-1)) - _q_at(qa, dq, t1).sqr()
    K1 = (Interval.point(p) - _matvec(Y, F_p)) + _matvec(M, box - p)
    z_lo = np.maximum(K1.lo, lo)
    z_hi = np.minimum(K1.hi, hi)
    bad = ~np.isfinite(z_lo) | ~np.isfinite(z_hi) | (z_lo > z_hi)
    z_lo = np.where(bad, lo, z_lo)  # the box itself always holds them
    z_hi = np.where(bad, hi, z_hi)
    if return_ratio:
        return ok, z_lo, z_hi, np.where(ok, ratio, np.inf)
    return ok, z_lo, z_hi


def _newton(geometry: Geometry, x: np.ndarray, q: np.ndarray, iters: int = 4):
    """Float Newton on F(X) = rho(X)^2 - q^2 from x (m, 3); returns (x, converged)."""
    x = np.array(x, dtype=np.float64)
    q2 = q * q
    conv = np.zeros(len(x), dtype=bool)
    with np.errstate(all="ignore"):
        for _ in range(iters):
            rsq, A = approx_rho_sq(geometry, x), approx_jacobian(geometry, x)
            ok = np.isfinite(A).all(axis=(1, 2)) & (np.abs(np.linalg.det(A)) > 1e-12)
            A[~ok] = np.eye(3)
            dx = np.linalg.solve(A, (rsq - q2)[..., None])[..., 0]
            dx[~ok] = np.nan
            x = x - dx
            conv = np.all(np.abs(dx) <= 1e-11 * (1.0 + np.abs(x)), axis=1)
    return x, conv & np.isfinite(x).all(axis=1)


# --------------------------------------------------------------------------------------
# Tracking many segments at once
# --------------------------------------------------------------------------------------
@dataclass
class Tracks:
    """A batch of tracks, one per row; see :func:`track`.

    ``status``: 0 running, 1 reached t = 1, -1 gave up.  At the end of a
    successful track, [x_lo, x_hi] is a box holding exactly one solution at
    q_b (the followed one) and [z_lo, z_hi], inside it, also holds it.
    """

    qa: Interval
    qb: Interval
    t: np.ndarray
    h: np.ndarray
    p: np.ndarray
    z_lo: np.ndarray
    z_hi: np.ndarray
    x_lo: np.ndarray
    x_hi: np.ndarray
    status: np.ndarray
    steps: np.ndarray


def _q_float(qa: Interval, dq: Interval, t: np.ndarray) -> np.ndarray:
    return _q_at(qa, dq, t).mid()


def step_tracks(geometry: Geometry, tr: Tracks, idx: np.ndarray) -> None:
    """One adaptive step for the running tracks ``idx`` (in place)."""
    if idx.size == 0:
        return
    qa, qb = tr.qa[idx], tr.qb[idx]
    dq = qb - qa
    t0 = tr.t[idx]
    t1 = np.minimum(1.0, t0 + tr.h[idx])
    p0 = tr.p[idx]
    # tangent predictor: dX/dt = A^-1 (2 rho(t) dq)
    with np.errstate(all="ignore"):
        A = approx_jacobian(geometry, p0)
        rhs = 2.0 * _q_float(qa, dq, t0) * dq.mid()
        try:
            tan = np.linalg.solve(A, rhs[..., None])[..., 0]
        except np.linalg.LinAlgError:
            tan = np.zeros_like(p0)
    tan = np.where(np.isfinite(tan), tan, 0.0)
    pred = p0 + (t1 - t0)[:, None] * tan
    p1, conv = _newton(geometry, pred, _q_float(qa, dq, t1))
    delta = np.where(conv[:, None], np.abs(p1 - p0), 0.0)
    c = 0.5 * (p0 + np.where(conv[:, None], p1, p0))
    # half-widths: the motion of the solution plus a margin; phi is scaled by the platform
    # size (a wide phi range widens the Jacobian's third column most)
    scale = _step_scale(geometry)
    spread = (delta / scale).max(axis=1, keepdims=True) * scale
    r = MARGIN_OWN * delta + MARGIN_ALL * spread + 1e-9 * (1.0 + np.abs(c))
    lo = round_down(np.minimum(c - r, tr.z_lo[idx]))
    hi = round_up(np.maximum(c + r, tr.z_hi[idx]))
    # one call: the step box over [t0, t1], and a tiny box around p1 at t1 alone
    eps = TINY * (1.0 + np.abs(p1))
    tlo, thi = round_down(p1 - eps), round_up(p1 + eps)
    m = idx.size
    both = np.concatenate([np.arange(m), np.arange(m)])
    ok2, zl2, zh2, ratio = krawczyk_segment(geometry, np.concatenate([lo, tlo]), np.concatenate([hi, thi]),
                                            qa[both], qb[both], np.concatenate([t0, t1]), np.concatenate([t1, t1]),
                                            p_end=np.concatenate([p1, p1]), return_ratio=True)
    ratio = ratio[:m]
    ok = ok2[:m] & conv
    # the tiny box replaces K1 n X when it is proved to hold a solution and lies in X
    # (then its solution is the unique one of X at t1, the followed one)
    tiny = ok2[m:] & np.all((lo <= tlo) & (thi <= hi), axis=1)
    zl = np.where(tiny[:, None], tlo, zl2[:m])
    zh = np.where(tiny[:, None], thi, zh2[:m])
    # accepted steps
    a = idx[ok]
    tr.t[a] = t1[ok]
    tr.p[a] = p1[ok]
    tr.z_lo[a], tr.z_hi[a] = zl[ok], zh[ok]
    tr.x_lo[a], tr.x_hi[a] = lo[ok], hi[ok]
    # grow fast while the image is well inside the box, slowly when it is close
    tr.h[a] = np.minimum(np.where(ratio[ok] < 0.4, 2.0, 1.25) * tr.h[a], 1.0)
    tr.status[a[tr.t[a] >= 1.0]] = 1
    # refused steps
    f = idx[~ok]
    tr.h[f] *= 0.5
    tr.status[f[tr.h[f] < MIN_STEP]] = -1
    tr.steps[idx] += 1
    tr.status[idx[(tr.steps[idx] >= MAX_STEPS) & (tr.status[idx] == 0)]] = -1


def new_tracks(qa: Interval, qb: Interval, p: np.ndarray, z_lo: np.ndarray, z_hi: np.ndarray, h0: float = 1.0) -> Tracks:
    """Tracks from boxes [z_lo, z_hi] (m, 3), each holding the solution to follow at q_a."""
    m = len(p)
    nan = np.full((m, 3), np.nan)
    return Tracks(qa, qb, np.zeros(m), np.full(m, h0), np.array(p, dtype=np.float64), np.array(z_lo, dtype=np.float64),
                  np.array(z_hi, dtype=np.float64), nan.copy(), nan.copy(), np.zeros(m, dtype=np.int8),
                  np.zeros(m, dtype=np.int32))


def track(geometry: Geometry, tr: Tracks) -> Tracks:
    """Run every track of the batch to the end (t = 1) or until it gives up."""
    while True:
        run = np.flatnonzero(tr.status == 0)
        if run.size == 0:
            return tr
        step_tracks(geometry, tr, run)


def certify_start(geometry: Geometry, q: Interval, x: np.ndarray, radius: float = 1e-7):
    """Boxes around Newton-refined x (m, 3) each proved to hold exactly one solution of q.

    Returns (ok, lo, hi, p): ``ok`` where the point Krawczyk test succeeded.
    """
    p, conv = _newton(geometry, x, q.mid())
    r = radius * (1.0 + np.abs(p))
    lo, hi = round_down(p - r), round_up(p + r)
    z = np.zeros(len(p))
    ok, zl, zh = krawczyk_segment(geometry, lo, hi, q, q, z, z, p_end=p)
    return ok & conv, lo, hi, p


# --------------------------------------------------------------------------------------
# Boxes compared modulo 2 pi in phi
# --------------------------------------------------------------------------------------
def shift_phi_boxes(lo: np.ndarray, hi: np.ndarray, turns: np.ndarray):
    """Boxes (lo, hi arrays (m, 3)) with phi moved by 2 pi turns (integer array (m,)), rounded outward."""
    two_pi = Interval(np.full(len(turns), 2 * PI_LO), np.full(len(turns), 2 * PI_HI)) * turns.astype(np.float64)
    ph = Interval(lo[:, 2], hi[:, 2]) + two_pi
    lo2, hi2 = lo.copy(), hi.copy()
    lo2[:, 2], hi2[:, 2] = ph.lo, ph.hi
    return lo2, hi2


def compare_mod_2pi(x_lo, x_hi, z_lo, z_hi):
    """(inside, apart): [z] + 2 pi k inside [x] for some integer k; [z] + 2 pi k misses [x] for every k.

    Arrays (m, 3).  Only the three k nearest the difference of the phi centres
    are tried: with both boxes narrower than 3 in phi, every other k puts the
    two phi ranges more than 3 pi - 3 apart, so ``apart`` is claimed only then.
    """
    k0 = np.rint(((x_lo[:, 2] + x_hi[:, 2]) - (z_lo[:, 2] + z_hi[:, 2])) / (4 * np.pi)).astype(np.int64)
    inside = np.zeros(len(k0), dtype=bool)
    apart = ((x_hi[:, 2] - x_lo[:, 2]) < 3.0) & ((z_hi[:, 2] - z_lo[:, 2]) < 3.0)
    for dk in (-1, 0, 1):
        lo2, hi2 = shift_phi_boxes(z_lo, z_hi, k0 + dk)
        inside |= np.all((x_lo <= lo2) & (hi2 <= x_hi), axis=1)
        apart &= np.any((hi2 < x_lo) | (x_hi < lo2), axis=1)
    return inside, apart & ~inside
