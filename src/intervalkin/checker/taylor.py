"""Second-order Taylor enclosures over boxes in arb: hyper-dual numbers and the two forms they give.

A hyper-dual number v + a e1 + b e2 + c e1 e2 (e1^2 = e2^2 = 0) carries, through
+, -, * and cos, sin, a value, two directional derivatives and their mixed second
derivative: evaluating f at X + u e1 + w e2 gives a = D_u f(X), b = D_w f(X),
c = D_w D_u f(X).  With ball arguments every part encloses its exact value at
every point of the balls (python-flint's guarantee, applied operation by
operation).

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

__all__ = ["HyperDual", "centred_enclosure", "value_enclosure", "slope_enclosure"]


class HyperDual:
    """v + a e1 + b e2 + c e1 e2 over arb balls (e1^2 = e2^2 = 0)."""

    __slots__ = ("v", "a", "b", "c")

    def __init__(self, v, a, b, c):
        self.v, self.a, self.b, self.c = v, a, b, c

    def __add__(self, o):
        if isinstance(o, HyperDual):
            return HyperDual(self.v + o.v, self.a + o.a, self.b + o.b, self.c + o.c)
        return HyperDual(self.v + o, self.a, self.b, self.c)

    __radd__ = __add__

    def __neg__(self):
        return HyperDual(-self.v, -self.a, -self.b, -self.c)

    def __sub__(self, o):
        return self + (-o)

    def __rsub__(self, o):
        return (-self) + o

    def __mul__(self, o):
        if isinstance(o, HyperDual):
            return HyperDual(self.v * o.v, self.v * o.a + self.a * o.v, self.v * o.b + self.b * o.v,
                             self.v * o.c + self.a * o.b + self.b * o.a + self.c * o.v)
        return HyperDual(self.v * o, self.a * o, self.b * o, self.c * o)

    __rmul__ = __mul__

    def cos(self):
        c, s = self.v.cos(), self.v.sin()
        return HyperDual(c, -s * self.a, -s * self.b, -s * self.c - c * self.a * self.b)

    def sin(self):
        c, s = self.v.cos(), self.v.sin()
        return HyperDual(s, c * self.a, c * self.b, c * self.c - s * self.a * self.b)


_ZERO, _ONE = arb(0), arb(1)
_UNIT = ((_ONE, _ZERO, _ZERO), (_ZERO, _ONE, _ZERO), (_ZERO, _ZERO, _ONE))
_PAIRS = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))


def _at(point, u, w) -> list:
    return [HyperDual(p, a, b, _ZERO) for p, a, b in zip(point, u, w)]


def _square(d):
    """d^2 over the ball d, kept >= 0 (d * d would allow negative values when d straddles 0)."""
    u = d.abs_upper()
    return arb.union(_ZERO, u * u)


def centred_enclosure(f: Callable, box: list):
    """f over the box (three balls): natural form intersected with the mean-value form
    f(m) + sum_k f_k(B) d_k (partial derivatives over the box, one unit direction at a time)."""
    mid = [v.mid() for v in box]
    d = [v - m for v, m in zip(box, mid)]
    h1 = f(*_at(box, _UNIT[0], _UNIT[1]))
    h2 = f(*_at(box, _UNIT[2], _UNIT[2]))
    return h1.v.intersection(f(*mid) + h1.a * d[0] + h1.b * d[1] + h2.a * d[2])


def value_enclosure(f: Callable, box: list):
    """f over the box (three balls): natural form intersected with the second-order Taylor form.

    f(m) + sum_k f_k(m) d_k + 1/2 sum_jk f_jk(B) d_j d_k, the partial derivatives taken
    one direction pair at a time (unit directions: no dependency between the offsets).
    """
    mid = [v.mid() for v in box]
    d = [v - m for v, m in zip(box, mid)]
    c1 = f(*_at(mid, _UNIT[0], _UNIT[1]))
    c2 = f(*_at(mid, _UNIT[2], _UNIT[2]))
    first = c1.a * d[0] + c1.b * d[1] + c2.a * d[2]
    second = _ZERO
    natural = None
    for j, k in _PAIRS:
        h = f(*_at(box, _UNIT[j], _UNIT[k]))
        natural = h.v
        second += h.c * (_square(d[j]) if j == k else 2 * d[j] * d[k])
    return natural.intersection(c1.v + first + second / 2)


def slope_enclosure(f: Callable, box: list, e: list):
    """D_e f over the box (three balls; e three exact balls): natural form intersected with the mean-value form

    D_e f(m) + sum_k D_k D_e f(B) d_k.
    """
    mid = [v.mid() for v in box]
    d = [v - m for v, m in zip(box, mid)]
    centre = f(*_at(mid, e, _UNIT[0]))
    out = centre.a
    natural = None
    for k in range(3):
        h = f(*_at(box, e, _UNIT[k]))
        natural = h.a
        out += h.c * d[k]
    return natural.intersection(out)
