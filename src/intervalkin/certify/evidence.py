"""Library results as claim fields, and the round trip through the checker before a claim is kept.

The fields follow the conventions of the file format (:mod:`intervalkin.certify.writer`):
joint vectors as exact decimal strings (``"14.98"``, or ``"p/q"`` when the
rational has no finite decimal form; :func:`intervalkin.core.exact.exact_text`),
boxes as lists of binary64 bounds.

A solver box is tight around its solution, and the checker re-proves it with its
own preconditioner and arithmetic, which may need a little more room; the
reduced sextic needs a shift phi0 whose leading coefficient f(phi0 + pi) is
proved non-zero.  :func:`certified` therefore tries the claim at the requested
precision and then higher ones, with the boxes padded outward by growing
relative margins, and over the shifts in :data:`PHI0`, and keeps the first form
the checker verifies.  Padding only enlarges boxes that already hold one
solution each; whatever is kept, the checker proved.  A claim that no attempt
verifies is not written; the last reason is reported instead.
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Iterable, Sequence

import numpy as np

from intervalkin.checker import check_claim
from intervalkin.core.exact import exact_text
from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import round_down, round_up

__all__ = ['PHI0', 'PRECISIONS', 'PADS', 'rho_text', 'box_json', 'pad_box', 'labels_of', 'certified']

#: Shifts phi0 tried for the reduced sextic (its leading coefficient f(phi0 + pi) must be non-zero).
PHI0 = (0.0,) + tuple(round(j * math.pi / 6, 6) for j in range(1, 12))
#: Working precisions tried for a solve claim, after the requested one.
PRECISIONS = (128, 256, 512)
#: Relative paddings tried around a solver box when the tight box does not pass the checker's Krawczyk test.
PADS = (0.0, 1e-13, 1e-11)


def rho_text(rho: Sequence[Fraction]) -> str:
    """A joint vector as exact decimals separated by commas, for statements."""
    return ", ".join(exact_text(r) for r in rho)


def box_json(box) -> list[list[float]]:
    """A box (3, 2) as [[xlo, xhi], [ylo, yhi], [philo, phihi]] of Python floats."""
    b = np.asarray(box, dtype=np.float64).reshape(3, 2)
    return [[float(lo), float(hi)] for lo, hi in b]


def pad_box(box: list[list[float]], rel: float) -> list[list[float]]:
    """The box widened on each side by ``rel`` (1 + |bound|), rounded outward; itself when ``rel`` is 0."""
    if rel == 0.0:
        return box
    out = []
    for lo, hi in box:
        d = rel * (1.0 + max(abs(lo), abs(hi)))
        out.append([float(round_down(lo - d)), float(round_up(hi + d))])
    return out


def labels_of(paving, i: int, names: Sequence[str]) -> dict[str, int]:
    """The labels ``names`` (those the paving has) of box ``i``, as ints."""
    return {n: int(paving.labels[n][i]) for n in names if n in paving.labels}


def certified(geometry: Geometry, kind: str, claim: dict, precision: int, pads=PADS,
              phi0s: Iterable[float] = PHI0, box_ok=None) -> tuple[dict | None, str]:
    """The claim with the first (precision, padding, phi0) the checker verifies, or (None, last reason).

    ``claim["solutions"]`` are the boxes to pad; ``phi0`` is varied only when the
    claim has one (a claim of completeness); ``box_ok(solution)`` may reject a
    padding (for example one that leaves a stated paving box).
    """
    why = "no attempt"
    precs = [precision] + [p for p in PRECISIONS if p > precision]
    base = [dict(s) for s in claim["solutions"]]
    phi0s = tuple(phi0s) if "phi0" in claim else (None,)
    for prec in precs:
        for rel in pads:
            sols = [dict(s, box=pad_box(s["box"], rel)) for s in base]
            if box_ok is not None and not all(box_ok(s) for s in sols):
                continue
            for phi0 in phi0s:
                c = dict(claim, precision=prec, solutions=sols)
                if phi0 is not None:
                    c["phi0"] = phi0
                ok, why = check_claim(geometry, kind, c, prec)
                if ok:
                    return c, ""
                if "leading coefficient" not in why:
                    break  # another shift cannot help
    return None, why
