"""``aspect_connected`` claims: a cover of the paving domain proving that one sign's part of W is connected.

For s = +1 (WA1) or -1 (WA2) let S = {X in W : s det A(X) > 0}.  The claim lists
boxes by integer octree coordinates (level L, i, j, k) of a domain D (hex floats),
each with a code: ``-1`` OUT (no point of S in the box), ``-2`` SINK (the box lies
in S), d >= 0: RET along the direction ``directions[d]`` = (a, b, c), i.e.
e = (a, b, c / phi_divisor), or -3 - c: OUT by the combination ``combinations[c]``
= (w_1, ..., w_7), integers >= 0 (optional field; none when absent).  The checker
re-proves, from the geometry alone:

1. D holds W: [x] and [y] contain A1 -+ rho_max_1 (exact rationals), and the phi
   range is 2 pi plus at most one finest slice, so that phi = phi_hi is phi_lo + 2 pi
   up to a point of the first slice (arb);
2. the boxes tile D: no duplicate, no box inside another, volumes summing to D's;
3. each box's code, in arb, on sub-boxes covering it (bisected while undecided):
   OUT: some leg certified beyond a limit, or s det A certified < 0; OUT by a
   combination: sum_j w_j f_j certified < 0 (then at each point some f_j < 0); SINK: every leg
   certified within its limits and s det A > 0; RET: each of the seven constraints
   (rho_i^2 - rho_min_i^2 >= 0, rho_max_i^2 - rho_i^2 >= 0, s det A > 0) certified
   satisfied or certified nondecreasing along e (values and D_e enclosed by the
   natural form intersected with the Taylor forms of :mod:`~intervalkin.checker.taylor`);
4. there is at least one SINK box; their face-connected groups (phi wraps) are counted;
5. in list order, every box across an exit face of a RET box (a face whose outward
   normal has a positive component along e) is OUT, a SINK or an earlier RET box,
   and no exit face lies on the x or y border of D;
6. the pieces: components of the union of the closed boxes that are not OUT (boxes
   meeting at a face, an edge or a corner; phi wraps), counted when they hold a sink.
   For this the phi range must exceed 2 pi by strictly less than its first and last
   finest slices, and the float cuts of the finest slices must increase strictly
   (boxes apart in integer coordinates are apart as real boxes).

Then S is nonempty with at most as many components as there are face-connected
groups of sinks, and connected when there is one group; it has at least as many
components as there are pieces holding a sink (proofs/lemma-aspect-retraction.md); a
cover made of OUT boxes only proves S empty.  Standard library and python-flint only.
"""

from __future__ import annotations

import math
from fractions import Fraction

from typing import Callable

from flint import arb

from intervalkin.checker.aspect_tiling import across, check_tiling, separate_pieces, sink_groups
from intervalkin.checker.labels import holds_on_box
from intervalkin.checker.model import ArbModel, balls, leg_sq
from intervalkin.checker.parse import Refused, get, read_aspect, read_hex_box, read_int
from intervalkin.checker.taylor import centred_enclosure, natural_slope, slope_enclosure, value_enclosure

__all__ = ["MAX_LEVEL", "retracts", "combination_negative", "check_aspect_connected"]

#: Deepest octree level a cover may use.
MAX_LEVEL = 20
#: Largest weight of a combination.
MAX_WEIGHT = 1 << 40
_OUT, _SINK = -1, -2


def _is_out(code: int) -> bool:
    """OUT (-1) or OUT by a combination (-3 - c)."""
    return code == _OUT or code <= -3


def _signed(v, sign: int) -> bool:
    """PROVED: sign * v > 0 on the whole ball."""
    return bool(v > 0) if sign > 0 else bool(v < 0)


def _has_sign(f: Callable, box: list, sign: int, natural=None) -> bool:
    """PROVED: sign * f > 0 on the box: natural form, then first-order, then second-order Taylor form."""
    for form in (None, centred_enclosure, value_enclosure):
        v = (f(*box) if natural is None else natural) if form is None else form(f, box)
        if _signed(v, sign):
            return True
    return False


def _beyond_or_opposite(model: ArbModel, b, sign: int) -> bool:
    """PROVED on the box: some leg beyond a limit, or sign * det A < 0."""
    box = balls(b)
    r = model.rho_sq(*box)
    if model.beyond_limits(r) or _has_sign(model.det, box, -sign):
        return True
    for i in range(3):
        leg, lo2, hi2 = leg_sq(model, i), model.rmin2[i], model.rmax2[i]
        if _has_sign(lambda *x: leg(*x) - hi2, box, 1, r[i] - hi2) or \
                _has_sign(lambda *x: lo2 - leg(*x), box, 1, lo2 - r[i]):
            return True
    return False


def _in_aspect(model: ArbModel, b, sign: int) -> bool:
    """PROVED on the box: every leg within its limits and sign * det A > 0."""
    box = balls(b)
    if not _has_sign(model.det, box, sign):
        return False
    r = model.rho_sq(*box)
    for i in range(3):
        low, high = bool(r[i] >= model.rmin2[i]), bool(r[i] <= model.rmax2[i])
        if low and high:
            continue
        t = value_enclosure(leg_sq(model, i), box)
        if not ((low or t >= model.rmin2[i]) and (high or t <= model.rmax2[i])):
            return False
    return True


def _slope_keeps(f: Callable, box: list, e, low: bool, high: bool) -> tuple[bool, bool]:
    """(low or D_e f >= 0 on the box, high or D_e f <= 0 on it), PROVED: the natural slope first (it settles
    about 19 in 20 of the legs' slopes and 2 in 5 of det A's on the paper's covers), the mean-value form where
    it does not (the natural form contains it, so the verdict is the one of the mean-value form alone)."""
    for form in (natural_slope, slope_enclosure):
        slope = form(f, box, e)
        low, high = low or bool(slope >= 0), high or bool(slope <= 0)
        if low and high:
            break
    return low, high


def retracts(model: ArbModel, b, sign: int, e) -> bool:
    """PROVED on the box ``b``: each constraint is satisfied on b or nondecreasing along e (balls e).

    Cheapest forms first: the natural value; else the slope along e; else the Taylor value.
    """
    box = balls(b)
    r = model.rho_sq(*box)
    for i in range(3):
        low, high = bool(r[i] >= model.rmin2[i]), bool(r[i] <= model.rmax2[i])
        if low and high:
            continue
        leg = leg_sq(model, i)
        low, high = _slope_keeps(leg, box, e, low, high)
        if low and high:
            continue
        t = value_enclosure(leg, box)
        if not ((low or t >= model.rmin2[i]) and (high or t <= model.rmax2[i])):
            return False
    d = model.det(*box)
    if _signed(d, sign):
        return True
    # s det A nondecreasing along e: D_e det >= 0 for s = +1, <= 0 for s = -1
    if all(_slope_keeps(model.det, box, e, sign < 0, sign > 0)):
        return True
    return _has_sign(model.det, box, sign, d)


def combination_negative(model: ArbModel, b, sign: int, w) -> bool:
    """PROVED on the box ``b``: sum_j w_j f_j < 0 for the seven constraints (w: 7 integers >= 0, not all 0).

    f_i = rho_i^2 - rho_min_i^2, f_{3+i} = rho_max_i^2 - rho_i^2 (i = 1, 2, 3), f_7 = sign det A.
    At each point of the box some f_j with w_j > 0 is then negative: the point is not in S.
    Natural form, then the first- and second-order Taylor forms.
    """
    legs = [leg_sq(model, i) for i in range(3)]
    wa = [arb(v) for v in w]
    rest = sum(wa[3 + i] * model.rmax2[i] - wa[i] * model.rmin2[i] for i in range(3))

    def f(x, y, phi):
        total = rest
        for i in range(3):
            if w[i] or w[3 + i]:
                total = total + (wa[i] - wa[3 + i]) * legs[i](x, y, phi)
        if w[6]:
            total = total + wa[6] * sign * model.det(x, y, phi)
        return total

    return _has_sign(f, balls(b), -1)


def _cut(lo: float, hi: float, level: int, i: int) -> float:
    """The float bound of slice i at ``level``: the paving's formula (shared faces are bitwise equal)."""
    if i == 1 << level:
        return hi
    return lo + i * math.ldexp(hi - lo, -level)


def _box(domain, key) -> tuple:
    lev = key[0]
    return tuple((_cut(lo, hi, lev, c), _cut(lo, hi, lev, c + 1)) for (lo, hi), c in zip(domain, key[1:]))


def _check_domain(model: ArbModel, domain, deepest: int) -> None:
    g = model.geometry
    (a1x, a1y), r = g.base[0], g.rho_max[0]
    (xl, xh), (yl, yh), (pl, ph) = domain
    if not (Fraction(xl) <= a1x - r and a1x + r <= Fraction(xh) and Fraction(yl) <= a1y - r
            and a1y + r <= Fraction(yh)):
        raise Refused("domain: its x, y ranges do not contain A1 -+ rho_max_1 (W may leave it)")
    excess = arb(ph) - arb(pl) - 2 * arb.pi()
    first, last = arb(_cut(pl, ph, deepest, 1)) - arb(pl), arb(ph) - arb(_cut(pl, ph, deepest, (1 << deepest) - 1))
    if not (excess >= 0 and excess <= first and excess <= last):
        raise Refused("domain: its phi range is not 2 pi plus at most its first and last finest slices")


def _read_rows(claim: dict):
    dirs = get(claim, "directions")
    div = read_int(get(claim, "phi_divisor"), "phi_divisor", 1, 1 << 20)
    if not isinstance(dirs, list):
        raise Refused("directions: expected a list of [a, b, c]")
    e = []
    for n, d in enumerate(dirs):
        if not isinstance(d, list) or len(d) != 3:
            raise Refused(f"directions[{n}]: expected [a, b, c]")
        a, b, c = (read_int(v, f"directions[{n}]", -(1 << 20), 1 << 20) for v in d)
        if (a, b, c) == (0, 0, 0):
            raise Refused(f"directions[{n}]: the zero vector retracts nothing")
        e.append((a, b, c, div))
    combos = claim.get("combinations", [])
    if not isinstance(combos, list):
        raise Refused("combinations: expected a list of [w_1, ..., w_7]")
    w = []
    for n, c in enumerate(combos):
        if not isinstance(c, list) or len(c) != 7:
            raise Refused(f"combinations[{n}]: expected 7 weights")
        ws = tuple(read_int(v, f"combinations[{n}]", 0, MAX_WEIGHT) for v in c)
        if not any(ws):
            raise Refused(f"combinations[{n}]: all weights are 0")
        w.append(ws)
    rows = get(claim, "boxes")
    if not isinstance(rows, list) or not rows:
        raise Refused("boxes: expected a non-empty list of [level, i, j, k, code]")
    out = []
    for n, row in enumerate(rows):
        if not isinstance(row, list) or len(row) != 5:
            raise Refused(f"boxes[{n}]: expected [level, i, j, k, code]")
        lev = read_int(row[0], f"boxes[{n}] level", 0, MAX_LEVEL)
        key = (lev,) + tuple(read_int(v, f"boxes[{n}] index", 0, (1 << lev) - 1) for v in row[1:4])
        out.append((key, read_int(row[4], f"boxes[{n}] code", -3 - (len(w) - 1), len(e) - 1)))
    return e, w, out


def _check_cuts(model: ArbModel, domain, deepest: int) -> None:
    """What the pieces need of the domain: strictly increasing finest cuts, a strict phi excess."""
    for n, (lo, hi) in enumerate(domain):
        step = math.ldexp(hi - lo, -deepest)
        # each cut lo + i * step is within one ulp of 2 M of its real value; a step above 4 such ulps keeps them apart
        if not step > 4 * math.ulp(2 * max(abs(lo), abs(hi), hi - lo)):
            raise Refused(f"domain axis {n}: the finest slices are too thin for their float cuts to increase strictly")
    pl, ph = domain[2]
    excess = arb(ph) - arb(pl) - 2 * arb.pi()
    first, last = arb(_cut(pl, ph, deepest, 1)) - arb(pl), arb(ph) - arb(_cut(pl, ph, deepest, (1 << deepest) - 1))
    if not (excess < first and excess < last):
        raise Refused("domain: for the pieces, the phi range must exceed 2 pi by less than its first and last slices")


def pieces_holding_sinks(keys: set, rows: list) -> int:
    """:func:`~intervalkin.checker.aspect_tiling.separate_pieces` over a claim's rows (key, code)."""
    return separate_pieces(keys, {k for k, c in rows if not _is_out(c)}, [k for k, c in rows if c == _SINK])


def _check_order(keys: set, rows: list, dirs: list, deepest: int) -> None:
    """Every box across an exit face of a retracting box is OUT, a sink or an earlier retracting box."""
    resolved = {key for key, code in rows if code < 0}  # OUT (plain or by a combination) and sinks
    for key, code in rows:
        if code < 0:
            continue
        a, b, c, _ = dirs[code]
        for face, comp in ((0, a), (2, b), (4, c)):
            if comp == 0:
                continue
            nbs = across(keys, key, face + (comp > 0), deepest)
            if nbs is None:
                raise Refused(f"box {list(key)}: an exit face lies on the x or y border of the domain")
            if any(nb not in resolved for nb in nbs):
                raise Refused(f"box {list(key)}: a box across an exit face is neither OUT, a sink nor an earlier "
                              "retracting box")
        resolved.add(key)


def check_aspect_connected(model: ArbModel, claim: dict, prec: int) -> tuple[str, dict]:
    """Re-prove one ``aspect_connected`` claim (module docstring); facts: aspect_sign, components_at_most.

    The combinatorial steps (domain, tiling, sinks, order) come first, the arb proofs box by box last.
    """
    aspect, sign = read_aspect(claim)
    domain = read_hex_box(get(claim, "domain"), "domain")
    dirs, combos, rows = _read_rows(claim)
    deepest = max(k[0] for k, _ in rows)
    keys = {k for k, _ in rows}
    if len(keys) != len(rows):
        raise Refused("boxes: a box is listed twice")
    _check_domain(model, domain, deepest)
    check_tiling(keys, deepest)
    sinks = [k for k, code in rows if code == _SINK]
    empty = all(_is_out(code) for _, code in rows)
    groups = sink_groups(keys, sinks, deepest)
    pieces = 0
    if not empty:
        if not sinks:
            raise Refused("no sink box: the retractions have nowhere to end")
        _check_order(keys, rows, dirs, deepest)
        _check_cuts(model, domain, deepest)
        pieces = pieces_holding_sinks(keys, rows)
    evec = [(arb(a), arb(b), arb(c) / div) for a, b, c, div in dirs]
    for key, code in rows:
        box = _box(domain, key)
        if code == _OUT:
            ok, what = holds_on_box(box, lambda s: _beyond_or_opposite(model, s, sign)), f"free of {aspect}"
        elif code == _SINK:
            ok, what = holds_on_box(box, lambda s: _in_aspect(model, s, sign)), f"inside {aspect}"
        elif code <= -3:
            w = combos[-3 - code]
            ok = holds_on_box(box, lambda s: combination_negative(model, s, sign, w))
            what = f"free of {aspect} by the combination {list(w)}"
        else:
            ok = holds_on_box(box, lambda s: retracts(model, s, sign, evec[code]))
            what = f"retracting along {list(dirs[code][:3])}"
        if not ok:
            raise Refused(f"box {list(key)}: not proved {what}")
    if empty:
        return f"every box of the cover is proved free of {aspect}: {aspect} is empty", \
            {"aspect_sign": sign, "components_at_most": 0, "components_at_least": 0}
    n_ret = sum(1 for _, code in rows if code >= 0)
    if groups == 1:
        what = "nonempty and connected"
    elif pieces == groups:
        what = f"nonempty, with exactly {groups} components (each group of sinks in its own piece)"
    else:
        what = f"nonempty, with at least {pieces} and at most {groups} components"
    return (f"{aspect} is {what}: {len(rows)} boxes tile the domain ({len(sinks)} sinks inside {aspect}, in "
            f"{groups} face-connected group(s); {n_ret} retract along certified monotone directions onto them in "
            f"order; the rest are free of {aspect}; the boxes not free of it make {pieces} separate piece(s) holding "
            f"sinks)"), {"aspect_sign": sign, "components_at_most": groups, "components_at_least": pieces}
