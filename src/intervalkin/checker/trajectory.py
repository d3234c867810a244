"""A ``trajectory`` claim re-proved: a motion between two assembly modes that never meets det A = 0.

The claim lists, for a joint vector q, its complete solution list (which fixes
the solution numbers: increasing phi in [-pi, pi]), the enclosures of the start
and goal solutions, and a chain of straight segments P(t) = A + t (B - A),
t in [0, 1], each given by the enclosures of its end points A, B and a tiling
of [0, 1] into pieces [t0, t1], every number a hex float (exact).

The checker proves (proofs/lemma-trajectory-certificate.md):

1. the solution list as for a complete ``dkp`` claim;
2. the start and goal enclosures each hold exactly one solution (Krawczyk),
   carry det A of the aspect's sign and lie in the listed solutions ``from``
   and ``to``;
3. on every piece, the arb ball A + [t0, t1] (B - A), which holds the piece for
   every A and B in their enclosures, has det A of the aspect's sign and every
   leg within its limits; an undecided piece is bisected in t (breadth first,
   at most :data:`PIECE_BUDGET` evaluations);
4. the pieces tile [0, 1] and consecutive segments share their end enclosure,
   so the motion is continuous; it starts in the start enclosure and ends in
   the goal enclosure shifted by 2 pi ``phi_turns`` (phi is unwrapped along
   the path).

Hence the platform moves from the exact start solution to the exact goal
solution of q keeping one sign of det A and the joint limits: a non-singular
change of assembly mode inside one aspect.
"""

from __future__ import annotations

from collections import deque

from flint import arb

from intervalkin.checker.model import (
    ArbModel,
    balls,
    exact_ball,
    has_sign,
    interval_ball,
)
from intervalkin.checker.parse import (
    Refused,
    get,
    inside,
    read_aspect,
    read_box,
    read_hex,
    read_hex_box,
    read_int,
    read_rho,
)
from intervalkin.checker.solutions import check_solutions, prove_solution_box

__all__ = ['PIECE_BUDGET', 'check_trajectory']

#: Evaluations allowed per piece of a trajectory segment (the piece's t range is bisected while undecided).
PIECE_BUDGET = 2000


def _piece_verdict(model: ArbModel, a: list, b: list, t0: float, t1: float, sign: int) -> int:
    """1: proved on the piece (det A of sign ``sign``, every leg within its limits); -1: proved false
    on the whole piece; 0: undecided.  The piece {A + t (B - A)} is enclosed by A + [t0, t1] (B - A)
    in arb, A and B the balls of the end enclosures."""
    T = interval_ball(t0, t1)
    P = [a[j] + T * (b[j] - a[j]) for j in range(3)]
    d = model.det(*P)
    r = model.rho_sq(*P)
    if has_sign(d, -sign) or model.beyond_limits(r):
        return -1
    if has_sign(d, sign) and model.in_limits(r):
        return 1
    return 0


def _prove_piece(model: ArbModel, a: list, b: list, t0: float, t1: float, sign: int) -> str:
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


def _numbered_solutions(model: ArbModel, claim: dict, rho, prec: int) -> list:
    """Step 1: the complete solution list of q, proved, listed in increasing phi within [-pi, pi]."""
    sols = get(claim, "solutions")
    if not isinstance(sols, list) or not sols:
        raise Refused("solutions: expected the complete list of solutions of rho")
    check_solutions(model, rho, sols, True, get(claim, "phi0"), prec)
    listed = [read_box(s["box"], f"solution {k} box") for k, s in enumerate(sols)]
    pi = arb.pi()
    for k, b in enumerate(listed):
        if not (arb(b[2][0]) >= -pi and arb(b[2][1]) <= pi):
            raise Refused(f"solution {k}: phi not proved within [-pi, pi]: solution numbers undefined")
        if k and not listed[k - 1][2][1] < b[2][0]:
            raise Refused(f"solutions {k - 1} and {k}: not listed in increasing phi: solution numbers undefined")
    return listed


def _segments(model: ArbModel, claim: dict, sign: int) -> tuple[list, int]:
    """Step 3: the end enclosures (A, B) of every segment, each piece proved; and the number of pieces."""
    segs = get(claim, "segments")
    if not isinstance(segs, list) or not segs:
        raise Refused("segments: expected a non-empty list")
    ends = []
    n_pieces = 0
    for k, s in enumerate(segs):
        A = read_hex_box(get(s, "start"), f"segment {k + 1} start")
        B = read_hex_box(get(s, "end"), f"segment {k + 1} end")
        pieces = get(s, "pieces")
        if not isinstance(pieces, list) or not pieces:
            raise Refused(f"segment {k + 1}: pieces: expected a non-empty list of [t0, t1]")
        ts = []
        for j, p in enumerate(pieces):
            if not isinstance(p, list) or len(p) != 2:
                raise Refused(f"segment {k + 1} piece {j}: expected [t0, t1], got {p!r}")
            ts.append((read_hex(p[0], f"segment {k + 1} piece {j} t0"),
                       read_hex(p[1], f"segment {k + 1} piece {j} t1")))
        if ts[0][0] != 0.0 or ts[-1][1] != 1.0 or any(not t0 < t1 for t0, t1 in ts) \
                or any(ts[j][1] != ts[j + 1][0] for j in range(len(ts) - 1)):
            raise Refused(f"segment {k + 1}: the pieces do not tile [0, 1] (sorted, each t0 < t1, "
                          "consecutive pieces sharing their end point)")
        a, b = balls(A), balls(B)
        for t0, t1 in ts:
            why = _prove_piece(model, a, b, t0, t1, sign)
            if why:
                raise Refused(f"segment {k + 1}, piece [{t0!r}, {t1!r}]: {why}")
        n_pieces += len(ts)
        ends.append((A, B))
    return ends, n_pieces


def check_trajectory(model: ArbModel, claim: dict, prec: int) -> tuple[str, dict]:
    """Re-prove one ``trajectory`` claim; (statement, facts) or :class:`Refused`."""
    g = model.geometry
    rho = read_rho(claim)
    aspect, sign = read_aspect(claim)
    if get(claim, "det_sign") != sign:
        raise Refused(f"det_sign {claim.get('det_sign')!r} is not the sign of {aspect}")
    # 1. the solutions of rho and their numbers (increasing phi in [-pi, pi], as intervalkin dkp)
    listed = _numbered_solutions(model, claim, rho, prec)
    n = len(listed)
    i_from = read_int(get(claim, "from"), "from", 1, n)
    i_to = read_int(get(claim, "to"), "to", 1, n)
    if i_from == i_to:
        raise Refused("from and to name the same solution")
    start = read_box(get(claim, "start_box"), "start_box")
    goal = read_box(get(claim, "goal_box"), "goal_box")
    # 2. the end solutions: one solution each (Krawczyk), det A of the aspect's sign, inside solutions from / to
    rho_sq = [exact_ball(r * r) for r in rho]
    for name, b in (("start_box", start), ("goal_box", goal)):
        prove_solution_box(model, b, rho_sq, sign, name, f" (the sign of {aspect})")
    if not inside(start, listed[i_from - 1]):
        raise Refused(f"start_box is not inside the box of solution {i_from}")
    if not inside(goal, listed[i_to - 1]):
        raise Refused(f"goal_box is not inside the box of solution {i_to}")
    # 3. the segments, each piece proved
    ends, n_pieces = _segments(model, claim, sign)
    # 4. continuity: consecutive segments share their end points; the waypoints lie in them
    for k in range(len(ends) - 1):
        if ends[k][1] != ends[k + 1][0]:
            raise Refused(f"segments {k + 1} and {k + 2} do not share their end point: the path is not continuous")
    wps = get(claim, "waypoints")
    if not isinstance(wps, list) or len(wps) != len(ends) + 1:
        raise Refused(f"waypoints: expected {len(ends) + 1} points (one more than the segments)")
    for k, w in enumerate(wps):
        if not isinstance(w, list) or len(w) != 3:
            raise Refused(f"waypoint {k}: expected [x, y, phi] as hex floats, got {w!r}")
        pt = tuple((v, v) for v in (read_hex(c, f"waypoint {k}") for c in w))
        if not inside(pt, ends[k][0] if k < len(ends) else ends[-1][1]):
            raise Refused(f"waypoint {k} is not in the enclosure of the segment end point it names")
    # the path starts at the start solution and ends at the goal solution (phi + 2 pi phi_turns)
    if not inside(start, ends[0][0]):
        raise Refused("start_box is not inside the start enclosure of segment 1")
    turns = read_int(get(claim, "phi_turns"), "phi_turns", -1000, 1000)
    shift = 2 * turns * arb.pi()
    (elo, ehi) = ends[-1][1][2]
    if not (inside(goal[:2], ends[-1][1][:2]) and arb(goal[2][0]) + shift >= arb(elo)
            and arb(goal[2][1]) + shift <= arb(ehi)):
        raise Refused(f"goal_box (phi + 2 pi * {turns}) is not inside the end enclosure of the last segment")
    q = ", ".join(str(r) for r in rho)
    lims = ", ".join(f"{lo} <= rho_{i + 1} <= {hi}" for i, (lo, hi) in enumerate(zip(g.rho_min, g.rho_max)))
    return (f"q = ({q}): the path of {len(ends)} straight segments ({n_pieces} pieces) from solution {i_from} "
            f"to solution {i_to} keeps det A {'> 0' if sign > 0 else '< 0'} and {lims} on every piece, "
            f"continuous from the exact start to the exact goal: a non-singular motion in {aspect}"), {}
