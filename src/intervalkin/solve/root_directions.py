"""The sign of D_e f at the roots of f beside the zeros of D, where a box enclosure of f cannot give it.

The retraction's pair patterns (:func:`~intervalkin.solve.window_fold.pair_direction_signs` with ``at_roots``)
need, for each critical piece of a pair window and each integer direction e in rho, the sign of
D_e f = sum_l e_l 2 rho_l df/dr_l at the double roots of f on the piece, or a proof that it holds none.  Near a
zero of D the Taylor form of f cancels; these read f through f |m_2|^2 = s^2 - D^2 V
(:func:`~intervalkin.solve.window_split.aligned_terms`, proofs/lemma-line-misses-circle.md):

* :func:`root_direction_signs`: at every root, |s| = |D| sqrt(V), and L D_e f = 2 s D_e s - D^2 D_e V
  (lemma-line-misses-circle.md, statement 4);
* :func:`double_root_signs`: at a double root s is also a zero of the phi-derivative of f L, which pins it far
  more tightly (lemma-double-root-s.md);
* :func:`simple_on_branches`: where V > 0, f L is the product of the branches s -+ D sqrt(V), and pieces where
  both branches' phi-slopes keep a sign hold no double root (lemma-branch-roots.md);
* what is still open is read from the singular poses of the full system, which do not degenerate at the zeros of
  D (:mod:`~intervalkin.solve.singular_directions`, lemma-singular-directions.md).

Everything is vectorised over pieces and directions, in outward-rounded interval and ball arithmetic.
"""

from __future__ import annotations

import numpy as np

from intervalkin.core.ball import Ball, cos_sin_multiple
from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import Interval, certainly_positive, integer_combinations, sign_label
from intervalkin.kinematics.reduced_equation import aligned_numerator, denominator
from intervalkin.solve.simple_roots import ReducedBoxes, trig_basis
from intervalkin.solve.singular_directions import singular_direction_signs
from intervalkin.solve.window_split import aligned_r_slopes, aligned_terms

__all__ = ["piece_direction_signs", "with_singular_signs", "root_direction_signs", "double_root_signs",
           "simple_on_branches", "branch_slopes", "S_PARTS"]


def piece_direction_signs(geometry: Geometry, boxes: np.ndarray, data: ReducedBoxes, owner: np.ndarray, lo: np.ndarray,
                          hi: np.ndarray, directions: np.ndarray, at_roots: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """((m, c) int8, the proved sign of D_e f = sum_l e_l 2 rho_l df/dr_l over R^2 x [lo, hi], R = boxes[owner], for
    each direction e (c, 3), 0 where not proved; (m,) bool, pieces proved to hold no root of f, or with
    ``at_roots`` no double root), ``data`` the :class:`ReducedBoxes` of ``boxes``.

    df/dr_l is the Taylor form's enclosure intersected with
    :func:`~intervalkin.solve.window_split.aligned_r_slopes` (tighter near the zeros of D).  ``at_roots``: the sign
    only at the roots of f on the pieces (all that a count changing through a double root needs): where the
    whole-piece form gives none, :func:`root_direction_signs`, then :func:`double_root_signs`; pieces where the
    forms disagree (which they could not at a root), or proved free of double roots by :func:`simple_on_branches`,
    are quiet: they hold no double root, so they need no sign.  The callers then fill what is still open on the
    windows that need it from the singular poses (:func:`with_singular_signs`)."""
    box = np.asarray(boxes, dtype=np.float64)[owner]
    aligned = aligned_r_slopes(geometry, boxes, owner, lo, hi)
    grad = [data.r_slope(owner, lo, hi, axis).intersect(aligned[axis])
            * Interval(2.0 * box[:, axis, 0], 2.0 * box[:, axis, 1]) for axis in range(3)]
    quiet = np.zeros(len(owner), dtype=bool)
    root = np.zeros((len(owner), len(directions)), dtype=np.int8)
    if at_roots:
        root, quiet = root_direction_signs(geometry, boxes, owner, lo, hi, directions)
        quiet |= simple_on_branches(geometry, boxes, owner, lo, hi)
        need = np.flatnonzero(~quiet & (root == 0).any(axis=1))
        double, no_double = double_root_signs(geometry, boxes, owner[need], lo[need], hi[need], directions)
        # both signs hold at a double root: opposite ones prove the piece holds none
        quiet[need] |= no_double | (root[need] * double < 0).any(axis=1)
        root[need] = np.where(root[need] != 0, root[need], double)
    sg = _direction_signs(grad, np.asarray(directions, dtype=np.float64))
    # both hold at any root of the piece: opposite proved signs prove it holds none
    quiet |= ((sg * root) < 0).any(axis=1)
    return np.where(sg != 0, sg, root), quiet


def with_singular_signs(geometry: Geometry, boxes: np.ndarray, owner: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                        directions: np.ndarray, signs: np.ndarray, quiet: np.ndarray, pieces: np.ndarray,
                        fold: bool = False, curvature: np.ndarray | None = None, gap: bool = False) -> None:
    """Fill, in place, the open directions of ``pieces`` (indices into the arrays of :func:`piece_direction_signs`)
    with the signs at the singular poses of the piece
    (:func:`~intervalkin.solve.singular_directions.singular_direction_signs`; ``fold``: ``signs`` hold the sign of
    f'' D_e f; ``curvature``, the sign of f'' at each piece's double roots or 0, is used where it is known; ``gap``:
    also the pieces where D has no sign, read without D), and make
    quiet the pieces that hold no double root: those with no singular pose, and those where the two readings prove
    opposite signs (both hold at a double root, so there is none)."""
    need = pieces[~quiet[pieces] & (signs[pieces] == 0).any(axis=1)]
    if not need.size:
        return
    singular, none = singular_direction_signs(geometry, boxes, owner[need], lo[need], hi[need], directions, fold=fold,
                                              curvature=None if curvature is None else curvature[need], gap=gap)
    quiet[need] |= none | (signs[need] * singular < 0).any(axis=1)
    signs[need] = np.where(signs[need] != 0, signs[need], singular)


#: Rows per block in :func:`_direction_signs`: its (rows, directions) temporaries stay in cache (the whole array at
#: once, about 500 MB each on the paper's paving, made the signs three times slower than the direction loop).
_SIGN_BLOCK = 2048


def _direction_signs(grad: list[Interval], directions: np.ndarray) -> np.ndarray:
    """(m, c) int8: the proved sign of sum_l e_l grad_l for each direction e (c, 3), 0 where not proved.  Integer
    directions with entries in -2..2 (the retraction's) go through two matrix products per end
    (:func:`integer_combinations`); others, direction by direction."""
    if directions.size and np.array_equal(directions, np.round(directions)) and np.abs(directions).max() <= 2:
        lo = np.column_stack([g.lo for g in grad])
        hi = np.column_stack([g.hi for g in grad])
        e = directions.astype(np.int64)
        out = np.empty((len(lo), len(e)), dtype=np.int8)
        for a in range(0, len(lo), _SIGN_BLOCK):  # blocks whose (rows, directions) temporaries stay in cache
            out[a:a + _SIGN_BLOCK] = sign_label(integer_combinations(lo[a:a + _SIGN_BLOCK], hi[a:a + _SIGN_BLOCK], e))
        return out
    return np.column_stack([sign_label(grad[0] * e[0] + grad[1] * e[1] + grad[2] * e[2]) for e in directions]
                           ).reshape(len(grad[0].lo), len(directions)).astype(np.int8)


#: Pieces per block in :func:`root_direction_signs` and :func:`double_root_signs` (their arrays are pieces x
#: directions): 2048 x 62 floats, 1 MB, stay in a core's cache; 16384 took a third longer on the paper's paving.
_ROOT_BLOCK = 2048


def root_direction_signs(geometry: Geometry, boxes: np.ndarray, owner: np.ndarray, lo: np.ndarray,
                         hi: np.ndarray, directions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """At the ROOTS of f only: ((m, c) int8, the sign of D_e f = sum_l e_l 2 rho_l df/dr_l at every root of f in
    R^2 x [lo, hi], R = boxes[owner], for each integer direction e (c, 3) in rho, 0 where not proved; (m,) bool,
    the pieces proved to hold no root of f).

    At a root f L = s^2 - D^2 V = 0, so |s| = |D| sqrt(V) with V >= 0 (proofs/lemma-line-misses-circle.md,
    statement 4): s lies in [-B, B], B = max |D| sqrt(max(V, 0)), and in its range over the piece; beside a zero
    of D, where a root has s near 0 but the piece's range of s does not, the intersection is far narrower, and
    where it is empty no point of the piece is a root.  Then L D_e f = 2 s D_e s - D^2 D_e V (statement 3), with
    one s for every axis, and L > 0 where it is proved."""
    return _in_blocks("root_direction_signs", _root_block, geometry, boxes, owner, lo, hi, directions)


def _in_blocks(name: str, block, geometry: Geometry, boxes: np.ndarray, owner: np.ndarray, lo: np.ndarray, hi: np.ndarray,
               directions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``block`` over runs of :data:`_ROOT_BLOCK` pieces (its arrays are pieces x directions); the directions'
    entries must lie in -2..2, which keeps the products of :func:`integer_combinations` exact."""
    directions = np.asarray(directions, dtype=np.int64)
    if directions.size and np.abs(directions).max() > 2:
        raise ValueError(f"{name}: direction entries must lie in -2..2 (their products are exact)")
    m = len(owner)
    signs = np.zeros((m, len(directions)), dtype=np.int8)
    flags = np.zeros(m, dtype=bool)
    for a in range(0, m, _ROOT_BLOCK):
        part = slice(a, min(a + _ROOT_BLOCK, m))
        signs[part], flags[part] = block(geometry, boxes, owner[part], lo[part], hi[part], directions)
    return signs, flags


def _root_block(geometry: Geometry, boxes: np.ndarray, owner: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                directions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    slopes, leg, s, d, k, r = aligned_terms(geometry, boxes, owner, lo, hi)
    s_lo, s_hi, bound = _s_at_roots(leg, s, d, k, r)
    rootless = ~(s_lo <= s_hi)
    signs = np.zeros((len(owner), len(directions)), dtype=np.int8)
    # where the bound does not narrow s, this is aligned_r_slopes' enclosure again: not worth a second time
    tight = np.flatnonzero(~rootless & (bound < np.maximum(np.abs(s.lo), np.abs(s.hi))))
    if not tight.size:
        return signs, rootless
    de_s, d2_de_v = _direction_terms(np.asarray(boxes, dtype=np.float64)[owner[tight]], slopes[tight], leg[tight],
                                     d[tight], k[tight], directions)
    value = Interval(s_lo[tight][:, None], s_hi[tight][:, None]) * de_s * 2.0 - d2_de_v
    signs[tight] = np.where(certainly_positive(leg[tight])[:, None], sign_label(value), 0)
    return signs, rootless


def _s_at_roots(leg: Interval, s: Interval, d: Interval, k: Interval,
                r: list[Interval]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(lo, hi) of s's range cut to [-B, B], B = max |D| sqrt(max(V, 0)) (|s| = |D| sqrt(V) at a root), and B."""
    v = r[0] * leg - k.sqr()
    m = len(v.lo)
    bound = (Interval(np.zeros(m), np.maximum(v.hi, 0.0)).sqrt()
             * Interval(np.zeros(m), np.maximum(np.abs(d.lo), np.abs(d.hi)))).hi
    return np.maximum(s.lo, -bound), np.minimum(s.hi, bound), bound


def _direction_terms(box: np.ndarray, slopes: Ball, leg: Interval, d: Interval, k: Interval,
                     directions: np.ndarray) -> tuple[Interval, Interval]:
    """(m, c) enclosures of D_e s and of D^2 D_e V over the boxes (D_e = sum_l e_l 2 rho_l d/dr_l), with
    dV/dr_1 = L + 2 k, dV/dr_2 = -2 k, dV/dr_3 = 0 (lemma-line-misses-circle.md, statement 3)."""
    rho2 = [Interval(2.0 * box[:, i, 0], 2.0 * box[:, i, 1]) for i in range(3)]
    ds = [slopes[:, i].to_interval() * rho2[i] for i in range(3)]
    dv = [(leg + k * 2.0) * rho2[0], k * -2.0 * rho2[1]]
    de_s = integer_combinations(np.column_stack([x.lo for x in ds]), np.column_stack([x.hi for x in ds]), directions)
    de_v = integer_combinations(np.column_stack([x.lo for x in dv]), np.column_stack([x.hi for x in dv]),
                                 directions[:, :2])
    d2 = d.sqr()
    return de_s, Interval(d2.lo[:, None], d2.hi[:, None]) * de_v


def simple_on_branches(geometry: Geometry, boxes: np.ndarray, owner: np.ndarray, lo: np.ndarray,
                       hi: np.ndarray) -> np.ndarray:
    """(m,) bool: no point of R^2 x [lo, hi], R = boxes[owner], is a double root of f (proofs/lemma-branch-roots.md).

    Where the line of legs 1 and 2 meets the circle of leg 1 (V > 0 proved) and D != 0, f L = s^2 - D^2 V is the
    product of the two branches g_+- = s -+ D sqrt(V), smooth in phi, never zero together.  A double root of f is
    then a double root of one branch, and there is none when both slopes g_+-' (:func:`branch_slopes`) have one
    strict sign over the piece.  Close to a zero of D the root bound of :func:`root_direction_signs` cannot sign
    D_e f (s takes both signs at the roots), but a pattern of pair windows changes only where u = min s f
    vanishes, at a double root: pieces proved free of those say nothing about the directions."""
    ok, plus, minus = branch_slopes(geometry, boxes, owner, lo, hi)
    return ok & (sign_label(plus) != 0) & (sign_label(minus) != 0)


def branch_slopes(geometry: Geometry, boxes: np.ndarray, owner: np.ndarray, lo: np.ndarray,
                  hi: np.ndarray) -> tuple[np.ndarray, Interval, Interval]:
    """((m,) bool, the rows where V > 0, L > 0 and D != 0 are proved over R^2 x [lo, hi]; there, enclosures of
    g_+-' = s' -+ (D' sqrt(V) + D V' / (2 sqrt(V))), with V' = L' (r_1 + k / 2) since V = r_1 L - k^2 and
    k = r_2 - r_1 - L / 4 (elsewhere meaningless))."""
    _, leg, _, d, k, r = aligned_terms(geometry, boxes, owner, lo, hi, with_s=False, with_slopes=False)
    v = r[0] * leg - k.sqr()
    ok = certainly_positive(v) & certainly_positive(leg) & (sign_label(d) != 0)
    s_phi, v_phi, d_phi = _phi_slopes(geometry, lo, hi, r, k)
    root_v = Interval(np.where(ok, v.lo, 1.0), np.where(ok, v.hi, 1.0)).sqrt()
    branch = d_phi * root_v + d * v_phi / (root_v * 2.0)
    return ok, s_phi - branch, s_phi + branch


def _phi_slopes(geometry: Geometry, lo: np.ndarray, hi: np.ndarray, r: list[Interval],
                k: Interval) -> tuple[Interval, Interval, Interval]:
    """(s', V', D') over R^2 x [lo, hi] (' = d/dphi; r the enclosures of r_i over R^2, k of k_2): the derivative
    basis times the aligned coefficients, V' = L' (r_1 + k / 2) (lemma-branch-roots.md, part 3)."""
    aligned = aligned_numerator(geometry)
    phi = Ball.from_interval(Interval(np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)))
    basis = trig_basis(phi, 1)
    coef = basis.matmul(Ball.from_interval(aligned.coefficients))
    s_phi = coef[:, 0]
    for i in range(3):
        s_phi = s_phi + coef[:, 1 + i] * Ball.from_interval(r[i])
    leg_phi = basis.matmul(Ball.from_interval(Interval(aligned.leg_square.lo[:, None],
                                                       aligned.leg_square.hi[:, None])))[:, 0].to_interval()
    c, sn = cos_sin_multiple(phi, 1, 1)  # d/dphi of (cos phi, sin phi)
    dd = Ball.from_interval(denominator(geometry))
    return s_phi.to_interval(), leg_phi * (r[0] + k * 0.5), (dd[1] * c + dd[2] * sn).to_interval()


#: Parts of each sign's range of s in :func:`double_root_signs`.
S_PARTS = 16


def double_root_signs(geometry: Geometry, boxes: np.ndarray, owner: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                      directions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """At the DOUBLE roots of f only: ((m, c) int8, the sign of D_e f there (0: not proved), (m,) bool, the pieces
    proved to hold none), for pieces where D != 0 is proved (others: 0 and False).  lemma-double-root-s.md:
    at a double root s^2 = D^2 V and (f L)' = 0, so s is a zero of

        Q(sigma) = 2 sigma s' - 2 (D' / D) sigma^2 - D^2 V'

    in the root bound's range of s; the parts of that range (each sign's side cut in :data:`S_PARTS`) where an
    enclosure of Q holds 0 bound s at the double roots far more tightly than |s| <= |D| sqrt(V), and
    L D_e f = 2 s D_e s - D^2 D_e V is signed over each sign's hull of them."""
    return _in_blocks("double_root_signs", _double_block, geometry, boxes, owner, lo, hi, directions)


def _double_block(geometry, boxes, owner, lo, hi, directions):
    slopes, leg, s, d, k, r = aligned_terms(geometry, boxes, owner, lo, hi)
    m = len(owner)
    s_lo, s_hi, _ = _s_at_roots(leg, s, d, k, r)
    ok = (sign_label(d) != 0) & certainly_positive(leg)
    signs = np.zeros((m, len(directions)), dtype=np.int8)
    none = ok & ~(s_lo <= s_hi)  # no root at all
    live = np.flatnonzero(ok & (s_lo <= s_hi) & np.isfinite(s_lo) & np.isfinite(s_hi))
    if not live.size:
        return signs, none
    s_phi, v_phi, d_phi = _phi_slopes(geometry, lo[live], hi[live], [x[live] for x in r], k[live])
    dl = d[live]
    ratio = (d_phi / dl) * 2.0
    const = dl.sqr() * v_phi
    hulls = []
    for side in (-1, 1):  # sigma <= 0, sigma >= 0: the sign of s at the double root
        a = np.where(side < 0, s_lo[live], np.maximum(s_lo[live], 0.0))
        b = np.where(side < 0, np.minimum(s_hi[live], 0.0), s_hi[live])
        grid = a[:, None] + (b - a)[:, None] * (np.arange(S_PARTS + 1) / S_PARTS)[None, :]
        grid[:, -1] = b  # the parts cover [a, b] exactly: consecutive parts share their float ends
        sigma = Interval(np.minimum(grid[:, :-1], grid[:, 1:]), np.maximum(grid[:, :-1], grid[:, 1:]))
        q = sigma * _column(s_phi) * 2.0 - sigma.sqr() * _column(ratio) - _column(const)
        keep = ~((q.lo > 0) | (q.hi < 0)) & (a <= b)[:, None]  # dropped only where Q is proved nonzero (not NaN)
        hulls.append((keep.any(axis=1), np.where(keep, sigma.lo, np.inf).min(axis=1),
                      np.where(keep, sigma.hi, -np.inf).max(axis=1)))
    none[live] = ~hulls[0][0] & ~hulls[1][0]
    de_s, d2_de_v = _direction_terms(np.asarray(boxes, dtype=np.float64)[owner[live]], slopes[live], leg[live], dl,
                                     k[live], directions)
    agreed = np.full((live.size, len(directions)), 2, dtype=np.int64)  # 2: no side seen yet
    for held, h_lo, h_hi in hulls:
        at = Interval(np.where(held, h_lo, 0.0)[:, None], np.where(held, h_hi, 0.0)[:, None])
        sg = sign_label(at * de_s * 2.0 - d2_de_v).astype(np.int64)
        agreed = np.where(~held[:, None], agreed, np.where((agreed == 2) | (agreed == sg), sg, 0))
    signs[live] = np.where(np.abs(agreed) == 1, agreed, 0)
    return signs, none


def _column(x: Interval) -> Interval:
    return Interval(x.lo[:, None], x.hi[:, None])
