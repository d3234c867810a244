"""Second-order Taylor enclosures over boxes in arb: jets of derivatives and the forms they give.

A jet carries, through +, -, * and cos, sin, a value f, the first derivatives
D_i f along n seed directions u_1 ... u_n, and the mixed second derivatives
D_j D_i f for a chosen list of pairs (i, j): evaluating f at X + sum_i u_i e_i
(e_i e_j = 0 unless (i, j) is a listed pair, e_i^2 = 0 unless (i, i) is) gives
them all in one pass.  With ball arguments every part encloses its exact value at
every point of the balls (python-flint's guarantee, applied operation by
operation).  Each part follows the product and chain rules term by term, in the
same order whichever other parts the jet carries, so one jet with six pairs gives
the same balls, bit for bit, as six jets of one pair each (one evaluation of f
instead of six: the checker's cover re-proof spends most of its time here).

For a box B with centre m and offsets d = X - m (balls), Taylor's theorem with
Lagrange remainder gives, for every X in B, some xi in B with

    f(X) = f(m) + D_d f(m) + 1/2 D_d D_d f(xi)          (:func:`value_enclosure`)
    D_e f(X) = D_e f(m) + D_d D_e f(xi)                  (:func:`slope_enclosure`)

so f(m) + D_d f(m) + [D_d D_d f(B)] / 2 encloses f over B: the first-order term is
a linear form of the offsets with point coefficients (no dependency loss), and the
loss sits in the second-order term only.  Each form is intersected with the
natural enclosure (the value part of the evaluation over B).  Standard library and
python-flint only.
"""

from __future__ import annotations

from typing import Callable

from flint import arb

__all__ = ["Jet", "seeded", "centred_enclosure", "value_enclosure", "natural_slope", "slope_enclosure"]


class Jet:
    """f, D_i f along n seeds and D_j D_i f for the pairs (i, j) of ``pairs``, over arb balls.

    ``d`` holds the n first derivatives, ``dd`` the second ones in the order of ``pairs``.
    """

    __slots__ = ("v", "d", "dd", "pairs")

    def __init__(self, v, d: list, dd: list, pairs: tuple):
        self.v, self.d, self.dd, self.pairs = v, d, dd, pairs

    def __add__(self, o):
        if isinstance(o, Jet):
            return Jet(self.v + o.v, [a + b for a, b in zip(self.d, o.d)], [a + b for a, b in zip(self.dd, o.dd)],
                       self.pairs)
        return Jet(self.v + o, self.d, self.dd, self.pairs)

    __radd__ = __add__

    def __neg__(self):
        return Jet(-self.v, [-a for a in self.d], [-c for c in self.dd], self.pairs)

    def __sub__(self, o):
        if isinstance(o, Jet):
            return Jet(self.v - o.v, [a - b for a, b in zip(self.d, o.d)], [a - b for a, b in zip(self.dd, o.dd)],
                       self.pairs)
        return Jet(self.v - o, self.d, self.dd, self.pairs)

    def __rsub__(self, o):
        return Jet(o - self.v, [-a for a in self.d], [-c for c in self.dd], self.pairs)

    def __mul__(self, o):
        if isinstance(o, Jet):
            v, d, ov, od = self.v, self.d, o.v, o.d
            # (fg)_ij = f g_ij + f_i g_j + f_j g_i + f_ij g
            return Jet(v * ov, [v * b + a * ov for a, b in zip(d, od)],
                       [v * oc + d[i] * od[j] + d[j] * od[i] + c * ov
                        for (i, j), c, oc in zip(self.pairs, self.dd, o.dd)], self.pairs)
        return Jet(self.v * o, [a * o for a in self.d], [c * o for c in self.dd], self.pairs)

    __rmul__ = __mul__

    def cos(self):
        c, s, d = self.v.cos(), self.v.sin(), self.d
        return Jet(c, [-s * a for a in d], [-s * cc - c * d[i] * d[j] for (i, j), cc in zip(self.pairs, self.dd)],
                   self.pairs)

    def sin(self):
        c, s, d = self.v.cos(), self.v.sin(), self.d
        return Jet(s, [c * a for a in d], [c * cc - s * d[i] * d[j] for (i, j), cc in zip(self.pairs, self.dd)],
                   self.pairs)


def seeded(point: list, seeds, pairs: tuple = ()) -> list:
    """The three arguments (x, y, phi) as jets: ``point`` (balls) moved along the seed directions (each three
    exact balls); second derivatives for ``pairs`` of seed indices, starting at 0."""
    zeros = [_ZERO] * len(pairs)
    return [Jet(p, [u[k] for u in seeds], zeros, pairs) for k, p in enumerate(point)]


_ZERO, _ONE = arb(0), arb(1)
_UNIT = ((_ONE, _ZERO, _ZERO), (_ZERO, _ONE, _ZERO), (_ZERO, _ZERO, _ONE))
_PAIRS = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))
#: Pairs (e, u_k) of the slope jet, whose seeds are (e, u_1, u_2, u_3).
_SLOPE_PAIRS = ((0, 1), (0, 2), (0, 3))


def _square(d):
    """d^2 over the ball d, kept >= 0 (d * d would allow negative values when d straddles 0)."""
    u = d.abs_upper()
    return arb.union(_ZERO, u * u)


def centred_enclosure(f: Callable, box: list):
    """f over the box (three balls): natural form intersected with the mean-value form
    f(m) + sum_k f_k(B) d_k (the partial derivatives over the box from one jet)."""
    mid = [v.mid() for v in box]
    d = [v - m for v, m in zip(box, mid)]
    h = f(*seeded(box, _UNIT))
    return h.v.intersection(f(*mid) + h.d[0] * d[0] + h.d[1] * d[1] + h.d[2] * d[2])


def value_enclosure(f: Callable, box: list):
    """f over the box (three balls): natural form intersected with the second-order Taylor form.

    f(m) + sum_k f_k(m) d_k + 1/2 sum_jk f_jk(B) d_j d_k, the second derivatives of the six
    pairs of unit directions in one jet (no dependency between the offsets).
    """
    mid = [v.mid() for v in box]
    d = [v - m for v, m in zip(box, mid)]
    c = f(*seeded(mid, _UNIT))
    first = c.d[0] * d[0] + c.d[1] * d[1] + c.d[2] * d[2]
    h = f(*seeded(box, _UNIT, _PAIRS))
    second = _ZERO
    for (j, k), hc in zip(_PAIRS, h.dd):
        second += hc * (_square(d[j]) if j == k else 2 * d[j] * d[k])
    return h.v.intersection(c.v + first + second / 2)


def natural_slope(f: Callable, box: list, e: list):
    """D_e f over the box (three balls; e three exact balls), natural form only: the cheap first try of a
    slope sign (it contains :func:`slope_enclosure`, so a sign it proves, that one proves too)."""
    return f(*seeded(box, (e,))).d[0]


def slope_enclosure(f: Callable, box: list, e: list):
    """D_e f over the box (three balls; e three exact balls): natural form intersected with the mean-value form

    D_e f(m) + sum_k D_k D_e f(B) d_k (seeds e and the unit directions, pairs (e, u_k), in one jet).
    """
    mid = [v.mid() for v in box]
    d = [v - m for v, m in zip(box, mid)]
    out = f(*seeded(mid, (e,))).d[0]
    h = f(*seeded(box, (e,) + _UNIT, _SLOPE_PAIRS))
    for k in range(3):
        out += h.dd[k] * d[k]
    return h.d[0].intersection(out)
