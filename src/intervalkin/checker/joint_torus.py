"""The torus search in arb: a joint box re-proved off g(S), or a pose box re-proved to hold its singular poses.

Let R = R_1 x R_2 x R_3 be a joint box (exact rational bounds, rho > 0).  Every pose
X = (x, y, phi) with g(X) in R has B1 = A1 + rho_1 (cos theta, sin theta) with rho_1 in
R_1, so a cover of the torus (theta, phi) by cells Theta x Phi gives pose boxes

    P(R, C) = (a_1x + R_1 cos(Theta)) x (a_1y + R_1 sin(Theta)) x Phi

(arb balls) holding every such pose, up to a multiple of 2 pi in phi.  A cell is

* *discarded* when rho_2^2 or rho_3^2 over P(R, C) misses R_2^2 or R_3^2, or det A
  over P(R, C) has a proved sign (natural form, then the centred form in the
  variables (rho_1, theta, phi) of :func:`~intervalkin.checker.taylor.centred_enclosure`),
  or, for a cell still undecided and narrower than ``EXCLUSION_WIDTH`` on both sides, when
  Krawczyk exclusion proves P(R, C) free of singular poses with joint vector in R
  (:func:`~intervalkin.checker.joint_exclusion.excluded`): no singular pose with its joint
  vector in R lies in the cell;
* *covered* (only when a pose box X is given) when P(R, C), shifted by 2 pi m for
  some m in -2..2, lies inside X, or (small cells only) when, for such a shift meeting X,
  every closed slab of P(R, C) outside one face of X is excluded as above: the cell's
  singular poses with joint vector in R then lie in X (up to the shift).

:func:`torus_search` bisects the cells (theta or phi, whichever moves the pose more)
until each is discarded or covered, within a budget.  All discarded: R does not meet
g(S) (proofs/lemma-clear-joint-box.md, re-proved here without the library).  All
discarded or covered: every singular pose with g(X) in R has a 2 pi-translate in X
(the covering hypothesis of proofs/lemma-fold-joint-box.md).  A cell left undecided
refuses the claim; nothing is assumed.  Standard library and python-flint only.
"""

from __future__ import annotations

import math
from fractions import Fraction

from flint import arb

from intervalkin.checker.joint_exclusion import excluded
from intervalkin.checker.model import ArbModel, exact_ball, interval_ball
from intervalkin.checker.taylor import centred_enclosure

__all__ = ["TORUS_BUDGET", "JointBox", "torus_search"]

#: Cells of theta and of phi at the start.
THETA_CELLS, PHI_CELLS = 16, 24
#: Cell evaluations allowed per joint box before the search gives up (the claim is then refused).
TORUS_BUDGET = 30000
#: A cell narrower than this (radians, both sides) that is still undecided stops the search at once.
MIN_WIDTH = 1e-9
#: An undecided cell narrower than this (radians, both sides) is also tried by Krawczyk exclusion
#: (:func:`~intervalkin.checker.joint_exclusion.excluded`); wider cells are only bisected.
EXCLUSION_WIDTH = 1e-2
#: A float just above pi: the cells cover [-TOP, TOP]^2, which holds [-pi, pi]^2 (checked in arb below).
TOP = math.nextafter(math.pi, math.inf)

#: (lo, hi) exact rational bounds of rho_1, rho_2, rho_3.
JointBox = tuple[tuple[Fraction, Fraction], ...]


class _Search:
    """One joint box R (and optionally a pose box X) on the torus."""

    def __init__(self, model: ArbModel, box: JointBox, pose=None):
        if not arb(TOP) > arb.pi():
            raise AssertionError("TOP must exceed pi")  # cannot happen: TOP is the float after pi
        self.model = model
        self.r1 = arb.union(exact_ball(box[0][0]), exact_ball(box[0][1]))
        self.lo2 = [exact_ball(lo * lo) for lo, _ in box]
        self.hi2 = [exact_ball(hi * hi) for _, hi in box]
        self.a1x, self.a1y = model.A[0]
        self.reach = max(float(v.upper()) for v in model.L) + 1.0
        self.r1_hi = float(box[0][1])
        self.r_sq = [arb.union(lo, hi) for lo, hi in zip(self.lo2, self.hi2)]
        self.pose = None
        if pose is not None:
            self.pose = [(arb(lo), arb(hi)) for lo, hi in pose]
            two_pi = 2 * arb.pi()
            self.shifts = [m * two_pi for m in (0, 1, -1, 2, -2)]

    def _covered(self, x, y, p) -> bool:
        (xl, xh), (yl, yh), (pl, ph) = self.pose
        if not (x >= xl and x <= xh and y >= yl and y <= yh):
            return False
        return any(p + s >= pl and p + s <= ph for s in self.shifts)

    def _det_centred(self, t, p):
        m = self.model

        def f(r, th, ph):
            return m.det(self.a1x + r * th.cos(), self.a1y + r * th.sin(), ph)
        return centred_enclosure(f, [self.r1, t, p])

    def settled(self, th: tuple[float, float], ph: tuple[float, float]) -> bool:
        """PROVED: the cell holds no singular pose with g in R, or (with a pose box) its pose box lies in X."""
        t, p = interval_ball(*th), interval_ball(*ph)
        x = self.a1x + self.r1 * t.cos()
        y = self.a1y + self.r1 * t.sin()
        r = self.model.rho_sq(x, y, p)
        for j in (1, 2):
            if r[j] < self.lo2[j] or r[j] > self.hi2[j]:
                return True
        d = self.model.det(x, y, p)
        if d > 0 or d < 0:
            return True
        if self.pose is not None and self._covered(x, y, p):
            return True
        d = self._det_centred(t, p)
        if d > 0 or d < 0:
            return True
        if not (th[1] - th[0] < EXCLUSION_WIDTH and ph[1] - ph[0] < EXCLUSION_WIDTH):
            return False
        if excluded(self.model, [x, y, p], self.r_sq):
            return True
        return self.pose is not None and self._outside_excluded(x, y, p)

    def _outside_excluded(self, x, y, p) -> bool:
        """PROVED: every singular pose of the cell with g in R has a 2 pi-translate in X.

        For a shift s with p + s meeting X's phi range, each point of the cell (phi shifted by
        s) outside X lies in one of the closed slabs {coordinate a <= lo_a} or {>= hi_a} of the
        cell's box; every such slab is excluded (det A and rho^2 are 2 pi-periodic in phi)."""
        for sh in self.shifts:
            box = [x, y, p + sh]
            if not all(v.overlaps(arb.union(lo, hi)) for v, (lo, hi) in zip(box, self.pose)):
                continue
            slabs = []
            for a, (lo, hi) in enumerate(self.pose):
                v = box[a]
                if not v.lower() >= lo:
                    slabs.append(box[:a] + [arb.union(v.lower(), lo)] + box[a + 1:])
                if not v.upper() <= hi:
                    slabs.append(box[:a] + [arb.union(hi, v.upper())] + box[a + 1:])
            if all(excluded(self.model, b, self.r_sq) for b in slabs):
                return True
        return False

    def run(self, budget: int) -> tuple[bool, str]:
        tc = [-TOP + 2 * TOP * k / THETA_CELLS for k in range(THETA_CELLS + 1)]
        pc = [-TOP + 2 * TOP * k / PHI_CELLS for k in range(PHI_CELLS + 1)]
        tc[0], tc[-1], pc[0], pc[-1] = -TOP, TOP, -TOP, TOP
        stack = [((tc[a], tc[a + 1]), (pc[b], pc[b + 1])) for a in range(THETA_CELLS) for b in range(PHI_CELLS)]
        evals = 0
        while stack:
            th, ph = stack.pop()
            evals += 1
            if evals > budget:
                return False, f"budget of {budget} cell evaluations spent (near theta = {th[0]:.6g}, phi = {ph[0]:.6g})"
            if self.settled(th, ph):
                continue
            wt, wp = th[1] - th[0], ph[1] - ph[0]
            if wt < MIN_WIDTH and wp < MIN_WIDTH:
                return False, f"a cell at theta = {th[0]:.9g}, phi = {ph[0]:.9g} stays undecided at width {MIN_WIDTH}"
            if self.r1_hi * wt >= self.reach * wp:
                mid = th[0] + wt / 2
                stack += [((th[0], mid), ph), ((mid, th[1]), ph)]
            else:
                mid = ph[0] + wp / 2
                stack += [(th, (ph[0], mid)), (th, (mid, ph[1]))]
        return True, f"{evals} torus cells"


def torus_search(model: ArbModel, box: JointBox, pose=None, budget: int = TORUS_BUDGET) -> tuple[bool, str]:
    """(proved, detail): every torus cell of the joint box ``box`` discarded, or covered by ``pose``.

    box : three (lo, hi) exact rational bounds of (rho_1, rho_2, rho_3), 0 < lo < hi.
    pose : None (the clear test: R does not meet g(S)) or three (lo, hi) binary64 bounds
        of (x, y, phi) (the cover test: every singular pose with g in R has a 2 pi-translate
        in the box).  ``detail`` counts the cells, or says where the search stopped.
    """
    return _Search(model, box, pose).run(budget)
