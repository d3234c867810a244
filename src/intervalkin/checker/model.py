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

from fractions import Fraction
from typing import Callable

from intervalkin.checker.parse import LABEL_BUDGET, _get, _q, _Refused, parse_exact
from intervalkin.core.geometry import Geometry


def _sqr(v):
    """v^2 as a ball, without the sign loss of v * v when v straddles 0."""
    from flint import arb

    if v > 0 or v < 0:
        return v * v
    u = v.abs_upper()
    return arb.union(arb(0), u * u)


def _ball(lo: float, hi: float):
    """A ball containing the real interval [lo, hi] (binary64 bounds)."""
    from flint import arb

    return arb.union(arb(lo), arb(hi))


class _Model:
    """Constants of one geometry at the current precision, and the arb formulas.

    Notation (DESIGN.md sections 1-2): B1 = (x, y), r_i = R(phi) p_i,
    u_i = B1 + r_i - A_i, rho_i^2 = |u_i|^2, F_i = rho_i^2 - (given rho_i)^2,
    row i of A = dF/dX = 2 (u_ix, u_iy, r_i x u_i) with a x b = a_x b_y - a_y b_x.
    """

    def __init__(self, geometry: Geometry):
        from flint import arb

        self.geometry = geometry
        self.A = [(_q(ax), _q(ay)) for ax, ay in geometry.base]
        self.p = [tuple(c.arb() for c in geometry.platform_point(i)) for i in range(3)]
        # polar form of p_i (one occurrence of phi per coordinate: tighter over wide boxes)
        self.L = [_q(geometry.platform_radius_sq(i)).sqrt() for i in range(3)]
        self.alpha = [arb(0)] + [arb.atan2(self.p[i][1], self.p[i][0]) for i in (1, 2)]
        self.rmin2 = [_q(v * v) for v in geometry.rho_min]
        self.rmax2 = [_q(v * v) for v in geometry.rho_max]

    # --- r_i in two forms -------------------------------------------------------------
    def rot(self, phi, i: int):
        """r_i = R(phi) p_i from the Cartesian platform coordinates (for points and thin boxes)."""
        c, s = phi.cos(), phi.sin()
        px, py = self.p[i]
        return px * c - py * s, px * s + py * c

    def rot_polar(self, phi, i: int):
        """r_i = L_i (cos(phi + alpha_i), sin(phi + alpha_i)) (for wide boxes)."""
        t = phi + self.alpha[i]
        return self.L[i] * t.cos(), self.L[i] * t.sin()

    # --- formulas -----------------------------------------------------------------------
    def rho_sq(self, x, y, phi) -> list:
        """rho_i^2 = (x + r_ix - A_ix)^2 + (y + r_iy - A_iy)^2, enclosed over balls."""
        out = []
        for i in range(3):
            ax, ay = self.A[i]
            if i == 0:
                out.append(_sqr(x - ax) + _sqr(y - ay))
            else:
                rx, ry = self.rot_polar(phi, i)
                out.append(_sqr(x + rx - ax) + _sqr(y + ry - ay))
        return out

    def det(self, x, y, phi):
        """det A = 8 [u1x (d2y w3 - w2 d3y) - u1y (d2x w3 - w2 d3x)].

        Row 1 of A is 2 (u_1, 0) (r_1 = 0); subtracting it from rows 2 and 3 leaves
        2 (d_i, w_i) with d_i = u_i - u_1 = r_i - A_i + A_1 and
        w_i = r_i x u_i = r_i x (B1 - A_i) (r_i x r_i = 0); expanding along the
        third column gives the formula (degree 2 in x, y: the cubic terms cancel).
        """
        a1x, a1y = self.A[0]
        u1x, u1y = x - a1x, y - a1y
        d, w = [], []
        for i in (1, 2):
            ax, ay = self.A[i]
            rx, ry = self.rot_polar(phi, i)
            d.append((rx - ax + a1x, ry - ay + a1y))
            w.append(rx * (y - ay) - ry * (x - ax))
        (d2x, d2y), (d3x, d3y) = d
        w2, w3 = w
        return 8 * (u1x * (d2y * w3 - w2 * d3y) - u1y * (d2x * w3 - w2 * d3x))

    def residual(self, x, y, phi, rho_sq) -> list:
        """F_i = |B_i - A_i|^2 - rho_i^2 (the original system, paper eq. 1-3)."""
        out = []
        for i in range(3):
            ax, ay = self.A[i]
            rx, ry = (0, 0) if i == 0 else self.rot(phi, i)
            out.append((x + rx - ax) ** 2 + (y + ry - ay) ** 2 - rho_sq[i])
        return out

    def jacobian(self, x, y, phi) -> list[list]:
        """F' = A, rows 2 (u_ix, u_iy, r_i x u_i) (r_1 = 0)."""
        rows = []
        for i in range(3):
            ax, ay = self.A[i]
            if i == 0:
                ux, uy = x - ax, y - ay
                rows.append([2 * ux, 2 * uy, 0 * ux])
            else:
                rx, ry = self.rot(phi, i)
                ux, uy = x + rx - ax, y + ry - ay
                rows.append([2 * ux, 2 * uy, 2 * (rx * uy - ry * ux)])
        return rows

    def D(self, phi):
        """D(phi) = m_2 x m_3, m_i = 2 (r_i - (A_i - A_1)): the determinant of the 2x2 system."""
        a1x, a1y = self.A[0]
        m = []
        for i in (1, 2):
            rx, ry = self.rot(phi, i)
            ax, ay = self.A[i]
            m.append((2 * (rx - (ax - a1x)), 2 * (ry - (ay - a1y))))
        return m[0][0] * m[1][1] - m[0][1] * m[1][0]


# --------------------------------------------------------------------------------------
# Certified answers over boxes (subdivided while undecided)
# --------------------------------------------------------------------------------------
def _holds_on_box(box, test: Callable, budget: int = LABEL_BUDGET) -> bool:
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


def _balls(b):
    return [_ball(lo, hi) for lo, hi in b]


def _in_w(model: _Model, b) -> bool:
    r = model.rho_sq(*_balls(b))
    return all(r[i] >= model.rmin2[i] and r[i] <= model.rmax2[i] for i in range(3))


def _out_w(model: _Model, b) -> bool:
    r = model.rho_sq(*_balls(b))
    return any(r[i] < model.rmin2[i] or r[i] > model.rmax2[i] for i in range(3))


def _det_positive(model: _Model, b) -> bool:
    return bool(model.det(*_balls(b)) > 0)


def _det_negative(model: _Model, b) -> bool:
    return bool(model.det(*_balls(b)) < 0)


def _prove_label(model: _Model, box, name: str, value: int) -> bool | None:
    """Re-prove one label (1 OUTSIDE, 2 INSIDE) of W or det_positive; None when it claims nothing."""
    tests = {
        ("W", 2): _in_w,
        ("W", 1): _out_w,
        ("det_positive", 2): _det_positive,
        ("det_positive", 1): _det_negative,
    }
    if value == 3:
        return None
    if (name, value) not in tests:
        raise _Refused(f"label {name} = {value!r}: not a label this checker knows (W, det_positive: 1, 2 or 3)")
    fn = tests[(name, value)]
    return _holds_on_box(box, lambda b: fn(model, b))


# --------------------------------------------------------------------------------------
# One checker per claim type
# --------------------------------------------------------------------------------------
def _rho(claim: dict, key: str = "rho") -> tuple[Fraction, Fraction, Fraction]:
    v = _get(claim, key)
    if not isinstance(v, list) or len(v) != 3:
        raise _Refused(f"{key}: expected three exact strings, got {v!r}")
    r = tuple(parse_exact(t, f"{key}[{i}]") for i, t in enumerate(v))
    if any(x <= 0 for x in r):
        raise _Refused(f"{key}: leg lengths must be positive")
    return r  # type: ignore[return-value]


def _strictly_in_limits(g: Geometry, rho) -> bool:
    return all(g.rho_min[i] < rho[i] < g.rho_max[i] for i in range(3))


def _inside(inner, outer) -> bool:
    return all(olo <= lo and hi <= ohi for (lo, hi), (olo, ohi) in zip(inner, outer))


_SIGN = {"WA1": 1, "WA2": -1}
