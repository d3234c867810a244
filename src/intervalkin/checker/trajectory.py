"""The independent checker of intervalkin certificate files (``intervalkin verify DIR``).

A certificate folder (written by :func:`intervalkin.certify.writer.write_certificates`;
schema in that module) states claims with their evidence.  This module re-proves
every claim from the files alone, in arb ball arithmetic (python-flint), and
prints one line per claim.  Its trusted base is small on purpose:

* the Python standard library and python-flint (arb, acb, arb_poly, acb_poly,
  arb_mat; ``acb_poly.roots`` for certified complex root isolation);
* :mod:`intervalkin.core.geometry` (reads the geometry TOML stored in the files as
  exact decimals; constants as exact rationals and surds) and
  :mod:`intervalkin.core.errors`;
* the few formulas written out below (rho_i^2, det A, F, F', the reduced
  sextic), re-derived here on purpose instead of imported from
  :mod:`intervalkin.kinematics` or :mod:`intervalkin.solve.dkp`.

It never imports the paving, predicate, joint, region, dkp or analysis code
(``tests/test_certificates.py::test_checker_imports_none_of_the_checked_modules``).
What each claim type proves, and what it still trusts, is in
``proofs/lemma-checker.md``.

Re-proved per claim type
------------------------
``dkp`` / ``joint_cell``
    Each solution box holds exactly one solution of the ORIGINAL system
    F_i = |B_i - A_i|^2 - rho_i^2 (Krawczyk, the checker's own preconditioner,
    strict interior inclusion); det A has the declared sign on the whole box;
    the boxes are pairwise disjoint with phi read modulo 2 pi; and, for a claim
    of completeness, the checker rebuilds the reduced sextic in t = tan((phi -
    phi0)/2) by its own real-polynomial derivation, proves its leading
    coefficient non-zero, isolates its roots (``acb_poly.roots``), counts the
    real ones, proves the 2x2 system regular at each, and requires that count
    to equal the number of boxes.  A ``joint_cell`` claim also checks that the
    witness lies in the joint limits and that its count and aspect split are
    the ones declared.
``aspect_distinct``
    Each box lies in W (rho_min_i^2 <= rho_i^2 <= rho_max_i^2 on the whole box)
    and det A has the declared sign on the whole box (box subdivided in arb
    when the natural enclosure is too wide); the two signs are opposite.
``region_distinct``
    The joint vector's listed solutions are re-proved (Krawczyk, one aspect,
    pairwise disjoint), each solution box lies in its stated paving box, and
    that paving box's W and det-sign labels are re-proved in arb.  The
    "off S_c" label and the box-to-piece map are NOT re-checked (they need the
    joint-space enclosure of g(S)); the claim text says so.
``box_labels``
    Every INSIDE / OUTSIDE label of the sampled boxes (W and det_positive) is
    re-proved in arb over the whole box, subdividing when needed; BOUNDARY
    labels claim nothing.  The sample indices are re-derived from the seed.
``trajectory``
    The joint vector's complete solution list is re-proved as for ``dkp`` (it
    fixes the solution numbers: increasing phi in [-pi, pi]); the start and
    goal enclosures each hold exactly one solution (Krawczyk), lie in the
    listed solutions ``from`` and ``to``, and carry det A of the stated sign.
    For every piece [t0, t1] of every straight segment A + t (B - A) (A, B
    the segment's end enclosures), the ball A + [t0, t1] (B - A) is formed in
    arb and det A is proved of the aspect's sign and rho_min_i^2 <= rho_i^2 <=
    rho_max_i^2 proved on it (the t range bisected while undecided, within
    :data:`PIECE_BUDGET`); the pieces tile [0, 1]; consecutive segments share
    their end enclosure; the start enclosure lies in the first segment's
    start, and the goal enclosure shifted by 2 pi phi_turns (phi unwrapped)
    in the last segment's end.
``counts``
    Each declared lower bound is recomputed from the referenced claims that
    verified (rules in :func:`_count_bound`); a declared lower bound larger than
    the recomputed one, or a count declared exact, is refused.
"""

from __future__ import annotations

from collections import deque

from intervalkin.checker.model import _SIGN, _ball, _balls, _inside, _Model, _rho
from intervalkin.checker.parse import (
    PIECE_BUDGET,
    _box,
    _get,
    _hex,
    _hex_box,
    _int,
    _q,
    _Refused,
)
from intervalkin.checker.solutions import _check_solve, _krawczyk


def _piece_verdict(model: _Model, a: list, b: list, t0: float, t1: float, sign: int) -> int:
    """1: proved on the piece (det A of sign ``sign``, every leg within its limits); -1: proved false
    on the whole piece; 0: undecided.  The piece {A + t (B - A)} is enclosed by A + [t0, t1] (B - A)
    in arb, A and B the balls of the end enclosures."""
    T = _ball(t0, t1)
    P = [a[j] + T * (b[j] - a[j]) for j in range(3)]
    d = model.det(*P)
    r = model.rho_sq(*P)
    if (d < 0 if sign > 0 else d > 0) or any(r[i] < model.rmin2[i] or r[i] > model.rmax2[i] for i in range(3)):
        return -1
    if (d > 0 if sign > 0 else d < 0) and all(r[i] >= model.rmin2[i] and r[i] <= model.rmax2[i] for i in range(3)):
        return 1
    return 0


def _prove_piece(model: _Model, a: list, b: list, t0: float, t1: float, sign: int) -> str:
    """"" when the piece [t0, t1] is proved (bisected in t while undecided), else why not.

    Sub-pieces are taken breadth first, so that a stretch proved wrong is found
    (and named) before the bisection closes in on a crossing of a boundary.
    """
    stack = deque([(t0, t1)])
    evals = 0
    while stack:
        lo, hi = stack.popleft()
        evals += 1
        if evals > PIECE_BUDGET:
            return f"not proved within {PIECE_BUDGET} sub-pieces (undecided near t = {lo!r})"
        v = _piece_verdict(model, a, b, lo, hi, sign)
        if v > 0:
            continue
        if v < 0:
            return (f"on t in [{lo!r}, {hi!r}] det A is proved of the wrong sign or a leg proved "
                    "beyond its limit")
        mid = lo + (hi - lo) / 2
        if not lo < mid < hi:
            return f"undecided at t = {lo!r} (cannot bisect further)"
        stack += [(lo, mid), (mid, hi)]
    return ""


def _check_trajectory(model: _Model, claim: dict, prec: int) -> tuple[str, dict]:
    from flint import arb

    g = model.geometry
    rho = _rho(claim)
    aspect = _get(claim, "aspect")
    if aspect not in _SIGN:
        raise _Refused(f"aspect must be WA1 or WA2, got {aspect!r}")
    sign = _SIGN[aspect]
    if _get(claim, "det_sign") != sign:
        raise _Refused(f"det_sign {claim.get('det_sign')!r} is not the sign of {aspect}")
    # 1. the solutions of rho and their numbers (increasing phi in [-pi, pi], as intervalkin dkp)
    sols = _get(claim, "solutions")
    if not isinstance(sols, list) or not sols:
        raise _Refused("solutions: expected the complete list of solutions of rho")
    _check_solve(model, rho, sols, True, _get(claim, "phi0"), prec)
    listed = [_box(s["box"], f"solution {k} box") for k, s in enumerate(sols)]
    pi = arb.pi()
    for k, b in enumerate(listed):
        if not (arb(b[2][0]) >= -pi and arb(b[2][1]) <= pi):
            raise _Refused(f"solution {k}: phi not proved within [-pi, pi]: solution numbers undefined")
        if k and not listed[k - 1][2][1] < b[2][0]:
            raise _Refused(f"solutions {k - 1} and {k}: not listed in increasing phi: solution numbers undefined")
    n = len(listed)
    i_from = _int(_get(claim, "from"), "from", 1, n)
    i_to = _int(_get(claim, "to"), "to", 1, n)
    if i_from == i_to:
        raise _Refused("from and to name the same solution")
    start = _box(_get(claim, "start_box"), "start_box")
    goal = _box(_get(claim, "goal_box"), "goal_box")
    # the end solutions: one solution each (Krawczyk), det A of the aspect's sign, inside solutions from / to
    rho_sq = [_q(r * r) for r in rho]
    for name, b in (("start_box", start), ("goal_box", goal)):
        if not b[2][1] - b[2][0] < 1.0:
            raise _Refused(f"{name}: phi width {b[2][1] - b[2][0]!r} is not < 1 rad")
        if not _krawczyk(model, b, rho_sq):
            raise _Refused(f"{name}: the Krawczyk test does not prove a unique solution of q in the box")
        d = model.det(*_balls(b))
        if not (d > 0 if sign > 0 else d < 0):
            raise _Refused(f"{name}: det A is not proved {'> 0' if sign > 0 else '< 0'} (the sign of {aspect}) "
                           f"on the box ({d.str(5)})")
    if not _inside(start, listed[i_from - 1]):
        raise _Refused(f"start_box is not inside the box of solution {i_from}")
    if not _inside(goal, listed[i_to - 1]):
        raise _Refused(f"goal_box is not inside the box of solution {i_to}")
    # 2. the segments: pieces tile [0, 1], each proved; consecutive segments share their end points
    segs = _get(claim, "segments")
    if not isinstance(segs, list) or not segs:
        raise _Refused("segments: expected a non-empty list")
    ends = []
    n_pieces = 0
    for k, s in enumerate(segs):
        A = _hex_box(_get(s, "start"), f"segment {k + 1} start")
        B = _hex_box(_get(s, "end"), f"segment {k + 1} end")
        pieces = _get(s, "pieces")
        if not isinstance(pieces, list) or not pieces:
            raise _Refused(f"segment {k + 1}: pieces: expected a non-empty list of [t0, t1]")
        ts = []
        for j, p in enumerate(pieces):
            if not isinstance(p, list) or len(p) != 2:
                raise _Refused(f"segment {k + 1} piece {j}: expected [t0, t1], got {p!r}")
            ts.append((_hex(p[0], f"segment {k + 1} piece {j} t0"), _hex(p[1], f"segment {k + 1} piece {j} t1")))
        if ts[0][0] != 0.0 or ts[-1][1] != 1.0 or any(not t0 < t1 for t0, t1 in ts) \
                or any(ts[j][1] != ts[j + 1][0] for j in range(len(ts) - 1)):
            raise _Refused(f"segment {k + 1}: the pieces do not tile [0, 1] (sorted, each t0 < t1, "
                           "consecutive pieces sharing their end point)")
        a, b = _balls(A), _balls(B)
        for t0, t1 in ts:
            why = _prove_piece(model, a, b, t0, t1, sign)
            if why:
                raise _Refused(f"segment {k + 1}, piece [{t0!r}, {t1!r}]: {why}")
        n_pieces += len(ts)
        ends.append((A, B))
    for k in range(len(ends) - 1):
        if ends[k][1] != ends[k + 1][0]:
            raise _Refused(f"segments {k + 1} and {k + 2} do not share their end point: the path is not continuous")
    wps = _get(claim, "waypoints")
    if not isinstance(wps, list) or len(wps) != len(ends) + 1:
        raise _Refused(f"waypoints: expected {len(ends) + 1} points (one more than the segments)")
    for k, w in enumerate(wps):
        if not isinstance(w, list) or len(w) != 3:
            raise _Refused(f"waypoint {k}: expected [x, y, phi] as hex floats, got {w!r}")
        pt = tuple((v, v) for v in (_hex(c, f"waypoint {k}") for c in w))
        if not _inside(pt, ends[k][0] if k < len(ends) else ends[-1][1]):
            raise _Refused(f"waypoint {k} is not in the enclosure of the segment end point it names")
    # 3. the path starts at the start solution and ends at the goal solution (phi + 2 pi phi_turns)
    if not _inside(start, ends[0][0]):
        raise _Refused("start_box is not inside the start enclosure of segment 1")
    turns = _int(_get(claim, "phi_turns"), "phi_turns", -1000, 1000)
    shift = 2 * turns * pi
    (elo, ehi) = ends[-1][1][2]
    if not (_inside(goal[:2], ends[-1][1][:2]) and arb(goal[2][0]) + shift >= arb(elo)
            and arb(goal[2][1]) + shift <= arb(ehi)):
        raise _Refused(f"goal_box (phi + 2 pi * {turns}) is not inside the end enclosure of the last segment")
    q = ", ".join(str(r) for r in rho)
    lims = ", ".join(f"{lo} <= rho_{i + 1} <= {hi}" for i, (lo, hi) in enumerate(zip(g.rho_min, g.rho_max)))
    return (f"q = ({q}): the path of {len(segs)} straight segments ({n_pieces} pieces) from solution {i_from} "
            f"to solution {i_to} keeps det A {'> 0' if sign > 0 else '< 0'} and {lims} on every piece, "
            f"continuous from the exact start to the exact goal: a non-singular motion in {aspect}"), {}
