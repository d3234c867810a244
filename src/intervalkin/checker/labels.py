"""Box labels re-proved in arb: W (the joint limits) and the sign of det A on a whole box.

A paving box of the library carries tri-state labels, 1 OUTSIDE, 2 INSIDE,
3 BOUNDARY.  For the two labels a certificate may state,

* ``W`` INSIDE: rho_min_i^2 <= rho_i^2 <= rho_max_i^2 for every leg at every pose
  of the box; OUTSIDE: some leg is beyond a limit at every pose of the box;
* ``det_positive`` INSIDE: det A > 0 on the whole box; OUTSIDE: det A < 0 on it,

the checker evaluates the formulas of :class:`~intervalkin.checker.model.ArbModel`
over the box.  When the enclosure is too wide to decide, the box is bisected and
the label must hold on every sub-box (the sub-boxes cover the box, so the label
holds on their union); past :data:`LABEL_BUDGET` evaluations the label counts as
not proved.  BOUNDARY claims nothing and is not checked.
"""

from __future__ import annotations

from typing import Callable

from flint import ctx

from intervalkin.checker.model import ArbModel, balls
from intervalkin.checker.parse import Refused, read_box
from intervalkin.core.geometry import Geometry

__all__ = ['LABEL_BUDGET', 'holds_on_box', 'prove_label', 'box_label_proved']

#: Sub-box evaluations allowed per re-proved box label (the box is bisected while undecided).
LABEL_BUDGET = 20000


def holds_on_box(box, test: Callable, budget: int = LABEL_BUDGET) -> bool:
    """True when ``test`` (True = certain) holds on sub-boxes that cover ``box``.

    Bisects the widest side (phi weighted by the platform size, since a turn of
    d phi moves B_i by about L_i d phi) until each sub-box is decided or the
    budget of evaluations is spent (then False: not proved).
    """
    stack = [tuple(box)]
    evals = 0
    while stack:
        b = stack.pop()
        evals += 1
        if evals > budget:
            return False
        if test(b):
            continue
        widths = [b[0][1] - b[0][0], b[1][1] - b[1][0], 20.0 * (b[2][1] - b[2][0])]
        k = max(range(3), key=lambda j: widths[j])
        lo, hi = b[k]
        mid = lo + (hi - lo) / 2
        if not lo < mid < hi:
            return False
        left, right = list(b), list(b)
        left[k], right[k] = (lo, mid), (mid, hi)
        stack += [tuple(left), tuple(right)]
    return True


def in_w(model: ArbModel, b) -> bool:
    """PROVED on the box ``b``: every leg within its limits."""
    return model.in_limits(model.rho_sq(*balls(b)))


def _out_w(model: ArbModel, b) -> bool:
    return model.beyond_limits(model.rho_sq(*balls(b)))


def det_positive(model: ArbModel, b) -> bool:
    """PROVED on the box ``b``: det A > 0."""
    return bool(model.det(*balls(b)) > 0)


def det_negative(model: ArbModel, b) -> bool:
    """PROVED on the box ``b``: det A < 0."""
    return bool(model.det(*balls(b)) < 0)


_TESTS = {
    ("W", 2): in_w,
    ("W", 1): _out_w,
    ("det_positive", 2): det_positive,
    ("det_positive", 1): det_negative,
}


def prove_label(model: ArbModel, box, name: str, value: int) -> bool | None:
    """Re-prove one label (1 OUTSIDE, 2 INSIDE) of W or det_positive; None when it claims nothing."""
    if value == 3:
        return None
    if (name, value) not in _TESTS:
        raise Refused(f"label {name} = {value!r}: not a label this checker knows (W, det_positive: 1, 2 or 3)")
    fn = _TESTS[(name, value)]
    return holds_on_box(box, lambda b: fn(model, b))


def box_label_proved(geometry: Geometry, box, name: str, value: int, precision: int = 128) -> bool | None:
    """Whether the checker re-proves label ``name`` = ``value`` (W or det_positive) on ``box`` (3, 2).

    None for BOUNDARY (3), which claims nothing.
    """
    b = read_box([[float(lo), float(hi)] for lo, hi in box])
    with ctx.workprec(precision):
        return prove_label(ArbModel(geometry), b, name, value)
